#!/usr/bin/python3
"""How far an int8 model's outputs move from its float model's, on real crops.

Usage:
  int8_sensitivity.py compare KIND FLOAT.onnx INT8.onnx CROPS.f32 --ort-calib PATH
      one line: the agreement of INT8 with FLOAT on the crops
  int8_sensitivity.py nodes KIND FLOAT.onnx RANGES.json CROPS.f32 --ort-calib PATH
      [--samples N] [--calibration minmax|p99.9|p99.99|p99.999]
      quantizes one quantizable node at a time (all others float) and prints, per node in
      graph order, the mean landmark difference it causes: which layers to leave float

KIND says how to read the outputs: pose (pose_landmark_*: 33 landmarks x, y of the points the
float model sees, crop pixels; world points, metres), hand (hand_landmark_*: 21 landmarks;
world), face (face_landmark: 468 points), posedet / palmdet / facedet (detectors: box and
keypoint values of the anchors the float model scores above 0.5, crop pixels).  CROPS is what
tools/convert/capture_crops writes (scripts/calibrate_int8.sh); the calibration crops for
`nodes` (choosing on held-out crops would bias the held-out figures).  Runs the models with
ort_calib --outputs (tools/convert/ort_calib.cpp).  docs/capture.md "int8 models" has what
this measured.
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

DETECTORS = {"posedet": (2254, 12), "palmdet": (2016, 18), "facedet": (896, 16)}
PER_SAMPLE = {"pose": 195 + 1 + 64 * 64 * 39 + 117, "hand": 63 + 1 + 1 + 63, "face": 1404 + 1}


def split(kind, a):
    """(points [N, ..., 2] to compare, world [N, ...] or None)."""
    if kind in DETECTORS:
        n, w = DETECTORS[kind]
        a = a.reshape(-1, n * w + n)
        return a[:, :n * w].reshape(-1, n, w), a[:, n * w:], None
    a = a.reshape(-1, PER_SAMPLE[kind])
    if kind == "pose":
        lm = a[:, :195].reshape(-1, 39, 5)[:, :33]
        return lm[..., :2], lm[..., 3], a[:, -117:]
    if kind == "hand":
        return a[:, :63].reshape(-1, 21, 3)[..., :2], None, a[:, 65:]
    return a[:, :1404].reshape(-1, 468, 3)[..., :2], None, None


def agreement(kind, fa, qa):
    """dict: mean, p99, max of the point differences; world max (or None)."""
    pf, sf, wf = split(kind, fa)
    pq, _, wq = split(kind, qa)
    d = np.abs(pf - pq)
    if kind in DETECTORS:
        d = d[sf > 0]  # anchors the float model scores above 0.5 (logit > 0)
    elif kind == "pose":
        d = d[sf > 0]  # points the float model calls visible
    d = d.ravel()
    out = {"mean": float(d.mean()), "p99": float(np.percentile(d, 99)), "max": float(d.max())}
    out["world_max"] = float(np.abs(wf - wq).max()) if wf is not None else None
    return out


def run(ort_calib, model, crops, out):
    subprocess.run([ort_calib, "--outputs", model, crops, out], check=True,
                   stdout=subprocess.DEVNULL)
    return np.fromfile(out, np.float32)


def fmt(a):
    s = f"mean {a['mean']:.3f} p99 {a['p99']:.2f} max {a['max']:.2f}"
    return s + (f" world max {a['world_max']:.4f}" if a["world_max"] is not None else "")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mode", choices=["compare", "nodes"])
    ap.add_argument("kind", choices=sorted(PER_SAMPLE) + sorted(DETECTORS))
    ap.add_argument("float_model")
    ap.add_argument("second", help="INT8.onnx (compare) or RANGES.json (nodes)")
    ap.add_argument("crops")
    ap.add_argument("--ort-calib", required=True)
    ap.add_argument("--samples", type=int, default=30, help="nodes: crops used (the first N)")
    ap.add_argument("--calibration", default="minmax", help="nodes: which ranges (quantize.py)")
    a = ap.parse_args(argv)
    work = tempfile.mkdtemp(prefix="int8_sensitivity_")
    if a.mode == "compare":
        fa = run(a.ort_calib, a.float_model, a.crops, os.path.join(work, "f.out"))
        qa = run(a.ort_calib, a.second, a.crops, os.path.join(work, "q.out"))
        print(f"{os.path.basename(a.second)}: {len(split(a.kind, fa)[0])} crops: "
              f"{fmt(agreement(a.kind, fa, qa))}")
        shutil.rmtree(work, ignore_errors=True)
        return 0
    import contextlib
    import io

    import onnx
    import quantize
    m = onnx.load(a.float_model)
    n_in = 1
    for d in m.graph.input[0].type.tensor_type.shape.dim:
        n_in *= max(1, d.dim_value)
    crops = os.path.join(work, "crops.f32")
    with open(a.crops, "rb") as f, open(crops, "wb") as g:
        g.write(f.read(a.samples * n_in * 4))
    fa = run(a.ort_calib, a.float_model, crops, os.path.join(work, "f.out"))
    names = [n.name for n in m.graph.node if n.op_type in quantize.QUANT_OPS]
    for k, name in enumerate(names):
        q = os.path.join(work, "q.onnx")
        others = tuple(x for x in names if x != name)
        kw = {"float_nodes": others, "calibration": a.calibration}
        try:
            with contextlib.redirect_stdout(io.StringIO()):
                quantize.quantize(a.float_model, a.second, q, **kw)
        except quantize.QuantizeError as e:
            print(f"{k} {name} - ({e})")
            continue
        qa = run(a.ort_calib, q, crops, os.path.join(work, "q.out"))
        print(f"{k} {name} {agreement(a.kind, fa, qa)['mean']:.3f}", flush=True)
    shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
