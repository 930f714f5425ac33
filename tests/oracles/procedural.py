"""Slow pure-Python oracles of ``core.shading.procedural``'s hashes and Perlin noise.

Written from the algorithms' own descriptions rather than from the kernel: Bob Jenkins'
lookup3 ``hashword`` for any number of 32-bit words (Cycles' ``hash_uint{,2,3,4}`` are
``hashword`` with ``initval`` 13), the float bits by ``struct``, PCG 2D/3D/4D of
Jarzynski and Olano (JCGT 9(3), 2020) on signed 32-bit integers as Cycles writes them,
and Perlin's improved noise as a sum over the lattice corners of each corner's gradient
dot product weighted by the product of the fade curves (the nested interpolations of the
kernel, expanded).
"""
import math
import struct

M = 0xFFFFFFFF


def _rot(x, k):
    return ((x << k) | (x >> (32 - k))) & M


def _mix(a, b, c):
    for s1, s2, s3 in ((4, 6, 8), (16, 19, 4)):
        a = ((a - c) & M) ^ _rot(c, s1)
        c = (c + b) & M
        b = ((b - a) & M) ^ _rot(a, s2)
        a = (a + c) & M
        c = ((c - b) & M) ^ _rot(b, s3)
        b = (b + a) & M
    return a, b, c


def _final(a, b, c):
    for x, y, k in (("c", "b", 14), ("a", "c", 11), ("b", "a", 25), ("c", "b", 16), ("a", "c", 4),
                    ("b", "a", 14), ("c", "b", 24)):
        v = {"a": a, "b": b, "c": c}
        v[x] = ((v[x] ^ v[y]) - _rot(v[y], k)) & M
        a, b, c = v["a"], v["b"], v["c"]
    return a, b, c


def hashword(words, initval):
    """lookup3's ``hashword``: the hash of a list of 32-bit words."""
    k = [w & M for w in words]
    a = b = c = (0xDEADBEEF + (len(k) << 2) + initval) & M
    while len(k) > 3:
        a, b, c = (a + k[0]) & M, (b + k[1]) & M, (c + k[2]) & M
        a, b, c = _mix(a, b, c)
        k = k[3:]
    if not k:
        return c
    if len(k) == 3:
        c = (c + k[2]) & M
    if len(k) >= 2:
        b = (b + k[1]) & M
    a = (a + k[0]) & M
    return _final(a, b, c)[2]


def float_bits(x):
    """The bits of ``x`` rounded to IEEE single precision."""
    return struct.unpack("<I", struct.pack("<f", x))[0]


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def hash_floats(*xs):
    """Cycles' ``hash_float{,2,3,4}_to_float``: the hash of the single-precision bits, rounded
    to single precision and scaled by 2**-32."""
    return f32(float(hashword([float_bits(x) for x in xs], 13))) * 2.0 ** -32


def _i32(v):
    v &= M
    return v - (1 << 32) if v >= 1 << 31 else v


def pcg(*v):
    """Cycles' ``hash_pcg{2,3,4}d_i`` of 2, 3 or 4 signed ints; each result in [0, 2**31)."""
    v = [_i32(x * 1664525 + 1013904223) for x in v]
    n = len(v)
    # the component each one is incremented by: 2D x += y*M, y += x*M; 3D/4D products of two others
    pairs = {3: ((1, 2), (2, 0), (0, 1)), 4: ((1, 3), (2, 0), (0, 1), (1, 2))}
    for rnd in range(2):
        if n == 2:
            v[0] = _i32(v[0] + v[1] * 1664525)
            v[1] = _i32(v[1] + v[0] * 1664525)
        else:
            for i, (p, q) in enumerate(pairs[n]):
                v[i] = _i32(v[i] + v[p] * v[q])
        if rnd == 0:
            v = [x ^ (x >> 16) for x in v]
    return [x & 0x7FFFFFFF for x in v]


def _gradient(h, f):
    """Cycles' gradient (grad1 .. grad4) of hash ``h`` dotted with the offset ``f``."""
    n = len(f)
    if n == 1:
        h &= 15
        g = 1.0 + (h & 7)
        return (-g if h & 8 else g) * f[0]
    if n == 2:
        h &= 7
        u, v = (f[0], 2.0 * f[1]) if h < 4 else (f[1], 2.0 * f[0])
        return (-u if h & 1 else u) + (-v if h & 2 else v)
    if n == 3:
        h &= 15
        u = f[0] if h < 8 else f[1]
        v = f[1] if h < 4 else (f[0] if h in (12, 14) else f[2])
        return (-u if h & 1 else u) + (-v if h & 2 else v)
    h &= 31
    u = f[0] if h < 24 else f[1]
    v = f[1] if h < 16 else f[2]
    s = f[2] if h < 8 else f[3]
    return (-u if h & 1 else u) + (-v if h & 2 else v) + (-s if h & 4 else s)


SCALES = {1: 0.25, 2: 0.6616, 3: 0.9820, 4: 0.8344}


def snoise(*p):
    """Cycles' signed Perlin noise ``snoise_{1..4}d`` of the point ``p``."""
    q = []
    for x in p:
        x = f32(x)
        corr = 0.5 if abs(x) >= 1e6 else 0.0
        q.append(f32(math.fmod(x, 100000.0) + corr))
    cells = [math.floor(x) for x in q]
    frac = [x - c for x, c in zip(q, cells)]
    fade = [t * t * t * (t * (t * 6.0 - 15.0) + 10.0) for t in frac]
    total = 0.0
    for corner in range(1 << len(q)):
        bits = [(corner >> k) & 1 for k in range(len(q))]
        weight = 1.0
        for b, u in zip(bits, fade):
            weight *= u if b else 1.0 - u
        h = hashword([c + b for c, b in zip(cells, bits)], 13)
        total += weight * _gradient(h, [f - b for f, b in zip(frac, bits)])
    return SCALES[len(q)] * total
