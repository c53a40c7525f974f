"""Minimal reader for TensorFlow Lite flatbuffers (subgraph 0 only).

Written for avatarmap's model converter.  Only the parts of the TFLite schema
that MediaPipe's float models use are decoded; field ids follow the public
TFLite schema (tensorflow/lite/schema/schema.fbs).  No flatbuffers library is
needed: tables, vectors and unions are read straight from the bytes.

FlatBuffers layout recap: a table starts with an int32 soffset to its vtable
(vtable = table_pos - soffset); the vtable holds uint16 vtable size, uint16
table size, then one uint16 offset per field id (0 = absent).  Offsets to
sub-tables, vectors and strings are uint32, relative to where they are stored.
A union occupies two field ids: the uint8 type, then the table offset.
"""

import struct

import numpy as np

# TensorType
FLOAT32, FLOAT16, INT32, UINT8, INT64, STRING, BOOL, INT16, COMPLEX64, INT8, FLOAT64 = range(11)
NP_DTYPE = {FLOAT32: np.float32, FLOAT16: np.float16, INT32: np.int32, UINT8: np.uint8,
            INT64: np.int64, BOOL: np.bool_, INT16: np.int16, INT8: np.int8,
            FLOAT64: np.float64}

# BuiltinOperator codes used here (values from the TFLite schema).
OPS = {
    0: "ADD", 1: "AVERAGE_POOL_2D", 2: "CONCATENATION", 3: "CONV_2D",
    4: "DEPTHWISE_CONV_2D", 5: "DEPTH_TO_SPACE", 6: "DEQUANTIZE", 9: "FULLY_CONNECTED",
    14: "LOGISTIC", 17: "MAX_POOL_2D", 18: "MUL", 19: "RELU", 20: "RELU_N1_TO_1",
    21: "RELU6", 22: "RESHAPE", 23: "RESIZE_BILINEAR", 25: "SOFTMAX", 28: "TANH",
    32: "CUSTOM", 34: "PAD", 40: "MEAN", 41: "SUB", 42: "DIV", 45: "STRIDED_SLICE",
    54: "PRELU", 124: "DENSIFY",
}

# ActivationFunctionType
ACT_NONE, ACT_RELU, ACT_RELU_N1_TO_1, ACT_RELU6, ACT_TANH = 0, 1, 2, 3, 4
ACT_NAMES = {0: "NONE", 1: "RELU", 2: "RELU_N1_TO_1", 3: "RELU6", 4: "TANH"}
# Padding
PAD_SAME, PAD_VALID = 0, 1
# DimensionType (sparsity)
DIM_DENSE, DIM_SPARSE_CSR = 0, 1


class FlatBuffer:
    def __init__(self, data):
        self.b = memoryview(data)

    def u8(self, p): return self.b[p]
    def i8(self, p): return struct.unpack_from("<b", self.b, p)[0]
    def u16(self, p): return struct.unpack_from("<H", self.b, p)[0]
    def i32(self, p): return struct.unpack_from("<i", self.b, p)[0]
    def u32(self, p): return struct.unpack_from("<I", self.b, p)[0]
    def u64(self, p): return struct.unpack_from("<Q", self.b, p)[0]

    def root(self):
        return self.u32(0)

    def field(self, table, fid):
        """Absolute position of field `fid` in `table`, or None when absent."""
        vt = table - self.i32(table)
        vsize = self.u16(vt)
        off = 4 + 2 * fid
        if off >= vsize:
            return None
        o = self.u16(vt + off)
        return table + o if o else None

    def scalar(self, table, fid, fmt, default):
        p = self.field(table, fid)
        return default if p is None else struct.unpack_from("<" + fmt, self.b, p)[0]

    def ref(self, table, fid):
        """Follow a uoffset field (table, vector or string); None when absent."""
        p = self.field(table, fid)
        return None if p is None else p + self.u32(p)

    def vector(self, table, fid):
        """(start, length) of a vector field; None when absent."""
        v = self.ref(table, fid)
        if v is None:
            return None
        return v + 4, self.u32(v)

    def tables(self, table, fid):
        v = self.vector(table, fid)
        if v is None:
            return []
        start, n = v
        return [start + 4 * i + self.u32(start + 4 * i) for i in range(n)]

    def array(self, table, fid, dtype):
        v = self.vector(table, fid)
        if v is None:
            return None
        start, n = v
        return np.frombuffer(self.b, dtype=np.dtype(dtype).newbyteorder("<"), count=n, offset=start)

    def string(self, table, fid):
        v = self.vector(table, fid)
        if v is None:
            return None
        start, n = v
        return bytes(self.b[start:start + n]).decode("utf-8", "replace")


