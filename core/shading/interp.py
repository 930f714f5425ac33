"""The shader program interpreter: a register machine (ops and layout: core/shading/ops.py).

``run`` evaluates one program at a shading point and returns its 3-vector result. The
registers are float32 (as Cycles' SVM stack); the arithmetic is float64. Every formula is
Blender's (Cycles' SVM) for the node it serves; tests/oracles/shading.py is the slow oracle.
"""
import math

from ..jit import function, inline
from ..textures import kernel as tex
from . import ops as O
from . import procedural as T

PI = math.pi


@inline
def _rd(regs, consts, k, i):
    """Component i of operand k (a register when k ≥ 0, else the constants from −1 − k)."""
    if k >= 0:
        return float(regs[k + i])
    return float(consts[-1 - k + i])


@inline
def _safe_div(a, b):
    return a / b if b != 0.0 else 0.0


@inline
def _trunc(a):
    return math.floor(a) if a >= 0.0 else math.ceil(a)


@inline
def _fmod(a, b):
    """C's fmod (the sign of a), 0 for b = 0 as Cycles' safe_modulo."""
    if b == 0.0:
        return 0.0
    return a - b * _trunc(a / b)


@inline
def _fract(a):
    return a - math.floor(a)


@inline
def _smoothmin(a, b, c):
    if c != 0.0:
        h = max(c - abs(a - b), 0.0) / c
        return min(a, b) - h * h * h * c * (1.0 / 6.0)
    return min(a, b)


@inline
def _wrap(v, hi, lo):
    r = hi - lo
    return v - r * math.floor((v - lo) / r) if r != 0.0 else lo


@inline
def _pingpong(a, b):
    return abs(_fract((a - b) / (b * 2.0)) * b * 2.0 - b) if b != 0.0 else 0.0


@inline
def _math_a(op, a, b, c):
    """Math ops 0 .. 20 (core/shading/ops.py MATH_OPS)."""
    if op == 0:
        return a + b
    if op == 1:
        return a - b
    if op == 2:
        return a * b
    if op == 3:
        return _safe_div(a, b)
    if op == 4:
        return a * b + c
    if op == 5:
        if a < 0.0 and b != float(int(b)):
            return 0.0
        if a == 0.0 and b < 0.0:
            return 0.0
        return a ** b
    if op == 6:
        if a <= 0.0 or b <= 0.0:
            return 0.0
        return _safe_div(math.log(a), math.log(b))
    if op == 7:
        return math.sqrt(max(a, 0.0))
    if op == 8:
        return 1.0 / math.sqrt(a) if a > 0.0 else 0.0
    if op == 9:
        return abs(a)
    if op == 10:
        return math.exp(min(a, 700.0))
    if op == 11:
        return min(a, b)
    if op == 12:
        return max(a, b)
    if op == 13:
        return 1.0 if a < b else 0.0
    if op == 14:
        return 1.0 if a > b else 0.0
    if op == 15:
        return 1.0 if a > 0.0 else (-1.0 if a < 0.0 else 0.0)
    if op == 16:
        return 1.0 if abs(a - b) <= max(c, 1e-5) else 0.0
    if op == 17:
        return _smoothmin(a, b, c)
    if op == 18:
        return -_smoothmin(-a, -b, c)
    if op == 19:
        return math.floor(a + 0.5)
    return math.floor(a)


@inline
def _math_b(op, a, b, c):
    """Math ops 21 .. 40."""
    if op == 21:
        return math.ceil(a)
    if op == 22:
        return _trunc(a)
    if op == 23:
        return _fract(a)
    if op == 24:
        return _fmod(a, b)
    if op == 25:
        return a - math.floor(a / b) * b if b != 0.0 else 0.0
    if op == 26:
        return _wrap(a, b, c)
    if op == 27:
        return math.floor(_safe_div(a, b)) * b
    if op == 28:
        return _pingpong(a, b)
    if op == 29:
        return math.sin(a)
    if op == 30:
        return math.cos(a)
    if op == 31:
        return math.tan(a)
    if op == 32:
        return math.asin(min(max(a, -1.0), 1.0))
    if op == 33:
        return math.acos(min(max(a, -1.0), 1.0))
    if op == 34:
        return math.atan(a)
    if op == 35:
        return math.atan2(a, b)
    if op == 36:
        return math.sinh(min(max(a, -700.0), 700.0))
    if op == 37:
        return math.cosh(min(max(a, -700.0), 700.0))
    if op == 38:
        return math.tanh(a)
    if op == 39:
        return a * (PI / 180.0)
    return a * (180.0 / PI)


@inline
def math_op(op, a, b, c):
    """Blender's Math node (Cycles' svm_math) operation ``op`` (index into MATH_OPS)."""
    if op <= 20:
        return _math_a(op, a, b, c)
    return _math_b(op, a, b, c)


