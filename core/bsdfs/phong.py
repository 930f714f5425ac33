"""Lambert (item 47) and the half-vector form (b) of the modified Phong BRDF (item 48).

The mirror-direction form (a) is a generalised cosine lobe: see lafortune.py.
Both functions take wo and wi in the upper hemisphere (the dispatch module handles the
sides); ρd = ra, ρs = rb per wavelength, clamped and scaled so that ρd + ρs ≤ 1.

(b) Half-vector (Blinn) lobe::

    f = ρd/π + ρs cosⁿ θh · (n+2)(n+4) / (8π (n + 2^(-n/2)))

At normal incidence ∫ cosⁿ(θ/2) cos θ dω = 8π (n + 2^(-n/2)) / ((n+2)(n+4)) (derived
with x = cos(θ/2): 8π ∫_{1/√2}^1 xⁿ (2x² − 1) x dx), the specular term's maximal albedo
(the lobe narrows towards grazing, where dω_i = 4 (wo·h) dω_h shrinks); with this
normalisation ρd + ρs ≤ 1 bounds the albedo, which the tests check at every angle.
Sampling: h by cosⁿ θh (item 21), wi = mirror of wo about h, p(wi) = p(h) / (4 wo·h);
a wi below the horizon is a failed sample (its f is 0), so there the pdf integrates to
less than 1. Diffuse and specular parts are chosen in proportion to the wavelength
averages of ρd and ρs.
"""
import math

from ..jit import function, inline
from ..sampling.warps import cosn_pdf, sample_cosine_hemisphere, sample_cosn
from .common import (
    INV_PI, clamp01, diffuse_glossy_pdf, glossy_prob, half_vector, lobe_sums, pow_pos, reflect_glossy)
from .params import BSDF_DIFFUSE, BSDF_REFLECTION, P_EXPONENT


# -- Lambert (item 47) ---------------------------------------------------------------

@function
def lambert_eval(ra, wix, wiy, wiz, out_f, want_f):
    if want_f:
        for i in range(ra.shape[0]):
            out_f[i] = clamp01(ra[i]) * INV_PI
    return wiz * INV_PI


@inline
def lambert_sample_dir(u1, u2):
    x, y, z, pdf = sample_cosine_hemisphere(u1, u2)
    if not (pdf > 0.0) or not (z > 0.0):
        return 0.0, 0.0, 1.0, 0
    return x, y, z, BSDF_REFLECTION | BSDF_DIFFUSE


# -- (b) half-vector (Blinn) form ---------------------------------------------------------

@inline
def blinn_norm(n):
    """(n+2)(n+4) / (8π (n + 2^(-n/2))): the specular albedo at normal incidence is 1."""
    return (n + 2.0) * (n + 4.0) / (8.0 * math.pi * (n + math.exp(-0.5 * n * math.log(2.0))))


@function
def blinn_eval(p, ra, rb, wox, woy, woz, wix, wiy, wiz, out_f, want_f):
    n = p[P_EXPONENT]
    hx, hy, hz, ok = half_vector(wox, woy, woz, wix, wiy, wiz)
    lobe = 0.0
    pdf_s = 0.0
    if ok:
        lobe = blinn_norm(n) * pow_pos(hz, n)
        doh = wox * hx + woy * hy + woz * hz
        if doh > 0.0:
            pdf_s = cosn_pdf(n, hx, hy, hz) / (4.0 * doh)
    md, ms = lobe_sums(ra, rb, 1.0, lobe, out_f, want_f)
    return diffuse_glossy_pdf(md, ms, wiz, pdf_s)


@function
def blinn_sample_dir(p, ra, rb, wox, woy, woz, u1, u2, u3):
    ps = glossy_prob(ra, rb)
    if ps < 0.0:
        return 0.0, 0.0, 1.0, 0
    if u3 < ps:
        hx, hy, hz, ph = sample_cosn(p[P_EXPONENT], u1, u2)
        doh = wox * hx + woy * hy + woz * hz
        if not (ph > 0.0) or not (doh > 0.0):
            return 0.0, 0.0, 1.0, 0
        return reflect_glossy(wox, woy, woz, hx, hy, hz)
    return lambert_sample_dir(u1, u2)
