"""Tag dispatch of the BSDF library: the interface the path tracer calls.

bsdf_eval, bsdf_pdf and bsdf_sample are ``@function``s (compiled once, called), as are
the models' evaluation and sampling functions; small helpers are ``@inline``.

Local shading frame (z = shading normal); unit directions pointing away from the
surface; wo towards the viewer, wi towards the light (radiance transport, camera paths).
``model`` is a MAT_* tag, ``p`` its float64[16] row (params.py), ``ra``, ``rb``, ``eta``,
``kappa`` float64[NW] spectra already looked up for the path's wavelengths (index 0 is
the hero).

bsdf_eval(model, p, ra, rb, eta, kappa, wo_x, wo_y, wo_z, wi_x, wi_y, wi_z, out_f) -> pdf
    f(wo, wi) per wavelength into out_f (without the cosine) and the solid-angle pdf of
    sampling wi with bsdf_sample. Delta components are never evaluated (f = 0, pdf = 0).
bsdf_pdf(model, p, ra, rb, eta, kappa, wo_x, wo_y, wo_z, wi_x, wi_y, wi_z) -> pdf
bsdf_sample(model, p, ra, rb, eta, kappa, wo_x, wo_y, wo_z, u1, u2, u3, out_w)
    -> (wi_x, wi_y, wi_z, pdf, flags)
    out_w = f |cos θi| / pdf per wavelength; for a delta event the discrete weight, pdf
    0 and BSDF_DELTA in flags. flags = 0 (and pdf 0, out_w 0) for a failed sample.
    With BSDF_DISPERSIVE only out_w[0] (the hero) is valid. u1, u2 ∈ [0, 1) drive the
    direction, u3 ∈ [0, 1) the choice of component.
bsdf_flags(model, p) -> the union of the flags the model can return.

Compile time: ``@inline`` (numba's IR inlining) deep-copies a callee's blocks together
with its whole variable scope at every call site, so the cost of inlining grows with
the square of the callee's expanded size; inlining the whole library into one kernel
took 5-10 minutes to compile. Hence the ``@function`` boundaries.

Two-sidedness (reflective models): with p[0] = 1 a wo below the surface is handled by
mirroring both directions to the upper side (z → −z); with p[0] = 0, or for any wo
exactly in the tangent plane, the BSDF is 0 and sampling fails. wi on the other side
of wo gives 0. The dielectrics are naturally two-sided (inside is z < 0).
"""
from .. import constants as C
from ..jit import function, inline
from .common import zero
from .ggx import ggx_conductor_eval, ggx_reflect_sample_dir, ggx_dielectric_eval, ggx_dielectric_sample_dir
from .lafortune import lobes_eval, lobes_sample_dir
from .params import (
    BSDF_DELTA, BSDF_DIFFUSE, BSDF_DISPERSIVE, BSDF_GLOSSY, BSDF_REFLECTION, BSDF_TRANSMISSION, P_TWO_SIDED)
from .principled import plastic_eval, plastic_sample_dir
from .phong import blinn_eval, blinn_sample_dir, lambert_eval, lambert_sample_dir
from .specular import conductor_sample, dielectric_sample, mirror_sample
from .ward import ward_eval, ward_sample_dir