@inline
def _vcomp(op, a, b, c):
    """The componentwise vector ops on one component (a, b, c of one axis)."""
    if op == 0:
        return a + b
    if op == 1:
        return a - b
    if op == 2:
        return a * b
    if op == 3:
        return _safe_div(a, b)
    if op == 4:
        return a * b + c
    if op == 15:
        return math.floor(_safe_div(a, b)) * b
    if op == 16:
        return math.floor(a)
    if op == 17:
        return math.ceil(a)
    if op == 18:
        return _fmod(a, b)
    if op == 19:
        return _wrap(a, b, c)
    if op == 20:
        return _fract(a)
    if op == 21:
        return abs(a)
    if op == 22:
        return math_op(5, a, b, 0.0)
    if op == 23:
        return 1.0 if a > 0.0 else (-1.0 if a < 0.0 else 0.0)
    if op == 24:
        return min(a, b)
    if op == 25:
        return max(a, b)
    if op == 26:
        return math.sin(a)
    if op == 27:
        return math.cos(a)
    return math.tan(a)


@inline
def vmath_op(op, a, b, c, s):
    """Blender's Vector Math node (Cycles' svm_vector_math) operation ``op`` (index into
    VMATH_OPS) on 3-tuples a, b, c and scale s: (x, y, z, value)."""
    ax, ay, az = a
    bx, by, bz = b
    cx, cy, cz = c
    if op == 5:
        return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx, 0.0
    if op == 6:
        d = bx * bx + by * by + bz * bz
        k = (ax * bx + ay * by + az * bz) / d if d != 0.0 else 0.0
        return k * bx, k * by, k * bz, 0.0
    if op == 7 or op == 8:
        ln = math.sqrt(bx * bx + by * by + bz * bz)
        if ln != 0.0:
            bx, by, bz = bx / ln, by / ln, bz / ln
        d = ax * bx + ay * by + az * bz
        if op == 7:
            return ax - 2.0 * d * bx, ay - 2.0 * d * by, az - 2.0 * d * bz, 0.0
        k = 1.0 - s * s * (1.0 - d * d)
        if k < 0.0:
            return 0.0, 0.0, 0.0, 0.0
        m = s * d + math.sqrt(k)
        return s * ax - m * bx, s * ay - m * by, s * az - m * bz, 0.0
    if op == 9:
        if cx * bx + cy * by + cz * bz < 0.0:
            return ax, ay, az, 0.0
        return -ax, -ay, -az, 0.0
    if op == 10:
        return 0.0, 0.0, 0.0, ax * bx + ay * by + az * bz
    if op == 11:
        dx, dy, dz = ax - bx, ay - by, az - bz
        return 0.0, 0.0, 0.0, math.sqrt(dx * dx + dy * dy + dz * dz)
    if op == 12:
        return 0.0, 0.0, 0.0, math.sqrt(ax * ax + ay * ay + az * az)
    if op == 13:
        return ax * s, ay * s, az * s, 0.0
    if op == 14:
        ln = math.sqrt(ax * ax + ay * ay + az * az)
        if ln == 0.0:
            return 0.0, 0.0, 0.0, 0.0
        return ax / ln, ay / ln, az / ln, 0.0
    return _vcomp(op, ax, bx, cx), _vcomp(op, ay, by, cy), _vcomp(op, az, bz, cz), 0.0


@inline
def rgb_to_hsv(r, g, b):
    cmax = max(r, g, b)
    cmin = min(r, g, b)
    cd = cmax - cmin
    v = cmax
    s = cd / cmax if cmax != 0.0 else 0.0
    h = 0.0
    if s != 0.0:
        cr = (cmax - r) / cd
        cg = (cmax - g) / cd
        cb = (cmax - b) / cd
        if r == cmax:
            h = cb - cg
        elif g == cmax:
            h = 2.0 + cr - cb
        else:
            h = 4.0 + cg - cr
        h /= 6.0
        if h < 0.0:
            h += 1.0
    return h, s, v


@inline
def hsv_to_rgb(h, s, v):
    if s == 0.0:
        return v, v, v
    if h == 1.0:
        h = 0.0
    h *= 6.0
    i = math.floor(h)
    f = h - i
    p = v * (1.0 - s)
    q = v * (1.0 - s * f)
    t = v * (1.0 - s * (1.0 - f))
    if i == 0.0:
        return v, t, p
    if i == 1.0:
        return q, v, p
    if i == 2.0:
        return p, v, t
    if i == 3.0:
        return p, q, v
    if i == 4.0:
        return t, p, v
    return v, p, q


