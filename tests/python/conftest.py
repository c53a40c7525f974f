"""Fixtures of the Python package tests (run by CTest: tests/python/CMakeLists.txt).

Environment (CTest sets it): AVATARMAP_C_LIBRARY (the built library), PYTHONPATH (the package
in bindings/python), AVATARMAP_CLI (the built `avatarmap` tool, for references),
AVATARMAP_TEST_DATA (the shared real data), AVATARMAP_MODELS (the capture models). Tests that
need something absent skip and say what.
"""

import os
import subprocess

import pytest


def _env_path(name):
    value = os.environ.get(name)
    return value if value and os.path.exists(value) else None


@pytest.fixture(scope="session")
def cli():
    """Runs the avatarmap tool: cli("solve", IN, "-o", OUT)."""
    exe = _env_path("AVATARMAP_CLI")
    if not exe:
        pytest.skip("AVATARMAP_CLI is not set to the built avatarmap tool (CTest sets it)")

    def run(*args):
        done = subprocess.run([exe] + [str(a) for a in args], capture_output=True, text=True)
        assert done.returncode == 0, "avatarmap %s: %s" % (" ".join(map(str, args)), done.stderr)
        return done.stdout
    return run


@pytest.fixture(scope="session")
def data():
    folder = _env_path("AVATARMAP_TEST_DATA")
    if not folder:
        pytest.skip("AVATARMAP_TEST_DATA is not set: the shared real data is absent")
    return folder


@pytest.fixture(scope="session")
def models():
    root = _env_path("AVATARMAP_MODELS")
    if not root or not os.path.isdir(os.path.join(root, "onnx")):
        pytest.skip("AVATARMAP_MODELS/onnx is absent: the capture models are not prepared "
                    "(scripts/prepare_capture.sh)")
    return os.path.join(root, "onnx")


@pytest.fixture(scope="session")
def synth_file(cli, tmp_path_factory):
    """A 4-second synthetic recording (pose + world, both hands, 478-point face, 1280x720,
    30 fps) with noise and low-visibility bursts, written by `avatarmap synth`."""
    path = tmp_path_factory.mktemp("synth") / "noisy.landmarks.jsonl"
    cli("synth", "-o", path, "--scenario", "noisy", "--seconds", 4, "--seed", 3)
    return path
