#!/usr/bin/python3
"""Convert a float TFLite model (MediaPipe's pose / hand / palm / face models) to ONNX.

Usage: /usr/bin/python3 tools/convert/tflite2onnx.py in.tflite out.onnx
           [--drop-outputs NAME,NAME] [--opset 13]

Needs only Debian's python3-onnx (>= 1.12) and python3-numpy.

Layout: the ONNX graph works in NCHW.  The graph input keeps TFLite's NHWC
shape and is transposed once; every rank-4 activation is held as NCHW
internally; rank-4 graph outputs are transposed back to NHWC, flat outputs
are passed through.  So the ONNX model has exactly the TFLite signature
(names, shapes, element order).  Constant-only subgraphs (DEQUANTIZE of
float16 weights, DENSIFY of sparse weights) are folded at conversion time.
MediaPipe's custom operators of face_landmark_with_attention (version 2 of
Landmarks2TransformMatrix, TransformTensorBilinear, TransformLandmarks) are
rewritten as standard ONNX operators (custom_ops() below).
See docs/convert.md.
"""

import argparse
import os
import sys

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from tflite_reader import (ACT_NONE, ACT_RELU, ACT_RELU6, ACT_RELU_N1_TO_1, ACT_TANH,  # noqa: E402
                           DIM_DENSE, PAD_SAME, Model, read_flexbuffer)

NHWC_TO_NCHW = [0, 3, 1, 2]
NCHW_TO_NHWC = [0, 2, 3, 1]


class ConversionError(Exception):
    pass


def densify(values, shape, sparsity):
    """Expand a TFLite sparse constant (DENSE / SPARSE_CSR levels, optional blocks)."""
    order = sparsity["traversal_order"]
    block_map = sparsity["block_map"]
    dims = sparsity["dim_metadata"]
    rank = len(shape)
    if len(order) != len(dims):
        raise ConversionError("sparsity: traversal_order and dim_metadata differ in length")
    block_size = [1] * rank
    for k, d in enumerate(block_map):
        block_size[d] = dims[order.index(rank + k)]["dense_size"]
    out = np.zeros(shape, dtype=values.dtype)
    coord = [0] * len(order)  # coordinate per traversal level
    pos = [0]                  # next stored value

    def place():
        full = [0] * rank
        for level, dim in enumerate(order):
            if dim < rank:
                full[dim] += coord[level] * block_size[dim]
            else:
                full[block_map[dim - rank]] += coord[level]
        out[tuple(full)] = values[pos[0]]
        pos[0] += 1

    def walk(level, parent):
        if level == len(order):
            place()
            return
        md = dims[level]
        if md["format"] == DIM_DENSE:
            n = md["dense_size"]
            for i in range(n):
                coord[level] = i
                walk(level + 1, parent * n + i)
        else:
            seg, idx = md["segments"], md["indices"]
            for k in range(int(seg[parent]), int(seg[parent + 1])):
                coord[level] = int(idx[k])
                walk(level + 1, k)

    walk(0, 0)
    if pos[0] != len(values):
        raise ConversionError("sparsity: %d values stored, %d placed" % (len(values), pos[0]))
    return out


