"""Homogeneous participating media in the path kernel (compendium item 54).

Radiance along a ray in a medium obeys dL/ds = −σt L + σs ∫ p L_i dω (no volume
emission here); its integral form is L(s) = τ(0, s) L(0) + ∫ τ(s', s) σs (∫ p L_i dω) ds'
with the transmittance τ = e^(−σt s) of a homogeneous medium.

Distance sampling. A path carries NW wavelengths and σt depends on λ, so one free-flight
distance serves them all by spectral MIS: the distance is drawn from the hero
wavelength's (index 0) density σt₀ e^(−σt₀ s) (or its survival e^(−σt₀ d) past the
segment), and every wavelength's contribution is divided by the *average* over the NW
wavelengths of the path pdf each of them would have used (the one-sample balance
heuristic over hero choices: Wilkie et al., "Hero Wavelength Spectral Sampling", EGSR
2014; Miller, Georgiev, Jarosz, "A null-scattering path integral formulation of light
transport", SIGGRAPH 2019, who write it as ratios of path pdfs). The hero index is the
same at every event of a path, so the average is over whole-path pdfs, not per event:
``mw[MW_R, j]`` keeps wavelength j's path pdf over the hero's (products of event pdfs),
and each event multiplies β_i by f_i · Σ_j r_j / Σ_j r_j p_j. The set of wavelengths is
rotation-invariant (λ_j = hero + j/NW in primary space), so given the set every slot is
the hero with probability 1/NW, which makes this unbiased for every λ_i.

For the path's wavelengths a medium that does not scatter at any of them is not sampled:
its transmittance is applied analytically (zero variance for absorbers).

Phase function: Henyey–Greenstein, p(cos θ) = (1 − g²) / (4π (1 + g² − 2g cos θ)^(3/2))
with cos θ between the incoming and outgoing travel directions (g > 0: forward), sampled
exactly by inverting its cdf, so phase / pdf = 1.

The per-event helpers are compiled as functions of their own (``function``): inlined into
the path kernel they added over a minute to its compile time.

Medium tracking keeps (medium, outer): crossing a surface towards its back side enters
the material's interior medium (the current one becomes ``outer``), towards its front
side returns to ``outer``. One level of nesting; the world has no medium.
"""
import math

import numpy as np

from .. import constants as C
from ..jit import function, inline
from ..geometry.bvh import trace_closest, trace_occluded, triangle_normal
from ..spectra.kernel import lookup

NW = C.N_WAVELENGTHS
LMIN = C.LAMBDA_MIN
LSTEP = C.LAMBDA_STEP
NL = C.N_LAMBDA
INV_4PI = 0.25 / math.pi

# rows of the per-path work array mw (MW_ROWS, NW)
MW_SA = 0  # σa of the current medium at the path's wavelengths (1/m)
MW_SS = 1  # σs
MW_R = 2  # path pdf of wavelength j over the hero's (spectral MIS)
MW_TR = 3  # scratch: shadow-ray transmittance, arrival factors
MW_ROWS = 4

G_ISOTROPIC = 1e-3  # |g| below this is rendered as isotropic (the inverse cdf loses precision)
MAX_CROSSINGS = 256  # null surfaces a shadow ray may pass


@inline
def _transmittance(st, d):
    if st <= 0.0:
        return 1.0
    if d == np.inf:
        return 0.0
    return math.exp(-st * d)


@inline
def _scatters(mw):
    for j in range(NW):
        if mw[MW_SS, j] > 0.0:
            return True
    return False


# ------------------------------------------------------------------ phase function

@inline
def hg_g(g):
    return 0.0 if abs(g) < G_ISOTROPIC else g


@inline
def hg_eval(g, cos_theta):
    """Henyey–Greenstein phase function (1/sr); cos_theta between travel directions."""
    g = hg_g(g)
    den = 1.0 + g * g - 2.0 * g * cos_theta
    if den <= 0.0:
        return 0.0
    return INV_4PI * (1.0 - g * g) / (den * math.sqrt(den))


@function
def hg_sample(g, dx, dy, dz, u1, u2):
    """A new travel direction after scattering a ray travelling along unit (dx, dy, dz):
    (x, y, z, pdf), pdf = phase value (exact inverse-cdf sampling)."""
    g = hg_g(g)
    if g == 0.0:
        c = 1.0 - 2.0 * u1
    else:
        sq = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1)
        c = (1.0 + g * g - sq * sq) / (2.0 * g)
    c = min(1.0, max(-1.0, c))
    s = math.sqrt(max(0.0, 1.0 - c * c))
    ph = 2.0 * math.pi * u2
    # orthonormal frame around d (Duff et al. 2017)
    sgn = 1.0 if dz >= 0.0 else -1.0
    a = -1.0 / (sgn + dz)
    b = dx * dy * a
    tx = 1.0 + sgn * dx * dx * a
    ty = sgn * b
    tz = -sgn * dx
    bx = b
    by = sgn + dy * dy * a
    bz = -dy
    cp = s * math.cos(ph)
    sp = s * math.sin(ph)
    wx = cp * tx + sp * bx + c * dx
    wy = cp * ty + sp * by + c * dy
    wz = cp * tz + sp * bz + c * dz
    return wx, wy, wz, hg_eval(g, c)


