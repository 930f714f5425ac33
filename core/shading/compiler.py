"""Node graph → shader program (core/shading/ops.py), without bpy.

A graph is a dict ``{"nodes": {name: node}}``; a node is a dict with ``type`` (Blender's
``node.type``, e.g. "MATH"), ``props`` (its settings: ``operation``, ``blend_type``,
``data_type``, ``clamp``, ramp stops, curve tables, ...) and ``inputs``: socket identifier →
a constant (float or 3-sequence) or a link ``("link", node name, output identifier)``. Node
groups, reroutes and muted nodes are resolved by the caller (addon/export/shading.py), so
the graph is flat.

``compile_output(graph, source, kind)`` compiles what feeds a material slot: ``source`` a
link or a constant, ``kind`` "colour" (result clamped by the kernel), "value" (a scalar in
x) or "vector". Unsupported nodes raise :class:`Unsupported` naming the node.
Socket conversions are Cycles': float → (f, f, f); colour → float by the linear Rec.709
luminance; vector → float by the mean of the components.
"""
from __future__ import annotations

import functools

import numpy as np

from . import ops as O
from .program import Program

LUMA = (0.2126729, 0.7151522, 0.0721750)  # linear Rec.709 → Y, Blender's scene-linear default
BLACKBODY_RANGE = (800.0, 12000.0)  # Cycles holds the Blackbody node's colour outside this range
WAVELENGTH_RANGE = (380.0, 780.0)


class Unsupported(Exception):
    """A node the compiler cannot translate: ``node`` its name, the message why."""

    def __init__(self, node, why):
        super().__init__(f"'{node}': {why}")
        self.node = node
        self.why = why


def _is_link(v):
    return isinstance(v, tuple) and len(v) == 3 and v[0] == "link"


class Compiler:
    def __init__(self, graph, camera=None, window=None):
        self.nodes = graph["nodes"]
        self.camera = camera  # world → camera 3×4 (rows), for Texture Coordinate Camera
        self.window = window  # (orthographic, half width, half height) of the frame, for Window
        self.ops = []
        self.consts = []
        self.nreg = 0
        self.attributes = []
        self.done = {}
        self.busy = set()
        self.mode = 0  # 0: the shading point; 1, 2: its neighbours at +bu, +bv (the Bump node's heights)

    # ------------------------------------------------------------------ emission helpers
    def reg(self, width):
        r = self.nreg
        self.nreg += width
        if self.nreg > O.MAX_REGISTERS:
            raise Unsupported("program", f"needs more than {O.MAX_REGISTERS} registers")
        return r

    def const(self, values):
        k = len(self.consts)
        self.consts.extend(float(v) for v in values)
        return k

    def cf(self, v):
        """Operand of the constant float v."""
        return -1 - self.const([v])

    def cv(self, v):
        return -1 - self.const(v)

    def emit(self, op, out, args, p=0, q=0):
        self.ops.extend([op, len(args), out, p, q] + [int(a) for a in args])
        return out

    def attr(self, name):
        if name not in self.attributes:
            self.attributes.append(name)
        return self.attributes.index(name)

    # ------------------------------------------------------------------ values and conversions
    def convert(self, operand, have, want):
        """``operand`` of type ``have`` ("f", "v" vector, "c" colour) as type ``want``."""
        if have == want or (have in "vc" and want in "vc"):
            return operand
        if want == "f":
            if operand < 0:
                v = self.consts[-1 - operand:-1 - operand + 3]
                return self.cf(sum(a * b for a, b in zip(v, LUMA)) if have == "c" else sum(v) / 3.0)
            out = self.reg(4)
            w = LUMA if have == "c" else (1 / 3, 1 / 3, 1 / 3)
            self.emit(O.OP_VMATH, out, [operand, self.cv(w), self.cv((0, 0, 0)), self.cf(0)], p=O.VMATH["DOT_PRODUCT"])
            return out + 3
        if operand < 0:
            return self.cv([self.consts[-1 - operand]] * 3)
        out = self.reg(3)
        return self.emit(O.OP_COMBINE, out, [operand, operand, operand])

    def source(self, value, want):
        """Operand of a constant or link ``value`` as type ``want``."""
        if _is_link(value):
            _, node, socket = value
            operand, have = self.output(node, socket)
            return self.convert(operand, have, want)
        if isinstance(value, (int, float, np.floating, np.integer)):
            return self.convert(self.cf(value), "f", want)
        v = [float(x) for x in value][:3]
        v += [0.0] * (3 - len(v))
        return self.convert(self.cv(v), "v", want) if want == "f" else self.cv(v)

    def input(self, node, ident, want, default=0.0):
        nd = self.nodes[node]
        return self.source(nd["inputs"].get(ident, default), want)

    def output(self, node, socket):
        if node not in self.nodes or self.nodes[node] is None:
            raise Unsupported(node, "not in the graph")
        key = (node, self.mode)
        if key not in self.done:
            if key in self.busy:
                raise Unsupported(node, "a cycle in the node tree")
            self.busy.add(key)
            nd = self.nodes[node]
            fn = NODES.get(nd["type"])
            if fn is None:
                raise Unsupported(node, f"node type {nd['type']} is not supported")
            self.done[key] = fn(self, node, nd, nd.get("props", {}))
            self.busy.discard(key)
        outs = self.done[key]
        if socket not in outs:
            raise Unsupported(node, f"output '{socket}' is not supported")
        return outs[socket]

    def finish(self, name, result):
        self.emit(O.OP_END, 0, [result])
        return Program(name=name, ops=np.asarray(self.ops, np.int32), consts=np.asarray(self.consts, np.float32),
                       attributes=list(self.attributes), n_registers=self.nreg)


