"""Landmarks and poses as NumPy arrays; reading, solving and writing whole files."""

from __future__ import annotations

import ctypes
import os
import stat
import threading
import warnings
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np

from . import _lib
from ._errors import InvalidArgumentError, error_for
from ._lib import (BLENDSHAPE_COUNT, BONE_COUNT, EXPRESSION_COUNT, FACE_POINTS, FACE_POINTS_NO_IRIS, HAND_POINTS,
                   POSE_DTYPE, POSE_POINTS, AvmFrameBlock, AvmSolverOptions, c_value, fn,
                   set_field, text)

PathLike = Union[str, "os.PathLike[str]"]

# (field, points per frame) of Landmarks, in avm_frame_block's order.
PARTS: Tuple[Tuple[str, int], ...] = (
    ("pose", POSE_POINTS), ("pose_world", POSE_POINTS),
    ("left_hand", HAND_POINTS), ("left_hand_world", HAND_POINTS),
    ("right_hand", HAND_POINTS), ("right_hand_world", HAND_POINTS),
    ("face", FACE_POINTS))

_ERR_SIZE = 2048
_MAX_PERSON_ID = 999999  # docs/file-formats.md, version 2


def _path(p: PathLike, what: str) -> bytes:
    try:
        b = os.fsencode(p)
    except TypeError:
        raise InvalidArgumentError("%s: expected a path (str or os.PathLike), got %s"
                                   % (what, type(p).__name__), 1) from None
    if b"\0" in b or not b:
        raise InvalidArgumentError("%s: %s" % (what, "a NUL character in %r" % (p,) if b
                                               else "an empty path"), 1)
    return b


def _check(status: int, message: Union[bytes, str, None]) -> None:
    if status != _lib.OK:
        raise error_for(status, message if isinstance(message, str) else text(message))


# ---- data ---------------------------------------------------------------------------------


def _nan_part(n: int, points: int) -> np.ndarray:
    return np.full((n, points, 5), np.nan, dtype=np.float32)


