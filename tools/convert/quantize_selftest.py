#!/usr/bin/python3
"""Self-test of tools/convert/quantize.py on a small synthetic model (CTest entry in
tests/convert/).

Checks, without ONNX Runtime: the quantisation arithmetic against values worked out by hand
(activation scale / zero point, per-channel int8 weights, int32 bias), the QDQ structure
(inputs and outputs unchanged, Pad folded into the Conv, Relu6 folded, the output layer kept
float), determinism (two runs give the same bytes), and the refusal of a float Conv between
quantized tensors.  With $AVATARMAP_ORT_RUN (tools/convert/ort_run.cpp) it also runs the
float model, the model with its Pad folded (must give the same output) and the int8 model
(must stay within a bound derived from the quantisation steps); with $AVATARMAP_ORT_CALIB it
checks ort_calib's minimum / maximum against numpy's on the instrumented model.
Exits 77 (skipped) without python3-onnx / numpy.
"""

import os
import shutil
import subprocess
import sys
import tempfile

try:
    import numpy as np
    import onnx
    from onnx import TensorProto, helper, numpy_helper
except ImportError:
    print("skip: needs python3-onnx and python3-numpy")
    sys.exit(77)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import quantize  # noqa: E402

FAILS = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILS.append(what)


def build_model(path):
    """x [1,8,8,3] NHWC -> Transpose -> Pad (bottom/right 1) -> Conv 3x3 s2 (8) -> Clip(0,6)
    -> depthwise Conv 3x3 (8) -> Add(skip) -> MaxPool 2x2 -> Conv 1x1 (4) -> y [1,4,2,2]."""
    rng = np.random.default_rng(1)
    w1 = (rng.standard_normal((8, 3, 3, 3)) * np.array([1, 2, 4, 8, 0.5, 1, 3, 0.1])
          .reshape(8, 1, 1, 1)).astype(np.float32)
    b1 = rng.standard_normal(8).astype(np.float32)
    w2 = rng.standard_normal((8, 1, 3, 3)).astype(np.float32) * 0.5
    b2 = rng.standard_normal(8).astype(np.float32) * 0.1
    w3 = rng.standard_normal((4, 8, 1, 1)).astype(np.float32)
    b3 = rng.standard_normal(4).astype(np.float32)
    inits = [numpy_helper.from_array(a, n) for a, n in [
        (w1, "w1"), (b1, "b1"), (w2, "w2"), (b2, "b2"), (w3, "w3"), (b3, "b3"),
        (np.array([0, 0, 0, 0, 0, 0, 1, 1], np.int64), "pads"),
        (np.array(0.0, np.float32), "lo"), (np.array(6.0, np.float32), "hi")]]
    nodes = [
        helper.make_node("Transpose", ["x"], ["t0"], name="n_Transpose", perm=[0, 3, 1, 2]),
        helper.make_node("Pad", ["t0", "pads"], ["t1"], name="n_Pad"),
        helper.make_node("Conv", ["t1", "w1", "b1"], ["c1"], name="n_Conv1", strides=[2, 2],
                         kernel_shape=[3, 3], pads=[0, 0, 0, 0]),
        helper.make_node("Clip", ["c1", "lo", "hi"], ["r1"], name="n_Clip1"),
        helper.make_node("Conv", ["r1", "w2", "b2"], ["c2"], name="n_Conv2", group=8,
                         kernel_shape=[3, 3], pads=[1, 1, 1, 1]),
        helper.make_node("Add", ["c2", "r1"], ["a2"], name="n_Add2"),
        helper.make_node("MaxPool", ["a2"], ["m2"], name="n_Pool", kernel_shape=[2, 2],
                         strides=[2, 2]),
        helper.make_node("Conv", ["m2", "w3", "b3"], ["y"], name="n_Conv3", kernel_shape=[1, 1]),
    ]
    g = helper.make_graph(nodes, "qtest",
                          [helper.make_tensor_value_info("x", TensorProto.FLOAT, [1, 8, 8, 3])],
                          [helper.make_tensor_value_info("y", TensorProto.FLOAT, [1, 4, 2, 2])],
                          inits)
    m = helper.make_model(g, opset_imports=[helper.make_opsetid("", 13)])
    m.ir_version = 7
    onnx.checker.check_model(m)
    onnx.save(m, path)
    return m


