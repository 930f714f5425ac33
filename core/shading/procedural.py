"""Blender's procedural texture nodes as Cycles evaluates them, for the shader program.

Each texture is a numba ``inline`` helper taking scalars (a point, the node's settings as
integer tags and its socket values) and returning a float or a tuple of floats, so that a
pattern computed here matches the one Cycles renders for the same coordinates. The
algorithms follow Cycles' kernel (``intern/cycles/kernel/svm/`` and ``util/hash.h`` in
Blender 5.0): Bob Jenkins' lookup3 hash on the bits of single-precision coordinates,
Perlin's gradient noise with Cycles' gradient sets and output scales, the fractal
variants of the Noise node, the fractal Voronoi of Blender 4+ (its 2D to 4D cells hashed
by PCG of their integer coordinates, Jarzynski and Olano, JCGT 9(3) 2020, its 1D cells by
lookup3 of the float coordinate), and the Wave, Magic, Checker, Brick, Gradient and White
Noise nodes. ``tests/shading/test_procedural_cycles.py`` renders each with Cycles and
compares pixel for pixel.

Cycles computes in single precision. Here every value that is hashed or floored (the
scaled coordinates, the fractal octaves' scaled points, the distorted points, the random
seed offsets) is rounded to single precision exactly where Cycles rounds it, so lattice
cells and hashes are the same bits; the smooth arithmetic in between runs in double
precision and differs from Cycles' by rounding only (about 1e-7 relative).

The textures are small ``inline`` entry points; the lattice work they repeat (Perlin
noise, the fractal noise types, the Voronoi octaves) is in ``function`` helpers compiled
once each, so a caller's compile does not grow with every inlined copy.

The integer tags follow the order of Cycles' enums; the ``*_TYPES`` dictionaries map
the identifiers of the bpy enum properties to them. Every function listed in
``__all__`` is complete.
"""
import math

import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic

from ..jit import function, inline

__all__ = [
    "hash_uint", "hash_uint2", "hash_uint3", "hash_uint4",
    "hash_float_to_float", "hash_float2_to_float", "hash_float3_to_float", "hash_float4_to_float",
    "hash_int_to_point", "hash_int_to_color",
    "perlin_signed", "noise_texture", "voronoi_texture", "wave_texture", "magic_texture",
    "checker_texture", "brick_texture", "brick_color", "gradient_texture", "white_noise_texture",
]

# Noise node types (Cycles' NodeNoiseType).
NOISE_MULTIFRACTAL, NOISE_FBM, NOISE_HYBRID_MULTIFRACTAL, NOISE_RIDGED_MULTIFRACTAL, NOISE_HETERO_TERRAIN = range(5)
NOISE_TYPES = {"MULTIFRACTAL": 0, "FBM": 1, "HYBRID_MULTIFRACTAL": 2, "RIDGED_MULTIFRACTAL": 3,
               "HETERO_TERRAIN": 4}
# Voronoi features and distance metrics (NodeVoronoiFeature, NodeVoronoiDistanceMetric).
VORONOI_F1, VORONOI_F2, VORONOI_SMOOTH_F1, VORONOI_DISTANCE_TO_EDGE, VORONOI_N_SPHERE_RADIUS = range(5)
VORONOI_FEATURES = {"F1": 0, "F2": 1, "SMOOTH_F1": 2, "DISTANCE_TO_EDGE": 3, "N_SPHERE_RADIUS": 4}
VORONOI_EUCLIDEAN, VORONOI_MANHATTAN, VORONOI_CHEBYCHEV, VORONOI_MINKOWSKI = range(4)
VORONOI_METRICS = {"EUCLIDEAN": 0, "MANHATTAN": 1, "CHEBYCHEV": 2, "MINKOWSKI": 3}
# Gradient types (NodeGradientType).
GRADIENT_TYPES = {"LINEAR": 0, "QUADRATIC": 1, "EASING": 2, "DIAGONAL": 3, "RADIAL": 4,
                  "QUADRATIC_SPHERE": 5, "SPHERICAL": 6}
# Wave type, directions and profile (NodeWaveType, NodeWaveBandsDirection, NodeWaveRingsDirection,
# NodeWaveProfile).
WAVE_TYPES = {"BANDS": 0, "RINGS": 1}
WAVE_BANDS_DIRECTIONS = {"X": 0, "Y": 1, "Z": 2, "DIAGONAL": 3}
WAVE_RINGS_DIRECTIONS = {"X": 0, "Y": 1, "Z": 2, "SPHERICAL": 3}
WAVE_PROFILES = {"SIN": 0, "SAW": 1, "TRI": 2}
# The nodes' dimensions enum ("1D" ... "4D") as the integer count.
DIMENSIONS = {"1D": 1, "2D": 2, "3D": 3, "4D": 4}

_M = 0xFFFFFFFF
_FLT_MAX = 3.4028234663852886e38
_TWO_PI_F = float(np.float32(2.0 * math.pi))
_HALF_PI_F = float(np.float32(0.5 * math.pi))
_EPS_F = float(np.float32(1e-6))
_SHRINK_F = float(np.float32(0.999999))
_TWO_POW_M32 = 2.0 ** -32


@intrinsic
def _f32_bits(typingctx, x):
    """The IEEE bits of a float32 as a uint32 (C's ``__float_as_uint``)."""
    if x != types.float32:
        return None

    def codegen(context, builder, sig, args):
        return builder.bitcast(args[0], ir.IntType(32))

    return types.uint32(types.float32), codegen


@inline
def _f32(v):
    """``v`` rounded to single precision (as a double)."""
    return np.float64(np.float32(v))


@inline
def _bits(v):
    """The bits of ``v`` rounded to single precision, as a non-negative int64."""
    return np.int64(_f32_bits(np.float32(v))) & _M


# ---------------------------------------------------------------- lookup3 hash


@inline
def _rot(x, k):
    return ((x << k) | (x >> (32 - k))) & _M


@inline
def _mix(a, b, c):
    a = ((a - c) & _M) ^ _rot(c, 4)
    c = (c + b) & _M
    b = ((b - a) & _M) ^ _rot(a, 6)
    a = (a + c) & _M
    c = ((c - b) & _M) ^ _rot(b, 8)
    b = (b + a) & _M
    a = ((a - c) & _M) ^ _rot(c, 16)
    c = (c + b) & _M
    b = ((b - a) & _M) ^ _rot(a, 19)
    a = (a + c) & _M
    c = ((c - b) & _M) ^ _rot(b, 4)
    b = (b + a) & _M
    return a, b, c


@inline
def _final(a, b, c):
    c = ((c ^ b) - _rot(b, 14)) & _M
    a = ((a ^ c) - _rot(c, 11)) & _M
    b = ((b ^ a) - _rot(a, 25)) & _M
    c = ((c ^ b) - _rot(b, 16)) & _M
    a = ((a ^ c) - _rot(c, 4)) & _M
    b = ((b ^ a) - _rot(a, 14)) & _M
    c = ((c ^ b) - _rot(b, 24)) & _M
    return c


@inline
def hash_uint(kx):
    """lookup3 hash of one 32-bit word (Cycles' ``hash_uint``).

    ``kx``: an integer, taken modulo 2**32 (a negative int is its two's complement).
    Returns the hash as an int64 in [0, 2**32)."""
    a = (0xDEADBEEF + (1 << 2) + 13) & _M
    return _final((a + kx) & _M, a, a)