def compile_output(graph, source, kind, name="program", camera=None, scale=None, weight=1.0, window=None):
    """The Program computing ``source`` (a link or a constant) as ``kind`` ("colour", "value",
    "vector"); ``scale``: a second source multiplied in (an emission's strength), ``weight`` a
    constant factor (the weight of the shader mixes above an emitter); ``camera`` the world →
    camera matrix (Cycles' camera space: x right, y up, z forward) and ``window``
    (orthographic, half width, half height of the frame: in metres for an orthographic
    camera, at unit distance for a perspective one) for the Camera and Window coordinates."""
    c = Compiler(graph, camera, window)
    want = "f" if kind == "value" else ("c" if kind == "colour" else "v")
    r = c.source(source, want)
    if kind == "value":
        r = c.convert(r, "f", "v")
    if scale is not None:
        s = c.source(scale, "f")
        out = c.reg(4)
        c.emit(O.OP_VMATH, out, [r, c.cv((0, 0, 0)), c.cv((0, 0, 0)), s], p=O.VMATH["SCALE"])
        r = out
    if weight != 1.0:
        out = c.reg(4)
        c.emit(O.OP_VMATH, out, [r, c.cv((0, 0, 0)), c.cv((0, 0, 0)), c.cf(weight)], p=O.VMATH["SCALE"])
        r = out
    return c.finish(name, r)


# ---------------------------------------------------------------------- node translations

def _value(c, name, nd, pr):
    return {"Value": (c.cf(pr.get("value", 0.0)), "f")}


def _rgb(c, name, nd, pr):
    return {"Color": (c.cv(pr.get("color", (0.0, 0.0, 0.0))[:3]), "c")}


def _math(c, name, nd, pr):
    op = pr.get("operation", "ADD")
    if op not in O.MATH:
        raise Unsupported(name, f"math operation {op}")
    a = [c.input(name, k, "f", 0.5) for k in ("Value", "Value_001", "Value_002")]
    out = c.reg(1)
    c.emit(O.OP_MATH, out, a, p=O.MATH[op], q=1 if pr.get("use_clamp") else 0)
    return {"Value": (out, "f")}


def _vmath(c, name, nd, pr):
    op = pr.get("operation", "ADD")
    if op not in O.VMATH:
        raise Unsupported(name, f"vector math operation {op}")
    a = [c.input(name, k, "v", (0.0, 0.0, 0.0)) for k in ("Vector", "Vector_001", "Vector_002")]
    a.append(c.input(name, "Scale", "f", 1.0))
    out = c.reg(4)
    c.emit(O.OP_VMATH, out, a, p=O.VMATH[op])
    return {"Vector": (out, "v"), "Value": (out + 3, "f")}


def _mix(c, name, nd, pr):
    dt = pr.get("data_type", "FLOAT")
    clamp_f = 1 if pr.get("clamp_factor", True) else 0
    if dt == "FLOAT":
        out = c.reg(1)
        c.emit(O.OP_MIXF, out, [c.input(name, "Factor_Float", "f", 0.5), c.input(name, "A_Float", "f"),
                                c.input(name, "B_Float", "f")], q=clamp_f)
        return {"Result_Float": (out, "f")}
    if dt == "VECTOR":
        uniform = pr.get("factor_mode", "UNIFORM") == "UNIFORM"
        fac = c.input(name, "Factor_Float", "f", 0.5) if uniform else c.input(name, "Factor_Vector", "v", 0.5)
        out = c.reg(3)
        c.emit(O.OP_MIXV, out, [fac, c.input(name, "A_Vector", "v"), c.input(name, "B_Vector", "v")],
               q=clamp_f | (0 if uniform else 2))
        return {"Result_Vector": (out, "v")}
    if dt == "RGBA":
        mode = pr.get("blend_type", "MIX")
        out = c.reg(3)
        c.emit(O.OP_MIXC, out, [c.input(name, "Factor_Float", "f", 0.5), c.input(name, "A_Color", "c"),
                                c.input(name, "B_Color", "c")], p=O.BLEND[mode],
               q=clamp_f | (2 if pr.get("clamp_result") else 0))
        return {"Result_Color": (out, "c")}
    raise Unsupported(name, f"mix data type {dt}")


