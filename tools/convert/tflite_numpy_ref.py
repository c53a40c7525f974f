#!/usr/bin/python3
"""Plain numpy interpreter for float TFLite graphs, used to check tflite2onnx.

Every operator is implemented directly in TFLite's NHWC layout from the TFLite
op semantics, without reusing anything from the ONNX mapping (only the
flatbuffer reader is shared).  Arithmetic is float64 so the reference is
more precise than either float32 runtime.

Usage: /usr/bin/python3 tools/convert/tflite_numpy_ref.py model.tflite [input.npy]
"""

import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from tflite_reader import DIM_DENSE, Model  # noqa: E402


def densify_ref(values, shape, sp):
    """Sparse -> dense, breadth-first: expand one traversal level at a time."""
    order, block_map, dims = sp["traversal_order"], sp["block_map"], sp["dim_metadata"]
    rank = len(shape)
    # each entry: (position at this level, coordinates per level so far)
    frontier = [(0, [])]
    for level, md in enumerate(dims):
        nxt = []
        for parent, coords in frontier:
            if md["format"] == DIM_DENSE:
                n = md["dense_size"]
                nxt.extend((parent * n + i, coords + [i]) for i in range(n))
            else:
                s, e = int(md["segments"][parent]), int(md["segments"][parent + 1])
                nxt.extend((k, coords + [int(md["indices"][k])]) for k in range(s, e))
        frontier = nxt
    assert len(frontier) == len(values), "sparse value count mismatch"
    bsize = {}
    for k, d in enumerate(block_map):
        bsize[d] = dims[order.index(rank + k)]["dense_size"]
    dense = np.zeros(shape, values.dtype)
    for v, (_, coords) in zip(values, frontier):
        full = [0] * rank
        for level, dim in enumerate(order):
            if dim < rank:
                full[dim] += coords[level] * bsize.get(dim, 1)
            else:
                full[block_map[dim - rank]] += coords[level]
        dense[tuple(full)] = v
    return dense


def tf_same(in_size, k, s, d):
    eff = (k - 1) * d + 1
    out = (in_size + s - 1) // s
    pad = max(0, (out - 1) * s + eff - in_size)
    return out, pad // 2


def act(x, a):
    if a == 0:
        return x
    if a == 1:
        return np.maximum(x, 0)
    if a == 2:
        return np.clip(x, -1, 1)
    if a == 3:
        return np.clip(x, 0, 6)
    if a == 4:
        return np.tanh(x)
    raise NotImplementedError("activation %d" % a)


def window_geometry(x, kh, kw, o, dil_h=1, dil_w=1):
    """Output size and leading pad for a TFLite window op; VALID when padding == 1."""
    _, h, w, _ = x.shape
    if o["padding"] == 0:
        oh, pt = tf_same(h, kh, o["stride_h"], dil_h)
        ow, pl = tf_same(w, kw, o["stride_w"], dil_w)
    else:
        oh = (h - ((kh - 1) * dil_h + 1)) // o["stride_h"] + 1
        ow = (w - ((kw - 1) * dil_w + 1)) // o["stride_w"] + 1
        pt = pl = 0
    return oh, ow, pt, pl


def taps(x, kh, kw, o, dil_h, dil_w, fill):
    """Yield (i, j, view) for each kernel tap: view[n, y, x, c] = input at that tap."""
    oh, ow, pt, pl = window_geometry(x, kh, kw, o, dil_h, dil_w)
    n, h, w, c = x.shape
    sh, sw = o["stride_h"], o["stride_w"]
    big_h = max(h + pt, (oh - 1) * sh + (kh - 1) * dil_h + 1)
    big_w = max(w + pl, (ow - 1) * sw + (kw - 1) * dil_w + 1)
    xp = np.full((n, big_h, big_w, c), fill, x.dtype)
    xp[:, pt:pt + h, pl:pl + w, :] = x
    for i in range(kh):
        for j in range(kw):
            y0, x0 = i * dil_h, j * dil_w
            yield i, j, xp[:, y0:y0 + (oh - 1) * sh + 1:sh, x0:x0 + (ow - 1) * sw + 1:sw, :]


def conv2d(x, w, b, o):
    cout, kh, kw, cin = w.shape
    acc = None
    for i, j, v in taps(x, kh, kw, o, o["dilation_h"], o["dilation_w"], 0.0):
        t = v @ w[:, i, j, :].T
        acc = t if acc is None else acc + t
    if b is not None:
        acc = acc + b
    return act(acc, o["act"])


def depthwise(x, w, b, o):
    _, kh, kw, cm = w.shape
    m = cm // x.shape[3]
    if m != 1:
        x = np.repeat(x, m, axis=3)   # output channel c*m+k reads input channel c
    acc = None
    for i, j, v in taps(x, kh, kw, o, o["dilation_h"], o["dilation_w"], 0.0):
        t = v * w[0, i, j, :]
        acc = t if acc is None else acc + t
    if b is not None:
        acc = acc + b
    return act(acc, o["act"])


def max_pool(x, o):
    acc = None
    for _, _, v in taps(x, o["filter_h"], o["filter_w"], o, 1, 1, -np.inf):
        acc = v.copy() if acc is None else np.maximum(acc, v)
    return act(acc, o["act"])


