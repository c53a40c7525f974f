#!/usr/bin/python3
"""Self-test for tflite2onnx on a tiny synthetic TFLite flatbuffer.

Builds (with a minimal flatbuffer writer) a model that uses every operator the
converter maps - float16 weights behind DEQUANTIZE, a CSR-sparse weight behind
DENSIFY, SAME / VALID padding with odd sizes, dilation, depth multiplier,
fused activations - converts it, runs onnx.checker and strict shape
inference, compares against the numpy reference interpreter when an ORT runner
is available ($AVATARMAP_ORT_RUN or --ort-run, see ort_run.cpp), and checks
--drop-outputs pruning.  A second synthetic model holds MediaPipe's custom
operators (Landmarks2TransformMatrix, TransformTensorBilinear and
TransformLandmarks, version 2, options as FlexBuffers) and STRIDED_SLICE: the
FlexBuffer reader is checked on a hand-encoded buffer, and each operator's ONNX
rewrite against the numpy reference on random inputs (with the ORT runner).
When $AVATARMAP_MODELS names a directory of real .tflite files, verify.py runs
on them too (needs the ORT runner).

Exit status 0 on success, 1 on failure; 77 ("skipped") when python3-onnx or
numpy is missing, so CTest can mark it skipped (SKIP_RETURN_CODE 77).
"""

import argparse
import os
import struct
import subprocess
import sys
import tempfile

try:
    import numpy as np
    import onnx  # noqa: F401
except ImportError as e:  # pragma: no cover
    print("selftest: skipped (%s); apt-get install python3-onnx python3-numpy" % e)
    sys.exit(77)

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import tflite2onnx  # noqa: E402
from tflite_numpy_ref import Interpreter, densify_ref  # noqa: E402
from tflite_reader import OPS, Model, read_flexbuffer  # noqa: E402


# ---------------------------------------------------------------- flatbuffer writer
class Writer:
    """Forward flatbuffer writer: parents first, children after (uoffsets point forward)."""

    def __init__(self, ident):
        self.buf = bytearray(struct.pack("<I", 0) + ident)

    def pad_to(self, n, extra=0):
        while (len(self.buf) + extra) % n:
            self.buf.append(0)

    def obj(self, o):
        kind = o[0]
        if kind == "table":
            return self.table(o[1])
        if kind == "vec":
            return self.vector(o[1], o[2])
        if kind == "bytes":
            self.pad_to(16, 4)
            pos = len(self.buf)
            self.buf += struct.pack("<I", len(o[1])) + o[1]
            return pos
        if kind == "str":
            data = o[1].encode()
            self.pad_to(4)
            pos = len(self.buf)
            self.buf += struct.pack("<I", len(data)) + data + b"\0"
            return pos
        if kind == "tables":
            self.pad_to(4)
            pos = len(self.buf)
            self.buf += struct.pack("<I", len(o[1]))
            slots = []
            for _ in o[1]:
                slots.append(len(self.buf))
                self.buf += b"\0\0\0\0"
            for slot, t in zip(slots, o[1]):
                self.patch(slot, self.obj(t))
            return pos
        raise ValueError(kind)

    def vector(self, fmt, values):
        size = struct.calcsize("<" + fmt)
        self.pad_to(max(4, size), 4)
        pos = len(self.buf)
        self.buf += struct.pack("<I", len(values)) + b"".join(struct.pack("<" + fmt, v) for v in values)
        return pos

    def patch(self, at, target):
        struct.pack_into("<I", self.buf, at, target - at)

    def table(self, fields):
        layout, off = [], 4
        for fid in sorted(fields):
            fmt, v = fields[fid]
            size = 4 if fmt == "off" else struct.calcsize("<" + fmt)
            off = (off + size - 1) // size * size
            layout.append((fid, fmt, v, off))
            off += size
        tsize = (off + 3) // 4 * 4
        n = max(fields) + 1 if fields else 0
        self.pad_to(2)
        vt = len(self.buf)
        entries = [0] * n
        for fid, _, _, o in layout:
            entries[fid] = o
        self.buf += struct.pack("<HH", 4 + 2 * n, tsize) + b"".join(struct.pack("<H", e) for e in entries)
        self.pad_to(8)
        tpos = len(self.buf)
        self.buf += bytes(tsize)
        struct.pack_into("<i", self.buf, tpos, tpos - vt)
        for fid, fmt, v, o in layout:
            if fmt != "off":
                struct.pack_into("<" + fmt, self.buf, tpos + o, v)
        for fid, fmt, v, o in layout:
            if fmt == "off":
                self.patch(tpos + o, self.obj(v))
        return tpos

    def finish(self, root):
        self.patch(0, self.obj(root))
        return bytes(self.buf)


