"""Exceptions: one per failing avm_status (the C API maps the library's error kinds to those one
to one), carrying the C API's message."""

from __future__ import annotations

from typing import Dict, Type


class AvatarmapError(Exception):
    """A call into the avatarmap C API failed. ``str(e)`` is the C API's message (what
    failed, naming the file, line, field or range); ``status`` is the avm_status value and
    ``status_name`` its description ("invalid argument", "parse error", ...)."""

    status: int = 7  # AVM_ERROR_INTERNAL

    def __init__(self, message: str, status: int = -1) -> None:
        super().__init__(message)
        if status >= 0:
            self.status = status

    @property
    def status_name(self) -> str:
        from ._lib import status_name
        return status_name(self.status)


class InvalidArgumentError(AvatarmapError, ValueError):
    """AVM_ERROR_INVALID_ARGUMENT: an option out of range, an array of the wrong shape,
    times not finite or out of order, ... (also a ValueError)."""
    status = 1


class FileIOError(AvatarmapError, OSError):
    """AVM_ERROR_IO: a file could not be opened, read, written or renamed (also an
    OSError)."""
    status = 2


class ParseError(AvatarmapError):
    """AVM_ERROR_PARSE: a file's content is malformed (the message says FILE:LINE)."""
    status = 3


class UnsupportedError(AvatarmapError):
    """AVM_ERROR_UNSUPPORTED: the feature is not in this build of the library (e.g. capture
    without ONNX Runtime), or the loaded library is older than this package."""
    status = 5


class OutOfMemoryError(AvatarmapError, MemoryError):
    """AVM_ERROR_OUT_OF_MEMORY: memory ran out (an input too large for the process; also a
    MemoryError)."""
    status = 6


class InternalError(AvatarmapError):
    """AVM_ERROR_INTERNAL: a stage failed on valid input (a bug in avatarmap or a library
    beneath it): please report it with the message."""
    status = 7


_BY_STATUS: Dict[int, Type[AvatarmapError]] = {
    1: InvalidArgumentError, 2: FileIOError, 3: ParseError, 5: UnsupportedError,
    6: OutOfMemoryError, 7: InternalError}


def error_for(status: int, message: str) -> AvatarmapError:
    """The exception of a non-OK status; an empty message becomes the status' name."""
    cls = _BY_STATUS.get(status, AvatarmapError)
    if not message:
        from ._lib import status_name
        message = status_name(status)
    return cls(message, status)