def _mix_rgb(c, name, nd, pr):
    out = c.reg(3)
    c.emit(O.OP_MIXC, out, [c.input(name, "Fac", "f", 0.5), c.input(name, "Color1", "c"),
                            c.input(name, "Color2", "c")], p=O.BLEND[pr.get("blend_type", "MIX")],
           q=1 | (2 if pr.get("use_clamp") else 0))
    return {"Color": (out, "c")}


def _clamp(c, name, nd, pr):
    out = c.reg(1)
    c.emit(O.OP_CLAMP, out, [c.input(name, "Value", "f"), c.input(name, "Min", "f"), c.input(name, "Max", "f", 1.0)],
           p=1 if pr.get("clamp_type", "MINMAX") == "RANGE" else 0)
    return {"Result": (out, "f")}


def _map_range(c, name, nd, pr):
    mode = O.MAPRANGE[pr.get("interpolation_type", "LINEAR")]
    clamp = 1 if pr.get("clamp", True) else 0
    if pr.get("data_type", "FLOAT") == "FLOAT_VECTOR":
        keys = ("Vector", "From_Min_FLOAT3", "From_Max_FLOAT3", "To_Min_FLOAT3", "To_Max_FLOAT3", "Steps_FLOAT3")
        out = c.reg(3)
        c.emit(O.OP_MAPRANGE, out, [c.input(name, k, "v", 0.0) for k in keys], p=mode, q=clamp | 2)
        return {"Vector": (out, "v")}
    keys = ("Value", "From Min", "From Max", "To Min", "To Max", "Steps")
    out = c.reg(1)
    c.emit(O.OP_MAPRANGE, out, [c.input(name, k, "f", 0.0) for k in keys], p=mode, q=clamp)
    return {"Result": (out, "f")}


def _separate(c, name, nd, pr, ident, outs, conv):
    v = c.input(name, ident, "c" if ident == "Color" else "v")
    if conv is not None:
        r = c.reg(3)
        v = c.emit(O.OP_CONVERT, r, [v], p=conv)
    if v < 0:
        return {o: (c.cf(c.consts[-1 - v + i]), "f") for i, o in enumerate(outs)}
    return {o: (v + i, "f") for i, o in enumerate(outs)}


def _separate_color(c, name, nd, pr):
    mode = pr.get("mode", "RGB")
    conv = {"RGB": None, "HSV": O.CONV_RGB_HSV, "HSL": O.CONV_RGB_HSL}[mode]
    return _separate(c, name, nd, pr, "Color", ("Red", "Green", "Blue"), conv)


def _separate_xyz(c, name, nd, pr):
    return _separate(c, name, nd, pr, "Vector", ("X", "Y", "Z"), None)


def _combine(c, name, nd, pr, keys, conv, ident, kind):
    out = c.reg(3)
    c.emit(O.OP_COMBINE, out, [c.input(name, k, "f") for k in keys])
    if conv is not None:
        r = c.reg(3)
        out = c.emit(O.OP_CONVERT, r, [out], p=conv)
    return {ident: (out, kind)}


def _combine_color(c, name, nd, pr):
    conv = {"RGB": None, "HSV": O.CONV_HSV_RGB, "HSL": O.CONV_HSL_RGB}[pr.get("mode", "RGB")]
    return _combine(c, name, nd, pr, ("Red", "Green", "Blue"), conv, "Color", "c")


def _combine_xyz(c, name, nd, pr):
    return _combine(c, name, nd, pr, ("X", "Y", "Z"), None, "Vector", "v")


def _colour_op(op, keys, defaults):
    def fn(c, name, nd, pr):
        out = c.reg(3)
        args = [c.input(name, k, "c" if k == "Color" else "f", d) for k, d in zip(keys, defaults)]
        c.emit(op, out, args)
        return {"Color": (out, "c")}
    return fn


def _rgb_to_bw(c, name, nd, pr):
    return {"Val": (c.convert(c.input(name, "Color", "c"), "c", "f"), "f")}


def _coord(c, which):
    if which == O.COORD_P and c.mode:
        return _attribute_op(c, "@world")  # the neighbour's position
    out = c.reg(3)
    return c.emit(O.OP_COORD, out, [], p=which)