# ---------------------------------------------------------------- TFLite model builder
CODES = {v: k for k, v in OPS.items()}
TYPES = {np.dtype(np.float32): 0, np.dtype(np.float16): 1, np.dtype(np.int32): 2}


class TFLiteBuilder:
    def __init__(self):
        self.tensors, self.buffers, self.ops, self.opcodes = [], [b""], [], []

    def tensor(self, shape, data=None, dtype=np.float32, sparsity=None, name=None):
        buf = 0
        if data is not None:
            self.buffers.append(np.ascontiguousarray(data).tobytes())
            buf = len(self.buffers) - 1
            dtype = np.asarray(data).dtype
        f = {0: ("off", ("vec", "i", list(shape))), 1: ("b", TYPES[np.dtype(dtype)]),
             2: ("I", buf), 3: ("off", ("str", name or "t%d" % len(self.tensors)))}
        if sparsity is not None:
            f[6] = ("off", sparsity)
        self.tensors.append(("table", f))
        return len(self.tensors) - 1

    def const(self, array):
        return self.tensor(np.asarray(array).shape, np.asarray(array))

    def op(self, name, inputs, out_shape, options=None, custom=None):
        if name not in self.opcodes:
            self.opcodes.append(name)
        out = self.tensor(out_shape)
        f = {0: ("I", self.opcodes.index(name)), 1: ("off", ("vec", "i", inputs)),
             2: ("off", ("vec", "i", [out]))}
        if options is not None:
            f[3] = ("B", 1)  # union type byte; this reader decodes options by opcode
            f[4] = ("off", ("table", options))
        if custom is not None:
            f[5] = ("off", ("vec", "B", list(custom)))
        self.ops.append(("table", f))
        return out

    def build(self, inputs, outputs, names=None):
        if names:  # rename output tensors
            for i, n in zip(outputs, names):
                self.tensors[i][1][3] = ("off", ("str", n))
        codes = [("table", {0: ("b", 32), 1: ("off", ("str", n[7:])), 2: ("i", 2), 3: ("i", 32)})
                 if n.startswith("CUSTOM:") else
                 ("table", {0: ("b", min(CODES[n], 127)), 2: ("i", 1), 3: ("i", CODES[n])}) for n in self.opcodes]
        sub = ("table", {0: ("off", ("tables", self.tensors)), 1: ("off", ("vec", "i", inputs)),
                         2: ("off", ("vec", "i", outputs)), 3: ("off", ("tables", self.ops)),
                         4: ("off", ("str", "main"))})
        bufs = [("table", {0: ("off", ("bytes", b))} if b else {}) for b in self.buffers]
        model = ("table", {0: ("I", 3), 1: ("off", ("tables", codes)), 2: ("off", ("tables", [sub])),
                           3: ("off", ("str", "avatarmap selftest")), 4: ("off", ("tables", bufs))})
        return Writer(b"TFL3").finish(model)


def conv_opts(pad, sh, sw, act=0, dh=1, dw=1):
    return {0: ("b", pad), 1: ("i", sw), 2: ("i", sh), 3: ("b", act), 4: ("i", dw), 5: ("i", dh)}


def dw_opts(pad, sh, sw, mult, act=0, dh=1, dw=1):
    return {0: ("b", pad), 1: ("i", sw), 2: ("i", sh), 3: ("i", mult), 4: ("b", act), 5: ("i", dw), 6: ("i", dh)}


def csr_sparsity(dense):
    """SparsityParameters for `dense` (rank 4): dims 0-2 DENSE, dim 3 SPARSE_CSR."""
    shape = dense.shape
    rows = dense.reshape(-1, shape[3])
    seg, idx, vals = [0], [], []
    for r in rows:
        nz = np.nonzero(r)[0]
        idx += [int(i) for i in nz]
        vals += [r[i] for i in nz]
        seg.append(len(idx))
    dims = [("table", {0: ("b", 0), 1: ("i", int(s))}) for s in shape[:3]]
    dims.append(("table", {0: ("b", 1), 2: ("B", 1), 3: ("off", ("table", {0: ("off", ("vec", "i", seg))})),
                           4: ("B", 3), 5: ("off", ("table", {0: ("off", ("vec", "B", idx))}))}))
    sp = ("table", {0: ("off", ("vec", "i", [0, 1, 2, 3])), 2: ("off", ("tables", dims))})
    return sp, np.array(vals, dense.dtype)