@inline
def evaluate_models(model, p, ra, rb, eta, kappa, wox, woy, woz, wix, wiy, wiz, out_f, want_f):
    """The model chain of bsdf_eval / bsdf_pdf after the side handling: reflective models
    get wo and wi in the upper hemisphere; the dielectrics any directions."""
    if model == C.MAT_LAMBERT:
        return lambert_eval(ra, wix, wiy, wiz, out_f, want_f)
    elif model == C.MAT_PHONG or model == C.MAT_LAFORTUNE:
        return lobes_eval(model, p, ra, rb, wox, woy, woz, wix, wiy, wiz, out_f, want_f)
    elif model == C.MAT_BLINN_PHONG:
        return blinn_eval(p, ra, rb, wox, woy, woz, wix, wiy, wiz, out_f, want_f)
    elif model == C.MAT_WARD:
        return ward_eval(p, ra, rb, wox, woy, woz, wix, wiy, wiz, out_f, want_f)
    elif model == C.MAT_GGX_CONDUCTOR:
        return ggx_conductor_eval(p, ra, eta, kappa, wox, woy, woz, wix, wiy, wiz, out_f, want_f)
    elif model == C.MAT_GGX_DIELECTRIC:
        return ggx_dielectric_eval(p, ra, rb, eta, wox, woy, woz, wix, wiy, wiz, out_f, want_f)
    elif model == C.MAT_PLASTIC:
        return plastic_eval(p, ra, rb, eta, kappa, wox, woy, woz, wix, wiy, wiz, out_f, want_f)
    if want_f:
        zero(out_f)
    return 0.0  # delta models (mirror, smooth conductor and dielectric) and unknown tags


@inline
def sample_direction(model, p, ra, rb, eta, kappa, wox, woy, woz, u1, u2, u3, out_w):
    """The model chain of bsdf_sample: (x, y, z, flags) of a sampled wi (wo on the upper
    side for the reflective models; flags 0: no sample). Delta events write their weight
    to out_w; other samples leave it alone (bsdf_sample weights them from
    evaluate_models)."""
    if model == C.MAT_LAMBERT:
        return lambert_sample_dir(u1, u2)
    elif model == C.MAT_PHONG or model == C.MAT_LAFORTUNE:
        return lobes_sample_dir(model, p, ra, rb, wox, woy, woz, u1, u2, u3)
    elif model == C.MAT_BLINN_PHONG:
        return blinn_sample_dir(p, ra, rb, wox, woy, woz, u1, u2, u3)
    elif model == C.MAT_WARD:
        return ward_sample_dir(p, ra, rb, wox, woy, woz, u1, u2, u3)
    elif model == C.MAT_GGX_CONDUCTOR:
        return ggx_reflect_sample_dir(p, wox, woy, woz, u1, u2)
    elif model == C.MAT_GGX_DIELECTRIC:
        return ggx_dielectric_sample_dir(p, ra, eta, wox, woy, woz, u1, u2, u3, out_w)
    elif model == C.MAT_PLASTIC:
        return plastic_sample_dir(p, ra, rb, eta, kappa, wox, woy, woz, u1, u2, u3)
    elif model == C.MAT_MIRROR:
        return mirror_sample(ra, wox, woy, woz, out_w)
    elif model == C.MAT_CONDUCTOR:
        return conductor_sample(ra, eta, kappa, wox, woy, woz, out_w)
    elif model == C.MAT_DIELECTRIC:
        return dielectric_sample(ra, rb, eta, wox, woy, woz, u3, out_w)
    return 0.0, 0.0, 1.0, 0


@inline
def weight_in_place(out_w, wi_z, pdf, flags):
    """f → f |cos θi| / pdf; only the hero survives a dispersive sample."""
    c = abs(wi_z) / pdf
    out_w[0] *= c
    for i in range(1, out_w.shape[0]):
        if flags & BSDF_DISPERSIVE:
            out_w[i] = 0.0
        else:
            out_w[i] *= c


@inline
def _is_reflective(model):
    return model != C.MAT_DIELECTRIC and model != C.MAT_GGX_DIELECTRIC


@inline
def _sides(model, p, wo_z, wi_z):
    """(ok, wo_z, wi_z): the side handling of bsdf_eval / bsdf_pdf (module docstring);
    ok False where the BSDF is 0."""
    if _is_reflective(model):
        if not (wo_z > 0.0):
            if wo_z < 0.0 and p[P_TWO_SIDED] != 0.0:
                wo_z = -wo_z
                wi_z = -wi_z
            else:
                return False, wo_z, wi_z
        if not (wi_z > 0.0):
            return False, wo_z, wi_z
    return True, wo_z, wi_z