@inline
def hash_uint2(kx, ky):
    """lookup3 hash of two words (``hash_uint2``); arguments and result as ``hash_uint``."""
    a = (0xDEADBEEF + (2 << 2) + 13) & _M
    return _final((a + kx) & _M, (a + ky) & _M, a)


@inline
def hash_uint3(kx, ky, kz):
    """lookup3 hash of three words (``hash_uint3``); arguments and result as ``hash_uint``."""
    a = (0xDEADBEEF + (3 << 2) + 13) & _M
    return _final((a + kx) & _M, (a + ky) & _M, (a + kz) & _M)


@inline
def hash_uint4(kx, ky, kz, kw):
    """lookup3 hash of four words (``hash_uint4``: one mix, then the last word and the
    final); arguments and result as ``hash_uint``."""
    a0 = (0xDEADBEEF + (4 << 2) + 13) & _M
    a, b, c = _mix((a0 + kx) & _M, (a0 + ky) & _M, (a0 + kz) & _M)
    return _final((a + kw) & _M, b, c)


@inline
def _unit(n):
    """Cycles' ``uint_to_float_incl``: the hash rounded to float32, times 2**-32, in [0, 1]."""
    return np.float64(np.float32(n)) * _TWO_POW_M32


@inline
def hash_float_to_float(x):
    """Hash of the float32 bits of ``x`` to [0, 1] (``hash_float_to_float``)."""
    return _unit(hash_uint(_bits(x)))


@inline
def hash_float2_to_float(x, y):
    """Hash of the float32 bits of ``(x, y)`` to [0, 1] (``hash_float2_to_float``)."""
    return _unit(hash_uint2(_bits(x), _bits(y)))


@inline
def hash_float3_to_float(x, y, z):
    """Hash of the float32 bits of ``(x, y, z)`` to [0, 1] (``hash_float3_to_float``)."""
    return _unit(hash_uint3(_bits(x), _bits(y), _bits(z)))


@inline
def hash_float4_to_float(x, y, z, w):
    """Hash of the float32 bits of ``(x, y, z, w)`` to [0, 1] (``hash_float4_to_float``)."""
    return _unit(hash_uint4(_bits(x), _bits(y), _bits(z), _bits(w)))


@inline
def _i32(v):
    """``v`` wrapped to a signed 32-bit integer (C's int overflow), as an int64."""
    return ((v + 0x80000000) & _M) - 0x80000000


@inline
def _pcg2(x, y):
    """Cycles' ``hash_pcg2d_i``: PCG 2D (Jarzynski and Olano 2020) on signed 32-bit ints."""
    x = _i32(x * 1664525 + 1013904223)
    y = _i32(y * 1664525 + 1013904223)
    x = _i32(x + y * 1664525)
    y = _i32(y + x * 1664525)
    x, y = x ^ (x >> 16), y ^ (y >> 16)
    x = _i32(x + y * 1664525)
    y = _i32(y + x * 1664525)
    return x & 0x7FFFFFFF, y & 0x7FFFFFFF


@inline
def _pcg3(x, y, z):
    """Cycles' ``hash_pcg3d_i``."""
    x = _i32(x * 1664525 + 1013904223)
    y = _i32(y * 1664525 + 1013904223)
    z = _i32(z * 1664525 + 1013904223)
    x = _i32(x + y * z)
    y = _i32(y + z * x)
    z = _i32(z + x * y)
    x, y, z = x ^ (x >> 16), y ^ (y >> 16), z ^ (z >> 16)
    x = _i32(x + y * z)
    y = _i32(y + z * x)
    z = _i32(z + x * y)
    return x & 0x7FFFFFFF, y & 0x7FFFFFFF, z & 0x7FFFFFFF


@inline
def _pcg4(x, y, z, w):
    """Cycles' ``hash_pcg4d_i``."""
    x = _i32(x * 1664525 + 1013904223)
    y = _i32(y * 1664525 + 1013904223)
    z = _i32(z * 1664525 + 1013904223)
    w = _i32(w * 1664525 + 1013904223)
    x = _i32(x + y * w)
    y = _i32(y + z * x)
    z = _i32(z + x * y)
    w = _i32(w + y * z)
    x, y, z, w = x ^ (x >> 16), y ^ (y >> 16), z ^ (z >> 16), w ^ (w >> 16)
    x = _i32(x + y * w)
    y = _i32(y + z * x)
    z = _i32(z + x * y)
    w = _i32(w + y * z)
    return x & 0x7FFFFFFF, y & 0x7FFFFFFF, z & 0x7FFFFFFF, w & 0x7FFFFFFF


@inline
def _unit31(h):
    """Cycles' ``hash_int*_to_float*`` scaling: the hash rounded to float32, times 2**-31."""
    return np.float64(np.float32(h)) * 2.0 ** -31


@inline
def hash_int_to_point(c0, c1, c2, c3, dims):
    """A Voronoi cell's random point in [0, 1]^dims, padded with 0: Cycles'
    ``hash_float_to_float`` of the cell's float coordinate in 1D, ``hash_int{2,3,4}_to_float{2,3,4}``
    (PCG) of its integer coordinates in 2D to 4D.

    ``c0 .. c3``: the cell's integer coordinates (integral floats); ``dims``: 1 to 4."""
    if dims == 1:
        return hash_float_to_float(c0), 0.0, 0.0, 0.0
    if dims == 2:
        a, b = _pcg2(np.int64(c0), np.int64(c1))
        return _unit31(a), _unit31(b), 0.0, 0.0
    if dims == 3:
        a, b, c = _pcg3(np.int64(c0), np.int64(c1), np.int64(c2))
        return _unit31(a), _unit31(b), _unit31(c), 0.0
    a, b, c, d = _pcg4(np.int64(c0), np.int64(c1), np.int64(c2), np.int64(c3))
    return _unit31(a), _unit31(b), _unit31(c), _unit31(d)


@inline
def hash_int_to_color(c0, c1, c2, c3, dims):
    """A Voronoi cell's colour: ``hash_float_to_float3`` in 1D, ``hash_int{2,3,4}_to_float3``
    (PCG; 2D hashes ``(x, y, 0)`` in 3D) in 2D to 4D. Arguments as ``hash_int_to_point``."""
    if dims == 1:
        return hash_float_to_float(c0), hash_float2_to_float(c0, 1.0), hash_float2_to_float(c0, 2.0)
    if dims == 2:
        a, b, c = _pcg3(np.int64(c0), np.int64(c1), np.int64(0))
        return _unit31(a), _unit31(b), _unit31(c)
    h0, h1, h2, _ = hash_int_to_point(c0, c1, c2, c3, dims)
    return h0, h1, h2


# ---------------------------------------------------------------- Perlin noise


@inline
def _fade(t):
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


@inline
def _lerp(a, b, t):
    return a + t * (b - a)


@inline
def _sgn(v, cond):
    return -v if cond else v


@inline
def _grad1(h, x):
    h = h & 15
    return _sgn(1.0 + (h & 7), h & 8) * x


@inline
def _grad2(h, x, y):
    h = h & 7
    u = x if h < 4 else y
    v = 2.0 * (y if h < 4 else x)
    return _sgn(u, h & 1) + _sgn(v, h & 2)