class Tensor:
    def __init__(self, index, name, shape, ttype, buffer, sparsity):
        self.index, self.name, self.shape, self.type = index, name, shape, ttype
        self.buffer, self.sparsity = buffer, sparsity

    def __repr__(self):
        return "Tensor(%d %r %s type=%d buf=%d%s)" % (self.index, self.name, self.shape, self.type,
                                                     self.buffer, " sparse" if self.sparsity else "")


class Operator:
    def __init__(self, index, op, inputs, outputs, options, version=1, custom=None):
        self.index, self.op, self.inputs, self.outputs, self.opt = index, op, inputs, outputs, options
        self.version = version  # the operator code's version (custom ops change meaning with it)
        self.custom = custom    # raw custom_options bytes of a CUSTOM op (a FlexBuffer), or None

    def __repr__(self):
        return "Op(%d %s in=%s out=%s %s)" % (self.index, self.op, self.inputs, self.outputs, self.opt)


def _sparse_index_vector(fb, table, type_fid):
    t = fb.scalar(table, type_fid, "B", 0)
    sub = fb.ref(table, type_fid + 1)
    if t == 0 or sub is None:
        return None
    dtype = {1: np.int32, 2: np.uint16, 3: np.uint8}[t]
    return fb.array(sub, 0, dtype).astype(np.int64)


def _read_sparsity(fb, sp):
    if sp is None:
        return None
    dims = []
    for dm in fb.tables(sp, 2):
        dims.append({
            "format": fb.scalar(dm, 0, "b", 0),
            "dense_size": fb.scalar(dm, 1, "i", 0),
            "segments": _sparse_index_vector(fb, dm, 2),
            "indices": _sparse_index_vector(fb, dm, 4),
        })
    tro = fb.array(sp, 0, np.int32)
    bm = fb.array(sp, 1, np.int32)
    return {"traversal_order": [] if tro is None else [int(x) for x in tro],
            "block_map": [] if bm is None else [int(x) for x in bm],
            "dim_metadata": dims}


def _read_options(fb, op, opt):
    """Decode the builtin options table `opt` (may be None) for op name `op`."""
    def s(fid, fmt, default):
        return default if opt is None else fb.scalar(opt, fid, fmt, default)

    if op == "CONV_2D":
        return dict(padding=s(0, "b", 0), stride_w=s(1, "i", 1), stride_h=s(2, "i", 1),
                    act=s(3, "b", 0), dilation_w=s(4, "i", 1), dilation_h=s(5, "i", 1))
    if op == "DEPTHWISE_CONV_2D":
        return dict(padding=s(0, "b", 0), stride_w=s(1, "i", 1), stride_h=s(2, "i", 1),
                    depth_multiplier=s(3, "i", 1), act=s(4, "b", 0),
                    dilation_w=s(5, "i", 1), dilation_h=s(6, "i", 1))
    if op in ("MAX_POOL_2D", "AVERAGE_POOL_2D"):
        return dict(padding=s(0, "b", 0), stride_w=s(1, "i", 1), stride_h=s(2, "i", 1),
                    filter_w=s(3, "i", 1), filter_h=s(4, "i", 1), act=s(5, "b", 0))
    if op in ("ADD", "MUL", "SUB", "DIV"):
        return dict(act=s(0, "b", 0))
    if op == "CONCATENATION":
        return dict(axis=s(0, "i", 0), act=s(1, "b", 0))
    if op == "FULLY_CONNECTED":
        return dict(act=s(0, "b", 0), weights_format=s(1, "b", 0), keep_num_dims=bool(s(2, "B", 0)))
    if op == "RESHAPE":
        ns = None if opt is None else fb.array(opt, 0, np.int32)
        return dict(new_shape=None if ns is None else [int(x) for x in ns])
    if op == "RESIZE_BILINEAR":
        return dict(align_corners=bool(s(2, "B", 0)), half_pixel_centers=bool(s(3, "B", 0)))
    if op == "MEAN":
        return dict(keep_dims=bool(s(0, "B", 0)))
    if op == "DEPTH_TO_SPACE":
        return dict(block_size=s(0, "i", 0))
    if op == "SOFTMAX":
        return dict(beta=s(0, "f", 1.0))
    if op == "STRIDED_SLICE":
        return dict(begin_mask=s(0, "i", 0), end_mask=s(1, "i", 0), ellipsis_mask=s(2, "i", 0),
                    new_axis_mask=s(3, "i", 0), shrink_axis_mask=s(4, "i", 0), offset=bool(s(5, "B", 0)))
    return {}