def _attribute_op(c, attr, normalise=False, mode=None):
    mode = c.mode if mode is None else mode
    out = c.reg(3)
    return c.emit(O.OP_ATTR, out, [], p=(1 if normalise else 0) | (2 if mode == 1 else 0) | (4 if mode == 2 else 0),
                  q=c.attr(attr))


def _normal_in(c, name, nd):
    n = nd["inputs"].get("Normal")
    return c.source(n, "v") if n is not None else _coord(c, O.COORD_N)


def _bump(c, name, nd, pr):
    if c.mode:
        raise Unsupported(name, "a Bump node inside the height of another")
    h = nd["inputs"].get("Height", 1.0)
    heights = []
    for mode in (0, 1, 2):
        c.mode = mode
        try:
            heights.append(c.source(h, "f"))
        finally:
            c.mode = 0
    pos = [_attribute_op(c, "@world", mode=m) for m in (0, 1, 2)]
    out = c.reg(3)
    c.emit(O.OP_BUMP, out, heights + [c.input(name, "Strength", "f", 1.0), c.input(name, "Distance", "f", 1.0)]
           + pos + [_normal_in(c, name, nd)], q=1 if pr.get("invert") else 0)
    return {"Normal": (out, "v")}


def _normal_map(c, name, nd, pr):
    space = pr.get("space", "TANGENT")
    if space not in O.NORMALMAP_SPACES:
        raise Unsupported(name, f"{space.lower()} space normal maps")
    uv = "uv:" + pr.get("uv_map", "")
    pos = [_attribute_op(c, "@world", mode=m) for m in (0, 1, 2)]
    uvs = [_attribute_op(c, uv, mode=m) for m in (0, 1, 2)]
    out = c.reg(3)
    c.emit(O.OP_NORMALMAP, out, [c.input(name, "Color", "c", (0.5, 0.5, 1.0)), c.input(name, "Strength", "f", 1.0)]
           + pos + uvs + [_coord(c, O.COORD_N)], p=O.NORMALMAP_SPACES[space])
    return {"Normal": (out, "v")}


def _tex_coord(c, name, nd, pr):
    outs = {}
    # each output's ops are emitted only when it is used: lazily through small closures
    uv = pr.get("uv_map", "")
    outs["Generated"] = lambda: (_attribute_op(c, "@generated"), "v")
    outs["Normal"] = lambda: (_attribute_op(c, "@normal", True), "v")
    outs["UV"] = lambda: (_attribute_op(c, "uv:" + uv), "v")
    outs["Object"] = lambda: (_attribute_op(c, "@object"), "v")
    outs["Camera"] = lambda: (_camera(c, name), "v")
    outs["Reflection"] = lambda: (_reflection(c), "v")
    outs["Window"] = lambda: (_window(c, name), "v")
    return _Lazy(outs)


def _camera(c, name):
    if c.camera is None:
        raise Unsupported(name, "Camera coordinates without a camera")
    m = np.asarray(c.camera, np.float64)[:3, :4].reshape(-1)
    out = c.reg(3)
    return c.emit(O.OP_XFORM, out, [_coord(c, O.COORD_P)], p=O.XF_POINT, q=c.const(m))


def _window(c, name):
    """Cycles' Window coordinates: the point's place in the camera's frame, (0, 0) to (1, 1)."""
    if c.camera is None or c.window is None:
        raise Unsupported(name, "Window coordinates without a camera")
    ortho, hx, hy = c.window
    s = np.array([[0.5 / hx, 0, 0, 0.5], [0, 0.5 / hy, 0, 0.5], [0, 0, 0, 0]], np.float64)
    cam = _camera(c, name)
    if ortho:
        v = cam
    else:  # Cycles' camera space: z is the distance in front of the camera
        x = c.reg(1)
        c.emit(O.OP_MATH, x, [cam, cam + 2, c.cf(0.0)], p=O.MATH["DIVIDE"])
        y = c.reg(1)
        c.emit(O.OP_MATH, y, [cam + 1, cam + 2, c.cf(0.0)], p=O.MATH["DIVIDE"])
        v = c.reg(3)
        c.emit(O.OP_COMBINE, v, [x, y, c.cf(0.0)])
    out = c.reg(3)
    return c.emit(O.OP_XFORM, out, [v], p=O.XF_POINT, q=c.const(s.reshape(-1)))


def _reflection(c):
    i = _coord(c, O.COORD_I)
    n = _coord(c, O.COORD_N)
    neg = c.reg(4)
    c.emit(O.OP_VMATH, neg, [i, c.cv((0, 0, 0)), c.cv((0, 0, 0)), c.cf(-1.0)], p=O.VMATH["SCALE"])
    out = c.reg(4)
    c.emit(O.OP_VMATH, out, [neg, n, c.cv((0, 0, 0)), c.cf(1.0)], p=O.VMATH["REFLECT"])
    return out


