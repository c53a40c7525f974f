"""Build step of the avatarmap package: the package carries the C library it was built with.

build_py copies libavatarmap_c.so into the package and writes avatarmap/_config.py with the
folders the library needs at run time (models, mapping tables), so the installed package finds
everything without environment variables. The library is taken from $AVATARMAP_C_LIBRARY,
else $AVATARMAP_BUILD_DIR/bindings/c, else the repository's build/bindings/c.
Metadata is in pyproject.toml.
"""

import os
import shutil
import sys

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))
# The repository (for its build/, models cache and mapping tables); AVATARMAP_SOURCE_DIR when
# this folder was copied elsewhere.
ROOT = os.environ.get("AVATARMAP_SOURCE_DIR") or os.path.normpath(os.path.join(HERE, "..", ".."))
LIBRARY = "libavatarmap_c.so"


def find_library():
    env = os.environ.get("AVATARMAP_C_LIBRARY")
    if env:
        candidates = [env]
    else:
        build = os.environ.get("AVATARMAP_BUILD_DIR") or os.path.join(ROOT, "build")
        candidates = [os.path.join(build, "bindings", "c", LIBRARY)]
    for path in candidates:
        if os.path.isfile(path):
            return os.path.realpath(path)
    sys.exit("avatarmap: the C library was not found (looked for %s).\n"
             "Build it first:  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release && "
             "cmake --build build --target avatarmap_c\n"
             "(or set AVATARMAP_C_LIBRARY=/path/to/libavatarmap_c.so, or AVATARMAP_BUILD_DIR)"
             % " or ".join(candidates))


class build_py_with_library(build_py):
    def run(self):
        super().run()
        source = find_library()
        package = os.path.join(self.build_lib, "avatarmap")
        os.makedirs(package, exist_ok=True)
        shutil.copyfile(source, os.path.join(package, LIBRARY))
        os.chmod(os.path.join(package, LIBRARY), 0o755)
        with open(os.path.join(package, "_config.py"), "w", encoding="utf-8") as f:
            f.write('"""Written by setup.py when the package was built."""\n')
            f.write("LIBRARY = None  # the copy beside this file is used\n")
            f.write("BUILT_FROM = %r\n" % source)


class BinaryDistribution(Distribution):
    """The wheel holds a native library: tag it for this platform, not py3-none-any."""

    def has_ext_modules(self):
        return True


# Packages here rather than in pyproject.toml's [tool.setuptools] (beta in Debian 12's
# setuptools 66, which warns).
setup(packages=["avatarmap"], package_data={"avatarmap": ["py.typed"]},
      cmdclass={"build_py": build_py_with_library}, distclass=BinaryDistribution)