def resize_bilinear(x, oh, ow, align_corners, half_pixel):
    n, h, w, c = x.shape

    def axis(out, inp):
        if align_corners and out > 1:
            scale = (inp - 1) / (out - 1)
        else:
            scale = inp / out
        pos = np.arange(out, dtype=np.float64)
        src = (pos + 0.5) * scale - 0.5 if half_pixel else pos * scale
        lo_f = np.floor(src)
        frac = src - lo_f
        lo = np.clip(lo_f, 0, inp - 1).astype(int)
        hi = np.clip(np.ceil(src), 0, inp - 1).astype(int)
        return lo, hi, frac

    y0, y1, fy = axis(oh, h)
    x0, x1, fx = axis(ow, w)
    top = x[:, y0] * (1 - fy)[None, :, None, None] + x[:, y1] * fy[None, :, None, None]
    return top[:, :, x0] * (1 - fx)[None, None, :, None] + top[:, :, x1] * fx[None, None, :, None]


def depth_to_space(x, bs):
    n, h, w, c = x.shape
    cout = c // (bs * bs)
    out = np.empty((n, h * bs, w * bs, cout), x.dtype)
    for i in range(bs):
        for j in range(bs):
            out[:, i::bs, j::bs, :] = x[:, :, :, (i * bs + j) * cout:(i * bs + j + 1) * cout]
    return out


class Interpreter:
    def __init__(self, model):
        self.m = model if isinstance(model, Model) else Model.load(model)
        self.consts = {}
        for t in self.m.tensors:
            v = self.m.raw_constant(t.index)
            if v is None:
                continue
            if t.sparsity is not None:
                v = densify_ref(v, t.shape, t.sparsity)
            self.consts[t.index] = v

    def run(self, *inputs):
        vals = dict(self.consts)
        for i, x in zip(self.m.inputs, inputs):
            vals[i] = np.asarray(x, np.float64).reshape(self.m.tensors[i].shape)
        for op in self.m.operators:
            ins = [vals[i] if i >= 0 else None for i in op.inputs]
            vals[op.outputs[0]] = self.eval(op, ins, op.opt)
        return [vals[i].astype(np.float32) for i in self.m.outputs]

    def eval(self, op, ins, o):
        k = op.op
        f = lambda v: None if v is None else np.asarray(v, np.float64)  # noqa: E731
        if k == "DEQUANTIZE":
            return ins[0].astype(np.float32).astype(np.float64)
        if k == "DENSIFY":
            return ins[0]
        if k == "CONV_2D":
            return conv2d(f(ins[0]), f(ins[1]), f(ins[2] if len(ins) > 2 else None), o)
        if k == "DEPTHWISE_CONV_2D":
            return depthwise(f(ins[0]), f(ins[1]), f(ins[2] if len(ins) > 2 else None), o)
        if k == "MAX_POOL_2D":
            return max_pool(ins[0], o)
        if k == "ADD":
            return act(f(ins[0]) + f(ins[1]), o["act"])
        if k == "MUL":
            return act(f(ins[0]) * f(ins[1]), o["act"])
        if k == "LOGISTIC":
            return 1.0 / (1.0 + np.exp(-ins[0]))
        if k == "RELU":
            return act(ins[0], 1)
        if k == "RELU6":
            return act(ins[0], 3)
        if k == "TANH":
            return np.tanh(ins[0])
        if k == "PRELU":
            return np.where(ins[0] >= 0, ins[0], ins[0] * f(ins[1]))
        if k == "PAD":
            return np.pad(ins[0], [tuple(int(v) for v in p) for p in np.asarray(ins[1]).reshape(-1, 2)])
        if k == "RESHAPE":
            return ins[0].reshape(self.m.tensors[op.outputs[0]].shape)
        if k == "RESIZE_BILINEAR":
            oh, ow = [int(v) for v in ins[1]]
            return resize_bilinear(ins[0], oh, ow, o["align_corners"], o["half_pixel_centers"])
        if k == "FULLY_CONNECTED":
            w = f(ins[1])
            y = ins[0].reshape(-1, w.shape[1]) @ w.T
            if len(ins) > 2 and ins[2] is not None:
                y = y + f(ins[2])
            if o["keep_num_dims"]:
                y = y.reshape(self.m.tensors[op.outputs[0]].shape)
            return act(y, o["act"])
        if k == "MEAN":
            axes = tuple(int(a) for a in np.atleast_1d(ins[1]))
            return ins[0].mean(axis=axes, keepdims=o["keep_dims"])
        if k == "CONCATENATION":
            return act(np.concatenate(ins, axis=o["axis"]), o["act"])
        if k == "DEPTH_TO_SPACE":
            return depth_to_space(ins[0], o["block_size"])
        raise NotImplementedError(k)


def main(argv):
    interp = Interpreter(argv[1])
    t = interp.m.tensors[interp.m.inputs[0]]
    x = np.load(argv[2]) if len(argv) > 2 else np.random.RandomState(0).rand(*t.shape).astype(np.float32)
    for i, y in zip(interp.m.outputs, interp.run(x)):
        print(interp.m.tensors[i].name, y.shape, float(y.ravel()[0]))


if __name__ == "__main__":
    main(sys.argv)
