"""The Principled BSDF's outer layers over the plastic (MAT_PLASTIC): a sheen on top of a coat.

The layering of Cycles' Principled BSDF (Blender 4.x/5.x, intern/cycles kernel/svm/closure.h,
the Principled node; kernel/closure/bsdf_sheen.h, bsdf_microfacet.h): the sheen is the first
layer, the coat the second, the plastic of plastic.py (specular over diffuse) the base. Each
layer weights everything below it by one minus its own directional albedo estimate towards
the viewer (wo), and the coat's tint absorbs on the way through it::

    f = f_sheen + W_s (f_coat + W_c T f_base)

    f_sheen = s R(μo, r_s) D_ltc(wi) / cos θi                  W_s = 1 − min(1, s R(μo, r_s))
    f_coat  = c F(wo·h, η_c) D G2 / (4 cos θo cos θi)          W_c = 1 − min(1, c F(μo, η_c))
    T       = 1 − c + c t^(1/cos θt),   cos θt = √(1 − (1 − μo²)/η_c²)

with μo = cos θo, s the sheen weight (times its grey tint), r_s its roughness, c the coat
weight, η_c its index (row entries 5-10, params.py) and t the coat tint per wavelength
(``kappa`` when row entry 8 is set, else 1). f_base is plastic.py's BSDF (either layering).

Coat: the GGX reflection lobe of roughness α_c with height-correlated Smith masking
(microfacet.py) and the unpolarised dielectric Fresnel factor of η_c (fresnel.py), single
scattering (Cycles sets no energy compensation on it). Its albedo estimate is the Fresnel
factor at the macro normal, F(μo, η_c): Cycles' estimate for a dielectric Fresnel (it assumes a
smooth surface), so W_c is independent of α_c. The tint is Beer's law over the path 1/cos θt
of the refracted view ray through a coat of unit thickness, normalised to t at normal
incidence and blended by c, exactly as Cycles applies it.

Sheen: the microfibre ("microflake volume") sheen of Zeltner, Burley and Chiang 2022,
"Practical Multiple-Scattering Sheen Using Linearly Transformed Cosines": f cos θi = R D_ltc
where D_ltc is a clamped cosine transformed by M with M⁻¹ = [[a, 0, b], [0, a, 0], [0, 0, 1]]
in the frame whose x axis is wo projected onto the surface::

    v = (a x + b z, a y, z),   D_ltc(wi) = max(v_z, 0)/π · (a / |v|²)²     (wi = (x, y, z))

(the cosine density of v/|v| times the Jacobian a²/|v|³ of the normalisation), a density of
directions inside the upper hemisphere (M keeps z > 0) that integrates to 1, so R is the
lobe's albedo. a(μo, r_s), b(μo, r_s) and R(μo, r_s) are the authors' fit to their
volumetric microfibre layer, the 32 × 32 table Cycles reads too (sheen_table.py; nodes i/31
in r_s and μo, read bilinearly as Cycles does, r_s clamped to [0.001, 1]); where a or R is
below 1e-5 the sheen is skipped (R = 0), as in Cycles. D_ltc is sampled exactly (a cosine
sample on the disk, mapped by M and normalised) and is the lobe's pdf. (The closed-form
fits of the same table that MaterialX uses differ from it by 5-15 % in f at grazing light.)

Like Cycles the model is not reciprocal (every weight depends on wo alone). Cycles weights
the layers below by one minus the largest of its three colour channels; here each
wavelength has its own weight, the same for the grey sheen and the untinted coat.

Sampling: a lobe with probability proportional to its albedo estimate summed over the
wavelengths: the sheen s R NW, the coat W_s c F(μo) NW, the base W_s W_c T̄ Σ_λ A_base
(T̄ the mean of T over the wavelengths, A_base the plastic's own lobe estimates,
``plastic_base_totals``); the base then picks its own lobe from the rescaled u3. The pdf
is the mixture, whichever lobe drew wi.

A row with c = s = 0 (entries 5-10 zero) is the plain plastic: ``plastic_eval`` and
``plastic_sample_dir`` (inlined into the dispatch, so the plain plastic pays one test and
no extra call) test the two entries and call plastic.py directly.
"""
import math

from ..jit import function, inline
from .common import INV_PI, clamp01, reflect_glossy
from .fresnel import fresnel_dielectric
from .microfacet import ggx_d, ggx_g1, ggx_g2, sample_ggx_vndf
from .params import (
    ALPHA_MIN, BSDF_DIFFUSE, BSDF_REFLECTION, P_COAT, P_COAT_ALPHA, P_COAT_IOR, P_COAT_TINTED, P_SHEEN,
    P_SHEEN_ROUGHNESS)
from .plastic import plastic_base_eval, plastic_base_sample_dir, plastic_base_totals
from .sheen_table import SHEEN_LTC

SHEEN_N = 32  # table nodes per axis
SHEEN_R_MIN = 1e-3  # roughness clamp (Cycles')
SHEEN_CUT = 1e-5  # a degenerate LTC (a or R below this) is skipped, as Cycles does