@inline
def rgb_to_hsl(r, g, b):
    cmax = max(r, g, b)
    cmin = min(r, g, b)
    l_ = min(1.0, (cmax + cmin) / 2.0)
    if cmax == cmin:
        return 0.0, 0.0, l_
    d = cmax - cmin
    s = d / (2.0 - cmax - cmin) if l_ > 0.5 else d / (cmax + cmin)
    if cmax == r:
        h = (g - b) / d + (6.0 if g < b else 0.0)
    elif cmax == g:
        h = (b - r) / d + 2.0
    else:
        h = (r - g) / d + 4.0
    return h / 6.0, s, l_


@inline
def hsl_to_rgb(h, s, l_):
    nr = min(max(abs(h * 6.0 - 3.0) - 1.0, 0.0), 1.0)
    ng = min(max(2.0 - abs(h * 6.0 - 2.0), 0.0), 1.0)
    nb = min(max(2.0 - abs(h * 6.0 - 4.0), 0.0), 1.0)
    ch = (1.0 - abs(2.0 * l_ - 1.0)) * s
    return (nr - 0.5) * ch + l_, (ng - 0.5) * ch + l_, (nb - 0.5) * ch + l_


@inline
def _lerp3(t, a, b):
    return a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t


@inline
def _blend_hsv(mode, t, c1, c2):
    """The Hue, Saturation, Color and Value blend modes (Cycles' svm_mix_*)."""
    tm = 1.0 - t
    if mode == 15 or mode == 17:
        h2, s2, v2 = rgb_to_hsv(c2[0], c2[1], c2[2])
        if s2 == 0.0:
            return c1
        h, s, v = rgb_to_hsv(c1[0], c1[1], c1[2])
        if mode == 17:
            s = s2
        return _lerp3(t, c1, hsv_to_rgb(h2, s, v))
    h, s, v = rgb_to_hsv(c1[0], c1[1], c1[2])
    h2, s2, v2 = rgb_to_hsv(c2[0], c2[1], c2[2])
    if mode == 16:
        if s == 0.0:
            return c1
        return hsv_to_rgb(h, tm * s + t * s2, v)
    return hsv_to_rgb(h, s, tm * v + t * v2)


@inline
def _blend_ch(mode, t, a, b):
    """One channel of the per-channel blend modes (Cycles' svm_mix_*): a the first colour, b the second."""
    tm = 1.0 - t
    if mode == 1:
        return a + (min(a, b) - a) * t
    if mode == 2:
        return a + (a * b - a) * t
    if mode == 3:
        tmp = tm + t * b
        if tmp <= 0.0:
            return 0.0
        tmp = 1.0 - (1.0 - a) / tmp
        return min(max(tmp, 0.0), 1.0)
    if mode == 4:
        return a + (max(a, b) - a) * t
    if mode == 5:
        return 1.0 - (tm + t * (1.0 - b)) * (1.0 - a)
    if mode == 6:
        if a == 0.0:
            return a
        tmp = 1.0 - t * b
        if tmp <= 0.0:
            return 1.0
        return min(a / tmp, 1.0)
    if mode == 7:
        return a + t * b
    if mode == 8:
        if a < 0.5:
            return a * (tm + 2.0 * t * b)
        return 1.0 - (tm + 2.0 * t * (1.0 - b)) * (1.0 - a)
    if mode == 9:
        scr = 1.0 - (1.0 - b) * (1.0 - a)
        return tm * a + t * ((1.0 - a) * b * a + a * scr)
    if mode == 10:
        return a + t * (2.0 * b - 1.0)
    if mode == 11:
        return a + (abs(a - b) - a) * t
    if mode == 12:
        return max(a + (a + b - 2.0 * a * b - a) * t, 0.0)
    if mode == 13:
        return a - t * b
    if mode == 14:
        return tm * a + t * a / b if b != 0.0 else a
    return a + (b - a) * t


@inline
def blend(mode, t, c1, c2):
    """Blender's Mix node colour blend ``mode`` (index into BLEND_MODES) of c1 by c2 at factor t."""
    if mode >= 15:
        return _blend_hsv(mode, t, c1, c2)
    return _blend_ch(mode, t, c1[0], c2[0]), _blend_ch(mode, t, c1[1], c2[1]), _blend_ch(mode, t, c1[2], c2[2])


@inline
def _smoothstep(e0, e1, x):
    if x < e0:
        return 0.0
    if x >= e1:
        return 1.0
    t = (x - e0) / (e1 - e0)
    return t * t * (3.0 - 2.0 * t)


@inline
def _smootherstep(e0, e1, x):
    t = min(max(_safe_div(x - e0, e1 - e0), 0.0), 1.0)
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


