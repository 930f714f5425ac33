"""A slow Python oracle of the shader program interpreter (core/shading/interp.py).

``evaluate(program, point)`` walks the instructions of a Program (core/shading/ops.py) with
plain Python arithmetic, written from Blender's manual and Cycles' SVM formulas (colorsys for
the HSV and HLS conversions), for a shading point given as a dict: P, N, Ng, I (3-sequences)
and attrs, the program's attributes by name (or corners, each attribute's three corner
values, and bary, the point's barycentrics). Image Texture ops need ``image(q, u, v)``.
"""
import colorsys
import math

from spectral_gi.core.shading import ops as O
from spectral_gi.core.shading.program import instructions


def _safe_div(a, b):
    return a / b if b != 0 else 0.0


def _smin(a, b, c):
    if c == 0:
        return min(a, b)
    h = max(c - abs(a - b), 0.0) / c
    return min(a, b) - h ** 3 * c / 6.0


def _wrap(v, hi, lo):
    r = hi - lo
    return v - r * math.floor((v - lo) / r) if r != 0 else lo


def _pow(a, b):
    if (a < 0 and b != int(b)) or (a == 0 and b < 0):
        return 0.0
    return a ** b


MATH = {
    "ADD": lambda a, b, c: a + b, "SUBTRACT": lambda a, b, c: a - b, "MULTIPLY": lambda a, b, c: a * b,
    "DIVIDE": lambda a, b, c: _safe_div(a, b), "MULTIPLY_ADD": lambda a, b, c: a * b + c,
    "POWER": lambda a, b, c: _pow(a, b),
    "LOGARITHM": lambda a, b, c: _safe_div(math.log(a), math.log(b)) if a > 0 and b > 0 else 0.0,
    "SQRT": lambda a, b, c: math.sqrt(max(a, 0.0)), "INVERSE_SQRT": lambda a, b, c: 1 / math.sqrt(a) if a > 0 else 0.0,
    "ABSOLUTE": lambda a, b, c: abs(a), "EXPONENT": lambda a, b, c: math.exp(a), "MINIMUM": lambda a, b, c: min(a, b),
    "MAXIMUM": lambda a, b, c: max(a, b), "LESS_THAN": lambda a, b, c: float(a < b),
    "GREATER_THAN": lambda a, b, c: float(a > b), "SIGN": lambda a, b, c: float((a > 0) - (a < 0)),
    "COMPARE": lambda a, b, c: float(abs(a - b) <= max(c, 1e-5)), "SMOOTH_MIN": _smin,
    "SMOOTH_MAX": lambda a, b, c: -_smin(-a, -b, c), "ROUND": lambda a, b, c: math.floor(a + 0.5),
    "FLOOR": lambda a, b, c: math.floor(a), "CEIL": lambda a, b, c: math.ceil(a),
    "TRUNC": lambda a, b, c: float(math.trunc(a)), "FRACT": lambda a, b, c: a - math.floor(a),
    "MODULO": lambda a, b, c: math.fmod(a, b) if b != 0 else 0.0,
    "FLOORED_MODULO": lambda a, b, c: a - math.floor(a / b) * b if b != 0 else 0.0, "WRAP": _wrap,
    "SNAP": lambda a, b, c: math.floor(_safe_div(a, b)) * b,
    "PINGPONG": lambda a, b, c: abs((((a - b) / (2 * b)) % 1.0) * 2 * b - b) if b != 0 else 0.0,
    "SINE": lambda a, b, c: math.sin(a), "COSINE": lambda a, b, c: math.cos(a),
    "TANGENT": lambda a, b, c: math.tan(a), "ARCSINE": lambda a, b, c: math.asin(min(max(a, -1), 1)),
    "ARCCOSINE": lambda a, b, c: math.acos(min(max(a, -1), 1)),
    "ARCTANGENT": lambda a, b, c: math.atan(a), "ARCTAN2": lambda a, b, c: math.atan2(a, b),
    "SINH": lambda a, b, c: math.sinh(a), "COSH": lambda a, b, c: math.cosh(a),
    "TANH": lambda a, b, c: math.tanh(a),
    "RADIANS": lambda a, b, c: math.radians(a), "DEGREES": lambda a, b, c: math.degrees(a),
}


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def _normalize(a):
    n = math.sqrt(_dot(a, a))
    return [x / n for x in a] if n else [0.0, 0.0, 0.0]


