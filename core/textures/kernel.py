"""Image texture lookups inside the path kernel (layout and conventions: core/textures.py).

All textures of a scene are one flat float32 array ``data`` plus an int64 table ``info``
(K, 6): offset, width, height, channels, interpolation tag, extension tag; texel (i, j)
(column, row from the top) channel c of texture t is data[offset + (j·W + i)·C + c].
UV (0, 0) is the image's bottom-left corner. Everything here is ``inline``.
"""
import math

from ..jit import inline

INTERP_CLOSEST = 0
INTERP_LINEAR = 1
EXT_REPEAT = 0
EXT_EXTEND = 1
EXT_CLIP = 2
INTERP_TAGS = {"closest": INTERP_CLOSEST, "linear": INTERP_LINEAR}
EXT_TAGS = {"repeat": EXT_REPEAT, "extend": EXT_EXTEND, "clip": EXT_CLIP}


@inline
def _wrap(i, n, ext):
    if ext == EXT_REPEAT:
        return i % n  # Python semantics: in [0, n) for negative i too
    if i < 0:
        return 0
    if i >= n:
        return n - 1
    return i


@inline
def _texel(data, base, w, c, i, j):
    """(r, g, b) of texel (i, j), grey for a one-channel texture."""
    k = base + (j * w + i) * c
    if c == 1:
        v = float(data[k])
        return v, v, v
    return float(data[k]), float(data[k + 1]), float(data[k + 2])


@inline
def sample(data, info, t, u, v):
    """(r, g, b) of texture ``t`` at UV (u, v): closest or bilinear, with its extension."""
    base = info[t, 0]
    w = info[t, 1]
    h = info[t, 2]
    c = info[t, 3]
    ext = info[t, 5]
    if ext == EXT_CLIP and (u < 0.0 or u > 1.0 or v < 0.0 or v > 1.0):
        return 0.0, 0.0, 0.0
    x = u * w
    y = (1.0 - v) * h
    if info[t, 4] == INTERP_CLOSEST:
        return _texel(data, base, w, c, _wrap(int(math.floor(x)), w, ext), _wrap(int(math.floor(y)), h, ext))
    x -= 0.5
    y -= 0.5
    fx = math.floor(x)
    fy = math.floor(y)
    ax = x - fx
    ay = y - fy
    i0 = int(fx)
    j0 = int(fy)
    i1 = _wrap(i0 + 1, w, ext)
    j1 = _wrap(j0 + 1, h, ext)
    i0 = _wrap(i0, w, ext)
    j0 = _wrap(j0, h, ext)
    r00, g00, b00 = _texel(data, base, w, c, i0, j0)
    r10, g10, b10 = _texel(data, base, w, c, i1, j0)
    r01, g01, b01 = _texel(data, base, w, c, i0, j1)
    r11, g11, b11 = _texel(data, base, w, c, i1, j1)
    w00 = (1.0 - ax) * (1.0 - ay)
    w10 = ax * (1.0 - ay)
    w01 = (1.0 - ax) * ay
    w11 = ax * ay
    return (w00 * r00 + w10 * r10 + w01 * r01 + w11 * r11,
            w00 * g00 + w10 * g10 + w01 * g01 + w11 * g11,
            w00 * b00 + w10 * b10 + w01 * b01 + w11 * b11)


@inline
def hit_uv(tri_tex, prim, bu, bv):
    """UV of the hit with barycentrics (bu, bv) of corners 1 and 2 of leaf triangle ``prim``."""
    b0 = 1.0 - bu - bv
    u = b0 * tri_tex[prim, 0] + bu * tri_tex[prim, 2] + bv * tri_tex[prim, 4]
    v = b0 * tri_tex[prim, 1] + bu * tri_tex[prim, 3] + bv * tri_tex[prim, 5]
    return u, v


@inline
def perturb_normal(tri_tex, prim, nx, ny, nz, r, g, b, strength):
    """The shading normal (nx, ny, nz) (unit) bent by the tangent-space normal-map texel (r, g, b).

    The tangent is the triangle's ∂p/∂u made orthogonal to n, the bitangent s·n × t (s the
    UV map's handedness), the mapped normal 2·rgb − 1 in that frame (OpenGL, +Y = +v), and
    ``strength`` blends the two normals as Blender's Normal Map node. Returns the unit
    normal, or n itself when the result degenerates."""
    tx = tri_tex[prim, 6]
    ty = tri_tex[prim, 7]
    tz = tri_tex[prim, 8]
    d = tx * nx + ty * ny + tz * nz
    tx -= d * nx
    ty -= d * ny
    tz -= d * nz
    tl = math.sqrt(tx * tx + ty * ty + tz * tz)
    if tl == 0.0:
        return nx, ny, nz
    tx /= tl
    ty /= tl
    tz /= tl
    s = tri_tex[prim, 9]
    bx = s * (ny * tz - nz * ty)
    by = s * (nz * tx - nx * tz)
    bz = s * (nx * ty - ny * tx)
    a = 2.0 * r - 1.0
    c = 2.0 * g - 1.0
    e = 2.0 * b - 1.0
    mx = a * tx + c * bx + e * nx
    my = a * ty + c * by + e * ny
    mz = a * tz + c * bz + e * nz
    ml = math.sqrt(mx * mx + my * my + mz * mz)
    if ml == 0.0:
        return nx, ny, nz
    mx /= ml
    my /= ml
    mz /= ml
    if strength != 1.0:
        mx = nx + (mx - nx) * strength
        my = ny + (my - ny) * strength
        mz = nz + (mz - nz) * strength
        ml = math.sqrt(mx * mx + my * my + mz * mz)
        if ml == 0.0:
            return nx, ny, nz
        mx /= ml
        my /= ml
        mz /= ml
    return mx, my, mz