@inline
def map_range(mode, clamp, v, f0, f1, t0, t1, steps):
    """Blender's Map Range node (Cycles' svm_map_range) on one component."""
    if f1 == f0:
        return 0.0
    if mode == 0:
        k = (v - f0) / (f1 - f0)
    elif mode == 1:
        k = (v - f0) / (f1 - f0)
        k = math.floor(k * (steps + 1.0)) / steps if steps > 0.0 else 0.0
    elif mode == 2:
        k = 1.0 - _smoothstep(f1, f0, v) if f0 > f1 else _smoothstep(f0, f1, v)
    else:
        k = 1.0 - _smootherstep(f1, f0, v) if f0 > f1 else _smootherstep(f0, f1, v)
    r = t0 + k * (t1 - t0)
    if clamp and mode <= 1:
        if t0 > t1:
            return min(max(r, t1), t0)
        return min(max(r, t0), t1)
    return r


@inline
def table(consts, q, ch, x):
    """Table lookup (Cycles' float_ramp_lookup): consts[q..] = n, lo, hi, extrapolate, then n
    entries of ``nc`` interleaved channels (nc = consts[q + 4]); channel ch at x, linear
    between entries, held or extrapolated linearly outside [lo, hi]."""
    n = int(consts[q])
    lo = float(consts[q + 1])
    hi = float(consts[q + 2])
    ext = consts[q + 3] != 0.0
    nc = int(consts[q + 4])
    base = q + 5 + ch
    f = (x - lo) / (hi - lo) * (n - 1) if hi != lo else 0.0
    if ext and (f < 0.0 or f > n - 1):
        if f < 0.0:
            t0 = float(consts[base])
            dy = t0 - float(consts[base + nc])
            f = -f
        else:
            t0 = float(consts[base + (n - 1) * nc])
            dy = t0 - float(consts[base + (n - 2) * nc])
            f = f - (n - 1)
        return t0 + dy * f
    f = min(max(f, 0.0), n - 1.0)
    i = min(int(f), n - 1)
    t = f - i
    r = float(consts[base + i * nc])
    if t > 0.0:
        r = (1.0 - t) * r + t * float(consts[base + (i + 1) * nc])
    return r


@inline
def _attr(tri_attr, prim, a, bu, bv):
    """Attribute a of leaf triangle prim interpolated at barycentrics (bu, bv) (linear, so
    also beyond the triangle)."""
    b0 = 1.0 - bu - bv
    k = a * 9
    return (b0 * tri_attr[prim, k] + bu * tri_attr[prim, k + 3] + bv * tri_attr[prim, k + 6],
            b0 * tri_attr[prim, k + 1] + bu * tri_attr[prim, k + 4] + bv * tri_attr[prim, k + 7],
            b0 * tri_attr[prim, k + 2] + bu * tri_attr[prim, k + 5] + bv * tri_attr[prim, k + 8])


@inline
def _norm3(x, y, z):
    ln = math.sqrt(x * x + y * y + z * z)
    if ln == 0.0:
        return x, y, z
    return x / ln, y / ln, z / ln


@inline
def _put3(regs, out, v):
    regs[out] = v[0]
    regs[out + 1] = v[1]
    regs[out + 2] = v[2]


@inline
def _vec(regs, consts, k):
    return _rd(regs, consts, k, 0), _rd(regs, consts, k, 1), _rd(regs, consts, k, 2)


@inline
def _fresnel(eta, cosi):
    """Cycles' fresnel_dielectric_cos: unpolarised Fresnel reflectance of a dielectric."""
    c = abs(cosi)
    g = eta * eta - 1.0 + c * c
    if g > 0.0:
        g = math.sqrt(g)
        a = (g - c) / (g + c)
        b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
        return 0.5 * a * a * (1.0 + b * b)
    return 1.0


@inline
def _geometry_ops(op, p, q, out, pc, ops, consts, regs, ctx, tri_attr, prim, bu, bv):
    """The ops that read the shading point: coordinates, attributes, Fresnel, Layer Weight."""
    ix, iy, iz = ctx[9], ctx[10], ctx[11]
    if op == O.OP_COORD:
        _put3(regs, out, (ctx[3 * p], ctx[3 * p + 1], ctx[3 * p + 2]))
    elif op == O.OP_ATTR:
        if p & 2:
            bu += O.BUMP_DELTA
        if p & 4:
            bv += O.BUMP_DELTA
        v = _attr(tri_attr, prim, q, bu, bv)
        if p & 1:
            v = _norm3(v[0], v[1], v[2])
        _put3(regs, out, v)
    else:
        nx, ny, nz = _norm3(_rd(regs, consts, ops[pc + 6], 0), _rd(regs, consts, ops[pc + 6], 1),
                            _rd(regs, consts, ops[pc + 6], 2))
        cosi = nx * ix + ny * iy + nz * iz
        b = _rd(regs, consts, ops[pc + 5], 0)
        backfacing = ctx[6] * ix + ctx[7] * iy + ctx[8] * iz < 0.0
        if op == O.OP_FRESNEL:
            eta = max(b, 1e-5)
            regs[out] = _fresnel(1.0 / eta if backfacing else eta, cosi)
        else:
            eta = max(1.0 - b, 1e-5)
            regs[out] = _fresnel(eta if backfacing else 1.0 / eta, cosi)
            f = abs(cosi)
            if b != 0.5:
                bl = min(max(b, 0.0), 1.0 - 1e-5)
                f = f ** (2.0 * bl if bl < 0.5 else 0.5 / (1.0 - bl))
            regs[out + 1] = 1.0 - f


