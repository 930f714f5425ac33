"""GGX (Trowbridge–Reitz) microfacet distribution, Smith masking and visible-normal sampling.

Anisotropic GGX with roughness (α_x, α_y) along the frame's x and y axes (Walter,
Marschner, Li, Torrance 2007, eq. 33, extended to two α as in Heitz 2014)::

    D(h) = 1 / (π α_x α_y ((h_x/α_x)² + (h_y/α_y)² + h_z²)²),   h_z > 0
    Λ(w) = (−1 + sqrt(1 + (α_x² w_x² + α_y² w_y²) / w_z²)) / 2
    G1(w) = 1 / (1 + Λ(w))

Masking–shadowing: Smith's *height-correlated* form G2(wo, wi) = 1/(1 + Λ(wo) + Λ(wi))
(Heitz 2014, "Understanding the masking-shadowing function", eq. 99), which is
exact for the Smith microsurface and a little larger than the separable G1·G1; it is
also what Cycles' and pbrt-v4's GGX use, so the Principled BSDF can be matched.
Back-facing microfacets (sign of w·h differing from the side of w) get zero.

Visible normals (Heitz 2018, "Sampling the GGX distribution of visible normals",
JCGT 7(4)): stretch wo by α, pick a point on the projected disk of the hemisphere
(warped towards the visible half), lift it, unstretch. The density of h is
D_wo(h) = G1(wo) max(0, wo·h) D(h) / cos θo.
"""
import math

from ..jit import inline

TWO_PI = 2.0 * math.pi


@inline
def ggx_d(hx, hy, hz, ax, ay):
    if not (hz > 0.0):
        return 0.0
    t = (hx / ax) ** 2 + (hy / ay) ** 2 + hz * hz
    return 1.0 / (math.pi * ax * ay * t * t)


@inline
def ggx_lambda(wx, wy, wz, ax, ay):
    z2 = wz * wz
    if not (z2 > 0.0):
        return math.inf
    a2t2 = (ax * ax * wx * wx + ay * ay * wy * wy) / z2
    # (sqrt(1 + x) - 1)/2 without cancellation for small x
    return 0.5 * a2t2 / (1.0 + math.sqrt(1.0 + a2t2))


@inline
def ggx_g1(wx, wy, wz, ax, ay):
    return 1.0 / (1.0 + ggx_lambda(wx, wy, wz, ax, ay))


@inline
def ggx_g2(wox, woy, woz, wix, wiy, wiz, ax, ay):
    """Height-correlated Smith masking-shadowing."""
    return 1.0 / (1.0 + ggx_lambda(wox, woy, woz, ax, ay) + ggx_lambda(wix, wiy, wiz, ax, ay))


@inline
def sample_ggx_vndf(wox, woy, woz, ax, ay, u1, u2):
    """A microfacet normal h (h_z ≥ 0) visible from wo (wo_z > 0), Heitz 2018."""
    # stretched view direction
    vx = ax * wox
    vy = ay * woy
    vz = woz
    vl = math.sqrt(vx * vx + vy * vy + vz * vz)
    vx /= vl
    vy /= vl
    vz /= vl
    # orthonormal basis (T1, T2, V)
    lsq = vx * vx + vy * vy
    if lsq > 0.0:
        il = 1.0 / math.sqrt(lsq)
        t1x = -vy * il
        t1y = vx * il
    else:
        t1x = 1.0
        t1y = 0.0
    t1z = 0.0
    t2x = vy * t1z - vz * t1y
    t2y = vz * t1x - vx * t1z
    t2z = vx * t1y - vy * t1x
    # uniform point on the disk, warped onto the visible half
    r = math.sqrt(u1)
    phi = TWO_PI * u2
    p1 = r * math.cos(phi)
    p2 = r * math.sin(phi)
    s = 0.5 * (1.0 + vz)
    p2 = (1.0 - s) * math.sqrt(max(1.0 - p1 * p1, 0.0)) + s * p2
    p3 = math.sqrt(max(1.0 - p1 * p1 - p2 * p2, 0.0))
    nx = p1 * t1x + p2 * t2x + p3 * vx
    ny = p1 * t1y + p2 * t2y + p3 * vy
    nz = p1 * t1z + p2 * t2z + p3 * vz
    # unstretch
    hx = ax * nx
    hy = ay * ny
    hz = max(nz, 0.0)
    hl = math.sqrt(hx * hx + hy * hy + hz * hz)
    if not (hl > 0.0):
        return 0.0, 0.0, 1.0
    return hx / hl, hy / hl, hz / hl


@inline
def ggx_vndf_pdf(wox, woy, woz, hx, hy, hz, ax, ay):
    """D_wo(h) for a wo on either side (the surface seen from below is the same
    microsurface: visible facets then have wo·h < 0)."""
    c = abs(woz)
    if not (c > 0.0):
        return 0.0
    doh = wox * hx + woy * hy + woz * hz
    if woz < 0.0:
        doh = -doh
    if not (doh > 0.0):
        return 0.0
    return ggx_g1(wox, woy, woz, ax, ay) * doh * ggx_d(hx, hy, hz, ax, ay) / c
