"""Compatibility shims for Blender's own importers, applied only around one call.

Debian 12 ships Blender 3.4 built against Python 3.11 and NumPy 1.24, both newer than that
Blender's bundled add-ons expect:

- the BVH importer (io_anim_bvh.import_bvh.read_bvh) opens files with mode 'rU'; Python 3.11
  removed the 'U' flag ("ValueError: invalid mode: 'rU'");
- the glTF importer (io_scene_gltf2) uses ``np.bool``, an alias NumPy 1.24 removed
  ("module 'numpy' has no attribute 'bool'").

``importer_shims()`` patches the running interpreter only (the importer module's global
``open`` and the ``numpy.bool`` attribute) for the duration of a ``with`` block and restores
what was there afterwards. No file of Blender is touched, and on a Blender whose importers no
longer need them the shims change nothing they use.
"""
import builtins
import contextlib

_MISSING = object()


def _open_without_u(file, mode="r", *args, **kwargs):
    """``open`` that drops the 'U' (universal newlines) flag Python 3.11 rejects; text mode
    already reads every newline convention."""
    if isinstance(mode, str) and "U" in mode:
        mode = mode.replace("U", "") or "r"
    return builtins.open(file, mode, *args, **kwargs)


@contextlib.contextmanager
def importer_shims():
    """Within the block: Blender's BVH importer opens files without 'U', and ``numpy.bool``
    exists. Both are undone on exit (also on an exception)."""
    undo = []
    try:
        try:
            from io_anim_bvh import import_bvh
        except ImportError:  # the BVH add-on is absent: nothing to shim
            import_bvh = None
        if import_bvh is not None:
            previous = import_bvh.__dict__.get("open", _MISSING)
            import_bvh.open = _open_without_u
            undo.append((import_bvh, "open", previous))
        try:
            import numpy
        except ImportError:
            numpy = None
        if numpy is not None and "bool" not in numpy.__dict__:
            numpy.bool = numpy.bool_
            undo.append((numpy, "bool", _MISSING))
        yield
    finally:
        for module, name, previous in reversed(undo):
            if previous is _MISSING:
                module.__dict__.pop(name, None)
            else:
                setattr(module, name, previous)