@inline
def _colour_ops(op, p, q, out, pc, ops, consts, regs):
    """The colour adjustment ops: Hue/Saturation/Value, Invert, Bright/Contrast, Gamma, conversions."""
    if op == O.OP_HSV:
        r, g, b = _vec(regs, consts, ops[pc + 9])
        fac = _rd(regs, consts, ops[pc + 8], 0)
        h, s, v = rgb_to_hsv(r, g, b)
        h = _fract(h + _rd(regs, consts, ops[pc + 5], 0) + 0.5)
        s = min(max(s * _rd(regs, consts, ops[pc + 6], 0), 0.0), 1.0)
        v *= _rd(regs, consts, ops[pc + 7], 0)
        c = hsv_to_rgb(h, s, v)
        _put3(regs, out, (max(fac * c[0] + (1.0 - fac) * r, 0.0), max(fac * c[1] + (1.0 - fac) * g, 0.0),
                          max(fac * c[2] + (1.0 - fac) * b, 0.0)))
    elif op == O.OP_INVERT:
        fac = _rd(regs, consts, ops[pc + 5], 0)
        c = _vec(regs, consts, ops[pc + 6])
        _put3(regs, out, _lerp3(fac, c, (1.0 - c[0], 1.0 - c[1], 1.0 - c[2])))
    elif op == O.OP_BRIGHT:
        c = _vec(regs, consts, ops[pc + 5])
        bright = _rd(regs, consts, ops[pc + 6], 0)
        contrast = _rd(regs, consts, ops[pc + 7], 0)
        a = 1.0 + contrast
        b = bright - contrast * 0.5
        _put3(regs, out, (max(a * c[0] + b, 0.0), max(a * c[1] + b, 0.0), max(a * c[2] + b, 0.0)))
    elif op == O.OP_GAMMA:
        c = _vec(regs, consts, ops[pc + 5])
        gm = _rd(regs, consts, ops[pc + 6], 0)
        _put3(regs, out, (c[0] ** gm if c[0] > 0.0 else c[0], c[1] ** gm if c[1] > 0.0 else c[1],
                          c[2] ** gm if c[2] > 0.0 else c[2]))
    else:
        x, y, z = _vec(regs, consts, ops[pc + 5])
        if p == O.CONV_RGB_HSV:
            _put3(regs, out, rgb_to_hsv(x, y, z))
        elif p == O.CONV_HSV_RGB:
            _put3(regs, out, hsv_to_rgb(x, y, z))
        elif p == O.CONV_RGB_HSL:
            _put3(regs, out, rgb_to_hsl(x, y, z))
        else:
            _put3(regs, out, hsl_to_rgb(x, y, z))


@inline
def _mix_ops(op, p, q, out, pc, ops, consts, regs):
    """Mix (float, vector, colour), Map Range, Clamp."""
    if op == O.OP_MIXF:
        t = _rd(regs, consts, ops[pc + 5], 0)
        if q & 1:
            t = min(max(t, 0.0), 1.0)
        a = _rd(regs, consts, ops[pc + 6], 0)
        regs[out] = a + (_rd(regs, consts, ops[pc + 7], 0) - a) * t
    elif op == O.OP_MIXV:
        k = ops[pc + 5]
        for i in range(3):
            t = _rd(regs, consts, k, i if q & 2 else 0)
            if q & 1:
                t = min(max(t, 0.0), 1.0)
            a = _rd(regs, consts, ops[pc + 6], i)
            regs[out + i] = a + (_rd(regs, consts, ops[pc + 7], i) - a) * t
    elif op == O.OP_MIXC:
        t = _rd(regs, consts, ops[pc + 5], 0)
        if q & 1:
            t = min(max(t, 0.0), 1.0)
        c = blend(p, t, _vec(regs, consts, ops[pc + 6]), _vec(regs, consts, ops[pc + 7]))
        if q & 2:
            c = (min(max(c[0], 0.0), 1.0), min(max(c[1], 0.0), 1.0), min(max(c[2], 0.0), 1.0))
        _put3(regs, out, c)
    elif op == O.OP_MAPRANGE:
        n = 3 if q & 2 else 1
        for i in range(n):
            regs[out + i] = map_range(p, (q & 1) != 0, _rd(regs, consts, ops[pc + 5], i),
                                      _rd(regs, consts, ops[pc + 6], i), _rd(regs, consts, ops[pc + 7], i),
                                      _rd(regs, consts, ops[pc + 8], i), _rd(regs, consts, ops[pc + 9], i),
                                      _rd(regs, consts, ops[pc + 10], i))
    else:
        v = _rd(regs, consts, ops[pc + 5], 0)
        lo = _rd(regs, consts, ops[pc + 6], 0)
        hi = _rd(regs, consts, ops[pc + 7], 0)
        if p == 1 and lo > hi:
            lo, hi = hi, lo
        regs[out] = min(max(v, lo), hi)


