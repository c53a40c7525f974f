"""Handles: Solver, Retargeter, Estimator, Live; capture_file."""

from __future__ import annotations

import ctypes
import threading
from dataclasses import dataclass
from typing import Any, Callable, List, Mapping, Optional, Tuple, Union

import numpy as np

from . import _lib
from ._data import (PARTS, Landmarks, PathLike, Poses, _check, _ERR_SIZE, _Handle, _part_array,
                    _path, solver_options)
from ._errors import InvalidArgumentError
from ._lib import (FACE_POINTS, FACE_POINTS_NO_IRIS, POSE_DTYPE, AvmCaptureSummary,
                   AvmEstimatorOptions, AvmFrame, AvmImage, AvmLandmark, AvmLivePerson,
                   AvmLiveStats, AvmPerson, c_value, fn, set_field, text)

FrameLike = Union[Landmarks, Mapping[str, Any]]


def _rest_records(n: int = 1) -> np.ndarray:
    return np.zeros(n, dtype=POSE_DTYPE)


# ---- one frame of landmarks <-> avm_frame -------------------------------------------------


def _c_frame(frame: FrameLike) -> Tuple[AvmFrame, List[np.ndarray]]:
    """An avm_frame over one frame: a Landmarks of length 1, or a mapping with "t" and parts
    of shape (points, 5) or (points, 3) (absent, None or NaN first x: not seen)."""
    if isinstance(frame, Landmarks):
        if len(frame) != 1:
            raise InvalidArgumentError("push: expected one frame, got Landmarks of %d"
                                       % len(frame), 1)
        get = lambda name: getattr(frame, name)[0]  # noqa: E731
        t = frame.t[0]
    elif isinstance(frame, Mapping):
        if "t" not in frame:
            raise InvalidArgumentError('push: the frame has no "t" (capture time, seconds)', 1)
        unknown = set(frame) - {"t"} - {name for name, _ in PARTS}
        if unknown:
            raise InvalidArgumentError("push: unknown frame keys %s (parts: %s)" % (
                sorted(unknown), ", ".join(name for name, _ in PARTS)), 1)
        get = frame.get
        t = frame["t"]
    else:
        raise InvalidArgumentError("push: expected Landmarks or a dict, got %s"
                                   % type(frame).__name__, 1)
    c = AvmFrame()
    set_field(c, "t", t, "push: t (capture time, seconds)")
    keep: List[np.ndarray] = []
    for name, points in PARTS:
        value = get(name)
        if value is None:
            continue
        try:
            raw = np.asarray(value)
        except (TypeError, ValueError) as e:  # e.g. ragged lists
            raise InvalidArgumentError("landmarks.%s: not an array of numbers (%s)" % (name, e),
                                       1) from None
        block = _part_array(raw[None], 1, name, points)
        if block is None or np.isnan(block[0, 0, 0]):
            continue  # not seen
        a = block[0]
        if name == "face":
            c.face_count = FACE_POINTS_NO_IRIS if np.isnan(a[FACE_POINTS_NO_IRIS, 0]) \
                else FACE_POINTS
        setattr(c, name, a.ctypes.data_as(ctypes.POINTER(AvmLandmark)))
        keep.append(a)
    return c, keep


def _landmarks_of(c: AvmFrame, t: float) -> Landmarks:
    """A Landmarks of one frame copied from an avm_frame the library filled."""
    out = Landmarks.empty(1)
    out.t[0] = t
    for name, points in PARTS:
        ptr = getattr(c, name)
        if not ptr:
            continue
        n = c.face_count if name == "face" else points
        if name == "face" and n not in (FACE_POINTS_NO_IRIS, FACE_POINTS):
            continue
        src = np.ctypeslib.as_array(ctypes.cast(ptr, ctypes.POINTER(ctypes.c_float)),
                                    shape=(n, 5))
        getattr(out, name)[0, :n] = src
    return out


# ---- solver -------------------------------------------------------------------------------


