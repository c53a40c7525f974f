#!/usr/bin/python3
"""Self-test for tflite2onnx on a tiny synthetic TFLite flatbuffer.

Builds (with a minimal flatbuffer writer) a model that uses every operator the
converter maps - float16 weights behind DEQUANTIZE, a CSR-sparse weight behind
DENSIFY, SAME / VALID padding with odd sizes, dilation, depth multiplier,
fused activations - converts it, runs onnx.checker and strict shape
inference, compares against the numpy reference interpreter when an ORT runner
is available ($AVATARMAP_ORT_RUN or --ort-run, see ort_run.cpp), and checks
--drop-outputs pruning.  When $AVATARMAP_MODELS names a directory of real
.tflite files, verify.py runs on them too (needs the ORT runner).

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
from tflite_reader import OPS, Model  # noqa: E402


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

    def op(self, name, inputs, out_shape, options=None):
        if name not in self.opcodes:
            self.opcodes.append(name)
        out = self.tensor(out_shape)
        f = {0: ("I", self.opcodes.index(name)), 1: ("off", ("vec", "i", inputs)),
             2: ("off", ("vec", "i", [out]))}
        if options is not None:
            f[3] = ("B", 1)  # union type byte; this reader decodes options by opcode
            f[4] = ("off", ("table", options))
        self.ops.append(("table", f))
        return out

    def build(self, inputs, outputs, names=None):
        if names:  # rename output tensors
            for i, n in zip(outputs, names):
                self.tensors[i][1][3] = ("off", ("str", n))
        codes = [("table", {0: ("b", min(CODES[n], 127)), 2: ("i", 1), 3: ("i", CODES[n])}) for n in self.opcodes]
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

    x = np.random.RandomState(1).uniform(-1, 1, (1, 9, 9, 3)).astype(np.float32)
    ref = Interpreter(src).run(x)
    if a.ort_run and os.path.exists(a.ort_run):
        got = run_ort(a.ort_run, dst, x, work)
        for (name, _), r in zip(outs, ref):
            d = float(np.max(np.abs(got[name] - r)))
            check(d < 1e-4, "ORT vs numpy %-8s max abs diff %.2e" % (name, d))
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
