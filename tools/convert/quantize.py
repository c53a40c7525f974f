#!/usr/bin/python3
"""int8 (QDQ) versions of the converted MediaPipe models, from calibrated activation ranges.

Usage:
  quantize.py instrument FLOAT.onnx OUT.onnx
      every intermediate tensor becomes a graph output (for ort_calib, which collects
      activation ranges on real crops)
  quantize.py quantize FLOAT.onnx RANGES.json OUT.onnx [--calibration minmax|p99.9|p99.99|
      p99.999] [--reduce-range] [--float-tail K] [--float-ops OP,OP] [--float-nodes N,N]
      [--float-from NODE] [--all-float]

Needs only Debian's python3-onnx (>= 1.12) and python3-numpy.  See docs/convert.md
("int8 models") for the scheme; in short:
- QuantizeLinear -> DequantizeLinear pairs ("QDQ") around the nodes that are quantized, so
  that ONNX Runtime's graph optimiser fuses DQ -> Conv -> Q into QLinearConv, DQ -> Add -> Q
  into QLinearAdd, Concat into QLinearConcat, and drops the pairs around MaxPool / Resize /
  Reshape / Transpose (which then run on uint8).
- weights: int8, symmetric (zero point 0), one scale per output channel (Conv) or per tensor
  (Gemm); [-127, 127], or [-63, 63] with --reduce-range.  Biases: int32 with scale
  input scale x weight scale.
- activations: uint8, asymmetric, from the calibrated range of the tensor (minimum and
  maximum, or percentiles), widened to include 0 so that 0 is exact.  A Relu or Clip right
  after a quantized node is folded into it (its output is the quantized tensor; ORT removes
  it since the uint8 range already clamps).
- the model's inputs and outputs stay float with the same names and shapes.  Nodes from which
  a graph output is reached through at most K quantizable nodes (--float-tail K, counting the
  node itself) stay float, as do op types in --float-ops, nodes in --float-nodes, every
  quantizable node from --float-from NODE on, and everything with --all-float.
The output is deterministic (same inputs -> same bytes).
"""

import argparse
import collections
import json
import sys

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

QUANT_OPS = {"Conv", "Add", "Mul", "Concat", "Gemm"}
FUSED_ACTS = {"Relu", "Clip"}
PASS_OPS = {"MaxPool", "Resize", "Reshape", "Transpose"}


class QuantizeError(Exception):
    pass


def instrument(src, dst):
    m = onnx.load(src)
    g = m.graph
    have = {o.name for o in g.output}
    for n in g.node:
        for t in n.output:
            if t and t not in have:
                g.output.append(helper.make_tensor_value_info(t, TensorProto.FLOAT, None))
                have.add(t)
    onnx.save(m, dst)


def activation_params(lo, hi):
    """uint8 scale and zero point for the real range [lo, hi] (widened to include 0)."""
    lo, hi = min(float(lo), 0.0), max(float(hi), 0.0)
    if hi - lo < 1e-12:
        hi = lo + 1e-6
    scale = np.float32((hi - lo) / 255.0)
    zp = int(np.clip(np.round(-lo / float(scale)), 0, 255))
    return scale, zp


def clip_bounds(node, inits):
    """(lo, hi) of a Relu or Clip node (None where unbounded)."""
    if node.op_type == "Relu":
        return 0.0, None
    lo = hi = None
    if len(node.input) > 1 and node.input[1]:
        lo = float(numpy_helper.to_array(inits[node.input[1]]))
    if len(node.input) > 2 and node.input[2]:
        hi = float(numpy_helper.to_array(inits[node.input[2]]))
    return lo, hi