@dataclass
class Landmarks:
    """Frames of MediaPipe landmarks, one row per frame (structure of arrays).

    ``t`` (N,) float64 capture times in seconds; ``pose``, ``pose_world`` (N, 33, 5),
    ``left_hand``, ``left_hand_world``, ``right_hand``, ``right_hand_world`` (N, 21, 5) and
    ``face`` (N, 478, 5) float32 rows of (x, y, z, visibility, presence): image points
    normalised to the image's width and height (y down), world points in metres. A part not
    seen in a frame is NaN there (its first point's x is what counts); a 468-point face has
    rows 468..477 NaN. ``left``/``right`` are the person's sides. ``image_width`` and
    ``image_height`` are pixels (0 unknown), ``fps`` the nominal rate (0 unknown).

    read_landmarks() returns a part that no frame of the file carries as a read-only NaN
    array of the same shape that takes no memory (``numpy.broadcast_to``); the other arrays
    are writable. ``np.array(lm.face)`` gives a writable copy of such a part.

    ``person`` (N,) int32 is each row's person id (docs/file-formats.md, version 2: a file of
    several people has one row per person in view and frame, a frame's people in consecutive
    rows with the same ``t``, ascending by id). read_landmarks() fills it; every row of a
    version-1 file (one person) is person 0. None (landmarks you build) is one person, 0.
    ``person_ids()`` lists the ids, ``for_person(id)`` gives one person's rows: solve() takes
    one person at a time.
    """

    t: np.ndarray
    pose: np.ndarray
    pose_world: np.ndarray
    left_hand: np.ndarray
    left_hand_world: np.ndarray
    right_hand: np.ndarray
    right_hand_world: np.ndarray
    face: np.ndarray
    image_width: int = 0
    image_height: int = 0
    fps: float = 0.0
    person: Optional[np.ndarray] = None

    def __len__(self) -> int:
        return int(np.shape(self.t)[0])

    def _person_column(self) -> Optional[np.ndarray]:
        """``person`` as a (N,) int32 array (None stays None); InvalidArgumentError when it is
        not one integer id in [0, 999999] per row."""
        if self.person is None:
            return None
        p = np.asarray(self.person)
        if p.shape != (len(self),) or (p.size and p.dtype.kind not in "iu"):
            raise InvalidArgumentError("landmarks.person: expected (%d,) integer person ids, "
                                       "got %s of %s" % (len(self), p.shape, p.dtype), 1)
        if p.size and (p.min() < 0 or p.max() > _MAX_PERSON_ID):
            raise InvalidArgumentError("landmarks.person: ids must be in [0, %d], got %d .. %d"
                                       % (_MAX_PERSON_ID, p.min(), p.max()), 1)
        return np.ascontiguousarray(p, dtype=np.int32)

    def person_ids(self) -> List[int]:
        """The distinct person ids of the rows, ascending ([] for no rows; [0] for one
        person without a ``person`` column)."""
        p = self._person_column()
        if p is None:
            return [0] if len(self) else []
        return [int(i) for i in np.unique(p)]

    def for_person(self, person: int) -> "Landmarks":
        """The rows of person ``person`` (an id of person_ids()) as Landmarks of their own, in
        file order, with the same image size and rate: copies, except that a part none of its
        rows carries stays a read-only NaN array that takes no memory. Raises
        InvalidArgumentError naming the ids there are when it has no row."""
        if isinstance(person, bool) or not isinstance(person, (int, np.integer)):
            raise InvalidArgumentError("for_person: expected an integer person id, got %r"
                                       % (person,), 1)
        p = self._person_column()
        if p is None:
            p = np.zeros(len(self), dtype=np.int32)
        rows = np.flatnonzero(p == person)
        if not len(rows):
            raise InvalidArgumentError("for_person: no row of person %d (the ids are %s)"
                                       % (person, ", ".join(map(str, self.person_ids()))
                                          or "none: no rows"), 1)
        n = len(rows)
        parts = {}
        for name, points in PARTS:
            a = getattr(self, name)
            if isinstance(a, np.ndarray) and _never_seen(a):
                parts[name] = np.broadcast_to(np.float32(np.nan), (n,) + a.shape[1:])
            else:
                parts[name] = np.asarray(a)[rows]
        return Landmarks(t=np.asarray(self.t)[rows], image_width=self.image_width,
                         image_height=self.image_height, fps=self.fps, person=p[rows], **parts)

    @classmethod
    def empty(cls, n: int, *, image_width: int = 0, image_height: int = 0,
              fps: float = 0.0) -> "Landmarks":
        """n frames with nothing seen (every point NaN, t zero): fill in what you have."""
        if n < 0:
            raise InvalidArgumentError("Landmarks.empty: n must be >= 0, got %d" % n, 1)
        parts = {name: _nan_part(n, points) for name, points in PARTS}
        return cls(t=np.zeros(n, dtype=np.float64), image_width=image_width,
                   image_height=image_height, fps=fps, person=np.zeros(n, dtype=np.int32),
                   **parts)

    def seen(self, part: str) -> np.ndarray:
        """(N,) bool: whether `part` ("pose", "left_hand", ...) was seen in each frame."""
        return ~np.isnan(np.asarray(getattr(self, part))[:, 0, 0])