def synthetic_model():
    rs = np.random.RandomState(7)
    f16 = lambda *s: (rs.randn(*s) * 0.5).astype(np.float16)  # noqa: E731
    b = TFLiteBuilder()
    x = b.tensor([1, 9, 9, 3], name="input")
    w1 = b.op("DEQUANTIZE", [b.const(f16(4, 3, 3, 3))], [4, 3, 3, 3])
    c1 = b.op("CONV_2D", [x, w1, b.const(rs.randn(4).astype(np.float32))], [1, 5, 5, 4], conv_opts(0, 2, 2, act=3))
    w2 = b.op("DEQUANTIZE", [b.const(f16(1, 3, 3, 8))], [1, 3, 3, 8])
    # PAD feeds a conv, not a pool: ORT's Pad fusion folds a zero Pad into a following MaxPool's
    # pads and then rejects pads >= kernel (and zero vs -inf padding would differ anyway).
    p1 = b.op("PAD", [c1, b.const(np.array([[0, 0], [1, 0], [0, 2], [0, 0]], np.int32))], [1, 6, 7, 4])
    d1 = b.op("DEPTHWISE_CONV_2D", [p1, w2, b.const(rs.randn(8).astype(np.float32))], [1, 6, 7, 8],
              dw_opts(0, 1, 1, 2, act=1, dh=2, dw=2))
    m1 = b.op("MAX_POOL_2D", [d1], [1, 3, 4, 8], {0: ("b", 0), 1: ("i", 2), 2: ("i", 2), 3: ("i", 3), 4: ("i", 3)})
    pr = b.op("PRELU", [m1, b.const((rs.rand(1, 1, 8) * 0.3).astype(np.float32))], [1, 3, 4, 8])
    ad = b.op("ADD", [pr, b.const(rs.randn(8).astype(np.float32))], [1, 3, 4, 8], {0: ("b", 0)})
    r1 = b.op("RESIZE_BILINEAR", [ad, b.const(np.array([6, 8], np.int32))], [1, 6, 8, 8],
              {2: ("B", 0), 3: ("B", 1)})
    r2 = b.op("RESIZE_BILINEAR", [ad, b.const(np.array([5, 7], np.int32))], [1, 5, 7, 8],
              {2: ("B", 1), 3: ("B", 0)})
    ds = b.op("DEPTH_TO_SPACE", [r1], [1, 12, 16, 2], {0: ("i", 2)})
    dense = rs.randn(4, 1, 1, 2).astype(np.float16)
    dense[dense < 0.2] = 0
    sp, vals = csr_sparsity(dense)
    sw = b.tensor([4, 1, 1, 2], vals, sparsity=sp)
    w3 = b.op("DEQUANTIZE", [b.op("DENSIFY", [sw], [4, 1, 1, 2])], [4, 1, 1, 2])
    c3 = b.op("CONV_2D", [ds, w3, -1], [1, 12, 16, 4], conv_opts(1, 1, 1))
    o0 = b.op("LOGISTIC", [c3], [1, 12, 16, 4])
    mn = b.op("MEAN", [ad, b.const(np.array([1, 2], np.int32))], [1, 8], {0: ("B", 0)})
    o1 = b.op("FULLY_CONNECTED", [mn, b.const(rs.randn(5, 8).astype(np.float32)),
                                  b.const(rs.randn(5).astype(np.float32))], [1, 5], {0: ("b", 0)})
    o2 = b.op("RESHAPE", [pr, b.const(np.array([1, 96], np.int32))], [1, 96], {0: ("off", ("vec", "i", [1, 96]))})
    q1 = b.op("RESHAPE", [ad, b.const(np.array([1, 24, 4], np.int32))], [1, 24, 4])
    q2 = b.op("RESHAPE", [r2, b.const(np.array([1, 70, 4], np.int32))], [1, 70, 4])
    o3 = b.op("CONCATENATION", [q1, q2], [1, 94, 4], {0: ("i", 1), 1: ("b", 0)})
    cc = b.op("CONCATENATION", [ad, pr], [1, 3, 4, 16], {0: ("i", -1), 1: ("b", 0)})
    o4 = b.op("RELU6", [cc], [1, 3, 4, 16])
    o5 = b.op("MEAN", [ad, b.const(np.array([1], np.int32))], [1, 4, 8], {0: ("B", 0)})
    fc2 = b.op("FULLY_CONNECTED", [r2, b.const(rs.randn(3, 280).astype(np.float32)), -1], [1, 3],
               {0: ("b", 1)})
    o6 = b.op("LOGISTIC", [fc2], [1, 3])
    names = ["heat", "fc", "flat", "concat", "relu6", "mean_h", "fc_flat"]
    return b.build([x], [o0, o1, o2, o3, o4, o5, o6], names), dense