class _Lazy(dict):
    """Outputs computed when first asked for."""

    def __contains__(self, key):
        return dict.__contains__(self, key)

    def __getitem__(self, key):
        v = dict.__getitem__(self, key)
        if callable(v):
            v = v()
            dict.__setitem__(self, key, v)
        return v


def _uv_map(c, name, nd, pr):
    return _Lazy({"UV": lambda: (_attribute_op(c, "uv:" + pr.get("uv_map", "")), "v")})


def _geometry(c, name, nd, pr):
    return _Lazy({"Position": lambda: (_coord(c, O.COORD_P), "v"), "Normal": lambda: (_coord(c, O.COORD_N), "v"),
                  "True Normal": lambda: (_coord(c, O.COORD_NG), "v"),
                  "Incoming": lambda: (_coord(c, O.COORD_I), "v")})


def _attribute(c, name, nd, pr):
    attr = pr.get("attribute_name", "")
    if pr.get("attribute_type", "GEOMETRY") != "GEOMETRY":
        raise Unsupported(name, f"{pr.get('attribute_type')} attributes")
    key = "col:" + attr

    outs = _Lazy()
    outs.update({"Color": lambda: (_attribute_op(c, key), "c"), "Vector": lambda: (outs["Color"][0], "v"),
                 "Fac": lambda: (c.convert(outs["Color"][0], "v", "f"), "f"), "Alpha": lambda: (c.cf(1.0), "f")})
    return outs


def _vertex_color(c, name, nd, pr):
    return _Lazy({"Color": lambda: (_attribute_op(c, "col:" + pr.get("layer_name", "")), "c"),
                  "Alpha": lambda: (c.cf(1.0), "f")})


def _mapping(c, name, nd, pr):
    vt = pr.get("vector_type", "POINT")
    vals = []
    if nd["inputs"].get("Vector") is None and vt in ("POINT", "TEXTURE"):
        nd = dict(nd, inputs=dict(nd["inputs"], Vector=(0.0, 0.0, 0.0)))
    for k, d in (("Location", (0, 0, 0)), ("Rotation", (0, 0, 0)), ("Scale", (1, 1, 1))):
        v = nd["inputs"].get(k, d)
        if _is_link(v):
            raise Unsupported(name, f"a linked {k}")
        vals.append(np.asarray(v, np.float64))
    m = mapping_matrix(vt, *vals)
    out = c.reg(3)
    p = {"POINT": O.XF_POINT, "TEXTURE": O.XF_POINT, "VECTOR": O.XF_VECTOR, "NORMAL": O.XF_NORMAL}[vt]
    c.emit(O.OP_XFORM, out, [c.input(name, "Vector", "v")], p=p, q=c.const(m[:3, :4].reshape(-1)))
    return {"Vector": (out, "v")}


def euler_xyz(r):
    """Blender's XYZ Euler rotation matrix (R = Rz Ry Rx)."""
    cx, cy, cz = np.cos(r)
    sx, sy, sz = np.sin(r)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def mapping_matrix(vector_type, loc, rot, scale):
    """4×4 matrix of Blender's Mapping node (Cycles' svm_mapping): Point: T R S; Texture: its
    inverse; Vector: R S; Normal: R S⁻¹ (then normalised)."""
    r = euler_xyz(rot)
    m = np.eye(4)
    if vector_type == "POINT":
        m[:3, :3] = r @ np.diag(scale)
        m[:3, 3] = loc
    elif vector_type == "TEXTURE":
        safe = np.where(scale != 0, scale, 1.0)
        inv_s = np.where(scale != 0, 1.0 / safe, 0.0)
        m[:3, :3] = np.diag(inv_s) @ r.T
        m[:3, 3] = -m[:3, :3] @ loc
    elif vector_type == "VECTOR":
        m[:3, :3] = r @ np.diag(scale)
    else:
        safe = np.where(scale != 0, scale, 1.0)
        m[:3, :3] = r @ np.diag(np.where(scale != 0, 1.0 / safe, 0.0))
    return m


def _image(c, name, nd, pr):
    t = pr.get("texture", -1)
    if t is None or t < 0:
        raise Unsupported(name, "an image that cannot be loaded")
    vec = nd["inputs"].get("Vector")
    uv = c.source(vec, "v") if vec is not None else _attribute_op(c, "uv:" + pr.get("uv_map", ""))
    if pr.get("projection", "FLAT") != "FLAT":
        raise Unsupported(name, f"{pr.get('projection')} projection")
    out = c.reg(4)
    c.emit(O.OP_IMAGE, out, [uv], q=int(t))
    return {"Color": (out, "c"), "Alpha": (out + 3, "f")}