class Solver(_Handle):
    """A per-frame solver (avm_solver): push frames in capture order, get each solved and
    One-Euro-filtered pose, sample the pose at render times. ``options`` as solve()'s
    (avm_solver_options' fields). Calls are serialised by a lock, so a Solver may be shared
    between threads; close() waits for a call in flight, and calls after it raise
    InvalidArgumentError("Solver is closed"). Different solvers run in parallel (the library
    releases the GIL)."""

    _destroy_name = "avm_solver_destroy"

    def __init__(self, **options: Any) -> None:
        super().__init__()
        o = solver_options(options)
        _check(fn("avm_solver_create")(o, ctypes.byref(self._h)), fn("avm_last_create_error")())

    def _call(self, name: str, *args: Any) -> None:
        with self._use() as h:
            st = fn(name)(h, *args)
            if st != _lib.OK:
                _check(st, fn("avm_solver_last_error")(h))

    def push(self, frame: FrameLike) -> Poses:
        """Solves one frame (a Landmarks of length 1 or a dict ``{"t": s, "pose": (33, 5),
        ...}``) and returns its filtered pose (Poses of length 1). A frame earlier than the
        previous one resets the solver first."""
        c, _keep = _c_frame(frame)
        rec = _rest_records()
        with self._use() as h:
            st = fn("avm_solver_push")(h, ctypes.byref(c))
            if st != _lib.OK:
                _check(st, fn("avm_solver_last_error")(h))
            _check(fn("avm_solver_get_pose")(h, rec.ctypes.data), fn("avm_solver_last_error")(h))
        return Poses.from_records(rec)

    def sample(self, t: float) -> Poses:
        """The pose at render time t (interpolated between the last frames, extrapolated a
        little past the newest, then held); Poses of length 1 with t = t."""
        rec = _rest_records()
        self._call("avm_solver_sample", c_value(ctypes.c_double, t, "sample: t"), rec.ctypes.data)
        return Poses.from_records(rec)

    def reset(self) -> None:
        """Forgets every frame pushed so far (options are kept)."""
        self._call("avm_solver_reset")


# ---- retargeter ---------------------------------------------------------------------------


class Retargeter(_Handle):
    """An avatar's rig bound to the proxy bones (avm_retargeter): proxy poses -> the rig's
    local joint rotations. ``mapping``: None / "auto" (the avatar's humanoid map, else the
    best table), a table name ("mixamo", ...) or a ``.json`` table path. Calls are serialised
    (a lock); close() waits for a call in flight."""

    _destroy_name = "avm_retargeter_destroy"

    def __init__(self, avatar_path: PathLike, mapping: Optional[str] = None) -> None:
        super().__init__()
        m = None if mapping is None else _path(mapping, "mapping")
        _check(fn("avm_retargeter_create")(_path(avatar_path, "avatar_path"), m,
                                           ctypes.byref(self._h)),
               fn("avm_last_create_error")())
        h = self._h
        count = fn("avm_retargeter_joint_count")(h)
        self.joint_names: List[str] = [text(fn("avm_retargeter_joint_name")(h, j))
                                       for j in range(count)]
        self.joint_parents: np.ndarray = np.array(
            [fn("avm_retargeter_joint_parent")(h, j) for j in range(count)], dtype=np.int32)
        self.binding: str = text(fn("avm_retargeter_binding_description")(h))

    @property
    def joint_count(self) -> int:
        return len(self.joint_names)

    def bone_joint(self, bone: Union[int, str]) -> int:
        """The joint driven by proxy bone ``bone`` (index or VRM name), -1 when none."""
        from . import bone_index
        b = bone_index(bone) if isinstance(bone, str) else c_value(ctypes.c_int, bone, "bone")
        with self._use() as h:
            return int(fn("avm_retargeter_bone_joint")(h, b))

    def apply(self, poses: Poses) -> Tuple[np.ndarray, np.ndarray]:
        """(rotations (N, J, 4) {x, y, z, w} local to each joint's parent, hips joint's
        translation (N, 3) in its parent's units) for every pose."""
        if not isinstance(poses, Poses):
            raise InvalidArgumentError("apply: expected avatarmap.Poses, got %s"
                                       % type(poses).__name__, 1)
        rec = np.ascontiguousarray(poses.records)
        n = len(rec)
        rot = np.empty((n, self.joint_count, 4), dtype=np.float32)
        hips = np.empty((n, 3), dtype=np.float32)
        if n:
            with self._use() as h:
                st = fn("avm_retargeter_apply_poses")(h, rec.ctypes.data, n, rot.ctypes.data,
                                                      hips.ctypes.data)
                if st != _lib.OK:
                    _check(st, fn("avm_retargeter_last_error")(h))
        return rot, hips


# ---- capture ------------------------------------------------------------------------------

_MODELS = {"lite": 0, "full": 1, "heavy": 2}
_HAND_MODELS = {"lite": 0, "full": 1}


