"""Small scalar helpers shared by the BSDF models (all ``@inline``).

Directions live in the local shading frame (z = shading normal), point away from the
surface and are unit vectors; ``wo`` points towards the viewer (camera paths).
"""
import math

from ..jit import inline
from .params import BSDF_GLOSSY, BSDF_REFLECTION

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
def lobe_sums(ra, rb, s_scale, lobe, out_f, want_f):
    """(Σ_λ ρd, Σ_λ ρs) of ``bounded_pair`` over the wavelengths; with want_f also
    f = ρd/π + ρs·lobe per wavelength into out_f (the diffuse + glossy models)."""
    md = 0.0
    ms = 0.0
    for i in range(ra.shape[0]):
        d, s = bounded_pair(ra[i], rb[i], s_scale)
        md += d
        ms += s
        if want_f:
            out_f[i] = d * INV_PI + s * lobe
    return md, ms


@inline
def glossy_prob(ra, rb):
    """Probability of sampling the glossy lobe, Σ ρs / Σ (ρd + ρs) over the wavelengths
    (Blinn–Phong, Ward); -1 when both are black."""
    md, ms = lobe_sums(ra, rb, 1.0, 0.0, ra, False)
    tot = md + ms
    if not (tot > 0.0):
        return -1.0
    return ms / tot


@inline
def diffuse_glossy_pdf(md, ms, wiz, pdf_s):
    """Mixture pdf (md cos θi/π + ms pdf_s) / (md + ms) of a diffuse and a glossy lobe."""
    tot = md + ms
    if not (tot > 0.0):
        return 0.0
    return (md * wiz * INV_PI + ms * pdf_s) / tot


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
def half_vector(wox, woy, woz, wix, wiy, wiz):
    """(hx, hy, hz, ok): h = (wo + wi)/|wo + wi|; ok False (and h = 0) when wi = −wo."""
    hx = wox + wix
    hy = woy + wiy
    hz = woz + wiz
    hl = math.sqrt(hx * hx + hy * hy + hz * hz)
    if not (hl > 0.0):
        return hx, hy, hz, False
    return hx / hl, hy / hl, hz / hl, True


@inline
def reflect_glossy(wox, woy, woz, hx, hy, hz):
    """(x, y, z, flags) of the mirror of wo about a sampled normal h; flags 0 (a failed
    sample) below the horizon."""
    x, y, z = reflect(wox, woy, woz, hx, hy, hz)
    if not (z > 0.0):
        return 0.0, 0.0, 1.0, 0
    return x, y, z, BSDF_REFLECTION | BSDF_GLOSSY


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