def bake_ramp(stops, interpolation="LINEAR"):
    """(RAMP_TABLE_SIZE, 4) RGBA of a Color Ramp at i/(size−1), as Blender's colour band
    evaluates it (BKE_colorband_evaluate): ``stops`` a list of (position, rgba), sorted here.
    Constant, linear, ease, cardinal and B-spline interpolation in RGB."""
    st = sorted(((float(p), np.asarray(c, np.float64)[:4]) for p, c in stops), key=lambda s: s[0])
    x = np.linspace(0.0, 1.0, O.RAMP_TABLE_SIZE)
    return np.stack([colorband_evaluate(st, interpolation, v) for v in x])


def _key_weights(t, kind):
    """Blender's key_curve_position_weights for cardinal and B-spline interpolation."""
    t2 = t * t
    t3 = t2 * t
    if kind == "CARDINAL":
        fc = 0.71
        return np.array([-fc * t3 + 2 * fc * t2 - fc * t, (2 - fc) * t3 + (fc - 3) * t2 + 1,
                         (fc - 2) * t3 + (3 - 2 * fc) * t2 + fc * t, fc * t3 - fc * t2])
    return np.array([-t3 / 6 + t2 / 2 - t / 2 + 1 / 6, t3 / 2 - t2 + 2 / 3, -t3 / 2 + t2 / 2 + t / 2 + 1 / 6, t3 / 6])


def colorband_evaluate(st, ipo, v):
    """One RGBA of a colour band (Blender's BKE_colorband_evaluate, RGB colour mode)."""
    n = len(st)
    if n == 0:
        return np.zeros(4)
    if n == 1:
        return st[0][1].copy()
    if v <= st[0][0] and ipo in ("LINEAR", "EASE", "CONSTANT"):
        return st[0][1].copy()
    if v >= st[-1][0] and ipo in ("LINEAR", "EASE", "CONSTANT"):
        return st[-1][1].copy()
    a = 0
    while a < n and v > st[a][0]:
        a += 1
    # a: the first stop right of v (n when v is right of all)
    if ipo in ("CARDINAL", "B_SPLINE"):
        if a == 0:
            a = 1
        if a == n:
            a = n - 1
        c1, c2 = st[a - 1], st[a]
        c0 = st[a - 2] if a >= 2 else (2 * c1[0] - c2[0], c1[1])
        c3 = st[a + 1] if a + 1 < n else (2 * c2[0] - c1[0], c2[1])
        if a == 1:
            c0 = (2 * c1[0] - c2[0], c1[1])
        d = c2[0] - c1[0]
        f = (v - c1[0]) / d if d != 0 else 0.0
        f = min(max(f, 0.0), 1.0)
        w = _key_weights(f, ipo)
        out = w[0] * c0[1] + w[1] * c1[1] + w[2] * c2[1] + w[3] * c3[1]
        return np.clip(out, 0.0, 1.0)
    c1, c2 = st[a - 1], st[a]
    if ipo == "CONSTANT":
        return c1[1].copy()
    d = c2[0] - c1[0]
    f = (v - c1[0]) / d if d != 0 else 0.0
    if ipo == "EASE":
        f = f * f * (3.0 - 2.0 * f)
    return (1 - f) * c1[1] + f * c2[1]


def _ramp(c, name, nd, pr):
    ipo = pr.get("interpolation", "LINEAR")
    tab = pr.get("table")
    if tab is None:
        tab = bake_ramp(pr.get("stops", []), ipo)
    out = c.reg(4)
    c.emit(O.OP_RAMP, out, [c.input(name, "Fac", "f", 0.5)], p=0 if ipo == "CONSTANT" else 1,
           q=c.const(np.asarray(tab, np.float64).reshape(-1)))
    return {"Color": (out, "c"), "Alpha": (out + 3, "f")}


def _table_consts(values, lo, hi, extrapolate):
    v = np.asarray(values, np.float64)
    nc = 1 if v.ndim == 1 else v.shape[1]
    return [v.shape[0], lo, hi, 1.0 if extrapolate else 0.0, nc] + list(v.reshape(-1))


def _curve_rgb(c, name, nd, pr):
    """RGB Curves: ``props['table']`` (n, 3), each channel's curve composed with the combined
    one, sampled over [lo, hi] (the exporter samples Blender's CurveMapping)."""
    out = c.reg(3)
    q = c.const(_table_consts(pr["table"], pr.get("lo", 0.0), pr.get("hi", 1.0), pr.get("extrapolate", False)))
    c.emit(O.OP_CURVES, out, [c.input(name, "Fac", "f", 1.0), c.input(name, "Color", "c")], q=q)
    return {"Color": (out, "c")}