@inline
def _table_ops(op, p, q, out, pc, ops, consts, regs, tex_data, tex_info):
    """Tables (curves, blackbody, wavelength), RGB Curves, Color Ramp, Image Texture."""
    if op == O.OP_TABLE:
        x = _rd(regs, consts, ops[pc + 5], 0)
        if p & 1:
            _put3(regs, out, (table(consts, q, 0, x), table(consts, q, 1, x), table(consts, q, 2, x)))
        else:
            regs[out] = table(consts, q, 0, x)
    elif op == O.OP_CURVES:
        fac = _rd(regs, consts, ops[pc + 5], 0)
        c = _vec(regs, consts, ops[pc + 6])
        _put3(regs, out, _lerp3(fac, c, (table(consts, q, 0, c[0]), table(consts, q, 1, c[1]),
                                         table(consts, q, 2, c[2]))))
    elif op == O.OP_RAMP:
        f = min(max(_rd(regs, consts, ops[pc + 5], 0), 0.0), 1.0) * (O.RAMP_TABLE_SIZE - 1)
        i = min(max(int(f), 0), O.RAMP_TABLE_SIZE - 1)
        t = f - i
        for c in range(4):
            r = float(consts[q + 4 * i + c])
            if p == 1 and t > 0.0:
                r = (1.0 - t) * r + t * float(consts[q + 4 * (i + 1) + c])
            regs[out + c] = r
    else:
        u = _rd(regs, consts, ops[pc + 5], 0)
        v = _rd(regs, consts, ops[pc + 5], 1)
        _put3(regs, out, tex.sample(tex_data, tex_info, q, u, v))
        regs[out + 3] = 1.0


@inline
def _sub3(a, b):
    return a[0] - b[0], a[1] - b[1], a[2] - b[2]


@inline
def _cross3(a, b):
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