def _estimator_options(models: Optional[PathLike], hands: bool, face: bool, threads: int,
                       model: str, hand_model: str, mirrored: bool = False,
                       static_images: bool = False) -> AvmEstimatorOptions:
    buf = ctypes.create_string_buffer(4096)  # room for a newer library's struct
    o = AvmEstimatorOptions.from_buffer(buf)
    o._buffer = buf  # type: ignore[attr-defined]
    _check(fn("avm_estimator_options_init_sized")(o, ctypes.sizeof(o)),
           "avm_estimator_options_init_sized failed")
    o.struct_size = ctypes.sizeof(AvmEstimatorOptions)
    folder = models if models is not None else _lib.models_dir_default()
    if folder is not None:
        o._models = _path(folder, "models")  # type: ignore[attr-defined]  # keep alive
        o.models_dir = o._models  # type: ignore[attr-defined]
    if not isinstance(model, str) or model not in _MODELS:
        raise InvalidArgumentError("model %r: expected \"lite\", \"full\" or \"heavy\""
                                   % (model,), 1)
    if not isinstance(hand_model, str) or hand_model not in _HAND_MODELS:
        raise InvalidArgumentError("hand_model %r: expected \"lite\" or \"full\""
                                   % (hand_model,), 1)
    o.model_complexity = _MODELS[model]
    o.hand_model_complexity = _HAND_MODELS[hand_model]
    for name, value in (("hands", hands), ("face", face), ("mirrored", mirrored),
                        ("static_images", static_images), ("threads", threads)):
        set_field(o, name, value)
    return o


def _c_image(image: Any) -> Tuple[AvmImage, np.ndarray]:
    """An avm_image over an (H, W, 3) RGB or (H, W, 4) RGBA uint8 array (rows may be
    padded; anything else is copied to a contiguous array first). A width, height or row
    stride beyond int32_t raises InvalidArgumentError (ctypes would keep its low 32 bits)."""
    a = np.asarray(image)
    if a.dtype != np.uint8 or a.ndim != 3 or a.shape[2] not in (3, 4):
        raise InvalidArgumentError("image: expected an (H, W, 3) RGB or (H, W, 4) RGBA uint8 "
                                   "array, got %s %s" % (a.dtype, a.shape), 1)
    if a.strides[2] != 1 or a.strides[1] != a.shape[2] or a.strides[0] < a.shape[1] * a.shape[2]:
        a = np.ascontiguousarray(a)
    c = AvmImage()
    c.data = a.ctypes.data
    set_field(c, "height", a.shape[0], "image height (shape[0])")
    set_field(c, "width", a.shape[1], "image width (shape[1])")
    set_field(c, "stride_bytes", a.strides[0], "image row stride (strides[0], bytes)")
    c.format = _lib.PIXEL_RGB8 if a.shape[2] == 3 else _lib.PIXEL_RGBA8
    return c, a


@dataclass
class Person:
    """One person of an image (Estimator.process_people): its id (kept while the person is
    followed, never given to anyone else), its slot (0 .. people-1, its place while its id
    lives), its Landmarks of one frame and its Poses of one."""
    id: int
    slot: int
    landmarks: Landmarks
    pose: Poses


@dataclass
class LivePerson:
    """A person a Live handle holds (Live.people()): id, slot and when it was last seen."""
    id: int
    slot: int
    seen_t: float