def fold_pads(g):
    """Folds each zero, spatial-only constant Pad whose one consumer is a Conv into that Conv's
    pads (the same arithmetic; ORT does this itself for float graphs, but a QDQ pair between the
    two would stop it).  Returns the number folded."""
    inits = {i.name: i for i in g.initializer}
    consumers = collections.defaultdict(list)
    for n in g.node:
        for t in n.input:
            consumers[t].append(n)
    outputs = {o.name for o in g.output}
    drop = set()
    for p in g.node:
        if p.op_type != "Pad" or p.output[0] in outputs or len(consumers[p.output[0]]) != 1:
            continue
        mode = next((helper.get_attribute_value(a) for a in p.attribute if a.name == "mode"),
                    b"constant")
        if mode != b"constant" or len(p.input) < 2 or p.input[1] not in inits:
            continue
        if len(p.input) > 2 and p.input[2]:
            if p.input[2] not in inits or float(numpy_helper.to_array(inits[p.input[2]])) != 0:
                continue
        pads = numpy_helper.to_array(inits[p.input[1]]).tolist()
        conv = consumers[p.output[0]][0]
        if (conv.op_type != "Conv" or conv.input[0] != p.output[0] or len(pads) != 8
                or pads[0] or pads[1] or pads[4] or pads[5] or min(pads) < 0):
            continue
        attrs = {a.name: a for a in conv.attribute}
        if "auto_pad" in attrs and helper.get_attribute_value(attrs["auto_pad"]) != b"NOTSET":
            continue
        old = list(helper.get_attribute_value(attrs["pads"])) if "pads" in attrs else [0] * 4
        new = [old[0] + pads[2], old[1] + pads[3], old[2] + pads[6], old[3] + pads[7]]
        if "pads" in attrs:
            conv.attribute.remove(attrs["pads"])
        conv.attribute.append(helper.make_attribute("pads", new))
        conv.input[0] = p.input[0]
        drop.add(id(p))
    kept = [n for n in g.node if id(n) not in drop]
    del g.node[:]
    g.node.extend(kept)
    return len(drop)


