"""Plastic (MAT_PLASTIC): a rough dielectric coat over a Lambertian base.

wo and wi on the upper side (the dispatch handles two-sidedness); ra = base
reflectance ρ, rb = coat tint, eta = coat index η (n_coat / n_outside) per wavelength;
F(μ) = F(μ, η) is the unpolarised dielectric Fresnel factor (fresnel.py)::

    f = f_coat + f_base
    f_coat = rb · F(wo·h) D(h) G2(wo, wi) / (4 cos θo cos θi),        h = (wo+wi)/|wo+wi|
    f_base = ρ/π · (1 − F(cos θo)) (1 − F(cos θi)) / (1 − F̄(η))

with the GGX distribution and height-correlated Smith masking of microfacet.py (the
coat is exactly the reflection lobe of the rough dielectric in ggx.py), and
F̄(η) = 2 ∫₀¹ F(μ) μ dμ, the Fresnel reflectance averaged over a diffuse hemisphere
(``fresnel_diffuse_reflectance``). Both terms are symmetric in wo and wi: the model is
reciprocal.

Coupling and its normalisation (the Kelemen–Szirmay-Kalos 2001 form, "A microfacet
based coupled specular-matte BRDF model with importance sampling": the base sees
(1 − specular albedo) on the way in and on the way out, divided by one minus its
hemispherical average so that no energy is created). The base's albedo is then exactly

    ρ_base(θo) = ρ (1 − F(cos θo)) · [2 ∫ (1 − F(μ)) μ dμ] / (1 − F̄) = ρ (1 − F(cos θo)),

and a white base under a lossless smooth coat reflects F + (1 − F) = 1 at every angle.
The same factor is the physical one of light trapped in a smooth coat: 1 − F̄(η) =
η² (1 − F̄(1/η)) (fresnel.py), so 1/(1 − F̄) = 1/(η² (1 − F̄_internal)) — the η² of the
radiance leaving the denser coat times the sum of the internal reflections of a *white*
base, the normalisation Mitsuba's roughplastic uses by default ("linear" mode). Choice:
we keep it linear in ρ (every colour of the base is scaled by the same factor, so the
base colour maps directly to the seen diffuse colour, as in Blender's Principled BSDF),
rather than the nonlinear ρ / (1 − ρ F̄_internal) of a coloured base's internal
bounces, which agrees for white and black and saturates the colours in between.

Rough coat: the Fresnel factors of the coupling use the macro-normal cosines, i.e. the
coat's specular albedo E_s(θo) is approximated by F(cos θo) (Mitsuba tabulates the
rough one instead). E_s falls below F towards grazing for rough coats (the energy every
single-scattering microfacet model loses), so a white plastic's albedo E_s + 1 − F is
below 1 there; for small α it exceeds F by a hair at mid angles (the facets' tilt raises
F more than masking removes): measured at most 7.2e-4 (η 1.33, α 0.1, θo 45°) over
α ∈ [0.01, 1], η ∈ [1.05, 3], θo ∈ [0°, 89.9°] (tests/test_bsdf.py bounds the total
albedo by 1 + 1e-3).

Sampling: the coat (GGX visible normals, wi = mirror of wo) with probability

    P_coat = Σ_λ rb F(cos θo) / Σ_λ (rb F(cos θo) + ρ (1 − F(cos θo)))

(the lobes' albedos, the coat's approximated as above, summed over the wavelengths), else
the base (cosine-weighted); the pdf is the mixture P_coat p_ggx + (1 − P_coat) cos θi/π
whichever lobe drew wi, so weights are f cos θi / pdf of the whole BSDF (MIS-consistent).
Roughness is clamped to α ≥ ALPHA_MIN = 1e-4 like the other GGX models: the coat stays a
density (no delta component) and nearly smooth there, with D ≤ 1/(π α²) ≈ 3·10⁷.

Cycles layering (row entry P_LAYERING = LAYERING_CYCLES; the Principled BSDF's default)
-------------------------------------------------------------------------------------
The layering of Cycles' Principled BSDF (Blender 4.x/5.x, intern/cycles kernel/svm/closure.h,
``closure_layering_weight``; kernel/closure/bsdf_microfacet.h): the coat is a GGX lobe with
Cycles' "generalised Schlick" Fresnel of the real curve, and the base is weighted by one
minus the coat's directional albedo *towards the viewer only*::

    f_coat = Fc(wo·h) D G2 / (4 cos θo cos θi) · k(μo),      Fc(c) = F0t + (1 − F0t) s(c)
    f_base = ρ/π · (1 − A(μo)),                               μo = cos θo

with F0 = ((η−1)/(η+1))², F0t = min(F0 rb, 1) (the tint scales the normal-incidence
reflectance only; grazing reflection stays white) and s(c) = (F(c, η) − F0)/(1 − F0).
A(μo) = (F0t + (1 − F0t) s̄) · E k is Cycles' estimate of the coat's albedo, with the
tables of layering.py: E(r, μo) the GGX albedo, s̄(r, μo, η) the mean Fresnel factor over
the visible normals, r = (α_x α_y)^¼.

Multiple scattering (row entry P_MULTISCATTER = 1; Cycles' "Multiscatter GGX", the
Principled default): k(μo) = 1 + F_ms (1 − E)/E with F_ms = F_ss Ē / (1 − F_ss (1 − Ē)),
F_ss = F0t + (1 − F0t)(F̄(η) − F0)/(1 − F0) (Kulla & Conty 2017, "Revisiting physically
based shading at Imageworks", as Cycles' ``microfacet_ggx_preserve_energy`` applies it;
F̄ is the exact hemispherical Fresnel average where Cycles uses a fit of it). Without it
(Cycles' "GGX") k = 1 and A = F0t + (1 − F0t) s̄.

This is *not* reciprocal (k and the base weight depend on wo alone) and not exactly
energy-conserving (A is an estimate). The base is weighted per wavelength by 1 − A(λ);
Cycles weights it by one minus the largest of its three colour channels, which is the
same for an untinted coat (the default) and differs for a tinted one. Sampling is the
same mixture as above with P_coat = Σ_λ A / Σ_λ (A + ρ (1 − A)), in evaluation and
sampling alike.
"""
from ..jit import function, inline
import math