def forward(m, x):
    """numpy float forward pass of the synthetic model; every tensor by name."""
    w = {i.name: numpy_helper.to_array(i).astype(np.float64) for i in m.graph.initializer}
    t = {"x": x.astype(np.float64)}
    t["t0"] = t["x"].transpose(0, 3, 1, 2)
    t["t1"] = np.pad(t["t0"], ((0, 0), (0, 0), (0, 1), (0, 1)))

    def conv(a, k, b, stride=1, pad=0, group=1):
        a = np.pad(a, ((0, 0), (0, 0), (pad, pad), (pad, pad)))
        co, ci, kh, kw = k.shape
        ho = (a.shape[2] - kh) // stride + 1
        wo = (a.shape[3] - kw) // stride + 1
        out = np.zeros((1, co, ho, wo))
        per = co // group
        for o in range(co):
            g0 = (o // per) * ci
            for i in range(ho):
                for j in range(wo):
                    patch = a[0, g0:g0 + ci, i * stride:i * stride + kh, j * stride:j * stride + kw]
                    out[0, o, i, j] = (patch * k[o]).sum() + b[o]
        return out

    t["c1"] = conv(t["t1"], w["w1"], w["b1"], stride=2)
    t["r1"] = np.clip(t["c1"], 0, 6)
    t["c2"] = conv(t["r1"], w["w2"], w["b2"], pad=1, group=8)
    t["a2"] = t["c2"] + t["r1"]
    a = t["a2"]
    t["m2"] = a.reshape(1, 8, 2, 2, 2, 2).max(axis=(3, 5))
    t["y"] = conv(t["m2"], w["w3"], w["b3"])
    return t


def ort(ort_run, model, x, work):
    xin = os.path.join(work, "x.bin")
    x.astype(np.float32).tofile(xin)
    out = os.path.join(work, "out")
    os.makedirs(out, exist_ok=True)
    subprocess.run([ort_run, model, out, xin], check=True, stdout=subprocess.DEVNULL)
    return np.fromfile(os.path.join(out, "0.bin"), np.float32)


def main():
    work = tempfile.mkdtemp(prefix="quantize_selftest_")
    src = os.path.join(work, "float.onnx")
    m = build_model(src)
    rng = np.random.default_rng(7)
    xs = [rng.uniform(0, 1, (1, 8, 8, 3)) for _ in range(8)]

    # -- arithmetic against hand-worked values --
    s, z = quantize.activation_params(-1.0, 3.0)
    check(abs(float(s) - 4 / 255) < 1e-9 and z == 64,
          f"range [-1, 3] -> scale 4/255, zp 64 ({s}, {z})")
    s, z = quantize.activation_params(0.5, 6.0)  # widened to include 0
    check(abs(float(s) - 6 / 255) < 1e-9 and z == 0, "range [0.5, 6] -> [0, 6]: scale 6/255, zp 0")
    s, z = quantize.activation_params(-2.0, -1.0)
    check(z == 255, "range [-2, -1] -> [-2, 0]: zero point 255")

    # -- ranges: numpy forward pass over the inputs --
    ranges = {}
    for x in xs:
        for k, v in forward(m, x).items():
            lo, hi = ranges.get(k, (np.inf, -np.inf))
            ranges[k] = (min(lo, v.min()), max(hi, v.max()))
    ranges_json = os.path.join(work, "ranges.json")
    import json
    with open(ranges_json, "w") as f:
        json.dump({"tensors": {k: {"min": float(lo), "max": float(hi)}
                               for k, (lo, hi) in ranges.items()}}, f)

    ort_calib = os.environ.get("AVATARMAP_ORT_CALIB", "")
    if ort_calib and os.path.exists(ort_calib):
        inst = os.path.join(work, "inst.onnx")
        quantize.instrument(src, inst)
        samples = os.path.join(work, "samples.f32")
        np.concatenate([x.astype(np.float32).ravel() for x in xs]).tofile(samples)
        out = os.path.join(work, "calib.json")
        subprocess.run([ort_calib, inst, samples, out], check=True, stdout=subprocess.DEVNULL)
        got = json.load(open(out))["tensors"]
        worst = max(max(abs(got[k]["min"] - ranges[k][0]), abs(got[k]["max"] - ranges[k][1]))
                    / max(1.0, abs(ranges[k][1])) for k in ranges if k in got)
        check(set(ranges) - {"x"} <= set(got), "ort_calib reports every intermediate tensor")
        check(worst < 1e-4, f"ort_calib min/max = numpy's (worst relative {worst:.2e})")
        lo, hi = got["c1"]["p99.9"]
        check(ranges["c1"][0] <= lo <= hi <= ranges["c1"][1], "percentile range inside min/max")
    else:
        print("skip ort_calib check: set AVATARMAP_ORT_CALIB")

    # -- quantize, structure --
    dst = os.path.join(work, "int8.onnx")
    quantize.quantize(src, ranges_json, dst)
    q = onnx.load(dst)
    ops = [n.op_type for n in q.graph.node]
    check("Pad" not in ops, "the Pad is folded into the Conv")
    conv1 = next(n for n in q.graph.node if n.name == "n_Conv1")
    pads = next(helper.get_attribute_value(a) for a in conv1.attribute if a.name == "pads")
    check(list(pads) == [0, 0, 1, 1], f"folded pads [0, 0, 1, 1] ({list(pads)})")
    check([i.name for i in q.graph.input] == ["x"] and [o.name for o in q.graph.output] == ["y"],
          "graph inputs and outputs unchanged")
    inits = {i.name: numpy_helper.to_array(i) for i in q.graph.initializer}
    wq = inits["n_Conv1_weight_int8"]
    ws = inits["n_Conv1_weight_scale"]
    w1 = numpy_helper.to_array(next(i for i in m.graph.initializer if i.name == "w1"))
    amax = np.abs(w1).reshape(8, -1).max(axis=1)
    check(wq.dtype == np.int8 and ws.shape == (8,), "Conv weights int8, one scale per channel")
    check(np.allclose(ws, amax / 127, rtol=1e-6), "weight scale = max |w| / 127 per channel")
    check(np.abs(wq).reshape(8, -1).max(axis=1).tolist() == [127] * 8,
          "each channel's largest weight maps to +-127")
    check(np.all(np.abs(wq * ws.reshape(8, 1, 1, 1) - w1) <= ws.reshape(8, 1, 1, 1) / 2 + 1e-7),
          "weights round to nearest")
    bq = inits["n_Conv1_bias_int32"]
    sx = float(inits["t0_scale"]) if "t0_scale" in inits else None
    b1 = numpy_helper.to_array(next(i for i in m.graph.initializer if i.name == "b1"))
    check(bq.dtype == np.int32 and sx is not None
          and np.array_equal(bq, np.round(b1 / (sx * ws)).astype(np.int32)),
          "bias int32 = round(b / (input scale x weight scale))")
    check("r1_scale" in inits and "c1_scale" not in inits and int(inits["r1_zero_point"]) == 0,
          "Relu6 folded: its output is quantized (zero point 0), the Conv's raw output is not")
    conv3 = next(n for n in q.graph.node if n.name == "n_Conv3")
    check(conv3.input[1] == "w3", "the output layer keeps its float weights (--float-tail 1)")
    # t0 (Conv1's input), r1 (Relu6 output), c2, a2 (Add), m2 (MaxPool: a2's parameters)
    check(ops.count("QuantizeLinear") == 5,
          f"5 quantized activations ({ops.count('QuantizeLinear')})")
    check(np.isclose(float(inits["m2_scale"]), float(inits["a2_scale"])),
          "MaxPool's output keeps its input's parameters (ORT then runs it on uint8)")

    dst2 = os.path.join(work, "int8_again.onnx")
    quantize.quantize(src, ranges_json, dst2)
    check(open(dst, "rb").read() == open(dst2, "rb").read(), "deterministic: same bytes twice")

    try:
        quantize.quantize(src, ranges_json, os.path.join(work, "bad.onnx"),
                          float_nodes=("n_Conv2",), float_tail=0)
        check(False, "a float Conv between quantized tensors is refused")
    except quantize.QuantizeError as e:
        check("n_Conv2" in str(e), "a float Conv between quantized tensors is refused")
    allf = os.path.join(work, "allfloat.onnx")
    quantize.quantize(src, ranges_json, allf, all_float=True)
    check(not any(n.op_type == "QuantizeLinear" for n in onnx.load(allf).graph.node),
          "--all-float quantizes nothing")

    # -- numerics under ONNX Runtime --
    ort_run = os.environ.get("AVATARMAP_ORT_RUN", "")
    if ort_run and os.path.exists(ort_run):
        worst_f = worst_fold = worst_q = 0.0
        for x in xs:
            ref = forward(m, x)["y"].ravel()
            yf = ort(ort_run, src, x, work)
            ya = ort(ort_run, allf, x, work)
            yq = ort(ort_run, dst, x, work)
            worst_f = max(worst_f, np.abs(yf - ref).max())
            worst_fold = max(worst_fold, np.abs(ya - yf).max())
            worst_q = max(worst_q, np.abs(yq - yf).max())
        check(worst_f < 1e-4, f"ORT float = numpy ({worst_f:.2e})")
        check(worst_fold < 1e-5, f"Pad folded: same output ({worst_fold:.2e})")
        # Bound: each input of the float output layer is off by about two steps of m2's
        # scale at most (its own rounding and what the layers before it passed on); the
        # layer sums 8 of them, weighted by |w3|. Observed: about a quarter of that.
        step = float(quantize.activation_params(*ranges["a2"])[0])
        bound = 2 * step * np.abs(numpy_helper.to_array(
            next(i for i in m.graph.initializer if i.name == "w3"))).sum(axis=1).max()
        check(0 < worst_q < bound,
              f"int8 within the quantisation bound ({worst_q:.4f} < {bound:.4f})")
    else:
        print("skip ORT execution: set AVATARMAP_ORT_RUN")

    shutil.rmtree(work, ignore_errors=True)
    if FAILS:
        print(f"{len(FAILS)} check(s) failed")
        return 1
    print("quantize self-test passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