# ------------------------------------------------------------------ medium state

@inline
def load(med_tab, medium, lam, mw):
    """σa, σs of ``medium`` (-1: none) at the path's wavelengths into mw."""
    for i in range(NW):
        if medium >= 0:
            mw[MW_SA, i] = lookup(med_tab, 2 * medium, lam[i])
            mw[MW_SS, i] = lookup(med_tab, 2 * medium + 1, lam[i])
        else:
            mw[MW_SA, i] = 0.0
            mw[MW_SS, i] = 0.0


@function
def start_path(med_tab, medium, lam, mw):
    """Reset the spectral-MIS ratios and load the camera's medium."""
    for i in range(NW):
        mw[MW_R, i] = 1.0
    load(med_tab, medium, lam, mw)


@inline
def crossed(medium, outer, interior, entering):
    """(medium, outer) after crossing a surface with ``interior`` medium."""
    if entering:
        return interior, medium
    return outer, -1


@function
def cross(medium, outer, interior, entering, med_tab, lam, mw):
    """Cross a surface and reload the coefficients if the medium changes."""
    m2, o2 = crossed(medium, outer, interior, entering)
    if m2 != medium:
        load(med_tab, m2, lam, mw)
    return m2, o2


# ------------------------------------------------------------------ distance sampling

@function
def free_flight(medium, mw, u):
    """Distance to the next scattering event from the hero's extinction; inf: none
    (no medium, or one that scatters none of the path's wavelengths)."""
    if medium < 0 or not _scatters(mw):
        return np.inf
    st = mw[MW_SA, 0] + mw[MW_SS, 0]
    if st <= 0.0:
        return np.inf
    return -math.log1p(-u) / st


@inline
def _event_pdf(st, tr, sampled, scatter):
    if not sampled:
        return 1.0
    return st * tr if scatter else tr


@inline
def _mis(mw, dist, scatter):
    """Σ_j r_j / Σ_j r_j p_j for an event at ``dist`` (scatter, or passing it)."""
    sampled = _scatters(mw)
    num = 0.0
    den = 0.0
    for j in range(NW):
        st = mw[MW_SA, j] + mw[MW_SS, j]
        p = _event_pdf(st, _transmittance(st, dist), sampled, scatter)
        num += mw[MW_R, j]
        den += mw[MW_R, j] * p
    if den <= 0.0:
        return 0.0
    return num / den


@function
def segment(medium, mw, beta, dist, scatter):
    """Weight β for the medium between two events ``dist`` apart: a scattering event at
    the end (``scatter``: f = τ σs) or passing through to a surface (f = τ)."""
    if medium < 0:
        return
    c = _mis(mw, dist, scatter)
    sampled = _scatters(mw)
    st0 = mw[MW_SA, 0] + mw[MW_SS, 0]
    p0 = _event_pdf(st0, _transmittance(st0, dist), sampled, scatter)
    for i in range(NW):
        st = mw[MW_SA, i] + mw[MW_SS, i]
        tr = _transmittance(st, dist)
        f = tr * mw[MW_SS, i] if scatter else tr
        beta[i] *= f * c
        if p0 > 0.0:
            mw[MW_R, i] *= _event_pdf(st, tr, sampled, scatter) / p0


@function
def arrival(medium, mw, dist):
    """Factors (into mw[MW_TR]) for light reaching the segment's start from an emitter at
    ``dist`` inside the current medium (1 outside media)."""
    if medium < 0:
        for i in range(NW):
            mw[MW_TR, i] = 1.0
        return
    c = _mis(mw, dist, False)
    for i in range(NW):
        mw[MW_TR, i] = _transmittance(mw[MW_SA, i] + mw[MW_SS, i], dist) * c


@inline
def drop_companions(beta, mw):
    """After a dispersive event only the hero can have made the path: its β becomes
    f/p_hero (times NW, as it now stands for all NW slots) and the companions stop."""
    s = 0.0
    for j in range(NW):
        s += mw[MW_R, j]
    beta[0] *= s
    mw[MW_R, 0] = 1.0
    for j in range(1, NW):
        beta[j] = 0.0
        mw[MW_R, j] = 0.0


