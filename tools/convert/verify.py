#!/usr/bin/python3
"""Check tflite2onnx numerically on real MediaPipe models.

For each model: convert, run the ONNX with ONNX Runtime (through the small
C++ runner tools/convert/ort_run.cpp, since Debian's Python has no
onnxruntime), run the independent numpy interpreter (tflite_numpy_ref.py) on
the same input, print the max abs difference per output.  Inputs: uniform
random in the model's input range, and a real 8-bit image crop (a PNG from
the shared data, resampled to the model's input size).  Where a third-party
conversion (zaru_*.onnx, NCHW input) exists, its outputs are compared too.

Usage: /usr/bin/python3 tools/convert/verify.py [--models DIR] --ort-run PATH
           [--zaru DIR] [--image PNG] [--work DIR] [name ...]
Exit status 1 when any difference exceeds --tol (default 1e-3 relative to the
output's magnitude, see check()); 77 (skipped) when no model named (or none at
all) is in --models (default $AVATARMAP_MODELS).
"""

import argparse
import os
import struct
import subprocess
import sys
import tempfile
import zlib

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from tflite2onnx import convert_file  # noqa: E402
from tflite_numpy_ref import Interpreter  # noqa: E402

MODELS = {  # name -> outputs to drop as a second variant
    "hand_landmark_lite": None, "hand_landmark_full": None,
    "palm_detection_lite": None, "palm_detection_full": None,
    "pose_detection": None, "face_detection_short_range": None, "face_landmark": None,
    "face_landmark_with_attention": None,
    "pose_landmark_lite": "Identity_2,Identity_3", "pose_landmark_full": "Identity_2,Identity_3",
    "pose_landmark_heavy": "Identity_2,Identity_3",
}
ZARU = {"hand_landmark_lite": "zaru_hand_landmark_lite.onnx",
        "palm_detection_lite": "zaru_palm_detection_lite.onnx"}


