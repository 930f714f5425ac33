"""Generalised cosine lobes: Lafortune's model (item 50) and the mirror-direction modified
Phong model (item 48a), which is one such lobe.

Lafortune, Foo, Torrance, Greenberg 1997::

    f = ρd/π + t · Σ_k max(0, Cx_k wi_x wo_x + Cy_k wi_y wo_y + Cz_k wi_z wo_z)^n_k

with ρd = ra, the lobe tint t = rb (both clamped to [0, 1]; ρd + t·A_max ≤ 1 enforced per
wavelength with A_max from the row). The lobe is symmetric in wi and wo (reciprocal,
item 44). With v = C ⊙ wo it is |v|ⁿ cosⁿ(wi, v̂): a cosine lobe around the axis v̂ (the
compendium's Θa, with C_k(Θi) = |v|ⁿ), clipped at 0 and by the horizon, whose albedo at
wo is |v|ⁿ F_n(v̂_z), Arvo's double-axis moment over the digon (item 10a).

Modified Phong (a) (Lewis 1994) is the single lobe C = (−1, −1, 1) (so v̂ is the mirror
direction of wo) scaled by (n+2)/2π::

    f = ρd/π + ρs (n+2)/(2π) cosⁿ α,   cos α = wi · mirror(wo)

∫ cosⁿα cos θi dωi over the hemisphere is at most 2π/(n+2) (item 9 with the extra
cosine), reached at normal incidence, so A_max = 1: ρd + ρs ≤ 1 bounds the albedo at
every angle (Lewis's πkd + 2π/(n+2) ks ≤ 1 in the compendium's unnormalised form).

Sampling (the compendium's three steps): choose the diffuse part or lobe k with
probabilities proportional to their albedos at wo, ρd and t·|v|ⁿ F_m(v̂_z) (averaged
over the wavelengths), then draw wi from cos θ/π (item 20) or from the cosᵐ lobe around
v̂ on the digon (item 23: rejection in core.sampling.lobes, density cosᵐ/G_m with G_m
the digon moment of item 10b). The proposal uses the integer m = round(n) because the
moment recurrences need an integer; f keeps the real n and weights are f cos/pdf, so
this only costs variance (for integer n the selection is exactly proportional to each
lobe's integral). The pdf is the mixture of all components.

Cost: this module computes both moments with one telescoped, early-terminating sum
(``digon_moments``), once per lobe, instead of the toolkit's O(n) recurrences for G and
F separately (the tests check it against ``core.sampling.lobes``).
"""
import math

from .. import constants as C
from ..jit import function, inline
from ..sampling.lobes import sample_offnormal_cosn
from ..sampling.warps import sample_cosine_hemisphere
from .common import INV_PI, INV_TWO_PI, lobe_sums, pow_pos
from .params import (
    BSDF_DIFFUSE, BSDF_GLOSSY, BSDF_REFLECTION, LAF_MAX_LOBES, P_EXPONENT, P_LAF_A_MAX, P_LAF_LOBES,
    P_LAF_N_LOBES)

TWO_PI = 2.0 * math.pi


@inline
def digon_moments(m, d):
    """(G_m(d), F_m(d)) for an integer m ≥ 0 and d = axis·N (items 10a, 10b).

    G_m = ∫_D cosᵐ(Θ, a) dω, F_m = ∫_D cosᵐ(Θ, a) cos(Θ, N) dω over the digon D. With
    q_j = c^j ∫_{-π/2}^{π/2} cos^j φ dφ (c = sqrt(1 − d²)), the recurrence of
    core.sampling.lobes, (k+1) G_k = (k−1) G_{k−2} + d q_{k−1}, telescopes to
    (m+1) G_m = H + d Σ q_j over j < m of the parity of m − 1, with H = 2(π − acos d)
    (m even) or π(1 + d) (m odd); F_m = (m d G_{m−1} + q_m)/(m + 2). The q_j fall
    geometrically (q_j/q_{j−2} = c²(j−1)/j), so the sums stop once a term no longer
    changes them: O(min(m, log ε / log c²)) work instead of O(m). d < 0 uses the
    complements G_m(d) = 2π/(m+1) − G_m(−d) and F_m(d) = F_m(−d) + 2π d/(m+2).
    """
    neg = d < 0.0
    a = min(abs(d), 1.0)
    c2 = max((1.0 - a) * (1.0 + a), 0.0)
    c = math.sqrt(c2)
    h0 = 2.0 * (math.pi - math.acos(a))
    h1 = math.pi * (1.0 + a)
    s0 = 0.0  # Σ q_j, j even ≥ 2
    s1 = 0.0  # Σ q_j, j odd
    if m >= 2:
        s1 = 2.0 * c  # q_1
        qa = math.pi  # q_{j-2}
        qb = s1  # q_{j-1}
        tol = 1e-17 * math.pi
        j = 2
        while j < m:
            q = c2 * (j - 1) / j * qa
            if j % 2 == 0:
                s0 += q
            else:
                s1 += q
            qa = qb
            qb = q
            if a * q < tol and a * qa < tol:
                break
            j += 1
    if m % 2 == 0:
        g = (h0 + a * s1) / (m + 1)
        g_prev = (h1 + a * s0) / m if m > 0 else 0.0
    else:
        g = (h1 + a * s0) / (m + 1)
        g_prev = (h0 + a * s1) / m
    if m == 0:
        f = 0.5 * math.pi * (1.0 + a)
    else:
        qm = 0.0
        if c > 0.0:
            qm = math.exp(m * math.log(c) + 0.5 * math.log(math.pi) + math.lgamma(0.5 * (m + 1))
                          - math.lgamma(0.5 * m + 1.0))
        f = (m * a * g_prev + qm) / (m + 2)
    if neg:
        g = max(TWO_PI / (m + 1) - g, 0.0)
        f = max(f - TWO_PI * a / (m + 2), 0.0)
    return g, f