# ------------------------------------------------------------------ shadow rays

@function
def shadow(o, w, dist, medium, outer, lam, mw, geo, mat_model, med, eps, stack):
    """Transmittance from o over ``dist`` along unit w into mw[MW_TR], passing null
    surfaces and switching media at them; False (and 0) if any other surface blocks it.
    geo, med: the geometry and media records (core/geometry/record.py, record.py here);
    mat_model: the materials' MAT_* tags."""
    ox, oy, oz = o
    wx, wy, wz = w
    nodes = geo.nodes
    tris = geo.tris
    e1 = geo.e1
    e2 = geo.e2
    tri_mat = geo.tri_mat
    mat_medium = med.mat_medium
    med_tab = med.med_tab
    for i in range(NW):
        mw[MW_TR, i] = 1.0
    t0 = 0.0
    for _ in range(MAX_CROSSINGS):
        t, prim, bu, bv = trace_closest(ox, oy, oz, wx, wy, wz, t0, dist, nodes, tris, stack)
        end = dist if prim < 0 else t
        if medium >= 0 and end > t0:
            for i in range(NW):
                st = lookup(med_tab, 2 * medium, lam[i]) + lookup(med_tab, 2 * medium + 1, lam[i])
                mw[MW_TR, i] *= _transmittance(st, end - t0)
        if prim < 0:
            return True
        m = tri_mat[prim]
        if mat_model[m] != C.MAT_NULL:
            break
        nx, ny, nz = triangle_normal(e1, e2, prim)
        medium, outer = crossed(medium, outer, mat_medium[m], nx * wx + ny * wy + nz * wz < 0.0)
        t0 = t + eps
        if t0 >= dist:
            return True
    for i in range(NW):
        mw[MW_TR, i] = 0.0
    return False


@inline
def unoccluded(has_media, o, w, tmax, vol, interior, cos_i, cos_n, lam, mw, fv, geo, mat_model, med, eps, stack):
    """Surface NEE visibility from o along w (vol: the (medium, outer) the path is in).
    Without media the plain any-hit query; with media the shadow ray starts in the medium
    on its side of the surface, passes null surfaces and scales fv by the transmittance."""
    medium, outer = vol
    if not has_media:
        return not trace_occluded(o[0], o[1], o[2], w[0], w[1], w[2], 0.0, tmax, geo.nodes, geo.tris, stack)
    if (cos_n > 0.0) != (cos_i > 0.0):
        medium, outer = crossed(medium, outer, interior, cos_n < 0.0)
    if not shadow(o, w, tmax, medium, outer, lam, mw, geo, mat_model, med, eps, stack):
        return False
    for i in range(NW):
        fv[i] *= mw[MW_TR, i]
    return True


# ------------------------------------------------------------------ next-event estimation

@inline
def pick(cdf, n, u):
    """Index i with cdf[i] ≤ u < cdf[i + 1] (binary search over n entries)."""
    lo = 0
    hi = n - 1
    while lo < hi:
        mid = (lo + hi) // 2
        if cdf[mid + 1] <= u:
            lo = mid + 1
        else:
            hi = mid
    return lo


@function
def nee(p, d, g, sample, le, vol, lam, beta, rad, mw, geo, mat_model, med, eps, stack):
    """Light sampling at a scattering point p (ray direction d, the path in vol = (medium,
    outer)): an emitter sample (sample = (unit direction w, distance, solid-angle pdf — inf
    for a delta light —, factor, selection probability pe), emitted radiance le per
    wavelength), HG phase, analytic transmittance through media and null surfaces, power
    heuristic against phase sampling."""
    dx, dy, dz = d
    wx, wy, wz, dist, lpdf, fac, pe = sample
    medium, outer = vol
    if fac <= 0.0 or lpdf <= 0.0:
        return
    ph = hg_eval(g, dx * wx + dy * wy + dz * wz)
    if ph <= 0.0:
        return
    tmax = dist * (1.0 - 1e-4) - eps if dist < np.inf else np.inf
    if not shadow(p, (wx, wy, wz), tmax, medium, outer, lam, mw, geo, mat_model, med, eps, stack):
        return
    if lpdf == np.inf:  # delta light: NEE only
        k = ph * fac / pe
    else:
        pl = pe * lpdf
        k = pl * pl / (pl * pl + ph * ph) * ph * fac / pl
    for i in range(NW):
        rad[i] += beta[i] * mw[MW_TR, i] * k * le[i]


@inline
def live_max(beta, pdf_lam):
    q = 0.0
    for i in range(NW):
        if pdf_lam[i] > 0.0:
            q = max(q, beta[i])
    return q