def quantize(src, ranges_path, dst, calibration="minmax", reduce_range=False, float_tail=1,
             float_ops=(), float_nodes=(), float_from=None, all_float=False):
    m = onnx.load(src)
    g = m.graph
    folded = fold_pads(g)
    with open(ranges_path) as f:
        ranges = json.load(f)["tensors"]
    inits = {i.name: i for i in g.initializer}
    consumers = collections.defaultdict(list)
    for n in g.node:
        for k, t in enumerate(n.input):
            if t:
                consumers[t].append((n, k))
    outputs = {o.name for o in g.output}
    inputs = {i.name for i in g.input}

    def is_act(t):
        return t and t not in inits

    def rng(t):
        if t in inputs and t not in ranges:
            raise QuantizeError(f"no range for graph input {t}")
        r = ranges.get(t)
        if r is None:
            return None
        if calibration == "minmax":
            return r["min"], r["max"]
        if calibration not in r:
            raise QuantizeError(f"ranges have no '{calibration}' for {t}")
        return r[calibration][0], r[calibration][1]

    # Distance (in quantizable nodes) from each node to a graph output.
    dist = {}
    order = list(g.node)
    for n in reversed(order):
        best = None
        for t in n.output:
            if t in outputs:
                best = 0
            for c, _ in consumers.get(t, []):
                d = dist.get(id(c))
                if d is not None and (best is None or d < best):
                    best = d
        if best is not None:
            dist[id(n)] = best + (1 if n.op_type in QUANT_OPS else 0)

    def effective_output(n):
        t = n.output[0]
        cs = consumers.get(t, [])
        if len(cs) == 1 and cs[0][0].op_type in FUSED_ACTS and t not in outputs:
            return cs[0][0].output[0], cs[0][0]
        return t, None

    names = [n.name for n in order]
    for name in list(float_nodes) + ([float_from] if float_from else []):
        if name not in names:
            raise QuantizeError(f"no node named {name}")
    first_float = names.index(float_from) if float_from else len(order)
    quantized = []
    for k, n in enumerate(order):
        if (all_float or n.op_type not in QUANT_OPS or n.op_type in float_ops
                or n.name in float_nodes or k >= first_float):
            continue
        d = dist.get(id(n))
        if d is not None and d <= float_tail:
            continue
        acts = [t for t in n.input if is_act(t)]
        if not acts or any(rng(t) is None for t in acts):
            continue
        if n.op_type in ("Conv", "Gemm") and (n.input[1] not in inits or len(acts) != 1):
            continue
        if n.op_type == "Gemm":
            attrs = {a.name: helper.get_attribute_value(a) for a in n.attribute}
            if attrs.get("transA", 0) or not attrs.get("transB", 0):
                continue
        out, _ = effective_output(n)
        if out in outputs or rng(out) is None:
            continue
        quantized.append(n)
    qset = {id(n) for n in quantized}

    # Tensors that get a QDQ pair, with their (lo, hi) range or the tensor they copy from.
    qdq = collections.OrderedDict()
    for n in quantized:
        for t in n.input:
            if is_act(t):
                qdq.setdefault(t, ("range", rng(t)))
        out, act = effective_output(n)
        lo, hi = rng(out)
        if act is not None:
            clo, chi = clip_bounds(act, inits)
            if clo is not None:
                lo = max(lo, clo)
            if chi is not None:
                hi = min(hi, chi)
        qdq[out] = ("range", (lo, hi))
    # A float Conv / Gemm between a DequantizeLinear and a QuantizeLinear would not stay float:
    # ORT's WeightBiasQuantization quantizes its weights itself, per tensor (measured on
    # pose_landmark_full: 0.6 px -> 1.7 px mean difference), so refuse that.
    for n in order:
        if id(n) in qset or n.op_type not in ("Conv", "Gemm"):
            continue
        out, _ = effective_output(n)
        if n.input[0] in qdq and out in qdq:
            raise QuantizeError(
                f"float node {n.name} would sit between quantized tensors ({n.input[0]} -> "
                f"{out}), where ONNX Runtime quantizes its weights per tensor; keep its "
                f"neighbours float too (--float-from)")
    # Ops that move uint8 values unchanged: the output copies the input's parameters.
    for n in order:
        if (n.op_type in PASS_OPS and n.op_type not in float_ops and n.input[0] in qdq
                and n.output[0] not in outputs):
            qdq[n.output[0]] = ("same", n.input[0])
    params = {}

    def resolve(t):
        if t not in params:
            kind, v = qdq[t]
            params[t] = resolve(v) if kind == "same" else activation_params(*v)
        return params[t]

    for t in qdq:
        resolve(t)

    new_inits = []
    new_nodes = collections.defaultdict(list)  # tensor -> nodes inserted after its producer
    dq_of = {}  # DequantizeLinear output -> the tensor it stands for

    def scalar(name, value, dtype):
        new_inits.append(numpy_helper.from_array(np.array(value, dtype=dtype), name))
        return name

    for t, (scale, zp) in params.items():
        s = scalar(t + "_scale", scale, np.float32)
        z = scalar(t + "_zero_point", zp, np.uint8)
        new_nodes[t].append(helper.make_node("QuantizeLinear", [t, s, z], [t + "_q"],
                                             name=t + "_QuantizeLinear"))
        for k, (c, slot) in enumerate(consumers.get(t, [])):
            dq_out = f"{t}_dq{k}"
            dq_of[dq_out] = t
            new_nodes[t].append(helper.make_node("DequantizeLinear", [t + "_q", s, z], [dq_out],
                                                 name=f"{t}_DequantizeLinear{k}"))
            c.input[slot] = dq_out

    qmax = 63 if reduce_range else 127
    used_weights = set()
    for n in quantized:
        if n.op_type in ("Conv", "Gemm"):
            w_name = n.input[1]
            w = numpy_helper.to_array(inits[w_name]).astype(np.float64)
            per_channel = n.op_type == "Conv"
            if per_channel:
                amax = np.abs(w.reshape(w.shape[0], -1)).max(axis=1)
            else:
                amax = np.array(np.abs(w).max())
            w_scale = np.where(amax > 0, amax / qmax, 1.0).astype(np.float32)
            bshape = (-1,) + (1,) * (w.ndim - 1) if per_channel else ()
            wq = np.clip(np.round(w / w_scale.reshape(bshape).astype(np.float64)), -qmax, qmax)
            base = n.name or w_name
            wq_name = base + "_weight_int8"
            new_inits.append(numpy_helper.from_array(wq.astype(np.int8), wq_name))
            ws = scalar(base + "_weight_scale", w_scale, np.float32)
            wz = scalar(base + "_weight_zero_point", np.zeros_like(w_scale, dtype=np.int8),
                        np.int8)
            attrs = {"axis": 0} if per_channel else {}
            new_nodes[wq_name].append(helper.make_node(
                "DequantizeLinear", [wq_name, ws, wz], [base + "_weight_dq"],
                name=base + "_weight_DequantizeLinear", **attrs))
            n.input[1] = base + "_weight_dq"
            used_weights.add(w_name)
            if len(n.input) > 2 and n.input[2]:
                b_name = n.input[2]
                b = numpy_helper.to_array(inits[b_name]).astype(np.float64)
                x_scale = float(params[dq_of[n.input[0]]][0])
                b_scale = (x_scale * w_scale.astype(np.float64)).astype(np.float32)
                bq = np.round(b / b_scale.astype(np.float64))
                bq = np.clip(bq, -2**31, 2**31 - 1).astype(np.int32)
                bq_name = base + "_bias_int32"
                new_inits.append(numpy_helper.from_array(bq, bq_name))
                bs = scalar(base + "_bias_scale", b_scale, np.float32)
                bz = scalar(base + "_bias_zero_point", np.zeros_like(bq, dtype=np.int32)
                            if per_channel else np.int32(0), np.int32)
                new_nodes[bq_name].append(helper.make_node(
                    "DequantizeLinear", [bq_name, bs, bz], [base + "_bias_dq"],
                    name=base + "_bias_DequantizeLinear", **attrs))
                n.input[2] = base + "_bias_dq"
                used_weights.add(b_name)
        else:
            for slot, t in enumerate(n.input):
                if t in inits:  # a constant operand (Add / Mul): uint8 per tensor
                    c = numpy_helper.to_array(inits[t]).astype(np.float64)
                    scale, zp = activation_params(c.min(), c.max())
                    cq = np.clip(np.round(c / float(scale)) + zp, 0, 255).astype(np.uint8)
                    base = f"{n.name or n.output[0]}_const{slot}"
                    new_inits.append(numpy_helper.from_array(cq, base + "_uint8"))
                    s = scalar(base + "_scale", scale, np.float32)
                    z = scalar(base + "_zero_point", zp, np.uint8)
                    new_nodes[base + "_uint8"].append(helper.make_node(
                        "DequantizeLinear", [base + "_uint8", s, z], [base + "_dq"],
                        name=base + "_DequantizeLinear"))
                    n.input[slot] = base + "_dq"
                    used_weights.add(t)

    # Rebuild the node list: each inserted node right after what produces its input.
    nodes = []
    for t in list(new_nodes):
        if t in inputs or t in inits or t.endswith(("_weight_int8", "_bias_int32", "_uint8")):
            nodes.extend(new_nodes.pop(t))
    for n in order:
        nodes.append(n)
        for t in n.output:
            nodes.extend(new_nodes.pop(t, []))
    if new_nodes:
        raise QuantizeError("internal: unplaced nodes for " + ", ".join(new_nodes))
    del g.node[:]
    g.node.extend(nodes)
    still_used = {t for n in g.node for t in n.input}
    keep = [i for i in g.initializer if i.name in still_used]
    del g.initializer[:]
    g.initializer.extend(keep + new_inits)
    onnx.checker.check_model(m)
    onnx.save(m, dst)
    counts = collections.Counter(n.op_type for n in quantized)
    print(f"quantize: {dst}: {len(quantized)} nodes quantized ({dict(sorted(counts.items()))}), "
          f"{len(params)} activations, calibration {calibration}"
          f"{', reduce_range' if reduce_range else ''}, float tail {float_tail}, "
          f"{folded} pads folded into convolutions")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    a = sub.add_parser("instrument")
    a.add_argument("src")
    a.add_argument("dst")
    q = sub.add_parser("quantize")
    q.add_argument("src")
    q.add_argument("ranges")
    q.add_argument("dst")
    q.add_argument("--calibration", default="minmax",
                   choices=["minmax", "p99.9", "p99.99", "p99.999"])
    q.add_argument("--reduce-range", action="store_true")
    q.add_argument("--float-tail", type=int, default=1)
    q.add_argument("--float-ops", default="")
    q.add_argument("--float-nodes", default="")
    q.add_argument("--float-from", default=None)
    q.add_argument("--all-float", action="store_true",
                   help="quantize nothing: for a model whose int8 version is slower or less "
                        "accurate, so that --precision int8 still finds a file")
    args = ap.parse_args(argv)
    try:
        if args.cmd == "instrument":
            instrument(args.src, args.dst)
        else:
            quantize(args.src, args.ranges, args.dst, args.calibration, args.reduce_range,
                     args.float_tail, tuple(o for o in args.float_ops.split(",") if o),
                     tuple(o for o in args.float_nodes.split(",") if o), args.float_from,
                     args.all_float)
    except (QuantizeError, OSError, KeyError, ValueError) as e:
        print(f"quantize: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