def _vmath(op, a, b, c, s):
    """(vector, value) of the Vector Math operation ``op``."""
    comp = {"ADD": lambda x, y, z: x + y, "SUBTRACT": lambda x, y, z: x - y, "MULTIPLY": lambda x, y, z: x * y,
            "DIVIDE": lambda x, y, z: _safe_div(x, y), "MULTIPLY_ADD": lambda x, y, z: x * y + z,
            "SNAP": lambda x, y, z: math.floor(_safe_div(x, y)) * y, "FLOOR": lambda x, y, z: math.floor(x),
            "CEIL": lambda x, y, z: math.ceil(x), "MODULO": lambda x, y, z: math.fmod(x, y) if y != 0 else 0.0,
            "WRAP": _wrap, "FRACTION": lambda x, y, z: x - math.floor(x), "ABSOLUTE": lambda x, y, z: abs(x),
            "POWER": lambda x, y, z: _pow(x, y), "SIGN": lambda x, y, z: float((x > 0) - (x < 0)),
            "MINIMUM": lambda x, y, z: min(x, y), "MAXIMUM": lambda x, y, z: max(x, y),
            "SINE": lambda x, y, z: math.sin(x), "COSINE": lambda x, y, z: math.cos(x),
            "TANGENT": lambda x, y, z: math.tan(x)}
    if op in comp:
        return [comp[op](x, y, z) for x, y, z in zip(a, b, c)], 0.0
    if op == "CROSS_PRODUCT":
        return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]], 0.0
    if op == "PROJECT":
        d = _dot(b, b)
        return [_dot(a, b) / d * x if d else 0.0 for x in b], 0.0
    if op == "REFLECT":
        n = _normalize(b) if any(b) else b
        return [x - 2 * _dot(n, a) * y for x, y in zip(a, n)], 0.0
    if op == "REFRACT":
        n = _normalize(b) if any(b) else b
        d = _dot(n, a)
        k = 1 - s * s * (1 - d * d)
        if k < 0:
            return [0.0, 0.0, 0.0], 0.0
        return [s * x - (s * d + math.sqrt(k)) * y for x, y in zip(a, n)], 0.0
    if op == "FACEFORWARD":
        return (list(a) if _dot(c, b) < 0 else [-x for x in a]), 0.0
    if op == "DOT_PRODUCT":
        return [0.0] * 3, _dot(a, b)
    if op == "DISTANCE":
        return [0.0] * 3, math.dist(a, b)
    if op == "LENGTH":
        return [0.0] * 3, math.sqrt(_dot(a, a))
    if op == "SCALE":
        return [x * s for x in a], 0.0
    if op == "NORMALIZE":
        return _normalize(a), 0.0
    raise ValueError(op)


def _hsv(c):
    return list(colorsys.rgb_to_hsv(*c)) if max(c) > 0 else [0.0, 0.0, max(c)]


def _rgb(h):
    return list(colorsys.hsv_to_rgb(h[0] % 1.0 if h[0] != 1.0 else 0.0, h[1], h[2]))


def _lerp(t, a, b):
    return [x + (y - x) * t for x, y in zip(a, b)]