@inline
def _node(x, lo):
    """(i0, i1, t) of x clamped to [lo, 1] on the table's nodes i/31 (Cycles' bilinear lookup)."""
    f = min(max(x, lo), 1.0) * (SHEEN_N - 1)
    i0 = min(int(f), SHEEN_N - 1)
    i1 = min(i0 + 1, SHEEN_N - 1)
    return i0, i1, f - i0


@inline
def _bilinear(k, r0, r1, tr, m0, m1, tm):
    a = (1.0 - tm) * SHEEN_LTC[k, r0, m0] + tm * SHEEN_LTC[k, r0, m1]
    b = (1.0 - tm) * SHEEN_LTC[k, r1, m0] + tm * SHEEN_LTC[k, r1, m1]
    return (1.0 - tr) * a + tr * b


@inline
def sheen_fit(mu, r):
    """(R, a, b) of the sheen's LTC at μo = mu and roughness r (module docstring); R = 0 for
    a degenerate fit."""
    r0, r1, tr = _node(r, SHEEN_R_MIN)
    m0, m1, tm = _node(mu, 0.0)
    a = _bilinear(0, r0, r1, tr, m0, m1, tm)
    b = _bilinear(1, r0, r1, tr, m0, m1, tm)
    alb = _bilinear(2, r0, r1, tr, m0, m1, tm)
    if not (a > SHEEN_CUT) or not (alb > SHEEN_CUT):
        return 0.0, 1.0, 0.0
    return min(alb, 1.0), a, b


@inline
def _sheen_frame(wox, woy):
    """(cos φ, sin φ) of wo's azimuth: the LTC frame's x axis (any, at normal incidence)."""
    l2 = wox * wox + woy * woy
    if not (l2 > 0.0):
        return 1.0, 0.0
    il = 1.0 / math.sqrt(l2)
    return wox * il, woy * il


@inline
def sheen_density(a, b, cx, cy, wix, wiy, wiz):
    """D_ltc(wi) in the frame of wo's azimuth (cx, cy)."""
    x = cx * wix + cy * wiy
    y = cx * wiy - cy * wix
    vx = a * x + b * wiz
    vy = a * y
    l2 = vx * vx + vy * vy + wiz * wiz
    if not (wiz > 0.0) or not (l2 > 0.0):
        return 0.0
    q = a / l2
    return wiz * INV_PI * q * q


@inline
def coat_tint(p, kappa, i, c, woz):
    """T at wavelength i (module docstring)."""
    if p[P_COAT_TINTED] == 0.0:
        return 1.0
    e = p[P_COAT_IOR]
    ct = math.sqrt(max(1.0 - (1.0 - woz * woz) / (e * e), 0.0))
    t = max(kappa[i], 0.0)
    if not (ct > 0.0):
        return 1.0 - c
    return 1.0 - c + c * t ** (1.0 / ct)


@inline
def _layer_weights(p, kappa, woz, nw):
    """(s R, W_s, c F(μo), W_c, T̄, a, b) of the outer layers at μo = woz (a, b: the sheen's LTC)."""
    s = p[P_SHEEN]
    sr = 0.0
    a = 1.0
    b = 0.0
    if s > 0.0:
        alb, a, b = sheen_fit(woz, p[P_SHEEN_ROUGHNESS])
        sr = s * alb
    c = p[P_COAT]
    cf = c * fresnel_dielectric(woz, p[P_COAT_IOR]) if c > 0.0 else 0.0
    t_mean = 0.0
    for i in range(nw):
        t_mean += coat_tint(p, kappa, i, c, woz)
    return sr, 1.0 - clamp01(sr), cf, 1.0 - clamp01(cf), t_mean / nw, a, b


@inline
def _coat_alpha(p):
    return max(p[P_COAT_ALPHA], ALPHA_MIN)


@inline
def coat_lobe(p, wox, woy, woz, wix, wiy, wiz, want_f):
    """(wo·h, D G2 / (4 cos θo cos θi), visible-normal pdf of wi) of the coat's GGX."""
    al = _coat_alpha(p)
    hx = wox + wix
    hy = woy + wiy
    hz = woz + wiz
    hl = math.sqrt(hx * hx + hy * hy + hz * hz)
    if not (hl > 0.0):
        return 0.0, 0.0, 0.0
    hx /= hl
    hy /= hl
    hz /= hl
    doh = wox * hx + woy * hy + woz * hz
    d = ggx_d(hx, hy, hz, al, al)
    if not (doh > 0.0) or not (d > 0.0):
        return 0.0, 0.0, 0.0
    base = 0.0
    if want_f:
        base = d * ggx_g2(wox, woy, woz, wix, wiy, wiz, al, al) / (4.0 * woz * wiz)
    return doh, base, ggx_g1(wox, woy, woz, al, al) * d / (4.0 * woz)


