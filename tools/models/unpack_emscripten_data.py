#!/usr/bin/env python3
"""Extracts the files of an Emscripten file package (`*_packed_assets.data`).

MediaPipe's npm packages ship some models inside an Emscripten file package: one `.data`
blob plus a loader `.js` whose `loadPackage({...})` call holds a JSON table of
`{"filename", "start", "end"}` byte ranges into the blob. This tool parses that table and
writes each file into OUT_DIR under its base name (the `/third_party/mediapipe/...` folders
are dropped; MediaPipe's base names are unique).

Usage:
  unpack_emscripten_data.py LOADER_JS DATA_FILE OUT_DIR [--list]

--list prints the table (name, start, end, size) and writes nothing.

A file already in OUT_DIR with the same bytes is left alone; one with different bytes is an
error (two packages disagree about a model of the same name). Exit status: 0 on success,
1 on any error, with a message naming the file. Python 3 standard library only.
"""

import json
import os
import re
import sys
import tempfile

_LOAD_PACKAGE = re.compile(r'loadPackage\((\{"files"\s*:.*?\})\);', re.DOTALL)


def parse_table(loader_path):
    """Returns (files, remote_package_size) from the loader's loadPackage({...}) call."""
    with open(loader_path, encoding="utf-8") as f:
        text = f.read()
    matches = _LOAD_PACKAGE.findall(text)
    if len(matches) != 1:
        raise ValueError(f"{loader_path}: expected one loadPackage({{\"files\": ...}}) call, "
                         f"found {len(matches)}")
    table = json.loads(matches[0])
    files = table["files"]
    for entry in files:
        if not (0 <= entry["start"] <= entry["end"]):
            raise ValueError(f"{loader_path}: bad range for {entry['filename']}: "
                             f"{entry['start']}..{entry['end']}")
    return files, table.get("remote_package_size")


def unpack(loader_path, data_path, out_dir, list_only=False):
    files, package_size = parse_table(loader_path)
    data_size = os.path.getsize(data_path)
    if package_size is not None and package_size != data_size:
        raise ValueError(f"{data_path}: size {data_size} differs from the loader's "
                         f"remote_package_size {package_size}")
    for entry in files:
        if entry["end"] > data_size:
            raise ValueError(f"{data_path}: {entry['filename']} ends at {entry['end']}, past "
                             f"the end of the data ({data_size})")
    if list_only:
        for entry in files:
            print(f"{entry['filename']}\t{entry['start']}\t{entry['end']}\t"
                  f"{entry['end'] - entry['start']}")
        return
    os.makedirs(out_dir, exist_ok=True)
    with open(data_path, "rb") as blob:
        for entry in files:
            name = os.path.basename(entry["filename"])
            if not name or name in (".", ".."):
                raise ValueError(f"{loader_path}: unusable file name {entry['filename']!r}")
            blob.seek(entry["start"])
            payload = blob.read(entry["end"] - entry["start"])
            target = os.path.join(out_dir, name)
            if os.path.exists(target):
                with open(target, "rb") as f:
                    if f.read() == payload:
                        continue
                raise ValueError(f"{target}: already exists with different content than "
                                 f"{entry['filename']} in {data_path}")
            # Write then rename, so an interrupted run never leaves a truncated model.
            fd, tmp = tempfile.mkstemp(dir=out_dir, prefix=f".{name}.")
            with os.fdopen(fd, "wb") as f:
                f.write(payload)
            os.chmod(tmp, 0o644)
            os.replace(tmp, target)
            print(f"  {name} ({len(payload)} bytes)")


def main(argv):
    args = [a for a in argv[1:] if a != "--list"]
    if len(args) != 3:
        print(__doc__.strip().split("\n\n")[2], file=sys.stderr)
        return 1
    try:
        unpack(args[0], args[1], args[2], list_only="--list" in argv[1:])
    except (OSError, ValueError, KeyError, json.JSONDecodeError) as e:
        print(f"unpack_emscripten_data: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