def blend(mode, t, a, b):
    """Blender's Mix node colour blend modes (the Blender manual, Cycles' svm_mix)."""
    tm = 1 - t
    if mode == "MIX":
        return _lerp(t, a, b)
    if mode == "ADD":
        return [x + t * y for x, y in zip(a, b)]
    if mode == "MULTIPLY":
        return _lerp(t, a, [x * y for x, y in zip(a, b)])
    if mode == "SUBTRACT":
        return [x - t * y for x, y in zip(a, b)]
    if mode == "SCREEN":
        return [1 - (tm + t * (1 - y)) * (1 - x) for x, y in zip(a, b)]
    if mode == "DIVIDE":
        return [tm * x + t * x / y if y != 0 else x for x, y in zip(a, b)]
    if mode == "DIFFERENCE":
        return _lerp(t, a, [abs(x - y) for x, y in zip(a, b)])
    if mode == "EXCLUSION":
        return [max(v, 0.0) for v in _lerp(t, a, [x + y - 2 * x * y for x, y in zip(a, b)])]
    if mode == "DARKEN":
        return _lerp(t, a, [min(x, y) for x, y in zip(a, b)])
    if mode == "LIGHTEN":
        return _lerp(t, a, [max(x, y) for x, y in zip(a, b)])
    if mode == "OVERLAY":
        return [x * (tm + 2 * t * y) if x < 0.5 else 1 - (tm + 2 * t * (1 - y)) * (1 - x) for x, y in zip(a, b)]
    if mode == "SOFT_LIGHT":
        return [tm * x + t * ((1 - x) * y * x + x * (1 - (1 - y) * (1 - x))) for x, y in zip(a, b)]
    if mode == "LINEAR_LIGHT":
        return [x + t * (2 * y - 1) for x, y in zip(a, b)]
    if mode == "DODGE":
        out = []
        for x, y in zip(a, b):
            if x != 0:
                d = 1 - t * y
                x = 1.0 if d <= 0 else min(x / d, 1.0)
            out.append(x)
        return out
    if mode == "BURN":
        out = []
        for x, y in zip(a, b):
            d = tm + t * y
            out.append(0.0 if d <= 0 else min(max(1 - (1 - x) / d, 0.0), 1.0))
        return out
    ha, hb = _hsv(a), _hsv(b)
    if mode in ("HUE", "COLOR"):
        if hb[1] == 0:
            return list(a)
        h = [hb[0], hb[1] if mode == "COLOR" else ha[1], ha[2]]
        return _lerp(t, a, _rgb(h))
    if mode == "SATURATION":
        if ha[1] == 0:
            return list(a)
        return _rgb([ha[0], tm * ha[1] + t * hb[1], ha[2]])
    if mode == "VALUE":
        return _rgb([ha[0], ha[1], tm * ha[2] + t * hb[2]])
    raise ValueError(mode)


def _smoothstep(e0, e1, x):
    t = min(max((x - e0) / (e1 - e0), 0.0), 1.0)
    return t * t * (3 - 2 * t)


def _smootherstep(e0, e1, x):
    t = min(max(_safe_div(x - e0, e1 - e0), 0.0), 1.0)
    return t ** 3 * (t * (6 * t - 15) + 10)


def map_range(mode, clamp, v, f0, f1, t0, t1, steps):
    if f1 == f0:
        return 0.0
    k = (v - f0) / (f1 - f0)
    if mode == "STEPPED":
        k = math.floor(k * (steps + 1)) / steps if steps > 0 else 0.0
    elif mode == "SMOOTHSTEP":
        k = 1 - _smoothstep(f1, f0, v) if f0 > f1 else _smoothstep(f0, f1, v)
    elif mode == "SMOOTHERSTEP":
        k = 1 - _smootherstep(f1, f0, v) if f0 > f1 else _smootherstep(f0, f1, v)
    r = t0 + k * (t1 - t0)
    if clamp and mode in ("LINEAR", "STEPPED"):
        r = min(max(r, min(t0, t1)), max(t0, t1))
    return r