@dataclass
class Poses:
    """Proxy poses of the 55 VRM 1.0 humanoid bones (``BONE_NAMES`` order), one per frame.

    ``t`` (N,) float64 seconds; ``hips_position`` (N, 3) float32 metres in VRM space (Y =
    hips height above the soles); ``rotations`` (N, 55, 4) float32 local rotations as
    quaternions {x, y, z, w} (identity = VRM T-pose); ``confidence`` (N, 55) 0..1;
    ``expressions`` (N, 21) weights 0..1 (``EXPRESSION_NAMES`` order); ``foot_contact``
    (N, 2) float32 per foot, [:, 0] left, [:, 1] right: 0 = free .. 1 = planted
    (docs/contacts.md; None = all 0 when writing); ``blendshapes`` (N, 52) float32 ARKit
    blendshape weights 0..1 (``BLENDSHAPE_NAMES`` order; all 0 when the face was not
    solved; None = all 0 when writing). The arrays of poses
    returned by this package are views of one record array laid out as the C API's avm_pose
    (``records``).
    """

    t: np.ndarray
    hips_position: np.ndarray
    rotations: np.ndarray
    confidence: np.ndarray
    expressions: np.ndarray
    foot_contact: Optional[np.ndarray] = None
    blendshapes: Optional[np.ndarray] = None
    _records: Optional[np.ndarray] = field(default=None, repr=False, compare=False)

    def __len__(self) -> int:
        return int(np.shape(self.t)[0])

    @classmethod
    def from_records(cls, records: np.ndarray) -> "Poses":
        """Poses viewing an array of dtype ``POSE_DTYPE`` (no copy)."""
        if records.dtype != POSE_DTYPE or records.ndim != 1:
            raise InvalidArgumentError("Poses.from_records: expected a 1-D array of "
                                       "avatarmap.POSE_DTYPE", 1)
        return cls(t=records["t"], hips_position=records["hips_position"],
                   rotations=records["rotations"], confidence=records["confidence"],
                   expressions=records["expressions"], foot_contact=records["foot_contact"],
                   blendshapes=records["blendshapes"], _records=records)

    @classmethod
    def empty(cls, n: int) -> "Poses":
        """n rest poses (identity rotations, hips at (0, 0.95, 0), confidence 0, t zero)."""
        rec = np.zeros(n, dtype=POSE_DTYPE)
        rec["rotations"][:, :, 3] = 1.0
        rec["hips_position"][:, 1] = 0.95
        return cls.from_records(rec)

    @property
    def records(self) -> np.ndarray:
        """The poses as one array of ``POSE_DTYPE`` (avm_pose's layout): the array these
        fields view when they still do, else a new one assembled from the fields."""
        rec = self._records
        if rec is not None and self._views(rec):
            return rec
        n = len(self)
        rec = np.zeros(n, dtype=POSE_DTYPE)  # padding 0, as the library writes it
        for name, shape in (("t", (n,)), ("hips_position", (n, 3)),
                            ("rotations", (n, BONE_COUNT, 4)), ("confidence", (n, BONE_COUNT)),
                            ("expressions", (n, EXPRESSION_COUNT)), ("foot_contact", (n, 2)),
                            ("blendshapes", (n, BLENDSHAPE_COUNT))):
            value = getattr(self, name)
            if value is None and name in ("foot_contact", "blendshapes"):
                value = np.zeros(shape, dtype=np.float32)
            value = np.asarray(value)
            if value.shape != shape:
                raise InvalidArgumentError("Poses.%s: shape %s, expected %s"
                                           % (name, value.shape, shape), 1)
            rec[name] = value
        return rec

    def _views(self, rec: np.ndarray) -> bool:
        for name in ("t", "hips_position", "rotations", "confidence", "expressions",
                     "foot_contact", "blendshapes"):
            a = getattr(self, name)
            b = rec[name]
            if not isinstance(a, np.ndarray) or a.shape != b.shape or a.strides != b.strides \
                    or a.__array_interface__["data"][0] != b.__array_interface__["data"][0]:
                return False
        return True

    def __getitem__(self, index: Union[int, slice]) -> "Poses":
        """Poses of one frame (an int) or of a slice of frames, as views."""
        rec = self.records
        if isinstance(index, (int, np.integer)):
            i = int(index)
            if i < 0:
                i += len(rec)
            if not 0 <= i < len(rec):
                raise IndexError("pose index %d out of range (%d poses)" % (index, len(rec)))
            return Poses.from_records(rec[i:i + 1])
        return Poses.from_records(rec[index])


# ---- options ------------------------------------------------------------------------------

SOLVER_OPTION_NAMES = tuple(n for n, _ in AvmSolverOptions._fields_ if n != "struct_size")


def solver_options(options: Dict[str, Any]) -> AvmSolverOptions:
    """avm_solver_options from keyword arguments named as its fields (file_filter also as
    "offline" | "live" | "none"). Each value is checked against its C field first
    (_lib.set_field: flags True/False or 0/1, integers within int32_t, finite floats within a
    float's range: InvalidArgumentError naming the option); the C API checks the rest of each
    range."""
    # Room for a newer library's longer struct: *_init writes the library's own size.
    buf = ctypes.create_string_buffer(4096)
    o = AvmSolverOptions.from_buffer(buf)
    o._buffer = buf  # type: ignore[attr-defined]  # keeps the memory alive
    # Sized: the library writes no more than this mirror of the struct holds.
    _check(fn("avm_solver_options_init_sized")(o, ctypes.sizeof(o)),
           "avm_solver_options_init_sized failed")
    o.struct_size = ctypes.sizeof(AvmSolverOptions)  # what this package knows
    for name, value in options.items():
        if name not in SOLVER_OPTION_NAMES:
            raise TypeError("unknown solver option %r (options: %s)"
                            % (name, ", ".join(SOLVER_OPTION_NAMES)))
        if name == "file_filter" and isinstance(value, str):
            if value not in _lib.FILE_FILTERS:
                raise InvalidArgumentError(
                    "file_filter %r: expected \"offline\", \"live\" or \"none\"" % value, 1)
            value = _lib.FILE_FILTERS[value]
        set_field(o, name, value, "solver option " + name)
    return o


# ---- arrays <-> avm_frame_block -----------------------------------------------------------


