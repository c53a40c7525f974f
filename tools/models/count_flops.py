#!/usr/bin/env python3
"""Counts the floating-point operations of one inference of ONNX models.

Usage: count_flops.py MODEL.onnx [...] [--json OUT.json]

Counts multiply-adds as 2 FLOPs in Conv (incl. grouped and depthwise), ConvTranspose, Gemm
and MatMul, the layers that hold nearly all of the arithmetic; element-wise operators,
pooling and resizing are left out (a few percent). Shapes come from ONNX shape inference,
so the models need static input shapes (ours have them). Needs Debian's python3-onnx: run it
with /usr/bin/python3. The JSON maps each file's base name to its FLOP count.
"""
import json
import os
import sys

import onnx
from onnx import shape_inference


def shape_of(value_info):
    dims = value_info.type.tensor_type.shape.dim
    if not dims or any(not d.HasField("dim_value") for d in dims):
        return None
    return [d.dim_value for d in dims]


def count(path):
    model = shape_inference.infer_shapes(onnx.load(path))
    g = model.graph
    shapes = {}
    for vi in list(g.input) + list(g.output) + list(g.value_info):
        s = shape_of(vi)
        if s is not None:
            shapes[vi.name] = s
    for init in g.initializer:
        shapes[init.name] = list(init.dims)
    total = 0
    unknown = 0
    for node in g.node:
        op = node.op_type
        if op not in ("Conv", "ConvTranspose", "Gemm", "MatMul"):
            continue
        try:
            if op in ("Conv", "ConvTranspose"):
                w = shapes[node.input[1]]
                group = 1
                for a in node.attribute:
                    if a.name == "group":
                        group = a.i
                if op == "Conv":
                    out = shapes[node.output[0]]
                    per_out = w[1] * int(_prod(w[2:]))  # Cin/group * kernel
                    total += 2 * _prod(out) * per_out
                else:
                    x = shapes[node.input[0]]
                    total += 2 * _prod(x) * (w[1] * int(_prod(w[2:])))
            else:
                a_shape = shapes[node.input[0]]
                b_shape = shapes[node.input[1]]
                out = shapes[node.output[0]]
                k = a_shape[-1]
                if op == "Gemm":
                    for at in node.attribute:
                        if at.name == "transA" and at.i:
                            k = a_shape[0]
                total += 2 * _prod(out) * k
        except KeyError:
            unknown += 1
    return total, unknown


def _prod(xs):
    p = 1
    for x in xs:
        p *= x
    return p


def main(argv):
    out_json = None
    paths = []
    i = 0
    while i < len(argv):
        if argv[i] == "--json":
            out_json = argv[i + 1]
            i += 2
            continue
        if argv[i] in ("-h", "--help"):
            print(__doc__)
            return 0
        paths.append(argv[i])
        i += 1
    if not paths:
        print(__doc__, file=sys.stderr)
        return 2
    result = {}
    for p in paths:
        flops, unknown = count(p)
        name = os.path.basename(p)
        result[name] = flops
        note = f" ({unknown} layers without shapes, not counted)" if unknown else ""
        print(f"{name}: {flops / 1e9:.3f} GFLOP{note}")
    if out_json:
        tmp = out_json + ".tmp"
        with open(tmp, "w") as f:
            json.dump(result, f, indent=1, sort_keys=True)
        os.replace(tmp, out_json)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