@inline
def _n_lobes(model, p):
    if model == C.MAT_PHONG:
        return 1
    k = int(p[P_LAF_N_LOBES])
    return min(max(k, 0), LAF_MAX_LOBES)


@inline
def _lobe(model, p, k):
    """(Cx, Cy, Cz, n, scale) of lobe k."""
    if model == C.MAT_PHONG:
        n = p[P_EXPONENT]
        return -1.0, -1.0, 1.0, n, (n + 2.0) * INV_TWO_PI
    b = P_LAF_LOBES + 4 * k
    return p[b], p[b + 1], p[b + 2], p[b + 3], 1.0


@inline
def _a_max(model, p):
    if model == C.MAT_PHONG:
        return 1.0
    return p[P_LAF_A_MAX]


@inline
def _lobe_seen_from(model, p, k, wox, woy, woz):
    """Lobe k for this wo: v = C ⊙ wo, |v| (0: the lobe is absent), the exponent n, its
    rounding m and the digon moments (g, f) of order m about v̂, and the lobe's scale."""
    cx, cy, cz, n, scale = _lobe(model, p, k)
    vx = cx * wox
    vy = cy * woy
    vz = cz * woz
    r = math.sqrt(vx * vx + vy * vy + vz * vz)
    if not (r > 0.0):
        return vx, vy, vz, 0.0, n, 0.0, 0.0, 0.0, scale
    mm = math.floor(n + 0.5)
    g, f = digon_moments(mm, vz / r)
    return vx, vy, vz, r, n, mm, g, f, scale


@function
def lobes_eval(model, p, ra, rb, wox, woy, woz, wix, wiy, wiz, out_f, want_f):
    """f and the mixture pdf of the lobe models (MAT_PHONG, MAT_LAFORTUNE).

    With the wavelength means (md, ms) and lobe albedos w_k the pdf is
    (md cos θi/π + ms Σ w_k p_k(wi)) / (md + ms Σ w_k), computed in one pass.
    """
    sw = 0.0
    swp = 0.0
    lobes = 0.0
    for k in range(_n_lobes(model, p)):
        vx, vy, vz, r, n, mm, g, f, scale = _lobe_seen_from(model, p, k, wox, woy, woz)
        if not (r > 0.0):
            continue
        lobes += scale * pow_pos(vx * wix + vy * wiy + vz * wiz, n)
        w = scale * pow_pos(r, n) * f
        if w > 0.0 and g > 0.0:
            sw += w
            swp += w * pow_pos((vx * wix + vy * wiy + vz * wiz) / r, mm) / g
    md, ms = lobe_sums(ra, rb, _a_max(model, p), lobes, out_f, want_f)
    tot = md + ms * sw
    if not (tot > 0.0):
        return 0.0
    return (md * wiz * INV_PI + ms * swp) / tot


@function
def lobes_sample_dir(model, p, ra, rb, wox, woy, woz, u1, u2, u3):
    """(x, y, z, flags). The component is chosen in one pass (weighted reservoir:
    component c replaces the current choice with probability w_c / Σ_{c' ≤ c} w_c', which
    selects c with probability w_c / Σ w), and u3 is rescaled into a fresh uniform for
    the chosen lobe's rejection stream."""
    nw = ra.shape[0]
    md, ms = lobe_sums(ra, rb, _a_max(model, p), 0.0, ra, False)
    md /= nw
    ms /= nw
    chosen = -1 if md > 0.0 else -2
    tot = md
    u = u3
    cm = 0.0
    cx_ = 0.0
    cy_ = 0.0
    cz_ = 0.0
    for k in range(_n_lobes(model, p)):
        vx, vy, vz, r, n, mm, g, f, scale = _lobe_seen_from(model, p, k, wox, woy, woz)
        if not (r > 0.0):
            continue
        w = ms * scale * pow_pos(r, n) * f
        if not (w > 0.0) or not (g > 0.0):
            continue
        tot += w
        q = w / tot
        if u < q:
            chosen = k
            u = u / q
            cm = mm
            cx_ = vx
            cy_ = vy
            cz_ = vz
        else:
            u = (u - q) / (1.0 - q)
    if chosen == -2:
        return 0.0, 0.0, 1.0, 0
    if chosen < 0:
        x, y, z, pd = sample_cosine_hemisphere(u1, u2)
        fl = BSDF_REFLECTION | BSDF_DIFFUSE
    else:
        u = min(max(u, 0.0), 0.9999999999999999)
        x, y, z, pd = sample_offnormal_cosn(cm, cx_, cy_, cz_, u1, u2, u)
        fl = BSDF_REFLECTION | BSDF_GLOSSY
    if not (pd > 0.0) or not (z > 0.0):
        return 0.0, 0.0, 1.0, 0
    return x, y, z, fl
