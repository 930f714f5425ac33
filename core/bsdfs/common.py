"""Small scalar helpers shared by the BSDF models (all ``@inline``).

Directions live in the local shading frame (z = shading normal), point away from the
surface and are unit vectors; ``wo`` points towards the viewer (camera paths).
"""
import math

from ..jit import inline

INV_PI = 1.0 / math.pi
INV_TWO_PI = 0.5 / math.pi


@inline
def clamp01(x):
    """x clamped to [0, 1]; NaN → 0."""
    if not (x > 0.0):
        return 0.0
    if x > 1.0:
        return 1.0
    return x


@inline
def bounded_pair(d, s, s_scale):
    """(ρd, ρs) clamped to [0, 1] and scaled down so that ρd + s_scale·ρs ≤ 1."""
    d = clamp01(d)
    s = clamp01(s)
    t = d + s_scale * s
    if t > 1.0:
        return d / t, s / t
    return d, s


@inline
def pow_pos(x, n):
    """max(x, 0)ⁿ with 0⁰ = 0 (a clipped cosine lobe; "negative values ... set to zero")."""
    if not (x > 0.0):
        return 0.0
    if n == 0.0:
        return 1.0
    return math.exp(n * math.log(x))


@inline
def reflect(wox, woy, woz, hx, hy, hz):
    """Mirror of wo about the unit vector h: 2(wo·h)h − wo (item 37)."""
    d = 2.0 * (wox * hx + woy * hy + woz * hz)
    return d * hx - wox, d * hy - woy, d * hz - woz


@inline
def all_equal(a):
    """True when every entry of the array equals the first (no dispersion)."""
    for i in range(1, a.shape[0]):
        if a[i] != a[0]:
            return False
    return True


@inline
def zero(out):
    for i in range(out.shape[0]):
        out[i] = 0.0