@inline
def _grad3(h, x, y, z):
    h = h & 15
    u = x if h < 8 else y
    vt = x if (h == 12 or h == 14) else z
    v = y if h < 4 else vt
    return _sgn(u, h & 1) + _sgn(v, h & 2)


@inline
def _grad4(h, x, y, z, w):
    h = h & 31
    u = x if h < 24 else y
    v = y if h < 16 else z
    s = z if h < 8 else w
    return _sgn(u, h & 1) + _sgn(v, h & 2) + _sgn(s, h & 4)


@inline
def _tri(v0, v1, v2, v3, v4, v5, v6, v7, x, y, z):
    x1 = 1.0 - x
    y1 = 1.0 - y
    return (1.0 - z) * (y1 * (v0 * x1 + v1 * x) + y * (v2 * x1 + v3 * x)) + \
        z * (y1 * (v4 * x1 + v5 * x) + y * (v6 * x1 + v7 * x))


@inline
def _perlin_1d(x):
    fl = np.floor(x)
    X = np.int64(fl)
    fx = x - fl
    return _lerp(_grad1(hash_uint(X & _M), fx), _grad1(hash_uint((X + 1) & _M), fx - 1.0), _fade(fx))


@inline
def _perlin_2d(x, y):
    flx = np.floor(x)
    fly = np.floor(y)
    X = np.int64(flx)
    Y = np.int64(fly)
    fx = x - flx
    fy = y - fly
    u = _fade(fx)
    v = _fade(fy)
    v0 = _grad2(hash_uint2(X & _M, Y & _M), fx, fy)
    v1 = _grad2(hash_uint2((X + 1) & _M, Y & _M), fx - 1.0, fy)
    v2 = _grad2(hash_uint2(X & _M, (Y + 1) & _M), fx, fy - 1.0)
    v3 = _grad2(hash_uint2((X + 1) & _M, (Y + 1) & _M), fx - 1.0, fy - 1.0)
    x1 = 1.0 - u
    return (1.0 - v) * (v0 * x1 + v1 * u) + v * (v2 * x1 + v3 * u)


@inline
def _perlin_3d(x, y, z):
    flx, fly, flz = np.floor(x), np.floor(y), np.floor(z)
    X, Y, Z = np.int64(flx), np.int64(fly), np.int64(flz)
    fx, fy, fz = x - flx, y - fly, z - flz
    X0, X1, Y0, Y1, Z0, Z1 = X & _M, (X + 1) & _M, Y & _M, (Y + 1) & _M, Z & _M, (Z + 1) & _M
    return _tri(_grad3(hash_uint3(X0, Y0, Z0), fx, fy, fz),
                _grad3(hash_uint3(X1, Y0, Z0), fx - 1.0, fy, fz),
                _grad3(hash_uint3(X0, Y1, Z0), fx, fy - 1.0, fz),
                _grad3(hash_uint3(X1, Y1, Z0), fx - 1.0, fy - 1.0, fz),
                _grad3(hash_uint3(X0, Y0, Z1), fx, fy, fz - 1.0),
                _grad3(hash_uint3(X1, Y0, Z1), fx - 1.0, fy, fz - 1.0),
                _grad3(hash_uint3(X0, Y1, Z1), fx, fy - 1.0, fz - 1.0),
                _grad3(hash_uint3(X1, Y1, Z1), fx - 1.0, fy - 1.0, fz - 1.0),
                _fade(fx), _fade(fy), _fade(fz))


@inline
def _perlin_4d_slab(X, Y, Z, Wc, fx, fy, fz, fw, u, v, t):
    """The trilinear blend of the eight 4D gradients of the lattice slab at ``w = Wc``."""
    X0, X1, Y0, Y1, Z0, Z1 = X & _M, (X + 1) & _M, Y & _M, (Y + 1) & _M, Z & _M, (Z + 1) & _M
    W0 = Wc & _M
    return _tri(_grad4(hash_uint4(X0, Y0, Z0, W0), fx, fy, fz, fw),
                _grad4(hash_uint4(X1, Y0, Z0, W0), fx - 1.0, fy, fz, fw),
                _grad4(hash_uint4(X0, Y1, Z0, W0), fx, fy - 1.0, fz, fw),
                _grad4(hash_uint4(X1, Y1, Z0, W0), fx - 1.0, fy - 1.0, fz, fw),
                _grad4(hash_uint4(X0, Y0, Z1, W0), fx, fy, fz - 1.0, fw),
                _grad4(hash_uint4(X1, Y0, Z1, W0), fx - 1.0, fy, fz - 1.0, fw),
                _grad4(hash_uint4(X0, Y1, Z1, W0), fx, fy - 1.0, fz - 1.0, fw),
                _grad4(hash_uint4(X1, Y1, Z1, W0), fx - 1.0, fy - 1.0, fz - 1.0, fw),
                u, v, t)


@inline
def _perlin_4d(x, y, z, w):
    flx, fly, flz, flw = np.floor(x), np.floor(y), np.floor(z), np.floor(w)
    X, Y, Z, W = np.int64(flx), np.int64(fly), np.int64(flz), np.int64(flw)
    fx, fy, fz, fw = x - flx, y - fly, z - flz, w - flw
    u, v, t = _fade(fx), _fade(fy), _fade(fz)
    a = _perlin_4d_slab(X, Y, Z, W, fx, fy, fz, fw, u, v, t)
    b = _perlin_4d_slab(X, Y, Z, W + 1, fx, fy, fz, fw - 1.0, u, v, t)
    return _lerp(a, b, _fade(fw))


@inline
def _wrap(p):
    """Cycles' repeat of the noise every 100000 on each axis, with its half-cell shift of
    coordinates of magnitude 1e6 and above (single precision)."""
    p = _f32(p)
    corr = 0.5 if abs(p) >= 1000000.0 else 0.0
    return _f32(np.fmod(p, 100000.0) + corr)


@function
def perlin_signed(p0, p1, p2, p3, dims):
    """Cycles' signed Perlin noise ``snoise_{1,2,3,4}d``, about [-1, 1].

    ``p0 .. p3``: the point's components (the first ``dims`` are used; a 1D point is
    ``p0``); ``dims``: 1 to 4. Includes the wrap every 100000 and Cycles' output scales
    (0.25, 0.6616, 0.9820, 0.8344)."""
    if dims == 1:
        return 0.25 * _perlin_1d(_wrap(p0))
    if dims == 2:
        return 0.6616 * _perlin_2d(_wrap(p0), _wrap(p1))
    if dims == 3:
        return 0.9820 * _perlin_3d(_wrap(p0), _wrap(p1), _wrap(p2))
    return 0.8344 * _perlin_4d(_wrap(p0), _wrap(p1), _wrap(p2), _wrap(p3))


# ---------------------------------------------------------------- fractal noise


@inline
def _fbm(p0, p1, p2, p3, dims, detail, roughness, lacunarity, normalize):
    fscale = 1.0
    amp = 1.0
    maxamp = 0.0
    total = 0.0
    for _ in range(int(detail) + 1):
        t = perlin_signed(_f32(fscale * p0), _f32(fscale * p1), _f32(fscale * p2), _f32(fscale * p3), dims)
        total += t * amp
        maxamp += amp
        amp = _f32(amp * roughness)
        fscale = _f32(fscale * lacunarity)
    rmd = detail - math.floor(detail)
    if rmd != 0.0:
        t = perlin_signed(_f32(fscale * p0), _f32(fscale * p1), _f32(fscale * p2), _f32(fscale * p3), dims)
        total2 = total + t * amp
        if normalize:
            return _lerp(0.5 * total / maxamp + 0.5, 0.5 * total2 / (maxamp + amp) + 0.5, rmd)
        return _lerp(total, total2, rmd)
    if normalize:
        return 0.5 * total / maxamp + 0.5
    return total