# FlexBuffer types (flatbuffers/flexbuffers.h, the format of a custom operator's options).
FBT_NULL, FBT_INT, FBT_UINT, FBT_FLOAT, FBT_KEY, FBT_STRING = 0, 1, 2, 3, 4, 5
FBT_INDIRECT_INT, FBT_INDIRECT_UINT, FBT_INDIRECT_FLOAT, FBT_MAP, FBT_VECTOR = 6, 7, 8, 9, 10
FBT_VECTOR_INT, FBT_VECTOR_UINT, FBT_VECTOR_FLOAT, FBT_VECTOR_KEY = 11, 12, 13, 14
FBT_BLOB, FBT_BOOL, FBT_VECTOR_BOOL = 25, 26, 36


def read_flexbuffer(data):
    """Decode a FlexBuffer (the format MediaPipe's custom ops keep their options in) into
    Python values: maps -> dict, vectors -> list, scalars -> int / float / bool / str.

    Layout recap: the buffer ends with the root's packed type byte and the root's byte width;
    a packed type is (type << 2) | log2(width of the value's elements); offsets are unsigned
    and point backwards; an untyped vector's elements are followed by one packed type byte
    per element; a map is a vector of values preceded by (keys vector offset, keys byte
    width, size); typed vectors hold one scalar type, fixed ones (INT2..FLOAT4) omit the size.
    """
    b = bytes(data)
    if len(b) < 3:
        raise ValueError("flexbuffer too short")

    def uint(p, w):
        return int.from_bytes(b[p:p + w], "little")

    def sint(p, w):
        return int.from_bytes(b[p:p + w], "little", signed=True)

    def flt(p, w):
        return struct.unpack_from("<f" if w == 4 else "<d", b, p)[0] if w in (4, 8) else \
            float(np.frombuffer(b[p:p + 2], "<f2")[0])

    def cstr(p):
        e = b.index(b"\0", p)
        return b[p:e].decode("utf-8", "replace")

    def value(p, parent_w, packed):
        t, w = packed >> 2, 1 << (packed & 3)
        if t == FBT_NULL:
            return None
        if t == FBT_INT:
            return sint(p, parent_w)
        if t in (FBT_UINT,):
            return uint(p, parent_w)
        if t == FBT_BOOL:
            return bool(uint(p, parent_w))
        if t == FBT_FLOAT:
            return flt(p, parent_w)
        q = p - uint(p, parent_w)  # everything else is stored behind an offset
        if t == FBT_INDIRECT_INT:
            return sint(q, w)
        if t == FBT_INDIRECT_UINT:
            return uint(q, w)
        if t == FBT_INDIRECT_FLOAT:
            return flt(q, w)
        if t == FBT_KEY:
            return cstr(q)
        if t in (FBT_STRING, FBT_BLOB):
            n = uint(q - w, w)
            raw = b[q:q + n]
            return raw.decode("utf-8", "replace") if t == FBT_STRING else raw
        if t in (FBT_VECTOR, FBT_MAP):
            n = uint(q - w, w)
            types = q + n * w
            vals = [value(q + i * w, w, b[types + i]) for i in range(n)]
            if t == FBT_VECTOR:
                return vals
            kq = q - 3 * w
            keys_at = kq - uint(kq, w)
            kw = uint(q - 2 * w, w)
            keys = [cstr(keys_at + i * kw - uint(keys_at + i * kw, kw)) for i in range(n)]
            return dict(zip(keys, vals))
        if FBT_VECTOR_INT <= t <= FBT_VECTOR_KEY or t == FBT_VECTOR_BOOL:
            n = uint(q - w, w)
            elem = {FBT_VECTOR_INT: FBT_INT, FBT_VECTOR_UINT: FBT_UINT, FBT_VECTOR_FLOAT: FBT_FLOAT,
                    FBT_VECTOR_KEY: FBT_KEY, FBT_VECTOR_BOOL: FBT_BOOL}[t]
            if elem == FBT_KEY:
                return [cstr(q + i * w - uint(q + i * w, w)) for i in range(n)]
            return [value(q + i * w, w, elem << 2) for i in range(n)]
        if 16 <= t <= 24:  # fixed-length typed vectors: INT2, UINT2, FLOAT2, INT3, ..., FLOAT4
            n = 2 + (t - 16) // 3
            elem = (FBT_INT, FBT_UINT, FBT_FLOAT)[(t - 16) % 3]
            return [value(q + i * w, w, elem << 2) for i in range(n)]
        raise ValueError("flexbuffer type %d not supported" % t)

    root_w = b[-1]
    return value(len(b) - 2 - root_w, root_w, b[-2])