@inline
def _dot3(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@inline
def _normal_ops(op, p, q, out, pc, ops, consts, regs):
    """Bump (Cycles' svm_node_set_bump, with the differentials of the barycentric offsets) and
    Normal Map (svm_node_normal_map; the tangent ∂p/∂u of the UV map, bitangent sign·n × t)."""
    nv = _vec(regs, consts, ops[pc + 13])
    n_in = _norm3(nv[0], nv[1], nv[2])
    if op == O.OP_BUMP:
        dpdx = _sub3(_vec(regs, consts, ops[pc + 11]), _vec(regs, consts, ops[pc + 10]))
        dpdy = _sub3(_vec(regs, consts, ops[pc + 12]), _vec(regs, consts, ops[pc + 10]))
        rx = _cross3(dpdy, n_in)
        ry = _cross3(n_in, dpdx)
        hc = _rd(regs, consts, ops[pc + 5], 0)
        hx = _rd(regs, consts, ops[pc + 6], 0) - hc
        hy = _rd(regs, consts, ops[pc + 7], 0) - hc
        det = _dot3(dpdx, rx)
        strength = max(_rd(regs, consts, ops[pc + 8], 0), 0.0)
        dist = _rd(regs, consts, ops[pc + 9], 0)
        if q & 1:
            dist = -dist
        sgn = 1.0 if det > 0.0 else (-1.0 if det < 0.0 else 0.0)
        a = abs(det)
        m = _norm3(a * n_in[0] - dist * sgn * (hx * rx[0] + hy * ry[0]),
                   a * n_in[1] - dist * sgn * (hx * rx[1] + hy * ry[1]),
                   a * n_in[2] - dist * sgn * (hx * rx[2] + hy * ry[2]))
    else:
        c = _vec(regs, consts, ops[pc + 5])
        cx, cy, cz = 2.0 * c[0] - 1.0, 2.0 * c[1] - 1.0, 2.0 * c[2] - 1.0
        strength = max(_rd(regs, consts, ops[pc + 6], 0), 0.0)
        if p == 0:
            p0 = _vec(regs, consts, ops[pc + 7])
            e1 = _sub3(_vec(regs, consts, ops[pc + 8]), p0)
            e2 = _sub3(_vec(regs, consts, ops[pc + 9]), p0)
            t0 = _vec(regs, consts, ops[pc + 10])
            d1 = _sub3(_vec(regs, consts, ops[pc + 11]), t0)
            d2 = _sub3(_vec(regs, consts, ops[pc + 12]), t0)
            det = d1[0] * d2[1] - d2[0] * d1[1]
            r = 1.0 / det if det != 0.0 else 0.0
            tu = ((e1[0] * d2[1] - e2[0] * d1[1]) * r, (e1[1] * d2[1] - e2[1] * d1[1]) * r,
                  (e1[2] * d2[1] - e2[2] * d1[1]) * r)
            bv_ = ((e2[0] * d1[0] - e1[0] * d2[0]) * r, (e2[1] * d1[0] - e1[1] * d2[0]) * r,
                   (e2[2] * d1[0] - e1[2] * d2[0]) * r)
            k = _dot3(tu, n_in)
            t = _norm3(tu[0] - k * n_in[0], tu[1] - k * n_in[1], tu[2] - k * n_in[2])
            b = _cross3(n_in, t)
            if _dot3(b, bv_) < 0.0:
                b = (-b[0], -b[1], -b[2])
            m = _norm3(cx * t[0] + cy * b[0] + cz * n_in[0], cx * t[1] + cy * b[1] + cz * n_in[1],
                       cx * t[2] + cy * b[2] + cz * n_in[2])
        elif p == 1:
            m = _norm3(cx, cy, cz)
        else:
            m = _norm3(cx, -cy, -cz)
    if strength != 1.0:
        m = _norm3(n_in[0] + (m[0] - n_in[0]) * strength, n_in[1] + (m[1] - n_in[1]) * strength,
                   n_in[2] + (m[2] - n_in[2]) * strength)
    _put3(regs, out, m)


@inline
def _proc_ops(p, q, out, pc, ops, consts, regs):
    """The procedural textures (core/shading/procedural.py): p = PROC_* kind, the operands
    the vector, W and the node's sockets in the order of ops.PROC_SOCKETS, the integer
    settings at consts[q..]; out: colour (3), then the node's float outputs."""
    x, y, z = _vec(regs, consts, ops[pc + 5])
    w = _rd(regs, consts, ops[pc + 6], 0)
    i0 = int(consts[q])
    i1 = int(consts[q + 1])
    i2 = int(consts[q + 2])
    i3 = int(consts[q + 3])
    if p == O.PROC_NOISE:
        fac, r, g, b = T.noise_texture(x, y, z, w, i0, i1, _rd(regs, consts, ops[pc + 7], 0),
                                       _rd(regs, consts, ops[pc + 8], 0), _rd(regs, consts, ops[pc + 9], 0),
                                       _rd(regs, consts, ops[pc + 10], 0), _rd(regs, consts, ops[pc + 11], 0),
                                       _rd(regs, consts, ops[pc + 12], 0), _rd(regs, consts, ops[pc + 13], 0), i2,
                                       True)
        _put3(regs, out, (r, g, b))
        regs[out + 3] = fac
    elif p == O.PROC_VORONOI:
        d, r, g, b, px, py, pz, wo, rad = T.voronoi_texture(
            x, y, z, w, i0, i1, i2, _rd(regs, consts, ops[pc + 7], 0), _rd(regs, consts, ops[pc + 8], 0),
            _rd(regs, consts, ops[pc + 9], 0), _rd(regs, consts, ops[pc + 10], 0), _rd(regs, consts, ops[pc + 11], 0),
            _rd(regs, consts, ops[pc + 12], 0), _rd(regs, consts, ops[pc + 13], 0), i3)
        _put3(regs, out, (r, g, b))
        _put3(regs, out + 3, (px, py, pz))
        regs[out + 6] = d
        regs[out + 7] = wo
        regs[out + 8] = rad
    elif p == O.PROC_WAVE:
        f = T.wave_texture(x, y, z, i0, i1, i2, i3, _rd(regs, consts, ops[pc + 7], 0),
                           _rd(regs, consts, ops[pc + 8], 0), _rd(regs, consts, ops[pc + 9], 0),
                           _rd(regs, consts, ops[pc + 10], 0), _rd(regs, consts, ops[pc + 11], 0),
                           _rd(regs, consts, ops[pc + 12], 0))
        _put3(regs, out, (f, f, f))
        regs[out + 3] = f
    elif p == O.PROC_MAGIC:
        r, g, b, f = T.magic_texture(x, y, z, i0, _rd(regs, consts, ops[pc + 7], 0),
                                     _rd(regs, consts, ops[pc + 8], 0))
        _put3(regs, out, (r, g, b))
        regs[out + 3] = f
    elif p == O.PROC_CHECKER:
        c1 = _vec(regs, consts, ops[pc + 8])
        c2 = _vec(regs, consts, ops[pc + 9])
        r, g, b, f = T.checker_texture(x, y, z, _rd(regs, consts, ops[pc + 7], 0), c1[0], c1[1], c1[2], c2[0],
                                       c2[1], c2[2])
        _put3(regs, out, (r, g, b))
        regs[out + 3] = f
    elif p == O.PROC_BRICK:
        tint, f = T.brick_texture(x, y, z, _rd(regs, consts, ops[pc + 7], 0), _rd(regs, consts, ops[pc + 8], 0),
                                  _rd(regs, consts, ops[pc + 9], 0), _rd(regs, consts, ops[pc + 10], 0),
                                  _rd(regs, consts, ops[pc + 11], 0), _rd(regs, consts, ops[pc + 12], 0),
                                  float(consts[q + 4]), i0, float(consts[q + 5]), i1)
        c1 = _vec(regs, consts, ops[pc + 13])
        c2 = _vec(regs, consts, ops[pc + 14])
        cm = _vec(regs, consts, ops[pc + 15])
        _put3(regs, out, T.brick_color(tint, f, c1[0], c1[1], c1[2], c2[0], c2[1], c2[2], cm[0], cm[1], cm[2]))
        regs[out + 3] = f
    elif p == O.PROC_GRADIENT:
        f = T.gradient_texture(x, y, z, i0)
        _put3(regs, out, (f, f, f))
        regs[out + 3] = f
    else:
        v, r, g, b = T.white_noise_texture(x, y, z, w, i0)
        _put3(regs, out, (r, g, b))
        regs[out + 3] = v


@function
def run(ops, consts, tex_data, tex_info, tri_attr, start, prim, bu, bv, ctx, regs):
    """The 3-vector result of the program at ops[start..] at a shading point of leaf triangle
    ``prim`` with barycentrics (bu, bv) of corners 1 and 2; ctx = (P, N, Ng, I) as 12 floats
    (world position, shading normal, geometric normal, unit direction towards the viewer);
    regs: float32 registers (at least the program's count)."""
    pc = start
    while True:
        op = ops[pc]
        n = ops[pc + 1]
        out = ops[pc + 2]
        p = ops[pc + 3]
        q = ops[pc + 4]
        if op == O.OP_END:
            k = ops[pc + 5]
            return _rd(regs, consts, k, 0), _rd(regs, consts, k, 1), _rd(regs, consts, k, 2)
        if op == O.OP_MATH:
            r = math_op(p, _rd(regs, consts, ops[pc + 5], 0), _rd(regs, consts, ops[pc + 6], 0),
                        _rd(regs, consts, ops[pc + 7], 0))
            if q != 0:
                r = min(max(r, 0.0), 1.0)
            regs[out] = r
        elif op == O.OP_VMATH:
            x, y, z, val = vmath_op(p, _vec(regs, consts, ops[pc + 5]), _vec(regs, consts, ops[pc + 6]),
                                    _vec(regs, consts, ops[pc + 7]), _rd(regs, consts, ops[pc + 8], 0))
            _put3(regs, out, (x, y, z))
            regs[out + 3] = val
        elif op == O.OP_XFORM:
            x, y, z = _vec(regs, consts, ops[pc + 5])
            w = 1.0 if p == O.XF_POINT else 0.0
            m = consts
            rx = m[q] * x + m[q + 1] * y + m[q + 2] * z + m[q + 3] * w
            ry = m[q + 4] * x + m[q + 5] * y + m[q + 6] * z + m[q + 7] * w
            rz = m[q + 8] * x + m[q + 9] * y + m[q + 10] * z + m[q + 11] * w
            if p == O.XF_NORMAL:
                rx, ry, rz = _norm3(rx, ry, rz)
            _put3(regs, out, (rx, ry, rz))
        elif op == O.OP_COMBINE:
            _put3(regs, out, (_rd(regs, consts, ops[pc + 5], 0), _rd(regs, consts, ops[pc + 6], 0),
                              _rd(regs, consts, ops[pc + 7], 0)))
        elif op == O.OP_COORD or op == O.OP_ATTR or op == O.OP_FRESNEL or op == O.OP_LAYER:
            _geometry_ops(op, p, q, out, pc, ops, consts, regs, ctx, tri_attr, prim, bu, bv)
        elif op == O.OP_HSV or op == O.OP_INVERT or op == O.OP_BRIGHT or op == O.OP_GAMMA or op == O.OP_CONVERT:
            _colour_ops(op, p, q, out, pc, ops, consts, regs)
        elif op == O.OP_MIXF or op == O.OP_MIXV or op == O.OP_MIXC or op == O.OP_MAPRANGE or op == O.OP_CLAMP:
            _mix_ops(op, p, q, out, pc, ops, consts, regs)
        elif op == O.OP_PROC:
            _proc_ops(p, q, out, pc, ops, consts, regs)
        elif op == O.OP_BUMP or op == O.OP_NORMALMAP:
            _normal_ops(op, p, q, out, pc, ops, consts, regs)
        else:
            _table_ops(op, p, q, out, pc, ops, consts, regs, tex_data, tex_info)
        pc += O.HEADER + n