@inline
def _multi_fractal(p0, p1, p2, p3, dims, detail, roughness, lacunarity):
    value = 1.0
    pwr = 1.0
    for _ in range(int(detail) + 1):
        value *= pwr * perlin_signed(p0, p1, p2, p3, dims) + 1.0
        pwr = _f32(pwr * roughness)
        p0, p1, p2, p3 = _f32(p0 * lacunarity), _f32(p1 * lacunarity), _f32(p2 * lacunarity), _f32(p3 * lacunarity)
    rmd = detail - math.floor(detail)
    if rmd != 0.0:
        value *= rmd * pwr * perlin_signed(p0, p1, p2, p3, dims) + 1.0
    return value


@inline
def _hetero_terrain(p0, p1, p2, p3, dims, detail, roughness, lacunarity, offset):
    pwr = roughness
    value = offset + perlin_signed(p0, p1, p2, p3, dims)
    p0, p1, p2, p3 = _f32(p0 * lacunarity), _f32(p1 * lacunarity), _f32(p2 * lacunarity), _f32(p3 * lacunarity)
    for _ in range(1, int(detail) + 1):
        value += (perlin_signed(p0, p1, p2, p3, dims) + offset) * pwr * value
        pwr = _f32(pwr * roughness)
        p0, p1, p2, p3 = _f32(p0 * lacunarity), _f32(p1 * lacunarity), _f32(p2 * lacunarity), _f32(p3 * lacunarity)
    rmd = detail - math.floor(detail)
    if rmd != 0.0:
        value += rmd * ((perlin_signed(p0, p1, p2, p3, dims) + offset) * pwr * value)
    return value


@inline
def _hybrid_multi_fractal(p0, p1, p2, p3, dims, detail, roughness, lacunarity, offset, gain):
    pwr = 1.0
    value = 0.0
    weight = 1.0
    n = int(detail)
    i = 0
    while weight > 0.001 and i <= n:
        weight = min(weight, 1.0)
        signal = (perlin_signed(p0, p1, p2, p3, dims) + offset) * pwr
        pwr = _f32(pwr * roughness)
        value += weight * signal
        weight *= gain * signal
        p0, p1, p2, p3 = _f32(p0 * lacunarity), _f32(p1 * lacunarity), _f32(p2 * lacunarity), _f32(p3 * lacunarity)
        i += 1
    rmd = detail - math.floor(detail)
    if rmd != 0.0 and weight > 0.001:
        weight = min(weight, 1.0)
        value += rmd * weight * ((perlin_signed(p0, p1, p2, p3, dims) + offset) * pwr)
    return value


@inline
def _ridged_multi_fractal(p0, p1, p2, p3, dims, detail, roughness, lacunarity, offset, gain):
    pwr = roughness
    signal = offset - abs(perlin_signed(p0, p1, p2, p3, dims))
    signal *= signal
    value = signal
    for _ in range(1, int(detail) + 1):
        p0, p1, p2, p3 = _f32(p0 * lacunarity), _f32(p1 * lacunarity), _f32(p2 * lacunarity), _f32(p3 * lacunarity)
        weight = min(max(signal * gain, 0.0), 1.0)
        signal = offset - abs(perlin_signed(p0, p1, p2, p3, dims))
        signal *= signal
        signal *= weight
        value += signal * pwr
        pwr = _f32(pwr * roughness)
    return value


@function
def _noise_select(p0, p1, p2, p3, dims, noise_type, detail, roughness, lacunarity, offset, gain, normalize):
    if noise_type == NOISE_MULTIFRACTAL:
        return _multi_fractal(p0, p1, p2, p3, dims, detail, roughness, lacunarity)
    if noise_type == NOISE_FBM:
        return _fbm(p0, p1, p2, p3, dims, detail, roughness, lacunarity, normalize)
    if noise_type == NOISE_HYBRID_MULTIFRACTAL:
        return _hybrid_multi_fractal(p0, p1, p2, p3, dims, detail, roughness, lacunarity, offset, gain)
    if noise_type == NOISE_RIDGED_MULTIFRACTAL:
        return _ridged_multi_fractal(p0, p1, p2, p3, dims, detail, roughness, lacunarity, offset, gain)
    if noise_type == NOISE_HETERO_TERRAIN:
        return _hetero_terrain(p0, p1, p2, p3, dims, detail, roughness, lacunarity, offset)
    return 0.0


@inline
def _seed_offset(seed, k, dims):
    """Component ``k`` of Cycles' ``random_float{,2,3,4}_offset(seed)``: in [100, 200]."""
    if dims == 1:
        h = hash_float_to_float(seed)
    else:
        h = hash_float2_to_float(seed, float(k))
    return _f32(100.0 + _f32(h * 100.0))


@inline
def _offset_point(p0, p1, p2, p3, dims, seed):
    """The point moved by the seed offset (single precision), unused components kept."""
    return (_f32(p0 + _seed_offset(seed, 0, dims)),
            _f32(p1 + _seed_offset(seed, 1, dims)) if dims > 1 else p1,
            _f32(p2 + _seed_offset(seed, 2, dims)) if dims > 2 else p2,
            _f32(p3 + _seed_offset(seed, 3, dims)) if dims > 3 else p3)


@inline
def _scaled_point(x, y, z, w, dims, scale):
    """The node's point times Scale in single precision, as the components ``p0 .. p3`` the
    lattice functions take: ``(w)`` in 1D, ``(x, y)``, ``(x, y, z)``, ``(x, y, z, w)``, padded with 0."""
    if dims == 1:
        return _f32(w * scale), 0.0, 0.0, 0.0
    if dims == 2:
        return _f32(x * scale), _f32(y * scale), 0.0, 0.0
    if dims == 3:
        return _f32(x * scale), _f32(y * scale), _f32(z * scale), 0.0
    return _f32(x * scale), _f32(y * scale), _f32(z * scale), _f32(w * scale)