def flexbuffer_map(d):
    """Encode {key: int | float | [int]} as a FlexBuffer map (all widths 4 bytes), written
    from the FlexBuffers format description: keys (C strings), int vectors, the keys vector,
    the map (keys offset, keys width, size, values, one type byte per value), then the root
    (offset, packed type, width)."""
    buf = bytearray()

    def align():
        while len(buf) % 4:
            buf.append(0)

    keys = sorted(d)
    kpos, vpos = {}, {}
    for k in keys:
        kpos[k] = len(buf)
        buf += k.encode() + b"\0"
    for k in keys:
        if isinstance(d[k], list):
            align()
            buf += struct.pack("<I", len(d[k]))
            vpos[k] = len(buf)
            buf += b"".join(struct.pack("<i", v) for v in d[k])
    align()
    buf += struct.pack("<I", len(keys))
    keys_vec = len(buf)
    for k in keys:
        buf += struct.pack("<I", len(buf) - kpos[k])
    buf += struct.pack("<I", len(buf) - keys_vec) + struct.pack("<II", 4, len(keys))
    map_pos = len(buf)
    types = []
    for k in keys:
        v = d[k]
        if isinstance(v, list):
            buf += struct.pack("<I", len(buf) - vpos[k])
            types.append((11 << 2) | 2)   # VECTOR_INT, 4-byte elements
        elif isinstance(v, float):
            buf += struct.pack("<f", v)
            types.append((3 << 2) | 2)    # FLOAT
        else:
            buf += struct.pack("<i", v)
            types.append((1 << 2) | 2)    # INT
    buf += bytes(types)
    buf += struct.pack("<I", len(buf) - map_pos) + bytes([(9 << 2) | 2, 4])  # MAP root
    return bytes(buf)


# The custom-operator model: the input (a 6x7 map, 3 channels) doubles as landmarks
# (x, y, z), 42 of them, scaled into the map's pixel range, so the matrices land on the map.
L2TM_OPTS = {"left_rotation_idx": 2, "right_rotation_idx": 9, "output_width": 4, "output_height": 5,
             "scale_x": 1.5, "scale_y": 1.25, "target_rotation_radians": 0.3,
             "subset_idxs": [1, 3, 4, 7, 8, 11, 13]}  # odd count: the last pairs with itself


def custom_ops_model():
    rs = np.random.RandomState(11)
    b = TFLiteBuilder()
    x = b.tensor([1, 6, 7, 3], name="input")
    lm = b.op("RESHAPE", [x, b.const(np.array([1, 42, 3], np.int32))], [1, 42, 3])
    lm = b.op("MUL", [lm, b.const(np.array([3.0], np.float32))], [1, 42, 3], {0: ("b", 0)})
    lm = b.op("ADD", [lm, b.const(np.array([3.0], np.float32))], [1, 42, 3], {0: ("b", 0)})
    mat = b.op("CUSTOM:Landmarks2TransformMatrix", [lm], [1, 4, 4], custom=flexbuffer_map(L2TM_OPTS))
    smp = b.op("CUSTOM:TransformTensorBilinear", [x, mat], [1, 5, 4, 3],
               custom=flexbuffer_map({"output_height": 5, "output_width": 4}))
    flat = b.op("RESHAPE", [smp, b.const(np.array([1, 30, 2], np.int32))], [1, 30, 2])
    m2 = b.op("MUL", [mat, b.const((1 + 0.1 * rs.randn(1, 4, 4)).astype(np.float32))], [1, 4, 4], {0: ("b", 0)})
    t2 = b.op("CUSTOM:TransformLandmarks", [flat, m2], [1, 30, 2])
    t3 = b.op("CUSTOM:TransformLandmarks", [lm, mat], [1, 42, 3])
    ss = b.op("STRIDED_SLICE", [x, b.const(np.array([0, 1, 5, 0], np.int32)), b.const(np.array([1, 6, 0, 2], np.int32)),
                                b.const(np.array([1, 2, -2, 1], np.int32))], [1, 3, 3, 3],
              {0: ("i", 0), 1: ("i", 0b1100)})  # end_mask on W and C: W 5, 3, 1; C all
    names = ["matrix", "sampled", "landmarks2", "landmarks3", "sliced"]
    return b.build([x], [mat, smp, t2, t3, ss], names)