from .common import INV_PI, clamp01, zero
from .fresnel import fresnel_dielectric, fresnel_diffuse_reflectance
from .ggx import _alphas, ggx_reflect_sample_dir, ggx_reflection
from .layering import ggx_albedo, ggx_albedo_avg, ggx_fresnel_mean
from .params import BSDF_GLOSSY, BSDF_REFLECTION, P_LAYERING, P_MULTISCATTER
from .phong import lambert_sample_dir


@inline
def plastic_coat_prob(ra, rb, eta, cos_o):
    """(P_coat, Σ_λ of the lobes' albedos) (see the module); P_coat -1 when both lobes are black."""
    s = 0.0
    t = 0.0
    for i in range(ra.shape[0]):
        f = fresnel_dielectric(cos_o, eta[i])
        c = clamp01(rb[i]) * f
        s += c
        t += c + clamp01(ra[i]) * (1.0 - f)
    if not (t > 0.0):
        return -1.0, 0.0
    return s / t, t


@inline
def _cycles_terms(p, woz):
    """(r, E, Ē, multiscatter) of the Cycles layering at μo = woz."""
    ax, ay = _alphas(p)
    r = math.sqrt(math.sqrt(ax * ay))
    return r, ggx_albedo(r, woz), ggx_albedo_avg(r), p[P_MULTISCATTER] != 0.0


@inline
def _cycles_layer(r, e_ss, e_avg, ms, tint, e, woz):
    """(F0, F0t, k, A) of one wavelength (module docstring, Cycles layering)."""
    f0 = ((e - 1.0) / (e + 1.0)) ** 2
    f0t = min(f0 * clamp01(tint), 1.0)
    f_est = f0t + (1.0 - f0t) * ggx_fresnel_mean(r, woz, e)
    k = 1.0
    if ms and e_ss > 0.0 and f0 < 1.0:
        s_avg = clamp01((fresnel_diffuse_reflectance(e) - f0) / (1.0 - f0))
        f_ss = f0t + (1.0 - f0t) * s_avg
        f_ms = f_ss * e_avg / (1.0 - f_ss * (1.0 - e_avg))
        k = 1.0 + f_ms * (1.0 - e_ss) / e_ss
        return f0, f0t, k, f_est * e_ss * k
    return f0, f0t, k, f_est