@inline
def noise_texture(x, y, z, w, dims, noise_type, scale, detail, roughness, lacunarity, offset, gain,
                  distortion, normalize, want_color):
    """Blender's Noise Texture node (Blender 4+), as Cycles' ``svm_node_tex_noise``.

    ``x, y, z``: the Vector input; ``w``: the W input (used by 1D and 4D);
    ``dims``: 1 to 4 (``DIMENSIONS``); ``noise_type``: a ``NOISE_TYPES`` tag;
    ``scale``: Scale (multiplies the vector and W); ``detail``: Detail (clamped to
    [0, 15]); ``roughness``: Roughness (clamped at 0 below); ``lacunarity``: Lacunarity;
    ``offset``, ``gain``: Offset and Gain (hybrid, ridged and hetero terrain);
    ``distortion``: Distortion; ``normalize``: the Normalize option (fBM only; 0 or 1);
    ``want_color``: compute the Color output (two more fractal evaluations), else it is 0.

    Returns ``(fac, r, g, b)``: the Fac output and the Color output."""
    detail = min(max(detail, 0.0), 15.0)
    roughness = max(roughness, 0.0)
    p0, p1, p2, p3 = _scaled_point(x, y, z, w, dims, scale)
    if distortion != 0.0:
        d0, d1, d2, d3 = 0.0, 0.0, 0.0, 0.0
        q0, q1, q2, q3 = _offset_point(p0, p1, p2, p3, dims, 0.0)
        d0 = perlin_signed(q0, q1, q2, q3, dims) * distortion
        if dims > 1:
            q0, q1, q2, q3 = _offset_point(p0, p1, p2, p3, dims, 1.0)
            d1 = perlin_signed(q0, q1, q2, q3, dims) * distortion
        if dims > 2:
            q0, q1, q2, q3 = _offset_point(p0, p1, p2, p3, dims, 2.0)
            d2 = perlin_signed(q0, q1, q2, q3, dims) * distortion
        if dims > 3:
            q0, q1, q2, q3 = _offset_point(p0, p1, p2, p3, dims, 3.0)
            d3 = perlin_signed(q0, q1, q2, q3, dims) * distortion
        p0, p1, p2, p3 = _f32(p0 + d0), _f32(p1 + d1), _f32(p2 + d2), _f32(p3 + d3)
    fac = _noise_select(p0, p1, p2, p3, dims, noise_type, detail, roughness, lacunarity, offset, gain,
                        normalize)
    if not want_color:
        return fac, 0.0, 0.0, 0.0
    q0, q1, q2, q3 = _offset_point(p0, p1, p2, p3, dims, float(dims))
    g = _noise_select(q0, q1, q2, q3, dims, noise_type, detail, roughness, lacunarity, offset, gain, normalize)
    q0, q1, q2, q3 = _offset_point(p0, p1, p2, p3, dims, float(dims + 1))
    b = _noise_select(q0, q1, q2, q3, dims, noise_type, detail, roughness, lacunarity, offset, gain, normalize)
    return fac, fac, g, b


# ---------------------------------------------------------------- Voronoi


@inline
def _metric(d0, d1, d2, d3, dims, metric, exponent):
    """Cycles' ``voronoi_distance`` of a difference vector (a 1D one is always ``|d|``)."""
    a0, a1, a2, a3 = abs(d0), abs(d1), abs(d2), abs(d3)
    if dims == 1:
        return a0
    if metric == VORONOI_EUCLIDEAN:
        return math.sqrt(d0 * d0 + d1 * d1 + d2 * d2 + d3 * d3)
    if metric == VORONOI_MANHATTAN:
        return a0 + a1 + a2 + a3
    if metric == VORONOI_CHEBYCHEV:
        return max(max(a0, a1), max(a2, a3))
    if metric == VORONOI_MINKOWSKI:
        s = a0 ** exponent + a1 ** exponent
        if dims > 2:
            s += a2 ** exponent
        if dims > 3:
            s += a3 ** exponent
        return s ** (1.0 / exponent)
    return 0.0


@inline
def _smoothstep(t):
    if t < 0.0:
        return 0.0
    if t >= 1.0:
        return 1.0
    return (3.0 - 2.0 * t) * t * t


@inline
def _cell(p0, p1, p2, p3):
    c0, c1, c2, c3 = np.floor(p0), np.floor(p1), np.floor(p2), np.floor(p3)
    return c0, c1, c2, c3, p0 - c0, p1 - c1, p2 - c2, p3 - c3


@function
def _voronoi_f(p0, p1, p2, p3, dims, metric, exponent, randomness, second):
    """One octave of F1 (``second`` false) or F2: (distance, r, g, b, position 0..3)."""
    c0, c1, c2, c3, l0, l1, l2, l3 = _cell(p0, p1, p2, p3)
    r1 = 1 if dims > 1 else 0
    r2 = 1 if dims > 2 else 0
    r3 = 1 if dims > 3 else 0
    d1, d2 = _FLT_MAX, _FLT_MAX
    o1 = (0.0, 0.0, 0.0, 0.0)
    o2 = o1
    q1 = o1
    q2 = o1
    for u in range(-r3, r3 + 1):
        for k in range(-r2, r2 + 1):
            for j in range(-r1, r1 + 1):
                for i in range(-1, 2):
                    h0, h1, h2, h3 = hash_int_to_point(c0 + i, c1 + j, c2 + k, c3 + u, dims)
                    q = (i + h0 * randomness, j + h1 * randomness, k + h2 * randomness, u + h3 * randomness)
                    d = _metric(q[0] - l0, q[1] - l1, q[2] - l2, q[3] - l3, dims, metric, exponent)
                    off = (float(i), float(j), float(k), float(u))
                    if d < d1:
                        d2, o2, q2 = d1, o1, q1
                        d1, o1, q1 = d, off, q
                    elif d < d2:
                        d2, o2, q2 = d, off, q
    if second:
        d1, o1, q1 = d2, o2, q2
    r, g, b = hash_int_to_color(c0 + o1[0], c1 + o1[1], c2 + o1[2], c3 + o1[3], dims)
    return d1, r, g, b, q1[0] + c0, q1[1] + c1, q1[2] + c2, q1[3] + c3


@function
def _voronoi_smooth_f1(p0, p1, p2, p3, dims, metric, exponent, randomness, smoothness):
    """One octave of Smooth F1: (distance, r, g, b, position 0..3)."""
    c0, c1, c2, c3, l0, l1, l2, l3 = _cell(p0, p1, p2, p3)
    r1 = 2 if dims > 1 else 0
    r2 = 2 if dims > 2 else 0
    r3 = 2 if dims > 3 else 0
    sd, sr, sg, sb = 0.0, 0.0, 0.0, 0.0
    s0, s1, s2, s3 = 0.0, 0.0, 0.0, 0.0
    h = -1.0
    for u in range(-r3, r3 + 1):
        for k in range(-r2, r2 + 1):
            for j in range(-r1, r1 + 1):
                for i in range(-2, 3):
                    h0, h1, h2, h3 = hash_int_to_point(c0 + i, c1 + j, c2 + k, c3 + u, dims)
                    q0, q1, q2, q3 = i + h0 * randomness, j + h1 * randomness, k + h2 * randomness, \
                        u + h3 * randomness
                    d = _metric(q0 - l0, q1 - l1, q2 - l2, q3 - l3, dims, metric, exponent)
                    h = 1.0 if h == -1.0 else _smoothstep(0.5 + 0.5 * (sd - d) / smoothness)
                    corr = smoothness * h * (1.0 - h)
                    sd = _lerp(sd, d, h) - corr
                    corr /= 1.0 + 3.0 * smoothness
                    cr, cg, cb = hash_int_to_color(c0 + i, c1 + j, c2 + k, c3 + u, dims)
                    sr, sg, sb = _lerp(sr, cr, h) - corr, _lerp(sg, cg, h) - corr, _lerp(sb, cb, h) - corr
                    s0, s1 = _lerp(s0, q0, h) - corr, _lerp(s1, q1, h) - corr
                    s2, s3 = _lerp(s2, q2, h) - corr, _lerp(s3, q3, h) - corr
    return sd, sr, sg, sb, c0 + s0, c1 + s1, c2 + s2, c3 + s3