def read_png_rgb(path):
    """8-bit RGB / RGBA non-interlaced PNG -> (H, W, 3) uint8."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, hdr = 8, b"", None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            hdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    w, h, depth, ctype, _, _, interlace = hdr
    assert depth == 8 and ctype in (2, 6) and interlace == 0, "unsupported PNG"
    bpp = 3 if ctype == 2 else 4
    raw = zlib.decompress(idat)
    stride = w * bpp
    img = np.zeros((h, stride), np.uint8)
    prev = np.zeros(stride, np.int32)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int32)
        cur = np.zeros(stride, np.int32)
        for x in range(stride):
            a = cur[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if f == 0:
                p = 0
            elif f == 1:
                p = a
            elif f == 2:
                p = b
            elif f == 3:
                p = (a + b) // 2
            else:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[x] = (line[x] + p) & 255
        img[y] = cur
        prev = cur
    return img.reshape(h, w, bpp)[:, :, :3]


def resample(img, size):
    h, w, _ = img.shape
    ys = ((np.arange(size) + 0.5) * h / size).astype(int)
    xs = ((np.arange(size) + 0.5) * w / size).astype(int)
    return img[ys][:, xs]


def run_ort(ort_run, onnx_path, x, work, threads=1, bench=0):
    inp = os.path.join(work, "in.bin")
    np.ascontiguousarray(x, np.float32).tofile(inp)
    cmd = [ort_run, onnx_path, work, "--threads", str(threads)] + (["--bench", str(bench)] if bench else []) + [inp]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    res, ms = {}, None
    for line in out.splitlines():
        parts = line.split()
        if parts[0] == "median_ms":
            ms = float(parts[1])
            continue
        shape = [int(d) for d in parts[2].split("x")]
        res[parts[1]] = np.fromfile(os.path.join(work, parts[0] + ".bin"), np.float32).reshape(shape)
    return res, ms


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--models", default=os.environ.get("AVATARMAP_MODELS", ""),
                    help="directory with the .tflite files (default $AVATARMAP_MODELS)")
    ap.add_argument("--ort-run", required=True, help="ort_run binary built from ort_run.cpp")
    ap.add_argument("--zaru", default="", help="directory with zaru_*.onnx third-party conversions")
    ap.add_argument("--image", default="", help="8-bit RGB PNG crop used as real input")
    ap.add_argument("--test-data-image", default="",
                    help="like --image, relative to $AVATARMAP_TEST_DATA (ignored when that is unset)")
    ap.add_argument("--work", default="")
    ap.add_argument("--bench", type=int, default=0, help="also time N runs with ORT (1 thread)")
    ap.add_argument("--tol", type=float, default=1e-3)
    ap.add_argument("names", nargs="*")
    a = ap.parse_args(argv)
    work = a.work or tempfile.mkdtemp(prefix="tflite2onnx_")
    if a.models and os.path.basename(os.path.normpath(a.models)) == "onnx" and os.path.isdir(a.models) \
            and not any(f.endswith(".tflite") for f in os.listdir(a.models)):
        a.models = os.path.dirname(os.path.normpath(a.models))  # $AVATARMAP_MODELS/onnx: the .tflite are above
    names = [n for n in (a.names or MODELS) if a.models and os.path.exists(os.path.join(a.models, n + ".tflite"))]
    if not names:
        print("verify: skipped: none of %s in --models / $AVATARMAP_MODELS (%r); scripts/fetch_models.sh"
              % (", ".join(a.names or MODELS), a.models))
        return 77
    if not a.image and a.test_data_image and os.environ.get("AVATARMAP_TEST_DATA"):
        path = os.path.join(os.environ["AVATARMAP_TEST_DATA"], a.test_data_image)
        a.image = path if os.path.exists(path) else ""
    image = read_png_rgb(a.image) if a.image else None
    worst = 0.0
    for name in names:
        src = os.path.join(a.models, name + ".tflite")
        interp = Interpreter(src)
        shape = interp.m.tensors[interp.m.inputs[0]].shape
        lo = -1.0 if "detection" in name else 0.0     # MediaPipe input ranges
        inputs = [("random", np.random.RandomState(0).uniform(lo, 1.0, shape).astype(np.float32))]
        if image is not None:
            crop = resample(image, shape[1]).astype(np.float32) / 255.0
            inputs.append(("image", (crop * (1.0 - lo) + lo)[None]))
        variants = [("", ())]
        if MODELS.get(name):
            variants.append(("_drop", MODELS[name].split(",")))
        for suffix, drop in variants:
            dst = os.path.join(work, name + suffix + ".onnx")
            convert_file(src, dst, drop)
            for label, x in inputs:
                ref = interp.run(x)
                ref = {interp.m.tensors[i].name: y for i, y in zip(interp.m.outputs, ref)}
                got, ms = run_ort(a.ort_run, dst, x, work, bench=a.bench if label == "random" else 0)
                cells = []
                for k, y in got.items():
                    d = float(np.max(np.abs(y - ref[k])))
                    scale = max(1.0, float(np.max(np.abs(ref[k]))))
                    worst = max(worst, d / scale)
                    cells.append("%s %.2e (|ref|max %.3g)" % (k, d, float(np.max(np.abs(ref[k])))))
                line = "%-26s %-6s vs numpy: %s" % (name + suffix, label, "; ".join(cells))
                if ms is not None:
                    line += "  [ORT 1 thread median %.2f ms]" % ms
                print(line, flush=True)
                if not suffix and name in ZARU and a.zaru:
                    z, _ = run_ort(a.ort_run, os.path.join(a.zaru, ZARU[name]), x.transpose(0, 3, 1, 2), work)
                    cells = ["%s %.2e" % (k, float(np.max(np.abs(z[k] - got[k])))) for k in got if k in z]
                    cells2 = ["%s %.2e" % (k, float(np.max(np.abs(z[k] - ref[k])))) for k in got if k in z]
                    print("%-26s %-6s ours vs zaru: %s | numpy vs zaru: %s"
                          % (name, label, "; ".join(cells), "; ".join(cells2)), flush=True)
    print("worst relative difference vs numpy: %.2e (tolerance %.0e)" % (worst, a.tol))
    return 0 if worst <= a.tol else 1


if __name__ == "__main__":
    sys.exit(main())