class Model:
    """Subgraph 0 of a .tflite file: tensors, operators, inputs, outputs, constants."""

    def __init__(self, data):
        if bytes(data[4:8]) != b"TFL3":
            raise ValueError("not a TFLite flatbuffer (identifier %r)" % bytes(data[4:8]))
        self.data = data
        fb = FlatBuffer(data)
        model = fb.root()
        self.version = fb.scalar(model, 0, "I", 0)
        self.opcodes = []
        self.opcode_versions = []
        for oc in fb.tables(model, 1):
            self.opcode_versions.append(fb.scalar(oc, 2, "i", 1))
            dep = fb.scalar(oc, 0, "b", 0)
            code = fb.scalar(oc, 3, "i", 0)
            code = max(int(dep), int(code))  # builtin_code wins once past 127
            name = OPS.get(code, "BUILTIN_%d" % code)
            if name == "CUSTOM":
                name = "CUSTOM:" + (fb.string(oc, 1) or "?")
            self.opcodes.append(name)
        buffers = fb.tables(model, 4)
        self.buffers = []
        for bt in buffers:
            v = fb.vector(bt, 0)
            if v is not None and v[1] > 0:
                self.buffers.append(bytes(fb.b[v[0]:v[0] + v[1]]))
                continue
            off, size = fb.scalar(bt, 1, "Q", 0), fb.scalar(bt, 2, "Q", 0)
            self.buffers.append(bytes(fb.b[off:off + size]) if off > 1 and size else b"")
        sgs = fb.tables(model, 2)
        if not sgs:
            raise ValueError("model has no subgraph")
        sg = sgs[0]
        self.tensors = []
        for i, t in enumerate(fb.tables(sg, 0)):
            shape = fb.array(t, 0, np.int32)
            self.tensors.append(Tensor(
                i, fb.string(t, 3) or ("t%d" % i),
                [] if shape is None else [int(x) for x in shape],
                fb.scalar(t, 1, "b", 0), fb.scalar(t, 2, "I", 0),
                _read_sparsity(fb, fb.ref(t, 6))))
        self.inputs = [int(x) for x in fb.array(sg, 1, np.int32)]
        self.outputs = [int(x) for x in fb.array(sg, 2, np.int32)]
        self.operators = []
        for i, o in enumerate(fb.tables(sg, 3)):
            code = fb.scalar(o, 0, "I", 0)
            op = self.opcodes[code]
            ins = fb.array(o, 1, np.int32)
            outs = fb.array(o, 2, np.int32)
            custom = fb.array(o, 5, np.uint8) if op.startswith("CUSTOM:") else None
            self.operators.append(Operator(
                i, op, [] if ins is None else [int(x) for x in ins],
                [] if outs is None else [int(x) for x in outs],
                _read_options(fb, op, fb.ref(o, 4)), self.opcode_versions[code],
                None if custom is None else bytes(custom)))

    @classmethod
    def load(cls, path):
        with open(path, "rb") as f:
            return cls(f.read())

    def raw_constant(self, idx):
        """The stored data of tensor `idx` as a numpy array (sparse values stay flat), or None."""
        t = self.tensors[idx]
        buf = self.buffers[t.buffer] if t.buffer < len(self.buffers) else b""
        if not buf:
            return None
        dt = np.dtype(NP_DTYPE[t.type]).newbyteorder("<")
        arr = np.frombuffer(buf, dtype=dt).astype(dt.newbyteorder("="))
        if t.sparsity is None:
            arr = arr.reshape(t.shape)
        return arr

    def op_histogram(self):
        h = {}
        for o in self.operators:
            h[o.op] = h.get(o.op, 0) + 1
        return h