def _never_seen(a: np.ndarray) -> bool:
    """Whether `a` is one NaN repeated (numpy.broadcast_to: every stride 0), as read_landmarks
    returns a part that no frame of its file carries."""
    return a.size > 0 and not any(a.strides) and bool(np.isnan(a.flat[0]))


def _part_array(value: Any, n: int, name: str, points: int) -> Optional[np.ndarray]:
    """A part as a C-contiguous float32 (n, points, 5) array; None (NULL in C: never seen)
    for None and for one NaN repeated (read_landmarks' part that no frame carries). Accepts
    (n, points, 3) (visibility and presence 1) and, for the face, 468 points."""
    if value is None:
        return None
    ok_points = (points, FACE_POINTS_NO_IRIS) if name == "face" else (points,)
    try:
        raw = np.asarray(value)
        if raw.dtype.kind == "c":
            raise TypeError("complex numbers")
        a = raw if raw.dtype.kind == "f" and _never_seen(raw) else raw.astype(np.float32,
                                                                             copy=False)
    except (TypeError, ValueError) as e:
        raise InvalidArgumentError("landmarks.%s: not an array of numbers (%s)" % (name, e),
                                   1) from None
    if a.ndim != 3 or a.shape[0] != n or a.shape[1] not in ok_points or a.shape[2] not in (3, 5):
        raise InvalidArgumentError(
            "landmarks.%s: shape %s, expected (%d, %s, 5) (or 3 columns: x, y, z)"
            % (name, a.shape, n, " or ".join(str(p) for p in ok_points)), 1)
    if _never_seen(a):
        return None  # no copy of n frames of NaN
    if a.shape[1] != points or a.shape[2] != 5:
        full = np.full((n, points, 5), np.nan, dtype=np.float32)
        full[:, :a.shape[1], :a.shape[2]] = a
        if a.shape[2] == 3:
            full[:, :a.shape[1], 3:] = 1.0
        a = full
    return np.ascontiguousarray(a)


def frame_block(landmarks: Landmarks) -> Tuple[AvmFrameBlock, List[np.ndarray]]:
    """An avm_frame_block over the landmarks' arrays (converted only when they are not
    already C-contiguous float32 of the right shape) and the arrays to keep alive."""
    try:
        t = np.ascontiguousarray(np.asarray(landmarks.t, dtype=np.float64))
    except (TypeError, ValueError) as e:
        raise InvalidArgumentError("landmarks.t: not an array of numbers (%s)" % e, 1) from None
    if t.ndim != 1:
        raise InvalidArgumentError("landmarks.t: shape %s, expected (N,)" % (t.shape,), 1)
    n = t.shape[0]
    block = AvmFrameBlock()
    block.struct_size = ctypes.sizeof(AvmFrameBlock)
    block.count = n
    block.t = t.ctypes.data
    keep = [t]
    for name, points in PARTS:
        a = _part_array(getattr(landmarks, name, None), n, name, points)
        if a is not None:
            setattr(block, name, a.ctypes.data)
            keep.append(a)
    person = landmarks._person_column() if isinstance(landmarks, Landmarks) else None
    if person is not None:
        block.person = person.ctypes.data
        keep.append(person)
    return block, keep


# ---- files --------------------------------------------------------------------------------


class _SerialGate:
    """Calls one at a time (a lock); close() refuses new calls at once and takes the lock, so
    it waits for the call in flight, and the calls queued behind it find the handle closed."""

    __slots__ = ("_owner", "_lock")

    def __init__(self, owner: "_Handle") -> None:
        self._owner = owner
        self._lock = threading.Lock()

    def __enter__(self) -> ctypes.c_void_p:
        if self._owner._closing:  # at once, not after the call in flight
            raise self._owner._closed_error()
        self._lock.acquire()
        if self._owner._closing or not self._owner._h:
            self._lock.release()
            raise self._owner._closed_error()
        return self._owner._h

    def __exit__(self, *exc: object) -> None:
        self._lock.release()

    def close(self, destroy: Any) -> None:
        self._owner._closing = True  # new calls are refused from here on
        with self._lock:
            destroy()


