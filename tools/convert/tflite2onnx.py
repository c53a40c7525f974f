#!/usr/bin/python3
"""Convert a float TFLite model (MediaPipe's pose / hand / palm models) to ONNX.

Usage: /usr/bin/python3 tools/convert/tflite2onnx.py in.tflite out.onnx
           [--drop-outputs NAME,NAME] [--opset 13]

Needs only Debian's python3-onnx (>= 1.12) and python3-numpy.

Layout: the ONNX graph works in NCHW.  The graph input keeps TFLite's NHWC
shape and is transposed once; every rank-4 activation is held as NCHW
internally; rank-4 graph outputs are transposed back to NHWC, flat outputs
are passed through.  So the ONNX model has exactly the TFLite signature
(names, shapes, element order).  Constant-only subgraphs (DEQUANTIZE of
float16 weights, DENSIFY of sparse weights) are folded at conversion time.
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
                           DIM_DENSE, PAD_SAME, Model)

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

    def convert_op(self, op):
        k = op.op
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
            if op.op.startswith("CUSTOM:"):
                raise ConversionError("custom operator %s is not supported" % op.op[7:])
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