def _table(consts, q, ch, x):
    n, lo, hi, ext, nc = int(consts[q]), consts[q + 1], consts[q + 2], consts[q + 3] != 0, int(consts[q + 4])
    vals = [consts[q + 5 + i * nc + ch] for i in range(n)]
    f = (x - lo) / (hi - lo) * (n - 1) if hi != lo else 0.0
    if ext and f < 0:
        return vals[0] + (vals[0] - vals[1]) * -f
    if ext and f > n - 1:
        return vals[-1] + (vals[-1] - vals[-2]) * (f - (n - 1))
    f = min(max(f, 0.0), n - 1)
    i = min(int(f), n - 1)
    t = f - i
    return vals[i] if t == 0 else (1 - t) * vals[i] + t * vals[i + 1]


def _fresnel(eta, cosi):
    c = abs(cosi)
    g = eta * eta - 1 + c * c
    if g <= 0:
        return 1.0
    g = math.sqrt(g)
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1) / (c * (g - c) + 1)
    return 0.5 * a * a * (1 + b * b)


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _blend_normal(n_in, m, strength):
    strength = max(strength, 0.0)
    if strength == 1.0:
        return m
    return _normalize([x + (y - x) * strength for x, y in zip(n_in, m)])


def _bump(scalars, pos, n_in, invert):
    """Cycles' svm_node_set_bump, the differentials being the neighbours' offsets."""
    hc, hx, hy, strength, dist = scalars
    n_in = _normalize(n_in)
    dpdx = [x - y for x, y in zip(pos[1], pos[0])]
    dpdy = [x - y for x, y in zip(pos[2], pos[0])]
    rx, ry = _cross(dpdy, n_in), _cross(n_in, dpdx)
    det = _dot(dpdx, rx)
    grad = [(hx - hc) * x + (hy - hc) * y for x, y in zip(rx, ry)]
    dist = -dist if invert else dist
    sign = (det > 0) - (det < 0)
    m = _normalize([abs(det) * n - dist * sign * g for n, g in zip(n_in, grad)])
    return _blend_normal(n_in, m, strength)


def _normal_map(space, colour, strength, pos, uvs, n_in):
    """Cycles' svm_node_normal_map: tangent space with the UV map's ∂p/∂u, or world space."""
    n_in = _normalize(n_in)
    c = [2 * x - 1 for x in colour]
    if space == 0:
        import numpy as np

        e = np.array([np.subtract(pos[1], pos[0]), np.subtract(pos[2], pos[0])])
        d = np.array([np.subtract(uvs[1], uvs[0])[:2], np.subtract(uvs[2], uvs[0])[:2]])
        dp_duv = np.linalg.solve(d, e)  # rows ∂p/∂u, ∂p/∂v
        t = dp_duv[0] - np.dot(dp_duv[0], n_in) * np.array(n_in)
        t = list(t / np.linalg.norm(t))
        b = _cross(n_in, t)
        if _dot(b, dp_duv[1]) < 0:
            b = [-x for x in b]
        m = _normalize([c[0] * x + c[1] * y + c[2] * z for x, y, z in zip(t, b, n_in)])
    elif space == 1:
        m = _normalize(c)
    else:
        m = _normalize([c[0], -c[1], -c[2]])
    return _blend_normal(n_in, m, strength)


def _procedural(kind, st, args, _ops):
    """The procedural textures through core/shading/procedural.py (the other helper's oracle
    tests them against Cycles' formulas); here the operands and outputs are checked."""
    from spectral_gi.core.shading import procedural as T

    v, w = args[0], args[1]
    f = args[2:]
    i = [int(x) for x in st[:4]]
    if kind == O.PROC_NOISE:
        fac, r, g, b = T.noise_texture(*v, w, i[0], i[1], *f[:7], i[2], True)
        return [r, g, b, fac]
    if kind == O.PROC_VORONOI:
        d, r, g, b, px, py, pz, wo, rad = T.voronoi_texture(*v, w, i[0], i[1], i[2], *f[:7], i[3])
        return [r, g, b, px, py, pz, d, wo, rad]
    if kind == O.PROC_WAVE:
        x = T.wave_texture(*v, *i, *f[:6])
        return [x, x, x, x]
    if kind == O.PROC_MAGIC:
        r, g, b, x = T.magic_texture(*v, i[0], f[0], f[1])
        return [r, g, b, x]
    raise ValueError(f"procedural kind {kind} not in the oracle")