@function
def _voronoi_edge(p0, p1, p2, p3, dims, randomness):
    """One octave of Distance to Edge."""
    c0, c1, c2, c3, l0, l1, l2, l3 = _cell(p0, p1, p2, p3)
    if dims == 1:
        mid = hash_float_to_float(c0) * randomness
        left = -1.0 + hash_float_to_float(c0 - 1.0) * randomness
        right = 1.0 + hash_float_to_float(c0 + 1.0) * randomness
        return min(abs((mid + left) / 2.0 - l0), abs((mid + right) / 2.0 - l0))
    r2 = 1 if dims > 2 else 0
    r3 = 1 if dims > 3 else 0
    best = _FLT_MAX
    v0, v1, v2, v3 = 0.0, 0.0, 0.0, 0.0
    for u in range(-r3, r3 + 1):
        for k in range(-r2, r2 + 1):
            for j in range(-1, 2):
                for i in range(-1, 2):
                    h0, h1, h2, h3 = hash_int_to_point(c0 + i, c1 + j, c2 + k, c3 + u, dims)
                    t0, t1 = i + h0 * randomness - l0, j + h1 * randomness - l1
                    t2, t3 = k + h2 * randomness - l2, u + h3 * randomness - l3
                    d = t0 * t0 + t1 * t1 + t2 * t2 + t3 * t3
                    if d < best:
                        best = d
                        v0, v1, v2, v3 = t0, t1, t2, t3
    best = _FLT_MAX
    for u in range(-r3, r3 + 1):
        for k in range(-r2, r2 + 1):
            for j in range(-1, 2):
                for i in range(-1, 2):
                    h0, h1, h2, h3 = hash_int_to_point(c0 + i, c1 + j, c2 + k, c3 + u, dims)
                    t0, t1 = i + h0 * randomness - l0, j + h1 * randomness - l1
                    t2, t3 = k + h2 * randomness - l2, u + h3 * randomness - l3
                    e0, e1, e2, e3 = t0 - v0, t1 - v1, t2 - v2, t3 - v3
                    ee = e0 * e0 + e1 * e1 + e2 * e2 + e3 * e3
                    if ee > 0.0001:
                        inv = 1.0 / math.sqrt(ee)
                        de = ((v0 + t0) * e0 + (v1 + t1) * e1 + (v2 + t2) * e2 + (v3 + t3) * e3) * 0.5 * inv
                        best = min(best, de)
    return best


@function
def _voronoi_radius(p0, p1, p2, p3, dims, randomness):
    """N-Sphere Radius: half the distance from the closest point to its closest neighbour."""
    c0, c1, c2, c3, l0, l1, l2, l3 = _cell(p0, p1, p2, p3)
    r1 = 1 if dims > 1 else 0
    r2 = 1 if dims > 2 else 0
    r3 = 1 if dims > 3 else 0
    best = _FLT_MAX
    q = (0.0, 0.0, 0.0, 0.0)
    o = q
    for u in range(-r3, r3 + 1):
        for k in range(-r2, r2 + 1):
            for j in range(-r1, r1 + 1):
                for i in range(-1, 2):
                    h0, h1, h2, h3 = hash_int_to_point(c0 + i, c1 + j, c2 + k, c3 + u, dims)
                    t = (i + h0 * randomness, j + h1 * randomness, k + h2 * randomness, u + h3 * randomness)
                    d = _metric(t[0] - l0, t[1] - l1, t[2] - l2, t[3] - l3, dims, VORONOI_EUCLIDEAN, 1.0)
                    if d < best:
                        best, q, o = d, t, (float(i), float(j), float(k), float(u))
    best = _FLT_MAX
    n = q
    for u in range(-r3, r3 + 1):
        for k in range(-r2, r2 + 1):
            for j in range(-r1, r1 + 1):
                for i in range(-1, 2):
                    if i == 0 and j == 0 and k == 0 and u == 0:
                        continue
                    f0, f1, f2, f3 = i + o[0], j + o[1], k + o[2], u + o[3]
                    h0, h1, h2, h3 = hash_int_to_point(c0 + f0, c1 + f1, c2 + f2, c3 + f3, dims)
                    t = (f0 + h0 * randomness, f1 + h1 * randomness, f2 + h2 * randomness, f3 + h3 * randomness)
                    d = _metric(q[0] - t[0], q[1] - t[1], q[2] - t[2], q[3] - t[3], dims, VORONOI_EUCLIDEAN, 1.0)
                    if d < best:
                        best, n = d, t
    return _metric(n[0] - q[0], n[1] - q[1], n[2] - q[2], n[3] - q[3], dims, VORONOI_EUCLIDEAN, 1.0) / 2.0


@inline
def _voronoi_octave(p0, p1, p2, p3, dims, feature, metric, exponent, randomness, smoothness):
    if feature == VORONOI_F2:
        return _voronoi_f(p0, p1, p2, p3, dims, metric, exponent, randomness, True)
    if feature == VORONOI_SMOOTH_F1 and smoothness != 0.0:
        return _voronoi_smooth_f1(p0, p1, p2, p3, dims, metric, exponent, randomness, smoothness)
    return _voronoi_f(p0, p1, p2, p3, dims, metric, exponent, randomness, False)


@inline
def _fractal_voronoi(p0, p1, p2, p3, dims, feature, metric, exponent, randomness, smoothness,
                     detail, roughness, lacunarity):
    """Blender 4's fractal Voronoi (F1, F2, Smooth F1): (distance, r, g, b, position 0..3,
    the summed amplitude)."""
    amp = 1.0
    max_amp = 0.0
    scale = 1.0
    dist, cr, cg, cb = 0.0, 0.0, 0.0, 0.0
    s0, s1, s2, s3 = 0.0, 0.0, 0.0, 0.0
    zero_input = detail == 0.0 or roughness == 0.0
    for i in range(int(math.ceil(detail)) + 1):
        od, orr, og, ob, q0, q1, q2, q3 = _voronoi_octave(
            _f32(p0 * scale), _f32(p1 * scale), _f32(p2 * scale), _f32(p3 * scale), dims, feature, metric,
            exponent, randomness, smoothness)
        if zero_input:
            return od, orr, og, ob, q0, q1, q2, q3, 1.0
        if i <= detail:
            max_amp += amp
            dist += od * amp
            cr, cg, cb = cr + orr * amp, cg + og * amp, cb + ob * amp
            s0, s1 = _lerp(s0, q0 / scale, amp), _lerp(s1, q1 / scale, amp)
            s2, s3 = _lerp(s2, q2 / scale, amp), _lerp(s3, q3 / scale, amp)
            scale = _f32(scale * lacunarity)
            amp = _f32(amp * roughness)
        else:
            rem = detail - math.floor(detail)
            if rem != 0.0:
                max_amp = _lerp(max_amp, max_amp + amp, rem)
                dist = _lerp(dist, dist + od * amp, rem)
                cr, cg, cb = _lerp(cr, cr + orr * amp, rem), _lerp(cg, cg + og * amp, rem), \
                    _lerp(cb, cb + ob * amp, rem)
                s0 = _lerp(s0, _lerp(s0, q0 / scale, amp), rem)
                s1 = _lerp(s1, _lerp(s1, q1 / scale, amp), rem)
                s2 = _lerp(s2, _lerp(s2, q2 / scale, amp), rem)
                s3 = _lerp(s3, _lerp(s3, q3 / scale, amp), rem)
    return dist, cr, cg, cb, s0, s1, s2, s3, max_amp


