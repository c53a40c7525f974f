#!/usr/bin/env python3
"""The folder rules of docs/architecture.md "Folders and targets", checked on the tree:

1. one folder is one target: every src/<layer>/ has avatarmap_add_library(<layer>) in
   CMakeLists.txt, and every such call names a folder that exists;
2. a source file includes private headers ("<folder>/x.hpp") only from its own layer's folder
   or src/common/ (the front-ends, src/cli/ and bindings/c/src/, likewise);
3. a layer includes only the public headers of itself and of the layers below it (src/ and
   include/avatarmap/ alike), so the include graph follows the layers;
4. tests are laid out like the sources: every tests/<dir>/ holding GoogleTest files
   (*_test.cpp) is a layer's folder.

Usage: check_layers.py [ROOT]. Prints each violation and exits 1, or prints a summary."""

import os
import re
import sys

# The public header folders of each layer (include/avatarmap/<folder>/).
PUBLIC = {
    "solve": ["core", "landmarks", "skeleton", "solve", "time"],
    "io": ["io"],
    "synth": ["synth"],
    "rig": ["rig", "export", "avatar", "jobs"],
    "media": ["media"],
    "capture": ["capture"],
    "live": ["live"],
    "stream": ["stream"],
    "render": ["render"],
}
# Which layers each layer may use (its own included), from the targets' link lines.
BELOW = {
    "common": {"solve", "io"},  # header-only pieces name public pose and landmark types
    "solve": set(),
    "io": {"solve"},
    "synth": {"io", "solve"},
    "rig": {"io", "solve"},
    "media": {"io", "solve"},
    "capture": {"media", "io", "solve"},
    "live": {"capture", "media", "io", "solve", "rig", "stream"},
    "stream": {"rig", "io", "solve"},
    "render": {"stream", "capture", "media", "rig", "io", "solve"},
}
FRONT_ENDS = {"cli": os.path.join("src", "cli"), "c": os.path.join("bindings", "c", "src")}
TEST_FRONT_ENDS = {"c", "cli", "python", "package", "interop", "viewer", "convert", "support",
                   "layers"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def sources(folder):
    for base, _, names in os.walk(folder):
        for name in names:
            if name.endswith((".cpp", ".hpp", ".h", ".c")):
                yield os.path.join(base, name)


def public_owner(include):
    """The layer whose public header `include` ("avatarmap/<folder>/x.hpp") is, or None."""
    parts = include.split("/")
    if len(parts) < 3 or parts[0] != "avatarmap":
        return None
    for layer, folders in PUBLIC.items():
        if parts[1] in folders:
            return layer
    return None


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                           os.path.join(os.path.dirname(__file__), "..", ".."))
    src = os.path.join(root, "src")
    problems = []
    layers = sorted(d for d in os.listdir(src)
                    if os.path.isdir(os.path.join(src, d)) and d not in FRONT_ENDS)
    cmake = open(os.path.join(root, "CMakeLists.txt"), encoding="utf-8").read()
    declared = set(re.findall(r"^avatarmap_add_library\((\w+)\)", cmake, re.M))
    for layer in layers:
        if layer not in declared:
            problems.append("src/%s/ has no avatarmap_add_library(%s) in CMakeLists.txt"
                            % (layer, layer))
        if layer not in BELOW:
            problems.append("src/%s/ is not a layer this check knows (add it to BELOW)" % layer)
    for name in declared - set(layers):
        problems.append("avatarmap_add_library(%s) names no folder src/%s/" % (name, name))

    checked = 0
    places = [(layer, os.path.join(src, layer)) for layer in layers]
    places += [(layer, os.path.join(root, folder)) for layer, folder in FRONT_ENDS.items()]
    places += [(layer, os.path.join(root, "include", "avatarmap", folder))
               for layer, folders in PUBLIC.items() for folder in folders]
    for layer, folder in places:
        if not os.path.isdir(folder):
            continue
        front_end = layer in FRONT_ENDS
        for path in sources(folder):
            checked += 1
            rel = os.path.relpath(path, root)
            text = open(path, encoding="utf-8", errors="replace").read()
            for include in INCLUDE.findall(text):
                first = include.split("/")[0]
                owner = public_owner(include)
                if owner is not None:
                    if not front_end and owner != layer and owner not in BELOW.get(layer, ()):
                        problems.append("%s includes %s: layer %s may not use layer %s"
                                        % (rel, include, layer, owner))
                elif first in layers or first in FRONT_ENDS:
                    if front_end and layer == "c" and "/" not in include:
                        continue
                    if first not in (layer, "common"):
                        problems.append("%s includes the private header %s of src/%s/ "
                                        "(share it through src/common/)" % (rel, include, first))

    tests = os.path.join(root, "tests")
    for entry in sorted(os.listdir(tests)):
        folder = os.path.join(tests, entry)
        if not os.path.isdir(folder) or entry in TEST_FRONT_ENDS:
            continue
        has_tests = any(n.endswith("_test.cpp") for _, _, names in os.walk(folder) for n in names)
        if has_tests and entry not in layers:
            problems.append("tests/%s/ holds GoogleTest files but src/%s/ is no layer" %
                            (entry, entry))

    for p in problems:
        print(p)
    if problems:
        print("%d problem(s): see docs/architecture.md \"Folders and targets\"" % len(problems))
        return 1
    print("layers: %d folders, %d files checked, no problem" % (len(layers), checked))
    return 0


if __name__ == "__main__":
    sys.exit(main())