def evaluate(program, point, image=None):
    """The program's 3-vector result at ``point`` (see the module docstring)."""
    regs = [0.0] * (program.n_registers + 4)
    consts = [float(x) for x in program.consts]

    def rd(k, i=0):
        return regs[k + i] if k >= 0 else consts[-1 - k + i]

    def vec(k):
        return [rd(k, i) for i in range(3)]

    def put(out, v):
        for i, x in enumerate(v):
            regs[out + i] = x

    for _pc, op, _n, out, p, q, a in instructions(program.ops):
        if op == O.OP_END:
            return vec(a[0])
        if op == O.OP_COORD:
            put(out, point[("P", "N", "Ng", "I")[p]])
        elif op == O.OP_ATTR:
            name = program.attributes[q]
            if "corners" in point:  # per-corner values, interpolated at the (offset) barycentrics
                bu, bv = point["bary"]
                bu += O.BUMP_DELTA if p & 2 else 0.0
                bv += O.BUMP_DELTA if p & 4 else 0.0
                c0, c1, c2 = point["corners"][name]
                v = [(1 - bu - bv) * x + bu * y + bv * z for x, y, z in zip(c0, c1, c2)]
            else:
                v = list(point["attrs"][name])
            put(out, _normalize(v) if p & 1 and any(v) else v)
        elif op == O.OP_XFORM:
            m = consts[q:q + 12]
            x = vec(a[0]) + [1.0 if p == O.XF_POINT else 0.0]
            r = [sum(m[4 * i + j] * x[j] for j in range(4)) for i in range(3)]
            put(out, _normalize(r) if p == O.XF_NORMAL and any(r) else r)
        elif op == O.OP_MATH:
            r = MATH[O.MATH_OPS[p]](rd(a[0]), rd(a[1]), rd(a[2]))
            regs[out] = min(max(r, 0.0), 1.0) if q else r
        elif op == O.OP_VMATH:
            v, val = _vmath(O.VMATH_OPS[p], vec(a[0]), vec(a[1]), vec(a[2]), rd(a[3]))
            put(out, v + [val])
        elif op == O.OP_MIXF:
            t = min(max(rd(a[0]), 0), 1) if q & 1 else rd(a[0])
            regs[out] = rd(a[1]) + (rd(a[2]) - rd(a[1])) * t
        elif op == O.OP_MIXV:
            t = vec(a[0]) if q & 2 else [rd(a[0])] * 3
            t = [min(max(x, 0), 1) for x in t] if q & 1 else t
            put(out, [x + (y - x) * s for x, y, s in zip(vec(a[1]), vec(a[2]), t)])
        elif op == O.OP_MIXC:
            t = min(max(rd(a[0]), 0), 1) if q & 1 else rd(a[0])
            c = blend(O.BLEND_MODES[p], t, vec(a[1]), vec(a[2]))
            put(out, [min(max(x, 0), 1) for x in c] if q & 2 else c)
        elif op == O.OP_TABLE:
            x = rd(a[0])
            put(out, [_table(consts, q, ch, x) for ch in range(3)] if p & 1 else [_table(consts, q, 0, x)])
        elif op == O.OP_CURVES:
            c = vec(a[1])
            put(out, _lerp(rd(a[0]), c, [_table(consts, q, ch, c[ch]) for ch in range(3)]))
        elif op == O.OP_HSV:
            c = vec(a[4])
            h = _hsv(c)
            h = [(h[0] + rd(a[0]) + 0.5) % 1.0, min(max(h[1] * rd(a[1]), 0), 1), h[2] * rd(a[2])]
            put(out, [max(v, 0.0) for v in _lerp(rd(a[3]), c, _rgb(h))])
        elif op == O.OP_INVERT:
            c = vec(a[1])
            put(out, _lerp(rd(a[0]), c, [1 - x for x in c]))
        elif op == O.OP_BRIGHT:
            k, b = 1 + rd(a[2]), rd(a[1]) - rd(a[2]) * 0.5
            put(out, [max(k * x + b, 0.0) for x in vec(a[0])])
        elif op == O.OP_GAMMA:
            put(out, [x ** rd(a[1]) if x > 0 else x for x in vec(a[0])])
        elif op == O.OP_CONVERT:
            v = vec(a[0])
            if p == O.CONV_RGB_HSV:
                put(out, _hsv(v))
            elif p == O.CONV_HSV_RGB:
                put(out, _rgb(v))
            elif p == O.CONV_RGB_HSL:
                h, l_, s = colorsys.rgb_to_hls(*v)
                put(out, [h, s, l_])
            else:
                put(out, list(colorsys.hls_to_rgb(v[0], v[2], v[1])))
        elif op == O.OP_COMBINE:
            put(out, [rd(a[0]), rd(a[1]), rd(a[2])])
        elif op == O.OP_MAPRANGE:
            n = 3 if q & 2 else 1
            put(out, [map_range(O.MAPRANGE_TYPES[p], q & 1, *[rd(k, i) for k in a]) for i in range(n)])
        elif op == O.OP_CLAMP:
            lo, hi = rd(a[1]), rd(a[2])
            if p == 1 and lo > hi:
                lo, hi = hi, lo
            regs[out] = min(max(rd(a[0]), lo), hi)
        elif op in (O.OP_FRESNEL, O.OP_LAYER):
            n = _normalize(vec(a[1]))
            cosi = _dot(n, point["I"])
            back = _dot(point["Ng"], point["I"]) < 0
            b = rd(a[0])
            if op == O.OP_FRESNEL:
                eta = max(b, 1e-5)
                regs[out] = _fresnel(1 / eta if back else eta, cosi)
            else:
                eta = max(1 - b, 1e-5)
                regs[out] = _fresnel(eta if back else 1 / eta, cosi)
                f = abs(cosi)
                if b != 0.5:
                    bl = min(max(b, 0.0), 1 - 1e-5)
                    f = f ** (2 * bl if bl < 0.5 else 0.5 / (1 - bl))
                regs[out + 1] = 1 - f
        elif op == O.OP_RAMP:
            f = min(max(rd(a[0]), 0.0), 1.0) * (O.RAMP_TABLE_SIZE - 1)
            i = min(int(f), O.RAMP_TABLE_SIZE - 1)
            t = f - i
            for ch in range(4):
                r = consts[q + 4 * i + ch]
                if p == 1 and t > 0:
                    r = (1 - t) * r + t * consts[q + 4 * (i + 1) + ch]
                regs[out + ch] = r
        elif op == O.OP_IMAGE:
            uv = vec(a[0])
            put(out, list(image(q, uv[0], uv[1])) + [1.0])
        elif op == O.OP_BUMP:
            put(out, _bump([rd(k) for k in a[:5]], [vec(k) for k in a[5:8]], vec(a[8]), q & 1))
        elif op == O.OP_NORMALMAP:
            put(out, _normal_map(p, vec(a[0]), rd(a[1]), [vec(k) for k in a[2:5]], [vec(k) for k in a[5:8]],
                                 vec(a[8])))
        elif op == O.OP_PROC:
            put(out, _procedural(p, consts[q:q + 6], [rd(k) if i else vec(k) for i, k in enumerate(a)], a))
        else:
            raise ValueError(f"op {op}")
    raise ValueError("no end")