def run_ort(ort_run, onnx_path, x, work):
    sys.path.insert(0, HERE)
    from verify import run_ort as vr
    return vr(ort_run, onnx_path, x, work)[0]


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--ort-run", default=os.environ.get("AVATARMAP_ORT_RUN", ""))
    ap.add_argument("--models", default=os.environ.get("AVATARMAP_MODELS", ""))
    a = ap.parse_args(argv)
    fails = []

    def check(cond, what):
        print(("ok   " if cond else "FAIL ") + what)
        if not cond:
            fails.append(what)

    # unit facts
    check(tflite2onnx.same_pads(9, 3, 2, 1) == (1, 1), "SAME pads 9/k3/s2")
    check(tflite2onnx.same_pads(6, 3, 2, 1) == (0, 1), "SAME pads put the extra pad at the end")
    check(tflite2onnx.same_pads(5, 3, 1, 2) == (2, 2), "SAME pads with dilation")

    data, dense = synthetic_model()
    work = tempfile.mkdtemp(prefix="tflite2onnx_selftest_")
    src = os.path.join(work, "synthetic.tflite")
    open(src, "wb").write(data)
    m = Model.load(src)
    check(len(m.operators) == 26 and m.tensors[m.inputs[0]].name == "input", "reader parses the synthetic model")
    sp_t = [t for t in m.tensors if t.sparsity][0]
    vals = m.raw_constant(sp_t.index)
    check(np.array_equal(tflite2onnx.densify(vals, sp_t.shape, sp_t.sparsity), dense)
          and np.array_equal(densify_ref(vals, sp_t.shape, sp_t.sparsity), dense), "CSR densify (both implementations)")

    dst = os.path.join(work, "synthetic.onnx")
    om = tflite2onnx.convert_file(src, dst)  # runs onnx.checker + strict shape inference
    ops = {n.op_type for n in om.graph.node}
    want = {"Conv", "Clip", "Relu", "Pad", "MaxPool", "PRelu", "Add", "Resize", "DepthToSpace", "Sigmoid",
            "ReduceMean", "Gemm", "Reshape", "Concat", "Transpose"}
    check(want <= ops, "ONNX graph uses %s" % sorted(want - ops if want - ops else want))
    check(not any(n.op_type in ("Cast", "DequantizeLinear") for n in om.graph.node), "weights folded at conversion")
    outs = [(o.name, [d.dim_value for d in o.type.tensor_type.shape.dim]) for o in om.graph.output]
    check(outs[0] == ("heat", [1, 12, 16, 4]) and outs[2] == ("flat", [1, 96]), "outputs keep TFLite names/shapes")

    dropped = tflite2onnx.convert_file(src, None, ["fc", "fc_flat"])
    check([o.name for o in dropped.graph.output] == ["heat", "flat", "concat", "relu6", "mean_h"]
          and not any(n.op_type == "Gemm" for n in dropped.graph.node), "--drop-outputs prunes the dead subgraph")
    try:
        tflite2onnx.convert_file(src, None, ["nope"])
        check(False, "--drop-outputs rejects unknown names")
    except tflite2onnx.ConversionError:
        check(True, "--drop-outputs rejects unknown names")

    # ---- custom operators
    fb_opts = read_flexbuffer(flexbuffer_map(L2TM_OPTS))
    check(fb_opts == {k: (np.float32(v).item() if isinstance(v, float) else v) for k, v in L2TM_OPTS.items()},
          "FlexBuffer map decodes (ints, floats, int vector)")
    csrc = os.path.join(work, "custom.tflite")
    open(csrc, "wb").write(custom_ops_model())
    cm = Model.load(csrc)
    check([o.version for o in cm.operators if o.op.startswith("CUSTOM:")] == [2, 2, 2, 2]
          and read_flexbuffer(cm.operators[3].custom)["subset_idxs"] == L2TM_OPTS["subset_idxs"],
          "reader keeps custom operators' version and options")
    cdst = os.path.join(work, "custom.onnx")
    cgraph = tflite2onnx.convert_file(csrc, cdst)
    cops = {n.op_type for n in cgraph.graph.node}
    check(not any(n.domain for n in cgraph.graph.node) and {"Gather", "MatMul", "Slice"} <= cops,
          "custom operators become standard ONNX operators")
    # The reference on a known case: identity-like landmarks give the documented matrix.
    pts = np.zeros((1, 42, 3))
    pts[0, 2, :2], pts[0, 9, :2] = (1.0, 1.0), (3.0, 1.0)   # horizontal: rotation = target
    from tflite_numpy_ref import landmarks_to_transform_matrix_ref, transform_tensor_bilinear_ref
    o = dict(L2TM_OPTS, target_rotation_radians=0.0, subset_idxs=[2, 9], scale_x=1.0, scale_y=1.0)
    mref = landmarks_to_transform_matrix_ref(pts, o)[0]
    # box x 1..3 (width 2), y 1..1 (height 0): centre (2, 1); scale 2/4, 0/5; shift -(2, 2.5)
    check(np.allclose(mref, [[0.5, 0, 0, 1.0], [0, 0, 0, 1.0], [0, 0, 1, 0], [0, 0, 0, 1]]),
          "reference Landmarks2TransformMatrix: known answer")
    fmap = np.arange(12, dtype=np.float64).reshape(1, 3, 4, 1)
    ident = np.eye(4)[None]
    check(np.allclose(transform_tensor_bilinear_ref(fmap, ident, (1, 3, 4, 1)), fmap),
          "reference TransformTensorBilinear: identity matrix reproduces the map")
    half = np.eye(4)[None].copy()
    half[0, 0, 3] = 0.5
    shifted = transform_tensor_bilinear_ref(fmap, half, (1, 3, 4, 1))[0, :, :, 0]
    check(np.allclose(shifted[:, :3], fmap[0, :, :3, 0] + 0.5) and np.allclose(shifted[:, 3], 0),
          "reference TransformTensorBilinear: half-pixel shift interpolates, outside is 0")

    x = np.random.RandomState(1).uniform(-1, 1, (1, 9, 9, 3)).astype(np.float32)
    ref = Interpreter(src).run(x)
    if a.ort_run and os.path.exists(a.ort_run):
        got = run_ort(a.ort_run, dst, x, work)
        for (name, _), r in zip(outs, ref):
            d = float(np.max(np.abs(got[name] - r)))
            check(d < 1e-4, "ORT vs numpy %-8s max abs diff %.2e" % (name, d))
        cinterp = Interpreter(csrc)
        cnames = [o.name for o in cgraph.graph.output]
        worst = {n: 0.0 for n in cnames}
        inputs = [np.random.RandomState(100 + k).uniform(-1, 1, (1, 6, 7, 3)).astype(np.float32) for k in range(8)]
        degenerate = inputs[0].copy().reshape(1, 42, 3)
        degenerate[0, 9] = degenerate[0, 2]       # both rotation landmarks on one spot: atan2(0, 0)
        inputs.append(degenerate.reshape(1, 6, 7, 3))
        nonzero = 0
        for cx in inputs:
            cref = cinterp.run(cx)
            cgot = run_ort(a.ort_run, cdst, cx, work)
            for n, r in zip(cnames, cref):
                worst[n] = max(worst[n], float(np.max(np.abs(cgot[n] - r))) / max(1.0, float(np.max(np.abs(r)))))
            nonzero += int(np.count_nonzero(cref[1]))
        for n in cnames:
            check(worst[n] < 1e-4, "ORT vs numpy, custom model %-10s max rel diff %.2e (9 inputs)" % (n, worst[n]))
        check(nonzero > 0.25 * 9 * 60, "the sampled maps are mostly inside the feature map (%d of %d)"
              % (nonzero, 9 * 60))
        if a.models:
            rc = subprocess.call([sys.executable, os.path.join(HERE, "verify.py"), "--models", a.models,
                                  "--ort-run", a.ort_run, "--work", work])
            check(rc == 0, "real models (verify.py on %s)" % a.models)
    else:
        print("skip ORT execution: no ort_run binary (set AVATARMAP_ORT_RUN); structure checks only")
    print("selftest: %s" % ("FAILED: " + "; ".join(fails) if fails else "passed"))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