class Estimator(_Handle):
    """Images -> landmarks -> solved, live-filtered poses (avm_estimator; `avatarmap live`'s
    steps on images you provide). ``models``: the converted models folder (default
    $AVATARMAP_MODELS/onnx, else the one recorded at install time); ``model`` "lite" |
    "full" | "heavy", ``hand_model`` "lite" | "full"; ``threads`` ONNX Runtime threads;
    ``solver_options`` as solve()'s (their filter fields set the live filter). Calls are
    serialised (a lock); close() waits for a call in flight."""

    _destroy_name = "avm_estimator_destroy"

    def __init__(self, models: Optional[PathLike] = None, *, hands: bool = True,
                 face: bool = True, threads: int = 2, model: str = "full",
                 hand_model: str = "full", mirrored: bool = False, static_images: bool = False,
                 people: int = 1, **solver_options_: Any) -> None:
        super().__init__()
        eo = _estimator_options(models, hands, face, threads, model, hand_model, mirrored,
                                static_images)
        set_field(eo, "max_people", people, "people (avm_estimator_options.max_people)")
        so = solver_options(solver_options_)
        _check(fn("avm_estimator_create")(eo, so, ctypes.byref(self._h)),
               fn("avm_last_create_error")())

    def process(self, image: Any, t: float) -> Tuple[Landmarks, Poses]:
        """Estimates the landmarks of one image (capture time t, increasing) and solves them:
        (Landmarks of one frame, NaN for parts not seen; Poses of one)."""
        c_image, _keep = _c_image(image)
        t = c_value(ctypes.c_double, t, "process: t")
        frame = AvmFrame()
        rec = _rest_records()
        with self._use() as h:
            st = fn("avm_estimator_process")(h, ctypes.byref(c_image), t,
                                             ctypes.byref(frame), rec.ctypes.data)
            if st != _lib.OK:
                _check(st, fn("avm_estimator_last_error")(h))
            landmarks = _landmarks_of(frame, t)
        landmarks.image_width, landmarks.image_height = c_image.width, c_image.height
        return landmarks, Poses.from_records(rec)

    def process_people(self, image: Any, t: float) -> List[Person]:
        """Several people (``people`` > 1): every person in one image (capture time t,
        increasing), each solved and filtered on its own, ascending by id
        (avm_estimator_process_people). A person's ``slot`` stays its own while its id lives.
        With people=1: the one person as id 0, slot 0, or [] when no body is seen. Use either
        this or process() on one Estimator."""
        c_image, _keep = _c_image(image)
        t = c_value(ctypes.c_double, t, "process_people: t")
        people = (AvmPerson * _lib.MAX_PEOPLE)()
        count = ctypes.c_int32(0)
        out: List[Person] = []
        with self._use() as h:
            st = fn("avm_estimator_process_people")(h, ctypes.byref(c_image), t, people,
                                                    _lib.MAX_PEOPLE, ctypes.byref(count))
            if st != _lib.OK:
                _check(st, fn("avm_estimator_last_error")(h))
            for p in people[:min(count.value, _lib.MAX_PEOPLE)]:
                landmarks = _landmarks_of(p.frame, t)
                landmarks.image_width, landmarks.image_height = c_image.width, c_image.height
                landmarks.person = np.array([p.id], dtype=np.int32)
                rec = np.frombuffer(ctypes.string_at(ctypes.addressof(p.pose),
                                                     ctypes.sizeof(p.pose)),
                                    dtype=POSE_DTYPE).copy()
                out.append(Person(p.id, p.slot, landmarks, Poses.from_records(rec)))
        return out


@dataclass
class LiveStats:
    """Counters and latency of a Live handle (avm_live_stats)."""
    pushed: int
    processed: int
    dropped: int
    failed: int
    latency_p50_ms: float
    latency_p95_ms: float
    latency_max_ms: float
    newest_t: float


class Live(_Handle):
    """A live capture (avm_live): a camera thread push()es images (copied, never waiting for
    the worker); a worker thread processes the newest; any thread sample()s the pose. Options
    as Estimator's. Any method from any thread: pushes from several threads take turns (a
    lock), sample(), latest() and stats() run beside them. close() waits for the calls in
    flight; calls after it raise InvalidArgumentError("Live is closed")."""

    _destroy_name = "avm_live_destroy"
    _serial = False  # avm_live's functions are for different threads at once

    def __init__(self, models: Optional[PathLike] = None, *, hands: bool = True,
                 face: bool = True, threads: int = 2, model: str = "full",
                 hand_model: str = "full", mirrored: bool = False, static_images: bool = False,
                 people: int = 1, **solver_options_: Any) -> None:
        super().__init__()
        self._push_lock = threading.Lock()
        eo = _estimator_options(models, hands, face, threads, model, hand_model, mirrored,
                                static_images)
        set_field(eo, "max_people", people, "people (avm_estimator_options.max_people)")
        so = solver_options(solver_options_)
        _check(fn("avm_live_create")(eo, so, ctypes.byref(self._h)),
               fn("avm_last_create_error")())

    @staticmethod
    def _error(h: ctypes.c_void_p, st: int) -> None:
        buf = ctypes.create_string_buffer(_ERR_SIZE)
        _check(st, fn("avm_live_last_error")(h, buf, _ERR_SIZE))

    def push(self, image: Any, t: float) -> None:
        """Hands an (H, W, 3|4) uint8 image with capture time t (increasing) to the worker."""
        c_image, _keep = _c_image(image)
        t = c_value(ctypes.c_double, t, "push: t")
        with self._push_lock, self._use() as h:
            st = fn("avm_live_push")(h, ctypes.byref(c_image), t)
            if st != _lib.OK:
                self._error(h, st)

    def _pose(self, name: str, *args: Any) -> Optional[Poses]:
        rec = _rest_records()
        with self._use() as h:
            st = fn(name)(h, *args, rec.ctypes.data)
            if st == _lib.ERROR_END_OF_FILE:
                return None
            if st != _lib.OK:
                self._error(h, st)
        return Poses.from_records(rec)

    def sample(self, t: float) -> Optional[Poses]:
        """The pose at capture time t (Poses of one), None before the first processed image."""
        return self._pose("avm_live_sample", c_value(ctypes.c_double, t, "sample: t"))

    def latest(self) -> Optional[Poses]:
        """The newest processed pose, None before the first."""
        return self._pose("avm_live_latest")

    def people(self) -> List[LivePerson]:
        """The people held now (in view, or unseen for under 1 s), ascending by id
        (avm_live_people). With people=1: one (id 0, slot 0) once an image was processed."""
        held = (AvmLivePerson * _lib.MAX_PEOPLE)()
        count = ctypes.c_int32(0)
        with self._use() as h:
            st = fn("avm_live_people")(h, held, _lib.MAX_PEOPLE, ctypes.byref(count))
            if st != _lib.OK:
                self._error(h, st)
        return [LivePerson(p.id, p.slot, p.seen_t)
                for p in held[:min(count.value, _lib.MAX_PEOPLE)]]

    def sample_person(self, person: int, t: float) -> Optional[Poses]:
        """As sample(), for the person with id ``person`` (people()); None when it is not
        held."""
        return self._pose("avm_live_sample_person",
                          c_value(ctypes.c_int32, person, "sample_person: person"),
                          c_value(ctypes.c_double, t, "sample_person: t"))

    def stats(self) -> LiveStats:
        s = AvmLiveStats()
        with self._use() as h:
            st = fn("avm_live_get_stats")(h, ctypes.byref(s))
            if st != _lib.OK:
                self._error(h, st)
        return LiveStats(**{name: getattr(s, name) for name, _ in AvmLiveStats._fields_})

    def last_error(self) -> str:
        """The message of the last image the worker failed on ("" when none)."""
        buf = ctypes.create_string_buffer(_ERR_SIZE)
        with self._use() as h:
            return text(fn("avm_live_last_error")(h, buf, _ERR_SIZE))