class _SharedGate:
    """Calls side by side (counted); close() refuses new calls at once and waits until the
    count is zero."""

    __slots__ = ("_owner", "_cond", "_busy")

    def __init__(self, owner: "_Handle") -> None:
        self._owner = owner
        self._cond = threading.Condition(threading.Lock())
        self._busy = 0

    def __enter__(self) -> ctypes.c_void_p:
        with self._cond:
            if self._owner._closing or not self._owner._h:
                raise self._owner._closed_error()
            self._busy += 1
            return self._owner._h

    def __exit__(self, *exc: object) -> None:
        with self._cond:
            self._busy -= 1
            if not self._busy:
                self._cond.notify_all()

    def close(self, destroy: Any) -> None:
        with self._cond:
            self._owner._closing = True
            while self._busy:
                self._cond.wait()
            destroy()  # under the lock: a second close() waits for the first to finish


class _Handle:
    """Owns a C handle; closed by close(), a `with` block or garbage collection.

    Every call on the handle goes through `with self._use() as h:`; it raises "<Class> is
    closed" once close() has begun, and close() waits for the calls in flight before
    destroying the handle, so a handle closed by one thread while others use it never reaches
    C freed. With _serial (the C handle is single-threaded: Solver, Retargeter, Estimator,
    readers, clips) calls also wait for each other; a Live lets its calls overlap (its C
    functions are for different threads) and serialises push() itself."""

    _destroy_name = ""
    _serial = True

    def __init__(self) -> None:
        self._h = ctypes.c_void_p()
        self._closing = False  # close() has begun: no new call starts
        self._gate = _SerialGate(self) if self._serial else _SharedGate(self)

    @property
    def closed(self) -> bool:
        return self._closing or not self._h

    def _closed_error(self) -> InvalidArgumentError:
        return InvalidArgumentError("%s is closed" % type(self).__name__, 1)

    def _handle(self) -> ctypes.c_void_p:
        if self.closed:
            raise self._closed_error()
        return self._h

    def _use(self) -> Union[_SerialGate, _SharedGate]:
        """The context of one call (or a few that belong together): the C handle."""
        return self._gate

    def close(self) -> None:
        """Frees the C handle (again: nothing). Waits for the calls in flight on other
        threads; calls made after it began raise InvalidArgumentError("... is closed")."""
        def destroy() -> None:
            h, self._h = self._h, ctypes.c_void_p()
            if h:
                fn(self._destroy_name)(h)
        self._gate.close(destroy)

    def __enter__(self):  # type: ignore[no-untyped-def]
        self._handle()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # interpreter shutdown (the library may be gone), or no __init__
            pass


class _Reader(_Handle):
    _destroy_name = "avm_landmark_reader_destroy"


class _Clip(_Handle):
    _destroy_name = "avm_clip_destroy"

    def __init__(self) -> None:
        super().__init__()
        _check(fn("avm_clip_create")(ctypes.byref(self._h)), fn("avm_last_create_error")())

    def last_error(self) -> bytes:
        return fn("avm_clip_last_error")(self._h)


_READ_BLOCK = 256          # frames per avm_landmark_reader_read call
_MIN_FRAME_BYTES = 8       # '{"t":0}\n': the least text of a frame
_MIN_POINT_BYTES = 8       # '[0,0,0],': the least text of one point
_FIRST_ALLOCATION = 256 << 20  # bytes: the most an array starts with; past it, it grows