def _curve_float(c, name, nd, pr):
    q = c.const(_table_consts(pr["table"], pr.get("lo", 0.0), pr.get("hi", 1.0), pr.get("extrapolate", False)))
    v = c.input(name, "Value", "f", 1.0)
    t = c.reg(1)
    c.emit(O.OP_TABLE, t, [v], q=q)
    out = c.reg(1)
    c.emit(O.OP_MIXF, out, [c.input(name, "Factor", "f", 1.0), v, t], q=0)
    return {"Value": (out, "f")}


@functools.lru_cache(maxsize=1)
def blackbody_table():
    """(n, 3) Cycles' Blackbody colour (linear Rec.709, luminance 1) against 10⁶/T, T in [800, 12000] K."""
    from ..photometry.units import light_emission_coeffs
    from ..spectra.uplift import emission_to_rgb

    lo, hi = 1e6 / BLACKBODY_RANGE[1], 1e6 / BLACKBODY_RANGE[0]
    mired = np.linspace(lo, hi, 96)
    rows = [emission_to_rgb(light_emission_coeffs("blackbody", temperature=1e6 / m), 0.0)[0] for m in mired]
    return np.asarray(rows, np.float64), lo, hi


def _blackbody(c, name, nd, pr):
    tab, lo, hi = blackbody_table()
    t = c.input(name, "Temperature", "f", 1500.0)
    m = c.reg(1)
    c.emit(O.OP_MATH, m, [c.cf(1e6), t, c.cf(0.0)], p=O.MATH["DIVIDE"])
    out = c.reg(3)
    c.emit(O.OP_TABLE, out, [m], p=1, q=c.const(_table_consts(tab, lo, hi, False)))
    return {"Color": (out, "c")}


@functools.lru_cache(maxsize=1)
def wavelength_table():
    """(403, 3) Cycles' Wavelength node colour at 379 .. 781 nm: CIE 1931 XYZ → linear
    Rec.709, divided by 2.52, negative channels clipped to 0."""
    from ..colour.tristimulus import cmfs

    wl, xyz = cmfs("1931")
    lam = np.arange(WAVELENGTH_RANGE[0], WAVELENGTH_RANGE[1] + 1.0)
    xyz_i = np.stack([np.interp(lam, wl, xyz[:, k]) for k in range(3)], axis=1)
    m = np.array([[3.2404542, -1.5371385, -0.4985314], [-0.9692660, 1.8760108, 0.0415560],
                  [0.0556434, -0.2040259, 1.0572252]])
    rgb = np.maximum(xyz_i @ m.T / 2.52, 0.0)
    # black outside [380, 780) nm: one zero entry on either side (the table spans 379 .. 781 nm)
    return np.concatenate([np.zeros((1, 3)), rgb, np.zeros((1, 3))])


def _wavelength(c, name, nd, pr):
    tab = wavelength_table()
    out = c.reg(3)
    c.emit(O.OP_TABLE, out, [c.input(name, "Wavelength", "f", 500.0)], p=1,
           q=c.const(_table_consts(tab, WAVELENGTH_RANGE[0] - 1.0, WAVELENGTH_RANGE[1] + 1.0, False)))
    return {"Color": (out, "c")}


def _fresnel(c, name, nd, pr):
    nrm = _normal_in(c, name, nd)
    out = c.reg(1)
    c.emit(O.OP_FRESNEL, out, [c.input(name, "IOR", "f", 1.45), nrm])
    return {"Fac": (out, "f")}


def _layer_weight(c, name, nd, pr):
    nrm = _normal_in(c, name, nd)
    out = c.reg(2)
    c.emit(O.OP_LAYER, out, [c.input(name, "Blend", "f", 0.5), nrm])
    return {"Fresnel": (out, "f"), "Facing": (out + 1, "f")}


PROC_DEFAULTS = {"Scale": 5.0, "Detail": 2.0, "Roughness": 0.5, "Lacunarity": 2.0, "Offset": 0.0, "Gain": 1.0,
                 "Distortion": 0.0, "Smoothness": 1.0, "Exponent": 0.5, "Randomness": 1.0, "Detail Scale": 1.0,
                 "Detail Roughness": 0.5, "Phase Offset": 0.0, "Color1": (0.8, 0.8, 0.8), "Color2": (0.2, 0.2, 0.2),
                 "Mortar": (0.0, 0.0, 0.0), "Mortar Size": 0.02, "Mortar Smooth": 0.1, "Bias": 0.0,
                 "Brick Width": 0.5, "Row Height": 0.25}
DIMENSIONS = {"1D": 1, "2D": 2, "3D": 3, "4D": 4}