@inline
def _fractal_voronoi_edge(p0, p1, p2, p3, dims, randomness, detail, roughness, lacunarity, normalize):
    amp = 1.0
    max_distance = 0.5 + 0.5 * randomness
    max_amp = max_distance
    scale = 1.0
    dist = 8.0
    zero_input = detail == 0.0 or roughness == 0.0
    for i in range(int(math.ceil(detail)) + 1):
        od = _voronoi_edge(_f32(p0 * scale), _f32(p1 * scale), _f32(p2 * scale), _f32(p3 * scale), dims,
                           randomness)
        if zero_input:
            dist = od
            break
        if i <= detail:
            max_amp = _lerp(max_amp, max_distance / scale, amp)
            dist = _lerp(dist, min(dist, od / scale), amp)
            scale = _f32(scale * lacunarity)
            amp = _f32(amp * roughness)
        else:
            rem = detail - math.floor(detail)
            if rem != 0.0:
                max_amp = _lerp(max_amp, _lerp(max_amp, max_distance / scale, amp), rem)
                dist = _lerp(dist, min(dist, _lerp(dist, min(dist, od / scale), amp)), rem)
    if normalize:
        dist /= max_amp
    return dist


@inline
def voronoi_texture(x, y, z, w, dims, feature, metric, scale, detail, roughness, lacunarity, smoothness,
                    exponent, randomness, normalize):
    """Blender's Voronoi Texture node (Blender 4+), as Cycles' ``svm_node_tex_voronoi``.

    ``x, y, z``: the Vector input; ``w``: the W input (1D and 4D); ``dims``: 1 to 4;
    ``feature``: a ``VORONOI_FEATURES`` tag; ``metric``: a ``VORONOI_METRICS`` tag (2D to 4D;
    1D distances are absolute differences; N-Sphere Radius is always Euclidean);
    ``scale``: Scale; ``detail``: Detail (clamped to [0, 15]); ``roughness``: Roughness
    (clamped to [0, 1]); ``lacunarity``: Lacunarity; ``smoothness``: Smoothness (Smooth F1;
    halved and clamped to [0, 0.5] as Cycles does); ``exponent``: Exponent (Minkowski);
    ``randomness``: Randomness (clamped to [0, 1]); ``normalize``: the Normalize option (0 or 1).

    Returns ``(distance, r, g, b, px, py, pz, w_out, radius)``: the Distance, Color,
    Position, W and Radius outputs (those a feature does not produce are 0)."""
    detail = min(max(detail, 0.0), 15.0)
    roughness = min(max(roughness, 0.0), 1.0)
    randomness = min(max(randomness, 0.0), 1.0)
    smoothness = min(max(smoothness / 2.0, 0.0), 0.5)
    p0, p1, p2, p3 = _scaled_point(x, y, z, w, dims, scale)
    if feature == VORONOI_DISTANCE_TO_EDGE:
        d = _fractal_voronoi_edge(p0, p1, p2, p3, dims, randomness, detail, roughness, lacunarity, normalize)
        return d, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    if feature == VORONOI_N_SPHERE_RADIUS:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, _voronoi_radius(p0, p1, p2, p3, dims, randomness)
    d, r, g, b, s0, s1, s2, s3, max_amp = _fractal_voronoi(
        p0, p1, p2, p3, dims, feature, metric, exponent, randomness, smoothness, detail, roughness, lacunarity)
    if normalize:
        hm = 0.5 + 0.5 * randomness
        max_distance = _metric(hm, hm if dims > 1 else 0.0, hm if dims > 2 else 0.0, hm if dims > 3 else 0.0,
                               dims, metric, exponent)
        if feature == VORONOI_F2:
            max_distance *= 2.0
        d /= max_amp * max_distance
        r, g, b = r / max_amp, g / max_amp, b / max_amp
    inv = 1.0 / scale if scale != 0.0 else 0.0
    if dims == 1:
        return d, r, g, b, 0.0, 0.0, 0.0, s0 * inv, 0.0
    return d, r, g, b, s0 * inv, s1 * inv, s2 * inv, s3 * inv if dims == 4 else 0.0, 0.0


# ---------------------------------------------------------------- the other textures


@inline
def wave_texture(x, y, z, wave_type, bands_direction, rings_direction, profile, scale, distortion, detail,
                 detail_scale, detail_roughness, phase):
    """Blender's Wave Texture node, as Cycles' ``svm_node_tex_wave``.

    ``x, y, z``: the Vector input; ``wave_type``: a ``WAVE_TYPES`` tag;
    ``bands_direction``: a ``WAVE_BANDS_DIRECTIONS`` tag (bands); ``rings_direction``: a
    ``WAVE_RINGS_DIRECTIONS`` tag (rings); ``profile``: a ``WAVE_PROFILES`` tag;
    ``scale``, ``distortion``, ``detail``, ``detail_scale``, ``detail_roughness``, ``phase``:
    the sockets Scale, Distortion, Detail, Detail Scale, Detail Roughness, Phase Offset.

    Returns the Fac output (the Color output is Fac in all three channels)."""
    p0 = _f32(_f32(_f32(x * scale) + _EPS_F) * _SHRINK_F)
    p1 = _f32(_f32(_f32(y * scale) + _EPS_F) * _SHRINK_F)
    p2 = _f32(_f32(_f32(z * scale) + _EPS_F) * _SHRINK_F)
    if wave_type == 0:
        if bands_direction == 0:
            n = p0 * 20.0
        elif bands_direction == 1:
            n = p1 * 20.0
        elif bands_direction == 2:
            n = p2 * 20.0
        else:
            n = (p0 + p1 + p2) * 10.0
    else:
        r0 = 0.0 if rings_direction == 0 else p0
        r1 = 0.0 if rings_direction == 1 else p1
        r2 = 0.0 if rings_direction == 2 else p2
        n = math.sqrt(r0 * r0 + r1 * r1 + r2 * r2) * 20.0
    n += phase
    if distortion != 0.0:
        f = _fbm(_f32(p0 * detail_scale), _f32(p1 * detail_scale), _f32(p2 * detail_scale), 0.0, 3, detail,
                 detail_roughness, 2.0, True)
        n += distortion * (f * 2.0 - 1.0)
    if profile == 0:
        return 0.5 + 0.5 * math.sin(n - _HALF_PI_F)
    n /= _TWO_PI_F
    if profile == 1:
        return n - math.floor(n)
    return abs(n - math.floor(n + 0.5)) * 2.0