@function
def bsdf_eval(model, p, ra, rb, eta, kappa, wo_x, wo_y, wo_z, wi_x, wi_y, wi_z, out_f):
    """f(wo, wi) into out_f[NW] (no cosine); returns the pdf of sampling wi."""
    ok, wo_z, wi_z = _sides(model, p, wo_z, wi_z)
    if not ok:
        zero(out_f)
        return 0.0
    return evaluate_models(model, p, ra, rb, eta, kappa, wo_x, wo_y, wo_z, wi_x, wi_y, wi_z, out_f, True)


@function
def bsdf_pdf(model, p, ra, rb, eta, kappa, wo_x, wo_y, wo_z, wi_x, wi_y, wi_z):
    """Solid-angle pdf of sampling wi given wo (0 for delta components): bsdf_eval's code
    with want_f = False (out_f is never written; ra stands in for it)."""
    ok, wo_z, wi_z = _sides(model, p, wo_z, wi_z)
    if not ok:
        return 0.0
    return evaluate_models(model, p, ra, rb, eta, kappa, wo_x, wo_y, wo_z, wi_x, wi_y, wi_z, ra, False)


@function
def bsdf_sample(model, p, ra, rb, eta, kappa, wo_x, wo_y, wo_z, u1, u2, u3, out_w):
    """Draw wi: (wi_x, wi_y, wi_z, pdf, flags); out_w = f |cos θi| / pdf (or the delta weight).

    Non-delta samples are weighted from the model's own evaluation, so the weight is
    exactly eval·|cos|/pdf.
    """
    flip = False
    if _is_reflective(model) and not (wo_z > 0.0):
        if wo_z < 0.0 and p[P_TWO_SIDED] != 0.0:
            flip = True
            wo_z = -wo_z
        else:
            zero(out_w)
            return 0.0, 0.0, 1.0, 0.0, 0
    x, y, z, fl = sample_direction(model, p, ra, rb, eta, kappa, wo_x, wo_y, wo_z, u1, u2, u3, out_w)
    if fl == 0:
        zero(out_w)
        return 0.0, 0.0, 1.0, 0.0, 0
    pdf = 0.0
    if (fl & BSDF_DELTA) == 0:
        pdf = evaluate_models(model, p, ra, rb, eta, kappa, wo_x, wo_y, wo_z, x, y, z, out_w, True)
        if not (pdf > 0.0):
            zero(out_w)
            return 0.0, 0.0, 1.0, 0.0, 0
        weight_in_place(out_w, z, pdf, fl)
    if flip:
        z = -z
    return x, y, z, pdf, fl


@inline
def bsdf_flags(model, p):
    """Static flags: the union of what bsdf_sample may return for a generic eta.

    DISPERSIVE is not static (it depends on eta per call); nor is the DELTA
    pass-through of an index-matched (eta = 1) rough dielectric."""
    if model == C.MAT_LAMBERT:
        return BSDF_REFLECTION | BSDF_DIFFUSE
    elif (model == C.MAT_PHONG or model == C.MAT_BLINN_PHONG or model == C.MAT_WARD or model == C.MAT_LAFORTUNE
          or model == C.MAT_PLASTIC):
        return BSDF_REFLECTION | BSDF_DIFFUSE | BSDF_GLOSSY
    elif model == C.MAT_MIRROR or model == C.MAT_CONDUCTOR:
        return BSDF_REFLECTION | BSDF_DELTA
    elif model == C.MAT_DIELECTRIC:
        return BSDF_REFLECTION | BSDF_TRANSMISSION | BSDF_DELTA
    elif model == C.MAT_GGX_CONDUCTOR:
        return BSDF_REFLECTION | BSDF_GLOSSY
    elif model == C.MAT_GGX_DIELECTRIC:
        return BSDF_REFLECTION | BSDF_TRANSMISSION | BSDF_GLOSSY
    return 0
