"""Rough microfacet models with the GGX distribution (Walter, Marschner, Li, Torrance 2007).

Conductor (wo, wi on the upper side; the dispatch handles two-sidedness)::

    f = ra · F_conductor(wo·h; η, κ) · D(h) G2(wo, wi) / (4 cos θo cos θi),  h = (wo+wi)/|wo+wi|

sampled with visible normals: h ~ D_wo, wi = mirror of wo about h,
p(wi) = D_wo(h) / (4 wo·h) = G1(wo) D(h) / (4 cos θo); weight = F G2/G1(wo).

Dielectric (both sides; eta = n_inside/n_outside, inside below; radiance transport as
in specular.py). With η_r = n_i/n_o the relative index of wi's side over wo's side and
F(wo·h) the unpolarised dielectric Fresnel factor (item 42)::

    reflection:   f_r = rb · F · D G2 / (4 |cos θo| |cos θi|),              h ∝ wo + wi
    transmission: f_t = ra · (1 − F) D G2 |wo·h| |wi·h|
                        / (|cos θo| |cos θi| (wo·h + η_r wi·h)²),          h ∝ −(wo + η_r wi)

(Walter et al. 2007, eqs. 20-21, with their n_o² divided out; f_t obeys the generalised
reciprocity f(wo, wi)/n_o² = f(wi, wo)/n_i², and in the smooth limit its sampling weight
is (n_o/n_i)², the radiance scaling of specular.py.) h is oriented to z > 0; facets that
face away from either direction contribute nothing.

Sampling: h ~ D_wo (for wo below, the visible normals of −wo: the surface seen from
inside is the same microsurface), reflection with probability P_R(h) = mean over the
wavelengths of F(wo·h, η_λ), else refraction of wo about h with eta[0]. Densities:
p_r(wi) = D_wo(h) P_R / (4 |wo·h|) and p_t(wi) = D_wo(h) (1 − P_R) η_r² |wi·h| / (wo·h + η_r wi·h)²,
the latter at the h of the hero (eta[0]): when eta varies with λ the transmitted sample
is DISPERSIVE and only out_w[0] is set; eval still returns f for every wavelength (at
its own h) and the hero's pdf.

eta = 1 (index-matched): transmission becomes the straight pass-through wi = −wo, a
delta event (TRANSMISSION | DELTA, weight ra (1 − F)/(1 − P_R)); eval gives it f = 0.
Roughness is clamped to α ≥ ALPHA_MIN.
"""
import math

from ..jit import function, inline
from .common import all_equal, clamp01, half_vector, reflect, reflect_glossy, zero
from .fresnel import fresnel_conductor, fresnel_dielectric, mean_fresnel_dielectric, refract_cos
from .microfacet import ggx_d, ggx_g1, ggx_g2, ggx_vndf_pdf, sample_ggx_vndf
from .params import (
    ALPHA_MIN, BSDF_DELTA, BSDF_DISPERSIVE, BSDF_GLOSSY, BSDF_REFLECTION, BSDF_TRANSMISSION, P_ALPHA_X,
    P_ALPHA_Y)

ETA_ONE_TOL = 1e-6


@inline
def _alphas(p):
    return max(p[P_ALPHA_X], ALPHA_MIN), max(p[P_ALPHA_Y], ALPHA_MIN)


# -- reflection: the conductor (and the plastic's coat) -----------------------------------

@inline
def ggx_reflection(p, wox, woy, woz, wix, wiy, wiz, want_f):
    """GGX reflection without its Fresnel factor, for wo and wi on the upper side:
    (wo·h, D G2 / (4 cos θo cos θi) (0 unless want_f), pdf of ``ggx_reflect_sample_dir``);
    (0, 0, 0) where no facet reflects wo into wi."""
    ax, ay = _alphas(p)
    hx, hy, hz, ok = half_vector(wox, woy, woz, wix, wiy, wiz)
    if not ok:
        return 0.0, 0.0, 0.0
    doh = wox * hx + woy * hy + woz * hz
    d = ggx_d(hx, hy, hz, ax, ay)
    if not (doh > 0.0) or not (d > 0.0):
        return 0.0, 0.0, 0.0
    base = 0.0
    if want_f:
        base = d * ggx_g2(wox, woy, woz, wix, wiy, wiz, ax, ay) / (4.0 * woz * wiz)
    return doh, base, ggx_g1(wox, woy, woz, ax, ay) * d / (4.0 * woz)


@function
def ggx_conductor_eval(p, ra, eta, kappa, wox, woy, woz, wix, wiy, wiz, out_f, want_f):
    doh, base, pdf = ggx_reflection(p, wox, woy, woz, wix, wiy, wiz, want_f)
    if want_f:
        if doh > 0.0:
            for i in range(ra.shape[0]):
                out_f[i] = clamp01(ra[i]) * fresnel_conductor(doh, eta[i], kappa[i]) * base
        else:
            zero(out_f)
    return pdf


@function
def ggx_reflect_sample_dir(p, wox, woy, woz, u1, u2):
    """wi = mirror of wo (upper side) about a visible GGX normal (the conductor's and
    the plastic coat's sampler)."""
    ax, ay = _alphas(p)
    hx, hy, hz = sample_ggx_vndf(wox, woy, woz, ax, ay, u1, u2)
    if not (wox * hx + woy * hy + woz * hz > 0.0):
        return 0.0, 0.0, 1.0, 0
    return reflect_glossy(wox, woy, woz, hx, hy, hz)


# -- dielectric ---------------------------------------------------------------------------

@inline
def _rel_eta(eta_i, woz):
    """n_i / n_o for a wi on the other side of wo."""
    if woz > 0.0:
        return eta_i
    return 1.0 / eta_i