@inline
def magic_texture(x, y, z, depth, scale, distortion):
    """Blender's Magic Texture node, as Cycles' ``svm_node_tex_magic``.

    ``x, y, z``: the Vector input; ``depth``: the Depth property (0 to 10); ``scale``,
    ``distortion``: the Scale and Distortion sockets.

    Returns ``(r, g, b, fac)``: the Color output and Fac (the mean of the colour)."""
    px = np.fmod(_f32(x), _TWO_PI_F)
    py = np.fmod(_f32(y), _TWO_PI_F)
    pz = np.fmod(_f32(z), _TWO_PI_F)
    a = math.sin((px + py + pz) * 5.0 * scale)
    b = math.cos((-px + py - pz) * 5.0 * scale)
    c = -math.cos((-px - py + pz) * 5.0 * scale)
    if depth > 0:
        a, b, c = a * distortion, b * distortion, c * distortion
        b = -math.cos(a - b + c) * distortion
        if depth > 1:
            a = math.cos(a - b - c) * distortion
            if depth > 2:
                c = math.sin(-a - b - c) * distortion
                if depth > 3:
                    a = -math.cos(-a + b - c) * distortion
                    if depth > 4:
                        b = -math.sin(-a + b + c) * distortion
                        if depth > 5:
                            b = -math.cos(-a + b + c) * distortion
                            if depth > 6:
                                a = math.cos(a + b + c) * distortion
                                if depth > 7:
                                    c = math.sin(a + b - c) * distortion
                                    if depth > 8:
                                        a = -math.cos(-a - b + c) * distortion
                                        if depth > 9:
                                            b = -math.sin(a - b + c) * distortion
    if distortion != 0.0:
        d2 = distortion * 2.0
        a, b, c = a / d2, b / d2, c / d2
    r, g, bl = 0.5 - a, 0.5 - b, 0.5 - c
    return r, g, bl, (r + g + bl) / 3.0


@inline
def checker_texture(x, y, z, scale, r1, g1, b1, r2, g2, b2):
    """Blender's Checker Texture node, as Cycles' ``svm_node_tex_checker``.

    ``x, y, z``: the Vector input; ``scale``: Scale; ``r1, g1, b1`` and ``r2, g2, b2``:
    Color1 and Color2.

    Returns ``(r, g, b, fac)``: Color1 where Fac is 1, else Color2."""
    xi = abs(np.int64(np.floor(_f32(_f32(_f32(x * scale) + _EPS_F) * _SHRINK_F))))
    yi = abs(np.int64(np.floor(_f32(_f32(_f32(y * scale) + _EPS_F) * _SHRINK_F))))
    zi = abs(np.int64(np.floor(_f32(_f32(_f32(z * scale) + _EPS_F) * _SHRINK_F))))
    if ((xi % 2) == (yi % 2)) == (zi % 2 == 1):
        return float(r1), float(g1), float(b1), 1.0
    return float(r2), float(g2), float(b2), 0.0


@inline
def _brick_noise(n):
    """Cycles' fast integer noise of the brick texture, in [0, 1)."""
    n = (n + 1013) & 0x7FFFFFFF
    n = ((n >> 13) ^ n) & _M
    t = (((((n * n) & _M) * 60493) & _M) + 19990303) & _M
    nn = (((n * t) & _M) + 1376312589) & 0x7FFFFFFF
    return 0.5 * (np.float64(np.float32(nn)) / 1073741824.0)


@inline
def brick_texture(x, y, z, scale, mortar_size, mortar_smooth, bias, brick_width, row_height, offset_amount,
                  offset_frequency, squash_amount, squash_frequency):
    """Blender's Brick Texture node's pattern, as Cycles' ``svm_brick``.

    ``x, y, z``: the Vector input; ``scale``, ``mortar_size``, ``mortar_smooth``, ``bias``,
    ``brick_width``, ``row_height``: the sockets Scale, Mortar Size, Mortar Smooth, Bias,
    Brick Width, Row Height; ``offset_amount``, ``offset_frequency``, ``squash_amount``,
    ``squash_frequency``: the properties Offset, Offset Frequency (int), Squash, Squash
    Frequency (int).

    Returns ``(tint, fac)``: the brick's tint (the blend of Color1 to Color2) and the Fac
    output (1 in the mortar); ``brick_color`` makes the Color output of them."""
    px = _f32(x * scale)
    py = _f32(y * scale)
    rownum = np.int64(np.floor(_f32(py / row_height)))
    offset = 0.0
    if offset_frequency != 0 and squash_frequency != 0:
        brick_width = brick_width if rownum % squash_frequency != 0 else _f32(brick_width * squash_amount)
        offset = 0.0 if rownum % offset_frequency != 0 else _f32(brick_width * offset_amount)
    bricknum = np.int64(np.floor(_f32(_f32(px + offset) / brick_width)))
    bx = _f32(px + offset) - brick_width * bricknum
    by = py - row_height * rownum
    tint = min(max(_brick_noise(((rownum << 16) + (bricknum & 0xFFFF)) & _M) + bias, 0.0), 1.0)
    min_dist = min(min(bx, by), min(brick_width - bx, row_height - by))
    if min_dist >= mortar_size:
        mortar = 0.0
    elif mortar_smooth == 0.0:
        mortar = 1.0
    else:
        mortar = _smoothstep((1.0 - min_dist / mortar_size) / mortar_smooth)
    return tint, mortar


@inline
def brick_color(tint, fac, r1, g1, b1, r2, g2, b2, rm, gm, bm):
    """The Brick Texture node's Color output from ``brick_texture``'s ``(tint, fac)`` and the
    sockets Color1 ``(r1, g1, b1)``, Color2 ``(r2, g2, b2)`` and Mortar ``(rm, gm, bm)``.

    Returns ``(r, g, b)``."""
    r, g, b = float(r1), float(g1), float(b1)
    if fac != 1.0:
        r, g, b = (1.0 - tint) * r + tint * r2, (1.0 - tint) * g + tint * g2, (1.0 - tint) * b + tint * b2
    return r * (1.0 - fac) + rm * fac, g * (1.0 - fac) + gm * fac, b * (1.0 - fac) + bm * fac


@inline
def gradient_texture(x, y, z, gradient_type):
    """Blender's Gradient Texture node, as Cycles' ``svm_node_tex_gradient``.

    ``x, y, z``: the Vector input; ``gradient_type``: a ``GRADIENT_TYPES`` tag.

    Returns the Fac output, clamped to [0, 1] (the Color output is Fac in all channels)."""
    if gradient_type == 0:
        f = x
    elif gradient_type == 1:
        r = max(x, 0.0)
        f = r * r
    elif gradient_type == 2:
        r = min(max(x, 0.0), 1.0)
        t = r * r
        f = 3.0 * t - 2.0 * t * r
    elif gradient_type == 3:
        f = (x + y) * 0.5
    elif gradient_type == 4:
        f = math.atan2(y, x) / _TWO_PI_F + 0.5
    else:
        r = max(0.999999 - math.sqrt(x * x + y * y + z * z), 0.0)
        f = r * r if gradient_type == 5 else r
    return min(max(f, 0.0), 1.0)


@inline
def white_noise_texture(x, y, z, w, dims):
    """Blender's White Noise Texture node, as Cycles' ``svm_node_tex_white_noise``: a hash of
    the input's single-precision bits.

    ``x, y, z``: the Vector input; ``w``: the W input (1D and 4D); ``dims``: 1 to 4.

    Returns ``(value, r, g, b)``: the Value output in [0, 1] and the Color output."""
    if dims == 1:
        return hash_float_to_float(w), hash_float_to_float(w), hash_float2_to_float(w, 1.0), \
            hash_float2_to_float(w, 2.0)
    if dims == 2:
        v = hash_float2_to_float(x, y)
        return v, v, hash_float3_to_float(x, y, 1.0), hash_float3_to_float(x, y, 2.0)
    if dims == 3:
        v = hash_float3_to_float(x, y, z)
        return v, v, hash_float4_to_float(x, y, z, 1.0), hash_float4_to_float(x, y, z, 2.0)
    v = hash_float4_to_float(x, y, z, w)
    return v, v, hash_float4_to_float(z, x, w, y), hash_float4_to_float(w, z, y, x)
