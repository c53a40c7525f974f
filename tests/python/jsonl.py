"""Independent readers of the JSON-lines formats (docs/file-formats.md) for the tests: plain
json, no avatarmap code, so the package's readers and the CLI's writers are checked against
the format's text."""

import json

import numpy as np

PARTS = (("pose", 33), ("pose_world", 33), ("left_hand", 21), ("left_hand_world", 21),
         ("right_hand", 21), ("right_hand_world", 21), ("face", 478))


def _f(v):
    return np.nan if v is None else v


def read_landmarks_json(path):
    """{"t": (N,), part: (N, points, 5) float32 NaN where absent, "header": dict}."""
    header, frames = {}, []
    with open(path, encoding="utf-8") as f:
        for i, line in enumerate(f):
            obj = json.loads(line)
            if i == 0 and obj.get("format") == "avatarmap.landmarks":
                header = obj
                continue
            frames.append(obj)
    n = len(frames)
    out = {"t": np.array([fr["t"] for fr in frames], dtype=np.float64), "header": header}
    for name, points in PARTS:
        a = np.full((n, points, 5), np.nan, dtype=np.float32)
        for i, fr in enumerate(frames):
            pts = fr.get(name)
            if pts is None:
                continue
            for j, p in enumerate(pts):
                row = [_f(v) for v in p] + [1.0] * (5 - len(p))
                a[i, j] = np.float32(row)
        out[name] = a
    return out


def read_poses_json(path, bone_names, expression_names, blendshape_names=()):
    """{"t", "hips_position", "rotations", "confidence", "expressions", "foot_contact",
    "blendshapes"} arrays of a *.pose.jsonl (absent confidence: None; absent foot_contact:
    0, 0; absent blendshapes: 0)."""
    frames = []
    with open(path, encoding="utf-8") as f:
        for i, line in enumerate(f):
            obj = json.loads(line)
            if i == 0 and obj.get("format") == "avatarmap.pose":
                continue
            frames.append(obj)
    n = len(frames)
    rot = np.zeros((n, len(bone_names), 4), dtype=np.float32)
    rot[:, :, 3] = 1
    hips = np.zeros((n, 3), dtype=np.float32)
    hips[:, 1] = 0.95
    conf = np.zeros((n, len(bone_names)), dtype=np.float32) if any(
        "confidence" in fr for fr in frames) else None
    expr = np.zeros((n, len(expression_names)), dtype=np.float32)
    contact = np.zeros((n, 2), dtype=np.float32)
    shapes = np.zeros((n, len(blendshape_names)), dtype=np.float32)
    for i, fr in enumerate(frames):
        unknown = set(fr.get("blendshapes", {})) - set(blendshape_names)
        assert not unknown or not blendshape_names, unknown
        for s, name in enumerate(blendshape_names):
            if name in fr.get("blendshapes", {}):
                shapes[i, s] = np.float32(_f(fr["blendshapes"][name]))
        if "foot_contact" in fr:
            contact[i] = np.clip(np.float32([_f(v) for v in fr["foot_contact"]]), 0, 1)
        if "hips_position" in fr:
            hips[i] = np.float32([_f(v) for v in fr["hips_position"]])
        for b, name in enumerate(bone_names):
            if name in fr.get("bones", {}):
                rot[i, b] = np.float32([_f(v) for v in fr["bones"][name]])
            if conf is not None and name in fr.get("confidence", {}):
                conf[i, b] = np.float32(_f(fr["confidence"][name]))
        for e, name in enumerate(expression_names):
            if name in fr.get("expressions", {}):
                expr[i, e] = np.float32(_f(fr["expressions"][name]))
    return {"t": np.array([fr["t"] for fr in frames], dtype=np.float64), "hips_position": hips,
            "rotations": rot, "confidence": conf, "expressions": expr, "foot_contact": contact,
            "blendshapes": shapes}