@inline
def _cycles_coat_prob(p, ra, rb, eta, woz):
    r, e_ss, e_avg, ms = _cycles_terms(p, woz)
    s = 0.0
    t = 0.0
    for i in range(ra.shape[0]):
        _, _, _, a_c = _cycles_layer(r, e_ss, e_avg, ms, rb[i], eta[i], woz)
        s += a_c
        t += a_c + clamp01(ra[i]) * (1.0 - clamp01(a_c))
    if not (t > 0.0):
        return -1.0, 0.0
    return s / t, t


@function
def plastic_cycles_eval(p, ra, rb, eta, wox, woy, woz, wix, wiy, wiz, out_f, want_f):
    """The Cycles layering (module docstring)."""
    doh, base, pdf_c = ggx_reflection(p, wox, woy, woz, wix, wiy, wiz, want_f)
    r, e_ss, e_avg, ms = _cycles_terms(p, woz)
    s = 0.0
    t = 0.0
    for i in range(ra.shape[0]):
        e = eta[i]
        f0, f0t, k, a_c = _cycles_layer(r, e_ss, e_avg, ms, rb[i], e, woz)
        a = clamp01(ra[i])
        s += a_c
        t += a_c + a * (1.0 - clamp01(a_c))
        if want_f:
            v = a * INV_PI * (1.0 - clamp01(a_c))
            if doh > 0.0 and f0 < 1.0:
                sc = clamp01((fresnel_dielectric(doh, e) - f0) / (1.0 - f0))
                v += (f0t + (1.0 - f0t) * sc) * base * k
            out_f[i] = v
    if not (t > 0.0):
        if want_f:
            zero(out_f)
        return 0.0
    pc = s / t
    return pc * pdf_c + (1.0 - pc) * wiz * INV_PI


@function
def plastic_base_eval(p, ra, rb, eta, wox, woy, woz, wix, wiy, wiz, out_f, want_f):
    """The plastic without the Principled outer layers (principled.py adds the coat and sheen)."""
    if p[P_LAYERING] != 0.0:
        return plastic_cycles_eval(p, ra, rb, eta, wox, woy, woz, wix, wiy, wiz, out_f, want_f)
    doh, base, pdf_c = ggx_reflection(p, wox, woy, woz, wix, wiy, wiz, want_f)
    s = 0.0
    t = 0.0
    for i in range(ra.shape[0]):  # one loop: every Fresnel call site is an inlined copy
        e = eta[i]
        fo = fresnel_dielectric(woz, e)
        a = clamp01(ra[i])
        b = clamp01(rb[i])
        s += b * fo
        t += b * fo + a * (1.0 - fo)
        if want_f:
            v = 0.0
            if a > 0.0:
                k = 1.0 - fresnel_diffuse_reflectance(e)
                if k > 0.0:
                    v = a * INV_PI * (1.0 - fo) * (1.0 - fresnel_dielectric(wiz, e)) / k
            if b > 0.0 and doh > 0.0:
                v += b * fresnel_dielectric(doh, e) * base
            out_f[i] = v
    if not (t > 0.0):
        if want_f:
            zero(out_f)
        return 0.0
    pc = s / t
    return pc * pdf_c + (1.0 - pc) * wiz * INV_PI


@function
def plastic_base_totals(p, ra, rb, eta, woz):
    """(P_coat, Σ_λ of the lobes' albedo estimates) of the sampling mixture (module docstring);
    P_coat = -1 when both lobes are black."""
    if p[P_LAYERING] != 0.0:
        return _cycles_coat_prob(p, ra, rb, eta, woz)
    return plastic_coat_prob(ra, rb, eta, woz)


@function
def plastic_base_sample_dir(p, ra, rb, eta, wox, woy, woz, u1, u2, u3):
    """Sampling of ``plastic_base_eval``."""
    pc, _ = plastic_base_totals(p, ra, rb, eta, woz)
    if pc < 0.0:
        return 0.0, 0.0, 1.0, 0
    if u3 < pc:
        x, y, z, fl = ggx_reflect_sample_dir(p, wox, woy, woz, u1, u2)
        if fl == 0:
            return 0.0, 0.0, 1.0, 0
        return x, y, z, BSDF_REFLECTION | BSDF_GLOSSY
    return lambert_sample_dir(u1, u2)
