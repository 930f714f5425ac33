"""Smooth (delta) models: perfect mirror (item 37), smooth dielectric (items 38-42) and
smooth conductor (item 42).

They are Dirac distributions (item 1): never evaluated (f = 0, pdf = 0 from eval/pdf);
``*_sample`` returns the discrete event (wi_x, wi_y, wi_z, flags) with its weight in
out_w and the DELTA flag (the dispatch reports pdf 0).

Smooth dielectric, transport mode *radiance* (camera paths: wo towards the viewer, wi
towards the light). wo may be on either side; eta is n_inside/n_outside (inside is
below, z < 0). Reflection (wi = mirror of wo, item 37) is chosen with probability
P_R = mean over the wavelengths of the unpolarised Fresnel reflectance F(cos θo, η_λ)
(item 42; 1 under total internal reflection, item 41) and weighted F_λ/P_R · rb.
Refraction (Snell, items 38-40: n_o sin θo = n_i sin θi) has weight
(1 − F_λ)/(1 − P_R) · ra · (n_o/n_i)², where n_o, n_i are the indices on wo's and wi's
sides: radiance is compressed into the smaller solid angle of the denser medium, so
light leaving glass (η = 1.5) towards a viewer outside is scaled by 1/η² (Veach 1997,
§5.2). The BSDF of importance (light paths) would not have this factor.

Dispersion: when eta differs across the wavelengths, the refracted direction depends on
λ. The transmitted direction is then computed with eta[0] (the hero wavelength), only
out_w[0] is set (the others are 0) and the flag DISPERSIVE tells the caller to drop
the companions. Reflection never disperses.
"""
from ..jit import function
from .common import all_equal, clamp01, zero
from .fresnel import fresnel_conductor, fresnel_dielectric, mean_fresnel_dielectric, refract_cos
from .params import BSDF_DELTA, BSDF_DISPERSIVE, BSDF_REFLECTION, BSDF_TRANSMISSION


@function
def mirror_sample(ra, wox, woy, woz, out_w):
    for i in range(ra.shape[0]):
        out_w[i] = clamp01(ra[i])
    return -wox, -woy, woz, BSDF_REFLECTION | BSDF_DELTA


@function
def conductor_sample(ra, eta, kappa, wox, woy, woz, out_w):
    for i in range(ra.shape[0]):
        out_w[i] = clamp01(ra[i]) * fresnel_conductor(woz, eta[i], kappa[i])
    return -wox, -woy, woz, BSDF_REFLECTION | BSDF_DELTA


@function
def dielectric_sample(ra, rb, eta, wox, woy, woz, u3, out_w):
    nw = ra.shape[0]
    if not (woz > 0.0 or woz < 0.0) or not (eta[0] > 0.0):
        zero(out_w)
        return 0.0, 0.0, 1.0, 0
    pr = mean_fresnel_dielectric(eta, woz)
    if u3 < pr:
        for i in range(nw):
            out_w[i] = clamp01(rb[i]) * fresnel_dielectric(woz, eta[i]) / pr
        return -wox, -woy, woz, BSDF_REFLECTION | BSDF_DELTA
    ct = refract_cos(woz, eta[0])
    if ct < 0.0:  # the hero is totally reflected (only possible when dispersive)
        zero(out_w)
        return 0.0, 0.0, 1.0, 0
    if woz > 0.0:
        inv_eta = 1.0 / eta[0]  # n_o / n_i
        wiz = -ct
    else:
        inv_eta = eta[0]
        wiz = ct
    q = 1.0 - pr
    if all_equal(eta):
        s = inv_eta * inv_eta / q
        for i in range(nw):
            out_w[i] = clamp01(ra[i]) * (1.0 - fresnel_dielectric(woz, eta[i])) * s
        fl = BSDF_TRANSMISSION | BSDF_DELTA
    else:
        zero(out_w)
        out_w[0] = clamp01(ra[0]) * (1.0 - fresnel_dielectric(woz, eta[0])) * inv_eta * inv_eta / q
        fl = BSDF_TRANSMISSION | BSDF_DELTA | BSDF_DISPERSIVE
    return -wox * inv_eta, -woy * inv_eta, wiz, fl
