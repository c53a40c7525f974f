#!/usr/bin/env bash
# The package installed both documented ways finds its library with no environment:
#   install_test.sh pip   PYTHON SOURCE_DIR LIBRARY WORK   (venv --system-site-packages + pip)
#   install_test.sh cmake PYTHON SOURCE_DIR BUILD_DIR WORK (cmake --install --prefix WORK/prefix)
# then, from /, with AVATARMAP_* and PYTHONPATH unset: import, check where the library came
# from, solve a small file. Exit 77 (skipped) when python3-venv is missing.
set -euo pipefail
mode=$1 python=$2 src=$3 what=$4 work=$5
rm -rf "$work" && mkdir -p "$work"
landmarks="$src/tests/python/data/two_frames.landmarks.jsonl"
case "$mode" in
  pip)
    if ! "$python" -m venv --system-site-packages "$work/venv" >/dev/null 2>&1; then
      echo "skipped: $python -m venv failed (Debian: apt-get install python3-venv)"; exit 77
    fi
    cp -r "$src/bindings/python" "$work/src"   # keep the source tree clean (pip builds in place)
    AVATARMAP_C_LIBRARY="$what" AVATARMAP_SOURCE_DIR="$src" \
      "$work/venv/bin/pip" install -q --no-build-isolation --no-index "$work/src"
    run_python="$work/venv/bin/python"
    expect_lib="$work/venv/"
    pythonpath=""
    ;;
  cmake)
    cmake --install "$what" --prefix "$work/prefix" >/dev/null
    pydir=$(ls -d "$work"/prefix/lib/python3*/dist-packages | head -1)
    run_python="$python"
    expect_lib="$work/prefix/lib/libavatarmap_c.so"
    pythonpath="$pydir"
    ;;
  *) echo "usage: $0 pip|cmake PYTHON SOURCE_DIR LIBRARY|BUILD_DIR WORK" >&2; exit 2 ;;
esac
cd /
env -u AVATARMAP_C_LIBRARY -u AVATARMAP_MODELS -u AVATARMAP_MAPPINGS -u PYTHONPATH \
  ${pythonpath:+PYTHONPATH="$pythonpath"} "$run_python" - "$landmarks" "$expect_lib" "$work" <<'PY'
import os, sys
import avatarmap as am
landmarks, expect_lib, work = sys.argv[1:]
assert am.library_path().startswith(expect_lib), (am.library_path(), expect_lib)
assert os.path.dirname(am.__file__).startswith(work), am.__file__
poses = am.solve(am.read_landmarks(landmarks))
assert len(poses) == 2 and poses.rotations.shape == (2, 55, 4)
am.write_animation(poses, os.path.join(work, "out.vrma"))
print("installed package OK:", am.__file__, "library", am.library_path(), am.version())
PY