def _proc_settings(t, pr):
    """The integer settings (and the brick's two float properties) of a procedural texture node."""
    from . import procedural as T

    dims = DIMENSIONS.get(pr.get("noise_dimensions", pr.get("voronoi_dimensions", "3D")), 3)
    if t == "TEX_NOISE":
        return [dims, T.NOISE_TYPES[pr.get("noise_type", "FBM")], int(bool(pr.get("normalize", True))), 0, 0, 0]
    if t == "TEX_VORONOI":
        return [dims, T.VORONOI_FEATURES[pr.get("feature", "F1")], T.VORONOI_METRICS[pr.get("distance", "EUCLIDEAN")],
                int(bool(pr.get("normalize", False))), 0, 0]
    if t == "TEX_WAVE":
        return [T.WAVE_TYPES[pr.get("wave_type", "BANDS")], T.WAVE_BANDS_DIRECTIONS[pr.get("bands_direction", "X")],
                T.WAVE_RINGS_DIRECTIONS[pr.get("rings_direction", "X")], T.WAVE_PROFILES[pr.get("wave_profile", "SIN")],
                0, 0]
    if t == "TEX_MAGIC":
        return [int(pr.get("turbulence_depth", 2)), 0, 0, 0, 0, 0]
    if t == "TEX_BRICK":
        return [int(pr.get("offset_frequency", 2)), int(pr.get("squash_frequency", 2)), 0, 0,
                float(pr.get("offset", 0.5)), float(pr.get("squash", 1.0))]
    if t == "TEX_GRADIENT":
        return [T.GRADIENT_TYPES[pr.get("gradient_type", "LINEAR")], 0, 0, 0, 0, 0]
    return [dims, 0, 0, 0, 0, 0]


def _procedural(c, name, nd, pr):
    t = nd["type"]
    kind = O.PROC_TYPES[t]
    vec = nd["inputs"].get("Vector")
    v = c.source(vec, "v") if vec is not None else _attribute_op(c, "@generated")
    args = [v, c.input(name, "W", "f", 0.0)]
    for sock in O.PROC_SOCKETS[kind]:
        d = PROC_DEFAULTS[sock]
        args.append(c.input(name, sock, "c" if isinstance(d, tuple) else "f", d))
    out = c.reg(O.OUT_WIDTH[O.OP_PROC])
    c.emit(O.OP_PROC, out, args, p=kind, q=c.const(_proc_settings(t, pr)))
    colour = (out, "c")
    if kind == O.PROC_VORONOI:
        return {"Color": colour, "Position": (out + 3, "v"), "Distance": (out + 6, "f"), "W": (out + 7, "f"),
                "Radius": (out + 8, "f")}
    if kind == O.PROC_WHITE:
        return {"Color": colour, "Value": (out + 3, "f")}
    return {"Color": colour, "Fac": (out + 3, "f")}


NODES = {
    "VALUE": _value, "RGB": _rgb, "MATH": _math, "VECT_MATH": _vmath, "MIX": _mix, "MIX_RGB": _mix_rgb,
    "CLAMP": _clamp, "MAP_RANGE": _map_range, "SEPARATE_COLOR": _separate_color, "SEPXYZ": _separate_xyz,
    "COMBINE_COLOR": _combine_color, "COMBXYZ": _combine_xyz,
    "HUE_SAT": _colour_op(O.OP_HSV, ("Hue", "Saturation", "Value", "Fac", "Color"), (0.5, 1.0, 1.0, 1.0, 0.8)),
    "INVERT": _colour_op(O.OP_INVERT, ("Fac", "Color"), (1.0, 0.0)),
    "BRIGHTCONTRAST": _colour_op(O.OP_BRIGHT, ("Color", "Bright", "Contrast"), (1.0, 0.0, 0.0)),
    "GAMMA": _colour_op(O.OP_GAMMA, ("Color", "Gamma"), (1.0, 1.0)),
    "RGBTOBW": _rgb_to_bw, "TEX_COORD": _tex_coord, "UVMAP": _uv_map, "NEW_GEOMETRY": _geometry,
    "ATTRIBUTE": _attribute, "VERTEX_COLOR": _vertex_color, "MAPPING": _mapping, "TEX_IMAGE": _image,
    "VALTORGB": _ramp, "CURVE_RGB": _curve_rgb, "CURVE_FLOAT": _curve_float, "BLACKBODY": _blackbody,
    "WAVELENGTH": _wavelength, "FRESNEL": _fresnel, "LAYER_WEIGHT": _layer_weight, "BUMP": _bump,
    "NORMAL_MAP": _normal_map,
}
NODES.update({t: _procedural for t in O.PROC_TYPES})
SUPPORTED_TYPES = frozenset(NODES)
