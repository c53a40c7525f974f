"""Options declared once: the library's option tables (`avatarmap options --json`, from
include/avatarmap/core/option_table.hpp) against the C API's defaults (avm_*_options_init,
read through the package's ctypes mirrors) and against the mirrors themselves: the same
fields, the same defaults, the same kinds and ranges, the same limits. The mirrors' field
order and offsets are checked against the header by test_layout.py."""

import ctypes
import json
import math
import os
import subprocess

import pytest

from avatarmap import _lib


@pytest.fixture(scope="module")
def tables():
    cli = os.environ.get("AVATARMAP_CLI")
    if not cli or not os.path.isfile(cli):
        pytest.skip("AVATARMAP_CLI (the avatarmap tool) is not given: no option tables to read")
    out = subprocess.run([cli, "options", "--json"], check=True, capture_output=True,
                         text=True, timeout=60).stdout
    return json.loads(out)


def _rows(tables, c_struct):
    """{name: row} of every table row the C struct `c_struct` has."""
    rows = {}
    for table in tables["sets"]:
        if table["c_struct"] != c_struct:
            continue
        for row in table["rows"]:
            if row["in_c"]:
                assert row["name"] not in rows, "%s is in two tables" % row["name"]
                rows[row["name"]] = row
    return rows


def _defaults(mirror, init):
    o = mirror()
    assert _lib.fn(init)(o, ctypes.sizeof(o)) == _lib.OK
    return o


MIRRORS = [(_lib.AvmSolverOptions, "avm_solver_options", "avm_solver_options_init_sized"),
           (_lib.AvmEstimatorOptions, "avm_estimator_options",
            "avm_estimator_options_init_sized")]


@pytest.mark.parametrize("mirror,c_struct,init", MIRRORS)
def test_mirror_fields_are_the_table_rows(tables, mirror, c_struct, init):
    rows = _rows(tables, c_struct)
    fields = [name for name, _ in mirror._fields_ if name != "struct_size"]
    assert sorted(fields) == sorted(rows), (
        "fields only in the mirror: %s; rows only in the tables: %s"
        % (sorted(set(fields) - set(rows)), sorted(set(rows) - set(fields))))


@pytest.mark.parametrize("mirror,c_struct,init", MIRRORS)
def test_c_defaults_are_the_table_defaults(tables, mirror, c_struct, init):
    o = _defaults(mirror, init)
    for name, row in _rows(tables, c_struct).items():
        value = getattr(o, name)
        if row["kind"] == "text":
            assert (value or b"").decode() == row["default"], name
            continue
        assert math.isclose(value, row["default"], rel_tol=1e-6, abs_tol=1e-9), (
            "%s: C default %r, table default %r" % (name, value, row["default"]))


@pytest.mark.parametrize("mirror,c_struct,init", MIRRORS)
def test_mirror_kinds_and_ranges_are_the_tables(tables, mirror, c_struct, init):
    rows = _rows(tables, c_struct)
    kinds = getattr(mirror, "_kinds_", {})
    ranges = getattr(mirror, "_ranges_", {})
    for name, row in rows.items():
        assert (kinds.get(name) == _lib.BOOL) == (row["kind"] == "boolean"), name
        if row["kind"] in ("integer", "choice"):
            assert ranges.get(name) == (row["min"], row["max"]), (
                "%s: mirror range %r, table range %r"
                % (name, ranges.get(name), (row["min"], row["max"])))
    for name in ranges:
        assert name in rows and rows[name]["kind"] in ("integer", "choice"), name


def test_limits_are_the_library_s(tables):
    assert _lib.MAX_FPS == tables["limits"]["max_fps"]
    assert _lib.MAX_MODEL_THREADS == tables["limits"]["max_model_threads"]
    fps = {row["name"]: row for t in tables["sets"] for row in t["rows"]}
    assert fps["output_fps"]["max"] == _lib.MAX_FPS
    assert fps["framerate"]["max"] == _lib.MAX_FPS
    assert fps["threads"]["max"] == _lib.MAX_MODEL_THREADS


def test_python_keyword_defaults_are_the_estimator_table_s(tables):
    """Estimator, Live and capture_file take the estimator options as keywords; their defaults
    are the table's."""
    import inspect

    import avatarmap as am
    rows = _rows(tables, "avm_estimator_options")
    names = {"hands": "hands", "face": "face", "threads": "threads",
             "mirrored": "mirrored", "static_images": "static_images"}
    choices = {"model": "model_complexity", "hand_model": "hand_model_complexity"}
    for fn in (am.Estimator.__init__, am.Live.__init__, am.capture_file):
        params = inspect.signature(fn).parameters
        for kw, name in names.items():
            if kw in params:
                assert params[kw].default == rows[name]["default"], (fn.__qualname__, kw)
        for kw, name in choices.items():
            if kw in params:
                row = rows[name]
                assert params[kw].default == row["choices"].split("|")[int(row["default"])], (
                    fn.__qualname__, kw)


def test_out_of_range_is_refused_with_the_table_s_message(tables):
    """A value out of a row's range is refused by the library with the one message format
    ("avm_solver_options.NAME must be RANGE, got V")."""
    import avatarmap as am
    with pytest.raises(am.InvalidArgumentError, match=r"hips_lean_share must be in \[0, 1\]"):
        am.Solver(hips_lean_share=2.0)