def _regular_file_size(path: bytes) -> int:
    """The size of a regular file, from os.stat alone (the file is never opened or read for
    it), or 0: a FIFO, /dev/stdin, a pipe from a shell's <(...), a device, an error (the
    reader reports it)."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return 0
    return st.st_size if stat.S_ISREG(st.st_mode) else 0


class _Rows:
    """A growing array of frames: rows [0, n) hold what was read. It starts at the most rows
    a file of `size` bytes can hold when each costs at least `min_text` bytes of text (never
    more than _FIRST_ALLOCATION bytes; rows never written are pages never touched) and
    doubles when full, so memory follows the frames read."""

    def __init__(self, row_shape: Tuple[int, ...], dtype: Any, size: int, min_text: int,
                 need: int) -> None:
        row_bytes = int(np.prod(row_shape, dtype=np.int64)) * np.dtype(dtype).itemsize
        guess = min(size // min_text, _FIRST_ALLOCATION // row_bytes)
        self.row_bytes = row_bytes
        self.data = np.empty((max(guess, need),) + row_shape, dtype=dtype)

    def reserve(self, n: int, need: int) -> None:
        """Room for `need` rows, keeping rows [0, n)."""
        if need > len(self.data):
            bigger = np.empty((max(need, 2 * len(self.data)),) + self.data.shape[1:],
                              dtype=self.data.dtype)
            bigger[:n] = self.data[:n]
            self.data = bigger

    def address(self, row: int) -> int:
        return self.data.ctypes.data + row * self.row_bytes

    def finish(self, n: int) -> np.ndarray:
        """Rows [0, n), the memory past them given back (realloc in place, no copy)."""
        a, self.data = self.data, np.empty((0,) + self.data.shape[1:], self.data.dtype)
        try:
            a.resize((n,) + a.shape[1:], refcheck=False)  # no view of `a` exists
            return a
        except ValueError:
            return a[:n]


def read_landmarks(path: PathLike) -> Landmarks:
    """Reads a whole ``*.landmarks.jsonl`` file (docs/file-formats.md) into arrays.

    The file is opened once and read once, front to back, so a FIFO, ``/dev/stdin`` or a
    shell's ``<(...)`` reads as a file does. Memory follows the frames read: a part that no
    frame carries takes none (a read-only NaN array, numpy.broadcast_to); a regular file's
    size (os.stat) only sizes the first allocation.

    Every line is a row: a file of several people (version 2) gives each row's id in
    ``person`` (0 for a version-1 file); ``for_person(id)`` takes one person's rows, as
    solve() needs.

    Raises FileIOError (cannot open), ParseError ("FILE:LINE: ..." of the first malformed
    line)."""
    p = _path(path, "read_landmarks")
    size = _regular_file_size(p)
    reader = _Reader()
    _check(fn("avm_landmark_reader_open")(p, ctypes.byref(reader._h)),
           fn("avm_last_create_error")())
    with reader, reader._use() as h:
        w, ht, fps = ctypes.c_int32(), ctypes.c_int32(), ctypes.c_double()
        _check(fn("avm_landmark_reader_header")(h, ctypes.byref(w), ctypes.byref(ht),
                                                ctypes.byref(fps)),
               fn("avm_landmark_reader_last_error")(h))
        # Parts are read straight into their arrays once a frame has carried them; until
        # then into one block of scratch rows, checked after each read.
        scratch = {name: np.empty((_READ_BLOCK, points, 5), dtype=np.float32)
                   for name, points in PARTS}
        t = _Rows((), np.float64, size, _MIN_FRAME_BYTES, _READ_BLOCK)
        person = _Rows((), np.int32, size, _MIN_FRAME_BYTES, _READ_BLOCK)
        parts: Dict[str, Optional[_Rows]] = {name: None for name, _ in PARTS}
        block = AvmFrameBlock()
        block.struct_size = ctypes.sizeof(AvmFrameBlock)
        block.count = _READ_BLOCK
        read = ctypes.c_int64()
        n = 0
        while True:
            t.reserve(n, n + _READ_BLOCK)
            block.t = t.address(n)
            person.reserve(n, n + _READ_BLOCK)
            block.person = person.address(n)
            for name, _ in PARTS:
                rows = parts[name]
                if rows is not None:
                    rows.reserve(n, n + _READ_BLOCK)
                setattr(block, name, rows.address(n) if rows is not None
                        else scratch[name].ctypes.data)
            st = fn("avm_landmark_reader_read")(h, ctypes.byref(block), ctypes.byref(read))
            if st == _lib.ERROR_END_OF_FILE:
                break
            _check(st, fn("avm_landmark_reader_last_error")(h))
            k = read.value
            if k <= 0:
                break
            for name, points in PARTS:
                if parts[name] is None and not np.isnan(scratch[name][:k]).all():
                    rows = _Rows((points, 5), np.float32, size, points * _MIN_POINT_BYTES,
                                 n + _READ_BLOCK)
                    rows.data[:n] = np.nan  # the frames before: not seen
                    rows.data[n:n + k] = scratch[name][:k]
                    parts[name] = rows
            n += k
    out = Landmarks(t=t.finish(n), person=person.finish(n), **{
        name: rows.finish(n) if rows is not None
        else np.broadcast_to(np.float32(np.nan), (n, points, 5))
        for (name, points), rows in zip(PARTS, parts.values())})
    out.image_width, out.image_height, out.fps = int(w.value), int(ht.value), float(fps.value)
    return out


def read_poses(path: PathLike) -> Poses:
    """Reads a whole ``*.pose.jsonl`` file (or a ``.vrma``) into arrays, with the library's
    reader of motion files (avm_clip_read, the one convert_file() uses): the frames in time
    order (sorted stably when the file has them out of order, as convert_file() sorts them).

    Raises FileIOError, ParseError, InvalidArgumentError (a landmark file: solve_file() it)."""
    clip = _Clip.__new__(_Clip)
    _Handle.__init__(clip)
    err = ctypes.create_string_buffer(_ERR_SIZE)
    _check(fn("avm_clip_read")(_path(path, "read_poses"), ctypes.byref(clip._h), err, _ERR_SIZE),
           err.value)
    with clip:
        return _clip_poses(clip)


def _clip_poses(clip: "_Clip") -> Poses:
    n = fn("avm_clip_frame_count")(clip._h)
    rec = np.empty(n, dtype=POSE_DTYPE)
    if n:
        _check(fn("avm_clip_get_poses")(clip._h, 0, n, rec.ctypes.data), clip.last_error())
    return Poses.from_records(rec)


def solve(landmarks: Landmarks, **options: Any) -> Poses:
    """Solves every frame into a proxy pose exactly as ``avatarmap solve`` / solve_file does
    (one avm_solve_frames call: offline smoothing by default, one pose per frame, no
    resampling).

    ``options`` are avm_solver_options' fields by name (``mirror=True``,
    ``file_filter="live"``, ``rotation_min_cutoff=1.2``, ...); the landmarks' image size is
    used when ``image_width``/``image_height`` are not given. The landmarks must be one
    person's: rows of several ``person`` ids raise InvalidArgumentError (solve
    ``landmarks.for_person(id)`` for each of ``landmarks.person_ids()``, or a file with
    ``solve_file(path, person=id)``). Raises InvalidArgumentError (shapes, options, a time
    not finite, several people)."""
    if not isinstance(landmarks, Landmarks):
        raise InvalidArgumentError("solve: expected avatarmap.Landmarks, got %s"
                                   % type(landmarks).__name__, 1)
    if "image_width" not in options and "image_height" not in options \
            and landmarks.image_width > 0 and landmarks.image_height > 0:
        options = dict(options, image_width=landmarks.image_width,
                       image_height=landmarks.image_height)
    o = solver_options(options)
    block, _keep = frame_block(landmarks)  # checks t and the parts first
    ids = landmarks.person_ids()
    if len(ids) > 1:
        raise InvalidArgumentError(
            "solve: the landmarks hold %d people (ids %s): solve one at a time, "
            "solve(landmarks.for_person(id)), or the file with solve_file(path, person=id)"
            % (len(ids), ", ".join(map(str, ids))), 1)
    rec = np.empty(block.count, dtype=POSE_DTYPE)
    err = ctypes.create_string_buffer(_ERR_SIZE)
    _check(fn("avm_solve_frames")(ctypes.byref(block), o, rec.ctypes.data, err, _ERR_SIZE),
           err.value)
    return Poses.from_records(rec)


def solve_file(in_landmarks: PathLike, out_pose: Optional[PathLike] = None,
               **options: Any) -> Optional[Poses]:
    """``avatarmap solve IN -o OUT``: a ``*.landmarks.jsonl`` file into a ``*.pose.jsonl``
    file, written atomically (avm_solve_file), and None. Without ``out_pose`` the same poses
    come back as Poses instead, confidence included (avm_solve_file_to_clip): the fastest way
    from a file to arrays, parsing ahead on a second thread as the CLI does. Options as
    solve()."""
    o = solver_options(options)
    err = ctypes.create_string_buffer(_ERR_SIZE)
    src = _path(in_landmarks, "solve_file")
    if out_pose is not None:
        _check(fn("avm_solve_file")(src, _path(out_pose, "solve_file"), o, err, _ERR_SIZE),
               err.value)
        return None
    clip = _Clip.__new__(_Clip)
    _Handle.__init__(clip)
    _check(fn("avm_solve_file_to_clip")(src, o, ctypes.byref(clip._h), err, _ERR_SIZE),
           err.value)
    with clip:
        return _clip_poses(clip)


def _text_arg(value: Optional[PathLike], what: str) -> Optional[bytes]:
    return None if value is None else _path(value, what)


def write_animation(poses: Poses, path: PathLike, *, fps: float = 0.0,
                    avatar: Optional[PathLike] = None, mapping: Optional[str] = None) -> None:
    """Writes poses as an animation file chosen by the extension: ``.vrma`` (VRM Animation),
    ``.glb`` (the avatar at ``avatar`` animated; required), ``.bvh`` (the proxy skeleton, or
    the avatar's rig with ``avatar``) or ``.pose.jsonl``. ``fps`` > 0 resamples; ``mapping``
    as ``avatarmap convert --rig`` (None = auto). Written atomically.

    Times must be finite and increasing (InvalidArgumentError otherwise)."""
    if not isinstance(poses, Poses):
        raise InvalidArgumentError("write_animation: expected avatarmap.Poses, got %s"
                                   % type(poses).__name__, 1)
    target = _Target(path, fps, avatar, mapping)
    rec = np.ascontiguousarray(poses.records)
    with _Clip() as clip:
        if len(rec):
            _check(fn("avm_clip_add_poses")(clip._h, rec.ctypes.data, len(rec)),
                   clip.last_error())
        target.write(clip)


class _Target:
    """An output's arguments, checked before any work (avm_clip_write's)."""

    def __init__(self, path: PathLike, fps: float, avatar: Optional[PathLike],
                 mapping: Optional[str]) -> None:
        self.path = _path(path, "path")
        self.fps = c_value(ctypes.c_double, fps, "fps")
        self.avatar = _text_arg(avatar, "avatar")
        self.mapping = _text_arg(mapping, "mapping")

    def write(self, clip: _Clip) -> None:
        err = ctypes.create_string_buffer(_ERR_SIZE)
        _check(fn("avm_clip_write")(clip._h, self.path, self.fps, self.avatar, self.mapping,
                                    err, _ERR_SIZE), err.value)


def motion_input_kind(path: PathLike) -> Optional[str]:
    """The kind of motion file convert_file() reads at ``path``, by the library's one rule
    (avm_motion_input_kind; the CLI's ``convert`` uses it too): "landmarks", "poses",
    "vrma" or "bvh", or None when it reads none. The name's extension decides first (any case:
    ``.landmarks.jsonl``, ``.pose.jsonl``, ``.vrma``); else "-" is landmarks; else the first
    bytes of a regular file (a GLB is a .vrma; a JSON header names its format); else a
    ``*.jsonl`` is landmarks."""
    return _motion_input(path)[0]


def _motion_input(path: PathLike) -> Tuple[Optional[str], str]:
    """(kind or None, the path without the extension that decided) by avm_motion_input_kind."""
    src = _path(path, "motion_input_kind")
    stem = ctypes.c_size_t(0)
    kind = _lib.MOTION_INPUTS.get(int(fn("avm_motion_input_kind")(src, ctypes.byref(stem))))
    return kind, os.fsdecode(src[:stem.value])


def convert_file(in_path: PathLike, out_path: PathLike, *, fps: float = 0.0,
                 avatar: Optional[PathLike] = None, mapping: Optional[str] = None,
                 **options: Any) -> int:
    """``avatarmap convert IN -o OUT`` inside the library: the same library job
    (avm_convert_file), so the same input and arguments give the CLI's bytes; returns the
    number of frames read (before any resampling to ``fps``).

    IN is any motion file the library reads (motion_input_kind()): a ``*.landmarks.jsonl``,
    solved first as solve_file(IN) solves it, with ``options`` as solve()'s (solver options
    for another input raise InvalidArgumentError); a ``*.pose.jsonl``; a ``.vrma``. Frames out
    of time order are sorted, for every input and output, with a warning (``warnings.warn``)
    that counts them, as the CLI warns. OUT's extension chooses the format as
    write_animation()'s does; ``fps`` 0 keeps the frames' own times (the CLI's default is 30,
    but for ``.pose.jsonl``), ``avatar`` and ``mapping`` as write_animation(). Written
    atomically."""
    src = _path(in_path, "convert_file")
    dst = _path(out_path, "convert_file")
    buf = ctypes.create_string_buffer(4096)  # room for a newer library's longer struct
    o = _lib.AvmConvertOptions.from_buffer(buf)
    _check(fn("avm_convert_options_init_sized")(o, ctypes.sizeof(o)),
           "avm_convert_options_init_sized failed")
    o.fps = c_value(ctypes.c_double, fps, "fps")
    o.avatar = _text_arg(avatar, "avatar")
    o.mapping = _text_arg(mapping, "mapping")
    solver = solver_options(options) if options else None
    if solver is not None:
        o.solver = ctypes.pointer(solver)
    warnings_seen: List[str] = []
    o.warning = _lib.WARNING_FN(lambda _user, message: warnings_seen.append(text(message)))
    summary = _lib.AvmConvertSummary(struct_size=ctypes.sizeof(_lib.AvmConvertSummary))
    err = ctypes.create_string_buffer(_ERR_SIZE)
    status = fn("avm_convert_file")(src, dst, o, ctypes.byref(summary), err, _ERR_SIZE)
    for message in warnings_seen:
        warnings.warn("convert_file: " + message, stacklevel=2)
    _check(status, err.value)
    return int(summary.frames_read)