@inline
def _lobe_probs(p, ra, rb, eta, woz, sr, ws, cf, wc, t_mean):
    """(q_sheen, q_coat, q_base); q_base < 0 when every lobe is black."""
    nw = ra.shape[0]
    _, t_b = plastic_base_totals(p, ra, rb, eta, woz)
    w_s = sr * nw
    w_c = ws * cf * nw
    w_b = ws * wc * t_mean * t_b
    tot = w_s + w_c + w_b
    if not (tot > 0.0):
        return 0.0, 0.0, -1.0
    return w_s / tot, w_c / tot, w_b / tot


@function
def principled_eval(p, ra, rb, eta, kappa, wox, woy, woz, wix, wiy, wiz, out_f, want_f):
    """f and pdf of the layered model (module docstring); wo, wi on the upper side."""
    nw = ra.shape[0]
    sr, ws, cf, wc, t_mean, a, b = _layer_weights(p, kappa, woz, nw)
    q_s, q_c, q_b = _lobe_probs(p, ra, rb, eta, woz, sr, ws, cf, wc, t_mean)
    pdf_b = plastic_base_eval(p, ra, rb, eta, wox, woy, woz, wix, wiy, wiz, out_f, want_f)
    if q_b < 0.0:
        if want_f:
            for i in range(nw):
                out_f[i] = 0.0
        return 0.0
    d_s = 0.0
    if sr > 0.0:
        cx, cy = _sheen_frame(wox, woy)
        d_s = sheen_density(a, b, cx, cy, wix, wiy, wiz)
    doh = 0.0
    g_c = 0.0
    pdf_c = 0.0
    if cf > 0.0:
        doh, g_c, pdf_c = coat_lobe(p, wox, woy, woz, wix, wiy, wiz, want_f)
    if want_f:
        c = p[P_COAT]
        fc = 0.0
        if doh > 0.0:
            fc = ws * c * fresnel_dielectric(doh, p[P_COAT_IOR]) * g_c
        fs = sr * d_s / wiz if wiz > 0.0 else 0.0
        for i in range(nw):
            out_f[i] = fs + fc + ws * wc * coat_tint(p, kappa, i, c, woz) * out_f[i]
    return q_s * d_s + q_c * pdf_c + q_b * pdf_b


@function
def principled_sample_dir(p, ra, rb, eta, kappa, wox, woy, woz, u1, u2, u3):
    """A direction from one lobe of the layered model, chosen by u3 (module docstring)."""
    sr, ws, cf, wc, t_mean, a, b = _layer_weights(p, kappa, woz, ra.shape[0])
    q_s, q_c, q_b = _lobe_probs(p, ra, rb, eta, woz, sr, ws, cf, wc, t_mean)
    if q_b < 0.0:
        return 0.0, 0.0, 1.0, 0
    if u3 < q_s:
        r2 = u1
        phi = 2.0 * math.pi * u2
        dr = math.sqrt(r2)
        dx = dr * math.cos(phi)
        dy = dr * math.sin(phi)
        dz = math.sqrt(max(1.0 - r2, 0.0))
        lx = dx - dz * b
        lz = dz * a
        ln = math.sqrt(lx * lx + dy * dy + lz * lz)
        if not (lz > 0.0) or not (ln > 0.0):
            return 0.0, 0.0, 1.0, 0
        cx, cy = _sheen_frame(wox, woy)
        lx /= ln
        ly = dy / ln
        return cx * lx - cy * ly, cy * lx + cx * ly, lz / ln, BSDF_REFLECTION | BSDF_DIFFUSE
    if u3 < q_s + q_c:
        al = _coat_alpha(p)
        hx, hy, hz = sample_ggx_vndf(wox, woy, woz, al, al, u1, u2)
        if not (wox * hx + woy * hy + woz * hz > 0.0):
            return 0.0, 0.0, 1.0, 0
        return reflect_glossy(wox, woy, woz, hx, hy, hz)
    u = min((u3 - q_s - q_c) / q_b, 0.9999999999999999) if q_b > 0.0 else 0.0
    return plastic_base_sample_dir(p, ra, rb, eta, wox, woy, woz, u1, u2, u)


@inline
def plastic_eval(p, ra, rb, eta, kappa, wox, woy, woz, wix, wiy, wiz, out_f, want_f):
    """MAT_PLASTIC: the plain plastic (plastic.py) or, with a coat or a sheen, the layered model."""
    if p[P_COAT] != 0.0 or p[P_SHEEN] != 0.0:
        return principled_eval(p, ra, rb, eta, kappa, wox, woy, woz, wix, wiy, wiz, out_f, want_f)
    return plastic_base_eval(p, ra, rb, eta, wox, woy, woz, wix, wiy, wiz, out_f, want_f)


@inline
def plastic_sample_dir(p, ra, rb, eta, kappa, wox, woy, woz, u1, u2, u3):
    """Sampling of ``plastic_eval``."""
    if p[P_COAT] != 0.0 or p[P_SHEEN] != 0.0:
        return principled_sample_dir(p, ra, rb, eta, kappa, wox, woy, woz, u1, u2, u3)
    return plastic_base_sample_dir(p, ra, rb, eta, wox, woy, woz, u1, u2, u3)
