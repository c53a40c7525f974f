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
from tflite_reader import DIM_DENSE, Model, read_flexbuffer  # noqa: E402


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


# ---- MediaPipe's custom operators (version 2), straight from their documented meaning ------
# Written as MediaPipe describes them (atan2, explicit 4x4 products, per-pixel loops), not as
# the ONNX rewrite in tflite2onnx.py does them.
def mat_translate(x, y):
    m = np.eye(4)
    m[0, 3], m[1, 3] = x, y
    return m


def mat_rotate(r):
    m = np.eye(4)
    m[0, 0], m[0, 1], m[1, 0], m[1, 1] = np.cos(r), -np.sin(r), np.sin(r), np.cos(r)
    return m


def landmarks_to_transform_matrix_ref(landmarks, o):
    """[1, N, 3] landmarks -> [1, 4, 4]: Landmarks2TransformMatrix v2."""
    pts = np.asarray(landmarks, np.float64).reshape(-1, 3)
    left, right = pts[o["left_rotation_idx"]], pts[o["right_rotation_idx"]]
    rot = o.get("target_rotation_radians", 0.0) - np.arctan2(right[1] - left[1], right[0] - left[0])
    idx = list(o["subset_idxs"])
    if len(idx) % 2:  # an odd list pairs its last index with itself
        idx.append(idx[-1])
    sub = np.array([[pts[i][0], pts[i][1], 0.0, 1.0] for i in idx])
    rotated = sub @ mat_rotate(rot).T
    lo, hi = rotated[:, :2].min(axis=0), rotated[:, :2].max(axis=0)
    centre = mat_rotate(-rot) @ np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, 0.0, 1.0])
    scale = np.diag([o["scale_x"] * (hi[0] - lo[0]) / o["output_width"],
                     o["scale_y"] * (hi[1] - lo[1]) / o["output_height"], 1.0, 1.0])
    t = (mat_translate(centre[0], centre[1]) @ mat_rotate(-rot) @ scale
         @ mat_translate(-o["output_width"] / 2.0, -o["output_height"] / 2.0))
    return t[None]


def transform_tensor_bilinear_ref(x, m, out_shape):
    """[1, H, W, C] map, [1, 4, 4] matrix -> [1, oh, ow, C]: TransformTensorBilinear v2."""
    x = np.asarray(x, np.float64)
    m = np.asarray(m, np.float64).reshape(4, 4)
    _, h, w, c = x.shape
    _, oh, ow, _ = out_shape
    # v2 samples pixel centres: S(-0.5) . M . S(+0.5)
    mm = mat_translate(-0.5, -0.5) @ m @ mat_translate(0.5, 0.5)
    out = np.zeros((1, oh, ow, c))

    def read(yy, xx):
        if 0 <= yy < h and 0 <= xx < w:
            return x[0, yy, xx]
        return np.zeros(c)

    for oy in range(oh):
        for ox in range(ow):
            px, py = (mm @ np.array([ox, oy, 0.0, 1.0]))[:2]
            if not (0.0 <= px <= w - 1 and 0.0 <= py <= h - 1):
                continue
            x0, y0 = int(np.floor(px)), int(np.floor(py))
            ax, ay = px - x0, py - y0
            top = (1 - ax) * read(y0, x0) + ax * read(y0, x0 + 1)
            bottom = (1 - ax) * read(y0 + 1, x0) + ax * read(y0 + 1, x0 + 1)
            out[0, oy, ox] = (1 - ay) * top + ay * bottom
    return out


def transform_landmarks_ref(lm, m):
    """[1, K, D] landmarks (D = 2 or 3), [1, 4, 4] matrix -> [1, K, D]: TransformLandmarks v2
    (x, y transformed as the point (x, y, 0, 1); z kept)."""
    lm = np.asarray(lm, np.float64)
    m = np.asarray(m, np.float64).reshape(4, 4)
    out = lm.copy()
    for k in range(lm.shape[1]):
        v = m @ np.array([lm[0, k, 0], lm[0, k, 1], 0.0, 1.0])
        out[0, k, 0], out[0, k, 1] = v[0], v[1]
    return out


def strided_slice_ref(x, begin, end, strides, o):
    assert not (o["ellipsis_mask"] or o["new_axis_mask"] or o["shrink_axis_mask"])
    sl = []
    for a in range(x.ndim):
        b = None if (o["begin_mask"] >> a) & 1 else int(begin[a])
        e = None if (o["end_mask"] >> a) & 1 else int(end[a]) + (int(begin[a]) if o["offset"] else 0)
        sl.append(slice(b, e, int(strides[a])))
    return x[tuple(sl)]


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
        if k == "SUB":
            return act(f(ins[0]) - f(ins[1]), o["act"])
        if k == "DIV":
            return act(f(ins[0]) / f(ins[1]), o["act"])
        if k == "STRIDED_SLICE":
            return strided_slice_ref(ins[0], ins[1], ins[2], ins[3], o)
        if k.startswith("CUSTOM:"):
            if op.version != 2:
                raise NotImplementedError("%s version %d" % (k, op.version))
            co = read_flexbuffer(op.custom) if op.custom else {}
            if k == "CUSTOM:Landmarks2TransformMatrix":
                return landmarks_to_transform_matrix_ref(ins[0], co)
            if k == "CUSTOM:TransformTensorBilinear":
                return transform_tensor_bilinear_ref(ins[0], ins[1], self.m.tensors[op.outputs[0]].shape)
            if k == "CUSTOM:TransformLandmarks":
                return transform_landmarks_ref(ins[0], ins[1])
        raise NotImplementedError(k)


def main(argv):
    interp = Interpreter(argv[1])
    t = interp.m.tensors[interp.m.inputs[0]]
    x = np.load(argv[2]) if len(argv) > 2 else np.random.RandomState(0).rand(*t.shape).astype(np.float32)
    for i, y in zip(interp.m.outputs, interp.run(x)):
        print(interp.m.tensors[i].name, y.shape, float(y.ravel()[0]))


if __name__ == "__main__":
    main(sys.argv)