def same_pads(in_size, kernel, stride, dilation):
    """TensorFlow SAME padding for one spatial axis: (begin, end), extra pad at the end."""
    eff = (kernel - 1) * dilation + 1
    out = -(-in_size // stride)
    total = max((out - 1) * stride + eff - in_size, 0)
    return total // 2, total - total // 2


class Converter:
    def __init__(self, model, opset=13, drop_outputs=()):
        self.m = model
        self.opset = opset
        self.nodes, self.inits = [], []
        self.consts = {}   # tensor index -> numpy array in TFLite layout
        self.names = {}    # tensor index -> ONNX value name (internal layout)
        self.counter = 0
        self.drop = set(drop_outputs)

    # ---- helpers ---------------------------------------------------------------
    def fresh(self, base):
        self.counter += 1
        return "%s__%d" % (base, self.counter)

    def shape(self, idx):
        return self.m.tensors[idx].shape

    def rank4(self, idx):
        return len(self.shape(idx)) == 4

    def init(self, base, array):
        name = self.fresh(base)
        self.inits.append(numpy_helper.from_array(np.ascontiguousarray(array), name))
        return name

    def node(self, op, inputs, outputs=None, base=None, **attrs):
        if outputs is None:
            outputs = [self.fresh(base or op.lower())]
        self.nodes.append(helper.make_node(op, inputs, outputs, name=self.fresh("n_" + op), **attrs))
        return outputs[0]

    def const(self, idx):
        """Constant value of tensor `idx` (float16 stays float16 until DEQUANTIZE folds it)."""
        if idx in self.consts:
            return self.consts[idx]
        t = self.m.tensors[idx]
        raw = self.m.raw_constant(idx)
        if raw is None:
            return None
        if t.sparsity is not None:
            raw = densify(raw, t.shape, t.sparsity)
        self.consts[idx] = raw
        return raw

    def need_const(self, idx, what):
        v = self.const(idx)
        if v is None:
            raise ConversionError("%s: tensor %d (%s) must be constant" % (what, idx, self.m.tensors[idx].name))
        return v.astype(np.float32) if v.dtype == np.float16 else v

    def value(self, idx):
        """ONNX name of tensor `idx` in internal layout (constants become initializers)."""
        if idx in self.names:
            return self.names[idx]
        v = self.const(idx)
        if v is None:
            raise ConversionError("tensor %d (%s) used before it is produced" % (idx, self.m.tensors[idx].name))
        if v.dtype == np.float16:
            v = v.astype(np.float32)
        if v.ndim == 4:
            v = v.transpose(NHWC_TO_NCHW)
        name = self.init("c%d" % idx, v)
        self.names[idx] = name
        return name

    def operand_like(self, idx, other):
        """Tensor `idx` as an operand broadcasting against activation `other` (layout-aware)."""
        v = self.const(idx)
        if v is None or idx in self.names or not self.rank4(other):
            return self.value(idx)
        v = v.astype(np.float32) if v.dtype == np.float16 else v
        v = v.reshape((1,) * (4 - v.ndim) + v.shape).transpose(NHWC_TO_NCHW)
        return self.init("c%d" % idx, v)

    def activation(self, x, act, out):
        if act == ACT_NONE:
            return self.node("Identity", [x], [out])
        if act == ACT_RELU:
            return self.node("Relu", [x], [out])
        if act == ACT_TANH:
            return self.node("Tanh", [x], [out])
        if act in (ACT_RELU6, ACT_RELU_N1_TO_1):
            lo, hi = (0.0, 6.0) if act == ACT_RELU6 else (-1.0, 1.0)
            return self.node("Clip", [x, self.init("lo", np.array(lo, np.float32)),
                                      self.init("hi", np.array(hi, np.float32))], [out])
        raise ConversionError("unsupported fused activation %d" % act)

    def out_name(self, idx):
        name = "t%d" % idx
        self.names[idx] = name
        return name

    def finish(self, op, y):
        """Route `y` into op's first output with its fused activation (if any)."""
        out = self.out_name(op.outputs[0])
        act = op.opt.get("act", ACT_NONE)
        if act == ACT_NONE:
            # rename the producing node's output instead of adding an Identity
            last = self.nodes[-1]
            if y in last.output:
                last.output[list(last.output).index(y)] = out
                return
        self.activation(y, act, out)

    def to_nhwc(self, idx):
        x = self.value(idx)
        return self.node("Transpose", [x], perm=NCHW_TO_NHWC) if self.rank4(idx) else x

    # ---- ops -------------------------------------------------------------------
    def conv(self, op, depthwise):
        o = op.opt
        x_idx, w_idx = op.inputs[0], op.inputs[1]
        _, h, w, c = self.shape(x_idx)
        wt = self.need_const(w_idx, op.op)
        if depthwise:
            kh, kw = wt.shape[1], wt.shape[2]
            wt = wt.transpose(3, 0, 1, 2)          # 1HW(C*M) -> (C*M)1HW
            group = c
        else:
            kh, kw = wt.shape[1], wt.shape[2]
            wt = wt.transpose(0, 3, 1, 2)          # OHWI -> OIHW
            group = 1
        if o["padding"] == PAD_SAME:
            pt, pb = same_pads(h, kh, o["stride_h"], o["dilation_h"])
            pl, pr = same_pads(w, kw, o["stride_w"], o["dilation_w"])
        else:
            pt = pb = pl = pr = 0
        ins = [self.value(x_idx), self.init("w%d" % w_idx, wt.astype(np.float32))]
        if len(op.inputs) > 2 and op.inputs[2] >= 0:
            ins.append(self.init("b%d" % op.inputs[2], self.need_const(op.inputs[2], op.op).astype(np.float32)))
        y = self.node("Conv", ins, kernel_shape=[kh, kw], strides=[o["stride_h"], o["stride_w"]],
                      dilations=[o["dilation_h"], o["dilation_w"]], pads=[pt, pl, pb, pr], group=group)
        self.finish(op, y)

    def pool(self, op):
        o = op.opt
        _, h, w, _ = self.shape(op.inputs[0])
        kh, kw = o["filter_h"], o["filter_w"]
        if o["padding"] == PAD_SAME:
            pt, pb = same_pads(h, kh, o["stride_h"], 1)
            pl, pr = same_pads(w, kw, o["stride_w"], 1)
        else:
            pt = pb = pl = pr = 0
        kind = "MaxPool" if op.op == "MAX_POOL_2D" else "AveragePool"
        extra = {} if kind == "MaxPool" else {"count_include_pad": 0}
        y = self.node(kind, [self.value(op.inputs[0])], kernel_shape=[kh, kw],
                      strides=[o["stride_h"], o["stride_w"]], pads=[pt, pl, pb, pr], **extra)
        self.finish(op, y)

    def binary(self, op, kind):
        a, b = op.inputs
        if self.const(a) is not None and self.const(b) is None:
            xa, xb = self.operand_like(a, b), self.value(b)
        else:
            xa, xb = self.value(a), self.operand_like(b, a)
        self.finish(op, self.node(kind, [xa, xb]))

    # ---- MediaPipe's custom operators -------------------------------------------------
    # Their meaning (version 2, the one face_landmark_with_attention uses) is documented in
    # docs/convert.md "Custom operators"; tflite_numpy_ref.py holds an independent reference.
    def scalar_const(self, v, dtype=np.float32):
        """A true rank-0 initializer (init() makes 0-d arrays rank 1)."""
        name = self.fresh("k")
        self.inits.append(numpy_helper.from_array(np.array(v, dtype), name))
        return name

    def landmarks_to_transform_matrix(self, op, o):
        """Similarity transform (4x4, row-major) mapping an output_width x output_height grid
        onto the rotated box of a landmark subset: rotation from two landmarks, box = extent of
        the subset in the rotated frame, scaled by scale_x / scale_y.  Trigonometry-free: the
        rotation's cosine and sine come from the normalised direction vector."""
        for key in ("left_rotation_idx", "right_rotation_idx", "output_width", "output_height",
                    "scale_x", "scale_y", "subset_idxs"):
            if key not in o:
                raise ConversionError("Landmarks2TransformMatrix: option %s missing" % key)
        n_points = self.shape(op.inputs[0])[1]
        subset = [int(i) for i in o["subset_idxs"]]
        li, ri = int(o["left_rotation_idx"]), int(o["right_rotation_idx"])
        if not subset or min(subset + [li, ri]) < 0 or max(subset + [li, ri]) >= n_points:
            raise ConversionError("Landmarks2TransformMatrix: landmark index out of range")
        ow, oh = float(o["output_width"]), float(o["output_height"])
        sx, sy = float(o["scale_x"]), float(o["scale_y"])
        if not (ow > 0 and oh > 0 and sx > 0 and sy > 0):
            raise ConversionError("Landmarks2TransformMatrix: sizes and scales must be > 0")
        target = float(o.get("target_rotation_radians", 0.0))
        x = self.value(op.inputs[0])                                     # [1, N, 3]
        i0 = self.scalar_const(0, np.int64)
        i1 = self.scalar_const(1, np.int64)
        d = self.node("Sub", [self.node("Gather", [x, self.init("ri", np.array([ri], np.int64))], axis=1),
                              self.node("Gather", [x, self.init("li", np.array([li], np.int64))], axis=1)])
        dx = self.node("Gather", [d, i0], axis=2)                       # [1, 1]
        dy = self.node("Gather", [d, i1], axis=2)
        norm = self.node("Sqrt", [self.node("Add", [self.node("Mul", [dx, dx]), self.node("Mul", [dy, dy])])])
        # atan2(0, 0) = 0: a zero direction counts as (1, 0)
        zero = self.node("Cast", [self.node("Equal", [norm, self.scalar_const(0.0)])], to=TensorProto.FLOAT)
        den = self.node("Add", [norm, zero])
        cos_t = self.node("Div", [self.node("Add", [dx, zero]), den])
        sin_t = self.node("Div", [dy, den])
        # r = target - theta
        ct, st = self.scalar_const(np.cos(target)), self.scalar_const(np.sin(target))
        c = self.node("Add", [self.node("Mul", [cos_t, ct]), self.node("Mul", [sin_t, st])])
        s = self.node("Sub", [self.node("Mul", [cos_t, st]), self.node("Mul", [sin_t, ct])])
        p = self.node("Gather", [x, self.init("subset", np.array(subset, np.int64))], axis=1)  # [1, K, 3]
        px = self.node("Gather", [p, i0], axis=2)                       # [1, K]
        py = self.node("Gather", [p, i1], axis=2)
        rx = self.node("Sub", [self.node("Mul", [c, px]), self.node("Mul", [s, py])])
        ry = self.node("Add", [self.node("Mul", [s, px]), self.node("Mul", [c, py])])
        half = self.scalar_const(0.5)
        ext = {}
        for name, v in (("x", rx), ("y", ry)):
            hi = self.node("ReduceMax", [v], axes=[1], keepdims=1)      # [1, 1]
            lo = self.node("ReduceMin", [v], axes=[1], keepdims=1)
            ext[name] = (self.node("Sub", [hi, lo]), self.node("Mul", [self.node("Add", [hi, lo]), half]))
        (w, mx), (h, my) = ext["x"], ext["y"]
        # box centre back in the landmarks' frame (rotation by -r)
        cx = self.node("Add", [self.node("Mul", [c, mx]), self.node("Mul", [s, my])])
        cy = self.node("Sub", [self.node("Mul", [c, my]), self.node("Mul", [s, mx])])
        scale_x = self.node("Mul", [w, self.scalar_const(sx / ow)])
        scale_y = self.node("Mul", [h, self.scalar_const(sy / oh)])
        a00 = self.node("Mul", [c, scale_x])
        a01 = self.node("Mul", [s, scale_y])
        a10 = self.node("Neg", [self.node("Mul", [s, scale_x])])
        a11 = self.node("Mul", [c, scale_y])
        hw, hh = self.scalar_const(-ow / 2.0), self.scalar_const(-oh / 2.0)
        tx = self.node("Add", [cx, self.node("Add", [self.node("Mul", [a00, hw]), self.node("Mul", [a01, hh])])])
        ty = self.node("Add", [cy, self.node("Add", [self.node("Mul", [a10, hw]), self.node("Mul", [a11, hh])])])
        z, one = self.init("zero11", np.zeros((1, 1), np.float32)), self.init("one11", np.ones((1, 1), np.float32))
        flat = self.node("Concat", [a00, a01, z, tx, a10, a11, z, ty, z, z, one, z, z, z, z, one], axis=1)
        self.node("Reshape", [flat, self.init("shape", np.array([1, 4, 4], np.int64))],
                  [self.out_name(op.outputs[0])])

    def matrix_parts(self, m_idx):
        """2x2 linear part (or its transpose) and translation of a [1, 4, 4] affine matrix."""
        m = self.node("Reshape", [self.value(m_idx), self.init("shape", np.array([16], np.int64))])
        a = self.node("Reshape", [self.node("Gather", [m, self.init("a", np.array([0, 1, 4, 5], np.int64))], axis=0),
                                  self.init("shape", np.array([2, 2], np.int64))])
        at = self.node("Reshape", [self.node("Gather", [m, self.init("at", np.array([0, 4, 1, 5], np.int64))], axis=0),
                                   self.init("shape", np.array([2, 2], np.int64))])
        t = self.node("Gather", [m, self.init("t", np.array([3, 7], np.int64))], axis=0)   # [2]
        return a, at, t

    def transform_tensor_bilinear(self, op, o):
        """Bilinear sampling of an NHWC feature map at (A (x + 0.5, y + 0.5) + t - 0.5) for each
        output pixel (x, y); samples outside [0, W-1] x [0, H-1] are 0.  Done with gathers on the
        flattened map (exact at every position, opset 13)."""
        f_idx, m_idx = op.inputs[0], op.inputs[1]
        n, h, w, ch = self.shape(f_idx)
        _, oh, ow, och = self.shape(op.outputs[0])
        if n != 1 or och != ch:
            raise ConversionError("TransformTensorBilinear: batch must be 1 and channels kept")
        if "output_height" in o and (o["output_height"], o["output_width"]) != (oh, ow):
            raise ConversionError("TransformTensorBilinear: options disagree with the output shape")
        a, _, t = self.matrix_parts(m_idx)
        gy, gx = np.meshgrid(np.arange(oh, dtype=np.float32) + 0.5, np.arange(ow, dtype=np.float32) + 0.5,
                             indexing="ij")
        grid = self.init("grid", np.stack([gx.ravel(), gy.ravel()]))   # [2, P], row-major pixels
        shift = self.node("Sub", [self.node("Reshape", [t, self.init("shape", np.array([2, 1], np.int64))]),
                                  self.scalar_const(0.5)])
        tc = self.node("Add", [self.node("MatMul", [a, grid]), shift])  # [2, P]
        tcx = self.node("Gather", [tc, self.scalar_const(0, np.int64)], axis=0)   # [P]
        tcy = self.node("Gather", [tc, self.scalar_const(1, np.int64)], axis=0)
        zero = self.scalar_const(0.0)
        inside = self.node("And", [
            self.node("And", [self.node("GreaterOrEqual", [tcx, zero]),
                              self.node("LessOrEqual", [tcx, self.scalar_const(w - 1.0)])]),
            self.node("And", [self.node("GreaterOrEqual", [tcy, zero]),
                              self.node("LessOrEqual", [tcy, self.scalar_const(h - 1.0)])])])
        mask = self.node("Cast", [inside], to=TensorProto.FLOAT)
        sx = self.node("Where", [inside, tcx, zero])  # NaN and far-away positions -> a safe 0
        sy = self.node("Where", [inside, tcy, zero])
        x0f, y0f = self.node("Floor", [sx]), self.node("Floor", [sy])
        fx, fy = self.node("Sub", [sx, x0f]), self.node("Sub", [sy, y0f])
        x0 = self.node("Cast", [x0f], to=TensorProto.INT64)
        y0 = self.node("Cast", [y0f], to=TensorProto.INT64)
        one_i = self.scalar_const(1, np.int64)
        # x0 + 1 == W only when fx == 0: clamping the index keeps that corner's weight at 0
        x1 = self.node("Min", [self.node("Add", [x0, one_i]), self.scalar_const(w - 1, np.int64)])
        y1 = self.node("Min", [self.node("Add", [y0, one_i]), self.scalar_const(h - 1, np.int64)])
        wi = self.scalar_const(w, np.int64)
        row0, row1 = self.node("Mul", [y0, wi]), self.node("Mul", [y1, wi])
        flat = self.node("Reshape", [self.value(f_idx), self.init("shape", np.array([ch, h * w], np.int64))])
        one = self.scalar_const(1.0)
        gx_, gy_ = self.node("Sub", [one, fx]), self.node("Sub", [one, fy])
        acc = None
        for row, col, wy, wx in ((row0, x0, gy_, gx_), (row0, x1, gy_, fx), (row1, x0, fy, gx_), (row1, x1, fy, fx)):
            q = self.node("Gather", [flat, self.node("Add", [row, col])], axis=1)   # [C, P]
            term = self.node("Mul", [q, self.node("Mul", [self.node("Mul", [wy, wx]), mask])])
            acc = term if acc is None else self.node("Add", [acc, term])
        self.node("Reshape", [acc, self.init("shape", np.array([1, ch, oh, ow], np.int64))],
                  [self.out_name(op.outputs[0])])

    def transform_landmarks(self, op, o):
        """(x, y) -> A (x, y) + t for each landmark of a [1, K, D] tensor (D = 2 or 3; z is
        passed through)."""
        l_idx, m_idx = op.inputs[0], op.inputs[1]
        shp = self.shape(l_idx)
        if len(shp) != 3 or shp[2] not in (2, 3):
            raise ConversionError("TransformLandmarks: landmarks must be [1, K, 2 or 3], got %s" % shp)
        _, at, t = self.matrix_parts(m_idx)
        x = self.value(l_idx)

        def last_axis(begin, end):
            return self.node("Slice", [x, self.init("s", np.array([begin], np.int64)),
                                       self.init("e", np.array([end], np.int64)),
                                       self.init("ax", np.array([2], np.int64))])

        xy = last_axis(0, 2) if shp[2] == 3 else x
        y = self.node("Add", [self.node("MatMul", [xy, at]), t])
        out = self.out_name(op.outputs[0])
        if shp[2] == 2:
            self.node("Identity", [y], [out])
        else:
            self.node("Concat", [y, last_axis(2, 3)], [out], axis=2)

    def custom_op(self, op):
        name = op.op[7:]
        handlers = {"Landmarks2TransformMatrix": self.landmarks_to_transform_matrix,
                    "TransformTensorBilinear": self.transform_tensor_bilinear,
                    "TransformLandmarks": self.transform_landmarks}
        if name not in handlers:
            raise ConversionError("custom operator %s is not supported (op #%d)" % (name, op.index))
        if op.version != 2:
            raise ConversionError("custom operator %s version %d is not supported (only 2)" % (name, op.version))
        try:
            opts = read_flexbuffer(op.custom) if op.custom else {}
        except (ValueError, IndexError, KeyError) as e:
            raise ConversionError("custom operator %s: bad options (%s)" % (name, e))
        if not isinstance(opts, dict):
            raise ConversionError("custom operator %s: options are not a map" % name)
        handlers[name](op, opts)

    def strided_slice(self, op):
        o = op.opt
        if o["ellipsis_mask"] or o["new_axis_mask"] or o["shrink_axis_mask"]:
            raise ConversionError("STRIDED_SLICE with ellipsis / new-axis / shrink masks")
        x_idx = op.inputs[0]
        rank = len(self.shape(x_idx))
        begin = [int(v) for v in self.need_const(op.inputs[1], "STRIDED_SLICE")]
        end = [int(v) for v in self.need_const(op.inputs[2], "STRIDED_SLICE")]
        steps = [int(v) for v in self.need_const(op.inputs[3], "STRIDED_SLICE")]
        big = np.iinfo(np.int64).max
        starts, ends = [], []
        for a in range(rank):
            st = steps[a]
            if st == 0:
                raise ConversionError("STRIDED_SLICE with a zero stride")
            b = begin[a] if not (o["begin_mask"] >> a) & 1 else (0 if st > 0 else -1)
            if (o["end_mask"] >> a) & 1:
                e = big if st > 0 else -big
            else:
                e = begin[a] + end[a] if o["offset"] else end[a]
            starts.append(b)
            ends.append(e)
        axes = list(range(rank))
        if rank == 4:
            axes = [NHWC_TO_NCHW.index(a) for a in axes]
        self.node("Slice", [self.value(x_idx), self.init("starts", np.array(starts, np.int64)),
                            self.init("ends", np.array(ends, np.int64)), self.init("axes", np.array(axes, np.int64)),
                            self.init("steps", np.array(steps, np.int64))], [self.out_name(op.outputs[0])])

    def convert_op(self, op):
        k = op.op
        if k.startswith("CUSTOM:"):
            return self.custom_op(op)
        if k == "STRIDED_SLICE":
            return self.strided_slice(op)
        if k in ("DEQUANTIZE", "DENSIFY"):
            src = op.inputs[0]
            v = self.const(src)
            if v is not None:
                if k == "DEQUANTIZE":
                    v = v.astype(np.float32)
                self.consts[op.outputs[0]] = v
                return
            if k == "DENSIFY":
                raise ConversionError("DENSIFY of a non-constant tensor")
            self.node("Cast", [self.value(src)], [self.out_name(op.outputs[0])], to=TensorProto.FLOAT)
            return
        if k == "CONV_2D":
            return self.conv(op, False)
        if k == "DEPTHWISE_CONV_2D":
            return self.conv(op, True)
        if k in ("MAX_POOL_2D", "AVERAGE_POOL_2D"):
            return self.pool(op)
        if k in ("ADD", "MUL", "SUB", "DIV"):
            return self.binary(op, {"ADD": "Add", "MUL": "Mul", "SUB": "Sub", "DIV": "Div"}[k])
        if k in ("LOGISTIC", "RELU", "RELU6", "TANH", "RELU_N1_TO_1"):
            x = self.value(op.inputs[0])
            out = self.out_name(op.outputs[0])
            if k == "LOGISTIC":
                self.node("Sigmoid", [x], [out])
            else:
                self.activation(x, {"RELU": ACT_RELU, "RELU6": ACT_RELU6, "TANH": ACT_TANH,
                                    "RELU_N1_TO_1": ACT_RELU_N1_TO_1}[k], out)
            return
        if k == "PRELU":
            x_idx, a_idx = op.inputs
            alpha = self.need_const(a_idx, k)
            if self.rank4(x_idx):
                alpha = alpha.reshape((1,) * (4 - alpha.ndim) + alpha.shape).transpose(NHWC_TO_NCHW)
            self.node("PRelu", [self.value(x_idx), self.init("alpha%d" % a_idx, alpha)],
                      [self.out_name(op.outputs[0])])
            return
        if k == "PAD":
            x_idx = op.inputs[0]
            p = self.need_const(op.inputs[1], k).astype(np.int64).reshape(-1, 2)
            if self.rank4(x_idx):
                p = p[NHWC_TO_NCHW]
            pads = np.concatenate([p[:, 0], p[:, 1]])
            self.node("Pad", [self.value(x_idx), self.init("pads", pads)], [self.out_name(op.outputs[0])],
                      mode="constant")
            return
        if k == "RESIZE_BILINEAR":
            x_idx = op.inputs[0]
            n, _, _, c = self.shape(x_idx)
            oh, ow = [int(v) for v in self.need_const(op.inputs[1], k)]
            if op.opt["half_pixel_centers"]:
                mode = "half_pixel"
            elif op.opt["align_corners"]:
                mode = "align_corners"
            else:
                mode = "asymmetric"
            self.node("Resize", [self.value(x_idx), "", "", self.init("sizes", np.array([n, c, oh, ow], np.int64))],
                      [self.out_name(op.outputs[0])], mode="linear", coordinate_transformation_mode=mode)
            return
        if k == "RESHAPE":
            x_idx, out_idx = op.inputs[0], op.outputs[0]
            new_shape = self.shape(out_idx)
            x = self.to_nhwc(x_idx)
            shp = self.init("shape", np.array(new_shape, np.int64))
            if len(new_shape) == 4:
                y = self.node("Reshape", [x, shp])
                self.node("Transpose", [y], [self.out_name(out_idx)], perm=NHWC_TO_NCHW)
            else:
                self.node("Reshape", [x, shp], [self.out_name(out_idx)])
            return
        if k == "FULLY_CONNECTED":
            x_idx, w_idx = op.inputs[0], op.inputs[1]
            wt = self.need_const(w_idx, k).astype(np.float32)
            x = self.to_nhwc(x_idx)
            if len(self.shape(x_idx)) != 2:
                x = self.node("Reshape", [x, self.init("shape", np.array([-1, wt.shape[1]], np.int64))])
            ins = [x, self.init("fc_w%d" % w_idx, wt)]
            if len(op.inputs) > 2 and op.inputs[2] >= 0:
                ins.append(self.init("fc_b%d" % op.inputs[2], self.need_const(op.inputs[2], k).astype(np.float32)))
            y = self.node("Gemm", ins, transB=1)
            if op.opt.get("keep_num_dims") and len(self.shape(op.outputs[0])) != 2:
                y = self.node("Reshape", [y, self.init("shape", np.array(self.shape(op.outputs[0]), np.int64))])
            self.finish(op, y)
            return
        if k == "MEAN":
            x_idx = op.inputs[0]
            axes = [int(a) for a in np.atleast_1d(self.need_const(op.inputs[1], k))]
            rank = len(self.shape(x_idx))
            axes = sorted(set(a % rank for a in axes))
            keep = op.opt["keep_dims"]
            x = self.value(x_idx)
            out = self.out_name(op.outputs[0])
            if rank == 4:
                internal = sorted(NHWC_TO_NCHW.index(a) for a in axes)
                remaining = [d for d in NHWC_TO_NCHW if d not in axes]  # NHWC labels in NCHW order
                if keep or remaining == sorted(remaining):
                    self.node("ReduceMean", [x], [out], axes=internal, keepdims=int(keep))
                else:
                    y = self.node("ReduceMean", [x], axes=internal, keepdims=0)
                    perm = [remaining.index(d) for d in sorted(remaining)]
                    self.node("Transpose", [y], [out], perm=perm)
            else:
                self.node("ReduceMean", [x], [out], axes=axes, keepdims=int(keep))
            return
        if k == "CONCATENATION":
            rank = len(self.shape(op.outputs[0]))
            axis = op.opt["axis"] % rank
            if rank == 4:
                axis = NHWC_TO_NCHW.index(axis)
            y = self.node("Concat", [self.value(i) for i in op.inputs], axis=axis)
            self.finish(op, y)
            return
        if k == "DEPTH_TO_SPACE":
            # TF's depth_to_space (NHWC) moves channel block (i*bs+j)*C+c to (h*bs+i, w*bs+j, c):
            # the same as ONNX DepthToSpace in DCR mode on the NCHW tensor.
            self.node("DepthToSpace", [self.value(op.inputs[0])], [self.out_name(op.outputs[0])],
                      blocksize=op.opt["block_size"], mode="DCR")
            return
        if k == "SOFTMAX":
            if op.opt.get("beta", 1.0) != 1.0:
                raise ConversionError("SOFTMAX with beta != 1")
            rank = len(self.shape(op.inputs[0]))
            axis = 1 if rank == 4 else rank - 1
            self.node("Softmax", [self.value(op.inputs[0])], [self.out_name(op.outputs[0])], axis=axis)
            return
        raise ConversionError("unsupported operator %s (op #%d)" % (k, op.index))

    # ---- driver ----------------------------------------------------------------
    def live_operators(self, outputs):
        producer = {}
        for op in self.m.operators:
            for o in op.outputs:
                producer[o] = op
        needed, stack, live = set(), list(outputs), set()
        while stack:
            t = stack.pop()
            if t in needed:
                continue
            needed.add(t)
            op = producer.get(t)
            if op is not None and op.index not in live:
                live.add(op.index)
                stack.extend(i for i in op.inputs if i >= 0)
        return [op for op in self.m.operators if op.index in live]

    def convert(self, graph_name="model"):
        m = self.m
        names = [m.tensors[i].name for i in m.outputs]
        unknown = self.drop - set(names)
        if unknown:
            raise ConversionError("--drop-outputs: no output named %s (outputs: %s)"
                                  % (", ".join(sorted(unknown)), ", ".join(names)))
        outputs = [i for i in m.outputs if m.tensors[i].name not in self.drop]
        if not outputs:
            raise ConversionError("every output dropped")
        used = set()

        def unique(name):
            base, k = name, 1
            while name in used:
                k += 1
                name = "%s_%d" % (base, k)
            used.add(name)
            return name

        graph_inputs = []
        for i in m.inputs:
            t = m.tensors[i]
            name = unique(t.name)
            graph_inputs.append(helper.make_tensor_value_info(name, TensorProto.FLOAT, t.shape))
            if len(t.shape) == 4:
                self.node("Transpose", [name], [self.out_name(i)], perm=NHWC_TO_NCHW)
            else:
                self.names[i] = name
        for op in self.live_operators(outputs):
            self.convert_op(op)
        graph_outputs = []
        for i in outputs:
            t = m.tensors[i]
            name = unique(t.name)
            x = self.value(i)
            if len(t.shape) == 4:
                self.node("Transpose", [x], [name], perm=NCHW_TO_NHWC)
            else:
                self.node("Identity", [x], [name])
            graph_outputs.append(helper.make_tensor_value_info(name, TensorProto.FLOAT, t.shape))
        graph = helper.make_graph(self.nodes, graph_name, graph_inputs, graph_outputs, self.inits)
        model = helper.make_model(graph, producer_name="avatarmap-tflite2onnx",
                                  opset_imports=[helper.make_opsetid("", self.opset)])
        model.ir_version = 7  # opset 13 era; readable by every ORT since 1.6
        return model


def convert_file(src, dst=None, drop_outputs=(), opset=13, check=True):
    model = Model.load(src)
    onnx_model = Converter(model, opset, drop_outputs).convert(os.path.splitext(os.path.basename(src))[0])
    if check:
        onnx.checker.check_model(onnx_model)
        onnx.shape_inference.infer_shapes(onnx_model, strict_mode=True)
    if dst:
        onnx.save(onnx_model, dst)
    return onnx_model


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("src")
    ap.add_argument("dst")
    ap.add_argument("--drop-outputs", default="", help="comma-separated TFLite output names to remove")
    ap.add_argument("--opset", type=int, default=13, choices=[13, 14, 15, 16, 17])
    a = ap.parse_args(argv)
    drop = [s for s in a.drop_outputs.split(",") if s]
    try:
        m = convert_file(a.src, a.dst, drop, a.opset)
    except ConversionError as e:
        print("tflite2onnx: %s: %s" % (a.src, e), file=sys.stderr)
        return 1
    g = m.graph
    print("%s -> %s: %d nodes, %d initializers; inputs %s; outputs %s" % (
        a.src, a.dst, len(g.node), len(g.initializer),
        [(v.name, [d.dim_value for d in v.type.tensor_type.shape.dim]) for v in g.input],
        [(v.name, [d.dim_value for d in v.type.tensor_type.shape.dim]) for v in g.output]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