@inline
def _oriented_half(hx, hy, hz, wox, woy, woz, wix, wiy, wiz):
    """(hx, hy, hz) normalised and turned to z ≥ 0, with wo·h, wi·h and whether both
    directions see the facet from their own side: (hx, hy, hz, doh, dih, ok)."""
    hl = math.sqrt(hx * hx + hy * hy + hz * hz)
    if not (hl > 0.0) or hl == math.inf:
        return 0.0, 0.0, 1.0, 0.0, 0.0, False
    if hz < 0.0:
        hl = -hl
    hx /= hl
    hy /= hl
    hz /= hl
    doh = wox * hx + woy * hy + woz * hz
    dih = wix * hx + wiy * hy + wiz * hz
    # both directions must see the facet from their own side
    ok = hz > 0.0 and doh * woz > 0.0 and dih * wiz > 0.0
    return hx, hy, hz, doh, dih, ok


@function
def ggx_dielectric_eval(p, ra, rb, eta, wox, woy, woz, wix, wiy, wiz, out_f, want_f):
    if want_f:
        zero(out_f)
    if not (woz > 0.0 or woz < 0.0) or not (wiz > 0.0 or wiz < 0.0) or not (eta[0] > 0.0):
        return 0.0
    ax, ay = _alphas(p)
    nw = ra.shape[0]
    g2 = ggx_g2(wox, woy, woz, wix, wiy, wiz, ax, ay)
    cc = abs(woz * wiz)
    if woz * wiz > 0.0:
        hx, hy, hz, doh, dih, ok = _oriented_half(wox + wix, woy + wiy, woz + wiz, wox, woy, woz, wix, wiy, wiz)
        if not ok:
            return 0.0
        d = ggx_d(hx, hy, hz, ax, ay)
        base = d * g2 / (4.0 * cc)
        sf = 0.0
        for i in range(nw):  # one Fresnel call site: inlined copies cost compile time
            f = fresnel_dielectric(doh, eta[i])
            sf += f
            if want_f:
                out_f[i] = clamp01(rb[i]) * f * base
        return ggx_vndf_pdf(wox, woy, woz, hx, hy, hz, ax, ay) * (sf / nw) / (4.0 * abs(doh))
    # transmission: f at each wavelength's own half vector; the pdf at the hero's
    pdf = 0.0
    for i in range(nw if want_f else 1):
        if not (eta[i] > 0.0):
            continue
        er = _rel_eta(eta[i], woz)
        if abs(er - 1.0) < ETA_ONE_TOL:
            continue  # index-matched: a delta pass-through, never evaluated
        # generalised half vector h ∝ −(wo + η_r wi)
        hx, hy, hz, doh, dih, ok = _oriented_half(-(wox + er * wix), -(woy + er * wiy), -(woz + er * wiz),
                                                  wox, woy, woz, wix, wiy, wiz)
        if not ok:
            continue
        den = doh + er * dih
        den2 = den * den
        if not (den2 > 0.0):
            continue
        if i == 0:
            pdf = (ggx_vndf_pdf(wox, woy, woz, hx, hy, hz, ax, ay) * (1.0 - mean_fresnel_dielectric(eta, doh))
                   * er * er * abs(dih) / den2)
        if want_f:
            out_f[i] = (clamp01(ra[i]) * (1.0 - fresnel_dielectric(doh, eta[i])) * ggx_d(hx, hy, hz, ax, ay) * g2
                        * abs(doh * dih) / (cc * den2))
    return pdf


@function
def ggx_dielectric_sample_dir(p, ra, eta, wox, woy, woz, u1, u2, u3, out_w):
    """(x, y, z, flags). The index-matched pass-through is a delta event: its weight is
    written to out_w and DELTA is set; otherwise out_w is untouched."""
    if not (woz > 0.0 or woz < 0.0) or not (eta[0] > 0.0):
        return 0.0, 0.0, 1.0, 0
    ax, ay = _alphas(p)
    s = 1.0 if woz > 0.0 else -1.0
    hx, hy, hz = sample_ggx_vndf(s * wox, s * woy, s * woz, ax, ay, u1, u2)
    doh = wox * hx + woy * hy + woz * hz
    if not (doh * s > 0.0):
        return 0.0, 0.0, 1.0, 0
    pr = mean_fresnel_dielectric(eta, doh)
    dispersive = not all_equal(eta)
    if u3 < pr:
        x, y, z = reflect(wox, woy, woz, hx, hy, hz)
        if not (z * woz > 0.0):
            return 0.0, 0.0, 1.0, 0
        return x, y, z, BSDF_REFLECTION | BSDF_GLOSSY
    er = _rel_eta(eta[0], woz)
    fl = BSDF_TRANSMISSION | BSDF_GLOSSY
    if dispersive:
        fl |= BSDF_DISPERSIVE
    if abs(er - 1.0) < ETA_ONE_TOL:
        # index-matched hero: the boundary is invisible, a straight pass-through
        q = 1.0 - pr
        zero(out_w)
        for i in range(1 if dispersive else ra.shape[0]):
            out_w[i] = clamp01(ra[i]) * (1.0 - fresnel_dielectric(doh, eta[i])) / q
        return -wox, -woy, -woz, (fl & ~BSDF_GLOSSY) | BSDF_DELTA
    ct = refract_cos(doh, eta[0])
    if ct < 0.0:
        return 0.0, 0.0, 1.0, 0
    inv = 1.0 / er
    k = inv * abs(doh) - ct
    if doh < 0.0:
        k = -k  # h flipped to wo's side
    x = -inv * wox + k * hx
    y = -inv * woy + k * hy
    z = -inv * woz + k * hz
    if not (z * woz < 0.0):
        return 0.0, 0.0, 1.0, 0
    return x, y, z, fl