@dataclass
class CaptureSummary:
    """What capture_file() did (avm_capture_summary)."""
    frames: int
    body_frames: int
    left_hand_frames: int
    right_hand_frames: int
    face_frames: int
    frames_not_decoded: int
    image_width: int
    image_height: int
    fps: float
    seconds: float
    people_ids: int = 0  # people=N > 1: distinct ids seen, lines written, frames with people
    person_lines: int = 0
    frames_with_people: int = 0


def capture_file(input: PathLike, out_landmarks: PathLike, *,
                 models: Optional[PathLike] = None, hands: bool = True, face: bool = True,
                 threads: int = 2, model: str = "full", hand_model: str = "full",
                 progress: Optional[Callable[[int, int], Any]] = None,
                 people: int = 1) -> CaptureSummary:
    """``avatarmap capture INPUT -o OUT``: a video file, an image, a folder of images or a
    printf pattern -> ``*.landmarks.jsonl`` (written atomically). ``threads`` 2 runs two
    lanes, 1 one thread. ``progress(done, total)`` is called about twice a second (total 0:
    unknown); an exception it raises is re-raised when the capture returns. ``people`` (1 ..
    8, ``capture --people N``) follows up to that many people, each with a stable id: with
    more than 1 the file is version 2, one line per person in view and frame
    (read_landmarks() gives each row's ``person``; docs/capture-people.md); the summary's
    body_frames, ..., face_frames then count lines."""
    eo = _estimator_options(models, hands, face, threads, model, hand_model)
    set_field(eo, "max_people", people, "people (avm_estimator_options.max_people)")
    summary = AvmCaptureSummary()
    summary.struct_size = ctypes.sizeof(AvmCaptureSummary)
    raised: List[BaseException] = []

    def on_progress(_user: Any, done: int, total: int) -> None:
        if raised:
            return
        try:
            progress(int(done), int(total))  # type: ignore[misc]
        except BaseException as e:  # noqa: B036 - re-raised below, never into C
            raised.append(e)

    callback = _lib.PROGRESS_FN(on_progress) if progress is not None else _lib.PROGRESS_FN()
    err = ctypes.create_string_buffer(_ERR_SIZE)
    st = fn("avm_capture_file")(_path(input, "input"), _path(out_landmarks, "out_landmarks"), eo,
                                ctypes.byref(summary), callback, None, err, _ERR_SIZE)
    if raised:
        raise raised[0]
    _check(st, err.value)
    return CaptureSummary(**{name: getattr(summary, name)
                             for name, _ in AvmCaptureSummary._fields_ if name != "struct_size"})
