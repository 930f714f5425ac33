"""The spectral path tracer kernel.

Bounces are counted as in Cycles: ``max_depth`` = 0 renders direct light only, and a
path may scatter at most ``max_depth + 1`` times.

Per path: N_WAVELENGTHS wavelengths (a hero and equally offset companions in the
primary sample space of the visible-wavelength density), next-event estimation on
emitters (emissive triangles and analytic area lights, chosen in proportion to their
power) combined with cosine-weighted BSDF sampling by the power heuristic (compendium
items 27–28, 51–52), and Russian roulette. An emissive triangle is sampled uniformly in
the solid angle it subtends (item 22, Arvo's spherical triangles) when that solid angle is
in a range given by the render settings (large, near emitters), else by area. Radiance becomes CIE XYZ per sample and is
summed into the film: X, Y, Z, sample count, Y².

Every random number is a pure function of (seed, pixel, sample, dimension), and each
pixel's samples are summed in sample order, so the film is bit-identical whatever the
number of threads or the split of samples into passes.
"""
import math
from typing import NamedTuple

import numpy as np
from .. import constants as C
from ..jit import fragment, function, inline, kernel
from ..bsdfs.dispatch import bsdf_eval, bsdf_flags, bsdf_sample
from ..bsdfs.common import clamp01
from ..bsdfs.params import (
    ALPHA_MIN, BSDF_DELTA, BSDF_DIFFUSE, BSDF_DISPERSIVE, BSDF_GLOSSY, P_TWO_SIDED)
from ..bsdfs.phong import lambert_sample_dir
from ..media import kernel as media
from ..textures import kernel as tex
from ..shading.interp import run as run_program
from ..geometry.bvh import STACK_SIZE, trace_closest, trace_occluded, triangle_normal, uidx
from ..geometry.visibility import (
    HIDE_DIFFUSE, HIDE_GLOSSY, HIDE_TRANSMISSION, HIDE_VOLUME, NEE_ONLY, NO_SHADOW, RAY_CAMERA, RAY_DIFFUSE,
    RAY_GLOSSY, RAY_TRANSMISSION, RAY_VOLUME)
from ..camera.kernel import CAM_LENS_R, camera_ray
from ..lights.kernel import env_lookup, env_sample, hit_light, sample_light, sun_hit
from ..sampling.qmc import pixel_seed, qmc_sample
from ..sampling.sphtri import SMALL_SOLID_ANGLE, sample_spherical_triangle, spherical_triangle_solid_angle
from ..sampling.tags import RANDOMIZE_OWEN, SAMPLER_INDEPENDENT
from ..spectra.kernel import lookup
from ..sampling.rng import path_key, shift_32, sobol_02, sobol_pair, sobol_pair_both, uniform

NW = C.N_WAVELENGTHS
LMIN = C.LAMBDA_MIN
LMAX = C.LAMBDA_MAX
LSTEP = C.LAMBDA_STEP
NL = C.N_LAMBDA
INV_PI = 1.0 / math.pi

# Visible-wavelength density p(λ) on [LMIN, LMAX]: a mixture of (1 − VIS_MIX) sech²(B (λ − λc))
# (the constants of pbrt-v4's SampleVisibleWavelengths, Pharr, Jakob, Humphreys 2023, §4.6.5,
# which follows the CIE Y curve with heavier tails) and VIS_MIX x̄ + ȳ + z̄ (CIE 1931), each
# normalised. The sech² alone puts few of a path's four equally spaced wavelengths under z̄'s
# narrow blue peak: one sample's Z then scatters by ±50 % (a flat spectrum), which is what
# makes a rare bright path a coloured firefly. With the mixture the per-sample spread of a
# flat spectrum's X, Y, Z is 7 %, 1.4 %, 19 % instead of 8.5 %, 3 %, 50 % (``VIS_LAM``).
VIS_B = 0.0072
VIS_C = 538.0
VIS_MIX = 0.3
VIS_N = 1024  # entries of the inverse cdf table


def _visible_table():
    """λ(u) at VIS_N equally spaced u in [0, 1]: the inverse of the mixture's cdf (trapezoids on
    the 1 nm grid). λ(u) is sampled by linear interpolation in this table, so the density that
    draws is exactly piecewise constant, 1 / ((VIS_N − 1) Δλ) in each interval."""
    from ..io import presets

    grid = np.arange(LMIN, LMAX + 0.5 * LSTEP, LSTEP)
    wl, xyz = presets.cmfs("1931")
    cie = sum(np.interp(grid, wl, xyz[:, k], left=0.0, right=0.0) for k in range(3))
    sech = 1.0 / np.cosh(VIS_B * (grid - VIS_C)) ** 2

    def unit(f):
        return f / np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(grid))

    pdf = (1.0 - VIS_MIX) * unit(sech) + VIS_MIX * unit(cie)
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (pdf[1:] + pdf[:-1]) * np.diff(grid))])
    table = np.interp(np.linspace(0.0, 1.0, VIS_N), cdf / cdf[-1], grid)
    table[0], table[-1] = LMIN, LMAX
    return np.ascontiguousarray(table)


VIS_LAM = _visible_table()

# The stratified sampler's Sobol dimensions: the camera (0-4) and two bounces of light and
# BSDF samples (5 per bounce without mixes or media: light pick, light pair, BSDF pair).
STRATIFIED_DIMS = 17

# Ray offset against self-intersection: relative to the scene's coordinate magnitude.
EPS_REL = 1e-5
RR_MAX_SURVIVAL = 0.95  # Russian roulette: the most a path's survival probability can be (``_roulette``)
WORK_ROWS = 11  # rows of render_rows' scratch ``work``: λ, pdf(λ), β, L, ρa, ρb, η, κ, f, Le, λ cell fraction



@function
def sample_dimension(sampler, index, dim, pseed, n):
    """Dimension ``dim`` of sample ``index`` of the low-discrepancy samplers, for the pixel
    with seed ``pseed``: the stratified sampler's pixel-filter pair (dimensions 1, 2) from a
    digitally shifted Sobol (0, 2) sequence (stratified positions in the pixel: what makes
    edges of bright emitters converge), its lens pair 3-4 and then pairs 2k, 2k + 1 (so the
    light and BSDF pairs of the first bounces are aligned) each from its own scrambled and
    shuffled (0, 2)-sequence; or dimension ``dim`` of an Owen-scrambled Halton or
    Hammersley set of ``n`` points. Compiled as a function of its own: the path kernel
    draws a number at some twenty places, and inlined at each of them this code would
    multiply the kernel's compile time."""
    if sampler == C.SAMPLER_STRATIFIED:
        if dim == 1 or dim == 2:
            return sobol_02(index, dim - 1, shift_32(pseed, dim))
        if dim == 3 or dim == 4:
            return sobol_pair(index, dim - 3, pseed, 1)
        return sobol_pair(index, dim & 1, pseed, dim >> 1)
    return qmc_sample(sampler, RANDOMIZE_OWEN, index, dim, pseed, n)


@inline
def rnd(sampler, key, pseed, index, dim, n):
    """The path's sample in dimension ``dim``: the counter RNG for the independent sampler
    and for the stratified sampler's dimensions past the first two bounces (which carry
    little of the image's variance), else the low-discrepancy point (whose dimensions past
    the prime table fall back to a hash of (pixel seed, index, dimension), as pbrt's
    samplers do). Only the hash is inlined; the rest is one call."""
    if sampler == SAMPLER_INDEPENDENT or (sampler == C.SAMPLER_STRATIFIED and dim >= STRATIFIED_DIMS):
        return uniform(key, dim)
    # np.int64(...): a literal dimension (0 ... 4 at the camera) would otherwise compile
    # one specialisation per literal value
    return sample_dimension(sampler, np.int64(index), np.int64(dim), pseed, np.int64(n))


@function
def rnd_f(sampler, key, pseed, index, dim, n):
    """``rnd`` as a function call: for the draws made once per sample or per medium event,
    so that only the hot surface draws are inlined into the path kernel (each inlined
    draw adds to its compile time)."""
    return rnd(sampler, key, pseed, np.int64(index), np.int64(dim), np.int64(n))


@function
def sample_pair(sampler, index, dim, pseed, n):
    """Dimensions ``dim`` and ``dim + 1`` of sample ``index`` (the low-discrepancy samplers, as
    ``sample_dimension``) in one call: for the stratified sampler's aligned pairs (even
    ``dim`` ≥ 6, one scrambled (0, 2)-sequence per pair) the pair's hash and shuffled index
    are computed once."""
    if sampler == C.SAMPLER_STRATIFIED and dim >= 6 and (dim & 1) == 0:
        return sobol_pair_both(index, pseed, dim >> 1)
    return sample_dimension(sampler, index, dim, pseed, n), sample_dimension(sampler, index, dim + 1, pseed, n)


@inline
def rnd2(sampler, key, pseed, index, dim, n):
    """``(rnd(..., dim, n), rnd(..., dim + 1, n))``, the same two values: the hot surface
    pairs (light sample, BSDF sample) in one sampler call."""
    if sampler == SAMPLER_INDEPENDENT or (sampler == C.SAMPLER_STRATIFIED and dim >= STRATIFIED_DIMS):
        return uniform(key, dim), uniform(key, dim + 1)
    if sampler == C.SAMPLER_STRATIFIED and dim + 1 >= STRATIFIED_DIMS:
        return sample_dimension(sampler, np.int64(index), np.int64(dim), pseed, np.int64(n)), uniform(key, dim + 1)
    return sample_pair(sampler, np.int64(index), np.int64(dim), pseed, np.int64(n))


@inline
def sample_visible(u):
    """A wavelength drawn from p(λ) with the uniform u in [0, 1), and p(λ): linear
    interpolation in the inverse cdf table VIS_LAM."""
    x = u * (VIS_N - 1)
    k = min(max(int(x), 0), VIS_N - 2)
    a = VIS_LAM[k]
    b = VIS_LAM[k + 1]
    return min(max(a + (x - k) * (b - a), LMIN), LMAX), 1.0 / ((VIS_N - 1) * (b - a))


@inline
def visible_pdf(lam):
    """p(λ) of ``sample_visible``: 1 / ((VIS_N − 1) Δλ) of the table interval holding λ."""
    k = min(max(np.searchsorted(VIS_LAM, lam, side="right") - 1, 0), VIS_N - 2)
    return 1.0 / ((VIS_N - 1) * (VIS_LAM[k + 1] - VIS_LAM[k]))


@inline
def lookup_cmf(cmf, k, lam):
    x = (lam - LMIN) / LSTEP
    i = int(x)
    if i < 0 or i >= NL - 1:
        return 0.0
    f = x - i
    c = uidx(i)
    return cmf[c, k] * (1.0 - f) + cmf[c + uidx(1), k] * f


@inline
def terminate_secondary(pdf_lam):
    """After a dispersive event only the hero wavelength's path is valid (Wilkie et al.
    2014): the companions are dropped and the hero's estimate is no longer averaged
    with theirs."""
    pdf_lam[0] /= NW
    for i in range(1, NW):
        pdf_lam[i] = 0.0


@inline
def power_heuristic(pa, pb):
    a = pa * pa
    b = pb * pb
    if a + b <= 0.0:
        return 0.0
    return a / (a + b)


@function
def _sph_triangle(tp, px, py, pz, v0, e1, e2, sph_lo, sph_hi, ua, ub):
    """The solid-angle branch of emissive-triangle sampling (compendium item 22), compiled
    once as a function of its own (Arvo's construction inlined at each caller would add to
    the path kernel's compile time).

    The rule depends on p and the triangle only: with Ω the triangle's solid angle seen
    from p (Van Oosterom–Strackee), the triangle is sampled uniformly in solid angle when
    max(sph_lo, SMALL_SOLID_ANGLE) ≤ Ω ≤ sph_hi, else by area. Returns (Ω, wx, wy, wz):
    Ω = 0 when the rule picks area sampling; the direction is drawn (Arvo 1995) only when
    ua ≥ 0 (ua < 0: just the rule and Ω, for the MIS weight of a BSDF-sampled hit). The
    corners are taken relative to p in the same float operations for both uses, so the
    NEE and the MIS weight see the same Ω."""
    ax = v0[tp, 0] - px
    ay = v0[tp, 1] - py
    az = v0[tp, 2] - pz
    bx = ax + e1[tp, 0]
    by = ay + e1[tp, 1]
    bz = az + e1[tp, 2]
    cx = ax + e2[tp, 0]
    cy = ay + e2[tp, 1]
    cz = az + e2[tp, 2]
    om = spherical_triangle_solid_angle(ax, ay, az, bx, by, bz, cx, cy, cz)
    if not (om >= max(sph_lo, SMALL_SOLID_ANGLE) and om <= sph_hi):
        return 0.0, 0.0, 0.0, 1.0
    if ua < 0.0:
        return om, 0.0, 0.0, 1.0
    wx, wy, wz, pdf = sample_spherical_triangle(ax, ay, az, bx, by, bz, cx, cy, cz, ua, ub)
    if not (pdf > 0.0):
        return 0.0, 0.0, 0.0, 1.0
    return om, wx, wy, wz


@inline
def _triangle_sample(tp, ua, ub, px, py, pz, v0, e1, e2, tri_mat, mat_emis, mat_emis_scale, mat_emis_two, sph_lo,
                     sph_hi):
    """A direction towards emissive triangle ``tp`` seen from p: (wx, wy, wz, dist, solid-angle
    pdf, fac, spectrum row, scale); fac = 0 when the triangle shows p its back (one-sided
    emitters) or nothing.

    Two strategies, chosen by a rule of (p, triangle) alone (``_sph_triangle``): uniform in
    the triangle's solid angle Ω when sph_lo ≤ Ω ≤ sph_hi (pdf 1/Ω: no 1/r² nor emitter
    cosine left in the estimate, which matters for large, near emitters), else a uniform
    point on its area (pdf r² / (A cos θ_y)). The MIS weight of a BSDF-sampled ray that hits
    the triangle applies the same rule (render_rows). The emitted radiance is constant over
    the triangle, so in either measure fac is 1 on the emitting side."""
    lnx, lny, lnz = triangle_normal(e1, e2, tp)
    ll = math.sqrt(lnx * lnx + lny * lny + lnz * lnz)
    lm = tri_mat[tp]
    # which side of the plane p is on (the same for every point of the triangle)
    hgt = (px - v0[tp, 0]) * lnx + (py - v0[tp, 1]) * lny + (pz - v0[tp, 2]) * lnz
    if ll == 0.0 or hgt == 0.0 or (hgt < 0.0 and mat_emis_two[lm] == 0):
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, mat_emis[lm], 0.0
    # Ω ≤ A / h² (h: p's distance to the plane): most small, far emitters never call the branch
    if sph_lo <= sph_hi and ll * ll * ll >= 2.0 * sph_lo * hgt * hgt:
        om, wx, wy, wz = _sph_triangle(np.int64(tp), px, py, pz, v0, e1, e2, sph_lo, sph_hi, ua, ub)
        if om > 0.0:
            # distance to the triangle's plane along w
            wn = -(wx * lnx + wy * lny + wz * lnz)
            if hgt * wn <= 0.0:
                return wx, wy, wz, 0.0, 0.0, 0.0, mat_emis[lm], 0.0
            return wx, wy, wz, hgt / wn, 1.0 / om, 1.0, mat_emis[lm], mat_emis_scale[lm]
    su = math.sqrt(ua)
    b1 = 1.0 - su
    b2 = ub * su
    wx = v0[tp, 0] + b1 * e1[tp, 0] + b2 * e2[tp, 0] - px
    wy = v0[tp, 1] + b1 * e1[tp, 1] + b2 * e2[tp, 1] - py
    wz = v0[tp, 2] + b1 * e1[tp, 2] + b2 * e2[tp, 2] - pz
    d2 = wx * wx + wy * wy + wz * wz
    dist = math.sqrt(d2)
    if dist == 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, mat_emis[lm], 0.0
    wx /= dist
    wy /= dist
    wz /= dist
    cos_y = -(lnx * wx + lny * wy + lnz * wz) / ll
    if cos_y < 0.0 and mat_emis_two[lm] != 0:
        cos_y = -cos_y
    if cos_y <= 0.0:
        return wx, wy, wz, dist, 0.0, 0.0, mat_emis[lm], 0.0
    return wx, wy, wz, dist, d2 / (0.5 * ll * cos_y), 1.0, mat_emis[lm], mat_emis_scale[lm]


@function
def _emitter_sample(ei, ua, ub, px, py, pz, lam, le, geo, mat, emt, st):
    """Emitter ``ei`` sampled from p, as the surface NEE does: (wx, wy, wz, dist, solid-angle
    pdf (inf: delta), fac) and its emitted spectral radiance (or intensity) into ``le``.
    Used by the surface NEE for analytic lights and the world, and at scattering points in
    media (``_medium_scatter``)."""
    v0 = geo.v0
    e1 = geo.e1
    e2 = geo.e2
    tri_mat = geo.tri_mat
    mat_emis = mat.emis
    mat_emis_scale = mat.emis_scale
    mat_emis_two = mat.emis_two
    spec = mat.spec
    light_kind = emt.light_kind
    light_geo = emt.light_geo
    light_prof = emt.light_prof
    light_spec = emt.light_spec
    light_scale = emt.light_scale
    light_two_sided = emt.light_two_sided
    emit_tri = emt.emit_tri
    emit_light = emt.emit_light
    world_img = emt.world_img
    world_dist = emt.world_dist
    world_par = emt.world_par
    world_row = emt.world_row
    sph_lo = st.sph_lo
    sph_hi = st.sph_hi
    if emit_tri[ei] >= 0:
        wx, wy, wz, dist, lpdf, fac, l_row, l_scale = _triangle_sample(
            emit_tri[ei], ua, ub, px, py, pz, v0, e1, e2, tri_mat, mat_emis, mat_emis_scale, mat_emis_two, sph_lo,
            sph_hi)
        for i in range(NW):
            le[i] = l_scale * lookup(spec, l_row, lam[i])
    elif emit_light[ei] >= 0:
        li = emit_light[ei]
        wx, wy, wz, dist, lpdf, fac = sample_light(light_kind[li], light_geo, light_prof, li, light_two_sided[li] != 0,
                                                   px, py, pz, ua, ub)
        for i in range(NW):
            le[i] = light_scale[li] * lookup(spec, light_spec[li], lam[i])
    else:  # the world image
        wx, wy, wz, lpdf, cr, cg, cb = env_sample(world_img, world_dist, world_par, ua, ub)
        dist = np.inf
        fac = 1.0
        cr *= world_par[2]
        cg *= world_par[2]
        cb *= world_par[2]
        for i in range(NW):
            le[i] = (cr * lookup(spec, world_row, lam[i]) + cg * lookup(spec, world_row + 1, lam[i])
                     + cb * lookup(spec, world_row + 2, lam[i]))
    return wx, wy, wz, dist, lpdf, fac



@inline
def _shadow_tmax(dist, eps, tp, ox, oy, oz, wx, wy, wz, v0, e1, e2):
    """How far the NEE shadow ray from the offset origin o (the shading point moved eps off
    its surface) towards a light sample ``dist`` away from the shading point may look for
    occluders: short of the sample by a relative 1e-4 and eps, and, when the sample lies on
    emissive triangle ``tp`` (-1: an analytic light or the world), short of that triangle's
    plane as seen from o. Measured from the shading point alone, a grazing sample's own
    triangle could come before the cut-off and block it (the plane is nearer to o by about
    eps / cos along the ray), which lost light from large emitters in large scenes."""
    if dist == np.inf:
        return np.inf
    tmax = dist * (1.0 - 1e-4) - eps
    if tp >= 0:
        nx, ny, nz = triangle_normal(e1, e2, tp)
        den = wx * nx + wy * ny + wz * nz
        if den != 0.0:
            tpl = ((v0[tp, 0] - ox) * nx + (v0[tp, 1] - oy) * ny + (v0[tp, 2] - oz) * nz) / den
            if tpl > 0.0:
                tmax = min(tmax, tpl * (1.0 - 1e-4))
    return tmax


@inline
def _lambert_eval(pm, ra, woz, wiz, fv):
    """bsdf_eval for MAT_LAMBERT, inline (the same arithmetic, so the same bits): the
    commonest material skips the dispatch's function call."""
    if not (woz > 0.0):
        if woz < 0.0 and pm[P_TWO_SIDED] != 0.0:
            wiz = -wiz
        else:
            for i in range(NW):
                fv[i] = 0.0
            return 0.0
    if not (wiz > 0.0):
        for i in range(NW):
            fv[i] = 0.0
        return 0.0
    for i in range(NW):
        fv[i] = clamp01(ra[i]) * INV_PI
    return wiz * INV_PI


@inline
def _lambert_sample(pm, ra, woz, u1, u2, fv):
    """bsdf_sample for MAT_LAMBERT, inline (same arithmetic as core.bsdfs.dispatch)."""
    flip = False
    if not (woz > 0.0):
        if woz < 0.0 and pm[P_TWO_SIDED] != 0.0:
            flip = True
        else:
            return 0.0, 0.0, 1.0, 0.0, 0
    x, y, z, fl = lambert_sample_dir(u1, u2)
    if fl == 0:
        return 0.0, 0.0, 1.0, 0.0, 0
    pdf = z * INV_PI
    if not (pdf > 0.0):
        return 0.0, 0.0, 1.0, 0.0, 0
    c = abs(z) / pdf
    for i in range(NW):
        fv[i] = clamp01(ra[i]) * INV_PI * c
    if flip:
        z = -z
    return x, y, z, pdf, fl


@inline
def lam_cell(lam):
    """The 1 nm grid cell and fraction of wavelength ``lam``, clamped as ``lookup`` clamps:
    a path's wavelengths are fixed, so the path kernel finds them once per path and reads
    every spectrum with ``at`` (the same values as ``lookup``, without its branches)."""
    x = (lam - LMIN) / LSTEP
    i = int(x)
    if i < 0:
        return 0, 0.0
    if i >= NL - 1:
        return NL - 2, 1.0
    return i, x - i


@inline
def at(table, row, li, lf):
    """Row ``row`` (≥ 0) of a (rows, N_LAMBDA) table at the wavelength of cell ``li``, fraction
    ``lf`` (unsigned indices: no wraparound code)."""
    r = uidx(row)
    c = uidx(li)
    return table[r, c] * (1.0 - lf) + table[r, c + uidx(1)] * lf


@inline
def _lookup_material(m, lc, lf, spec, ior_tab, mat_ra, mat_rb, mat_eta, mat_kappa, mat_ior, ra, rb, eta, kappa):
    r_a = mat_ra[m]
    r_b = mat_rb[m]
    r_e = mat_eta[m]
    r_k = mat_kappa[m]
    for i in range(NW):
        ra[i] = at(spec, r_a, lc[i], lf[i]) if r_a >= 0 else 0.0
        rb[i] = at(spec, r_b, lc[i], lf[i]) if r_b >= 0 else 1.0
        eta[i] = at(ior_tab, r_e, lc[i], lf[i]) if r_e >= 0 else mat_ior[m]
        kappa[i] = at(ior_tab, r_k, lc[i], lf[i]) if r_k >= 0 else 0.0


@function
def _light_hits(sensing, depth, blocked, t_end, t_lo, o, d, full_weight, prev_pdf, medium, scr, spec, emt, vis, rc):
    """Add the emission of the analytic lights the ray (o, d) meets before t_end to L
    (they are hit for their emission and never occlude, as in Cycles). ``sensing``: a
    camera ray of the measuring pass (lights unseen); ``blocked``: the ray hit a surface
    or scattered in a medium (the sun, at infinity, is not reached); ``full_weight``: the
    previous vertex was a delta event or NEE is off (weight 1, else the power heuristic
    against the light's NEE pdf; the analytic lights are the last entries of the emitter
    table). o, d: the ray's origin and direction; scr: the path's ``Scratch``; spec: the
    spectrum table; emt: the emitters record; vis: the visibility record (None: none) and rc
    = (ray class, receiving triangle) of the ray (``_vis_hit``)."""
    ox, oy, oz = o
    dx, dy, dz = d
    mw = scr.mw
    beta = scr.work[2]
    rad = scr.work[3]
    lf = scr.work[10]
    lc = scr.lc
    light_kind = emt.light_kind
    light_geo = emt.light_geo
    light_prof = emt.light_prof
    light_spec = emt.light_spec
    light_scale = emt.light_scale
    light_two_sided = emt.light_two_sided
    light_visible = emt.light_visible
    emit_prob = emt.emit_prob
    n_lights = light_kind.shape[0]
    n_emit = emit_prob.shape[0]
    for li in range(n_lights):
        if depth == 0 and (light_visible[li] == 0 or sensing):
            continue
        if vis is not None and n_emit > 0 and not _vis_hit(vis, n_emit - n_lights + li, rc, full_weight):
            continue
        lk = light_kind[li]
        if lk == C.LIGHT_SUN:
            if blocked:
                continue
            fac, lpdf = sun_hit(light_geo, li, dx, dy, dz)
            tl = np.inf
        else:
            tl, fac, lpdf = hit_light(lk, light_geo, light_prof, li, light_two_sided[li] != 0,
                                      ox, oy, oz, dx, dy, dz, t_end)
            if tl == np.inf or tl <= t_lo:
                continue
        if fac <= 0.0:
            continue
        w = 1.0
        if not full_weight:
            w = power_heuristic(prev_pdf, emit_prob[n_emit - n_lights + li] * lpdf)
        media.arrival(medium, mw, tl - t_lo)
        for i in range(NW):
            rad[i] += beta[i] * w * fac * light_scale[li] * at(spec, light_spec[li], lc[i], lf[i]) \
                * mw[media.MW_TR, i]


@inline
def _vis_hit(vis, e, rc, full_weight):
    """Whether a ray of class rc[0] leaving triangle rc[1] (-1: none, the camera or a medium)
    counts emitter ``e`` it meets (core/geometry/visibility.py): not when the emitter is
    hidden from that class, nor a receiver the emitter is not linked to, nor (unless
    ``full_weight``: after a delta event, or without NEE) an emitter of ``NEE_ONLY``."""
    rclass, rcv = rc
    h = vis.emit_hide[e]
    if rclass != RAY_CAMERA and (h & (1 << rclass)) != 0:
        return False
    if (h & NEE_ONLY) != 0 and not full_weight:
        return False
    if rcv >= 0 and vis.rcv_ok[vis.tri_rcv[rcv], vis.emit_rgrp[e]] == 0:
        return False
    return True


@inline
def _vis_nee(vis, e, prim, model, pm, woz, cos_n, fac, lpdf):
    """Next-event estimation of emitter ``e`` at triangle ``prim`` under the visibility
    record: fac 0 when the emitter does not light the triangle (light linking) or is hidden
    from the scattering towards it (transmission when the light lies on the other side of
    the surface from wo, else the material's kind: diffuse, glossy, or both, which is hidden
    only when both are); an ``NEE_ONLY`` emitter's sample as a delta light's (fac / pdf, pdf
    ∞: weight 1, no MIS). Returns (fac, lpdf, no shadow test)."""
    h = vis.emit_hide[e]
    if vis.rcv_ok[vis.tri_rcv[prim], vis.emit_rgrp[e]] == 0:
        return 0.0, lpdf, False
    if (h & (HIDE_DIFFUSE | HIDE_GLOSSY | HIDE_TRANSMISSION)) != 0:
        if woz * cos_n < 0.0:
            hid = (h & HIDE_TRANSMISSION) != 0
        else:
            fl = bsdf_flags(model, pm)
            dif = (fl & BSDF_DIFFUSE) != 0
            glo = (fl & BSDF_GLOSSY) != 0
            if dif and glo:
                hid = (h & HIDE_DIFFUSE) != 0 and (h & HIDE_GLOSSY) != 0
            elif dif:
                hid = (h & HIDE_DIFFUSE) != 0
            else:
                hid = (h & HIDE_GLOSSY) != 0
        if hid:
            return 0.0, lpdf, False
    if (h & NEE_ONLY) != 0 and lpdf != np.inf and lpdf > 0.0:
        fac = fac / lpdf
        lpdf = np.inf
    return fac, lpdf, (h & NO_SHADOW) != 0


@function
def _occluded_linked(vis, sgrp, o, d, tmax, eps, nodes, tris, stack):
    """Whether something that casts the shadows of shadow group ``sgrp`` lies on the ray (o, d)
    before tmax: the closest hits in turn, passing triangles of a blocker class that does
    not occlude the group (shadow visibility off, or not in the emitter's blockers)."""
    ox, oy, oz = o
    dx, dy, dz = d
    t_lo = 0.0
    while True:
        t, prim, _bu, _bv = trace_closest(ox, oy, oz, dx, dy, dz, t_lo, tmax, nodes, tris, stack)
        if prim < 0 or not t < tmax:
            return False
        if vis.blk_ok[vis.tri_blk[prim], sgrp] != 0:
            return True
        t_lo = t + eps


@inline
def _ray_class(flags, wiz, woz):
    """The class of a bounce (core/geometry/visibility.py) from the sampled lobe's flags and
    the sides of wi and wo: transmission, diffuse, else glossy."""
    if wiz * woz < 0.0:
        return RAY_TRANSMISSION
    if (flags & BSDF_DIFFUSE) != 0:
        return RAY_DIFFUSE
    return RAY_GLOSSY


@function
def _world_hit(d, full_weight, prev_pdf, scr, spec, emt):
    """Add the world's radiance seen along d to the path's L: the equirectangular image (MIS
    weighted against its NEE pdf unless ``full_weight``) or the constant spectrum."""
    dx, dy, dz = d
    beta = scr.work[2]
    rad = scr.work[3]
    lf = scr.work[10]
    lc = scr.lc
    world_spec = emt.world_spec
    world_scale = emt.world_scale
    world_img = emt.world_img
    world_dist = emt.world_dist
    world_par = emt.world_par
    world_row = emt.world_row
    world_emit = emt.world_emit
    emit_prob = emt.emit_prob
    if world_par[3] > 0.0:
        tr, tg, tb, wpdf = env_lookup(world_img, world_dist, world_par, dx, dy, dz)
        w = 1.0
        if not full_weight and world_emit >= 0:
            w = power_heuristic(prev_pdf, emit_prob[world_emit] * wpdf)
        cr = w * world_par[2] * tr
        cg = w * world_par[2] * tg
        cb = w * world_par[2] * tb
        for i in range(NW):
            rad[i] += beta[i] * (cr * at(spec, world_row, lc[i], lf[i]) + cg * at(spec, world_row + 1, lc[i], lf[i])
                                 + cb * at(spec, world_row + 2, lc[i], lf[i]))
    elif world_spec >= 0:
        for i in range(NW):
            rad[i] += beta[i] * world_scale * at(spec, world_spec, lc[i], lf[i])


@function
def _textures(m, prim, bu, bv, sn, d, cos_i, pm, scr, spec, txr):
    """Material ``m``'s image textures at the hit (prim, bu, bv): the base colour texel's
    rgb uplifted into ``ra`` (ρ(λ) = r B_r + g B_g + b B_b, Mallett–Yuksel, basis rows
    tex_row..), the roughness texel as GGX α = roughness² on both axes in a copy of the
    parameter row ``pm`` written to ``pm_tex``, and the normal map applied to the shading
    normal, kept only on the side the ray comes from (as the interpolated normal).
    Returns (base colour textured, roughness textured, r, g, b, shading normal).
    sn: the shading normal, d: the ray's direction, scr: the path's ``Scratch`` (ρa and the
    textured parameter row are written there), txr: the textures record."""
    snx, sny, snz = sn
    dx, dy, dz = d
    pm_tex = scr.pm_tex
    ra = scr.work[4]
    lf = scr.work[10]
    lc = scr.lc
    tex_row = txr.tex_row
    tri_tex = txr.tri_tex
    tex_data = txr.tex_data
    tex_info = txr.tex_info
    mat_tex = txr.mat_tex
    mat_nstr = txr.mat_nstr
    t_base = mat_tex[m, 0]
    t_rough = mat_tex[m, 1]
    t_nrm = mat_tex[m, 2]
    tu, tv = tex.hit_uv(tri_tex, prim, bu, bv)
    cr = 0.0
    cg = 0.0
    cb = 0.0
    if t_base >= 0:
        cr, cg, cb = tex.sample(tex_data, tex_info, t_base, tu, tv)
        for i in range(NW):
            ra[i] = (cr * at(spec, tex_row, lc[i], lf[i]) + cg * at(spec, tex_row + 1, lc[i], lf[i])
                     + cb * at(spec, tex_row + 2, lc[i], lf[i]))
    if t_rough >= 0:
        rr, _g, _b = tex.sample(tex_data, tex_info, t_rough, tu, tv)
        for k in range(pm_tex.shape[0]):
            pm_tex[k] = pm[k]
        pm_tex[1] = max(rr * rr, ALPHA_MIN)
        pm_tex[2] = pm_tex[1]
    if t_nrm >= 0:
        nr_, ng_, nb_ = tex.sample(tex_data, tex_info, t_nrm, tu, tv)
        qx, qy, qz = tex.perturb_normal(tri_tex, prim, snx, sny, snz, nr_, ng_, nb_, mat_nstr[m])
        if -(qx * dx + qy * dy + qz * dz) * cos_i > 0.0:
            snx = qx
            sny = qy
            snz = qz
    return t_base >= 0, t_rough >= 0, cr, cg, cb, snx, sny, snz


@function
def _splat(film, spectral, y, x, rad, pdf_lam, lam, cmf, photometric):
    """Add the path's spectral radiance estimate to pixel (x, y): CIE XYZ, the sample count
    and the sum of Y² (or, when ``photometric``, the V(λ)-weighted Y and its square), and
    the spectral bins. A sample whose XYZ, V or square is not finite (NaN or Inf, which
    validated input cannot produce) is left out, the count included: the pixel is the mean
    of its finite samples and the film's count tells how many were dropped. Returns whether
    the sample was added."""
    n_bins = spectral.shape[2]
    bin_width = (LMAX - LMIN) / max(n_bins, 1)
    X = 0.0
    Y = 0.0
    Z = 0.0
    V = 0.0
    for i in range(NW):
        if pdf_lam[i] > 0.0:
            v = rad[i] / (pdf_lam[i] * NW)
            X += v * lookup_cmf(cmf, 0, lam[i])
            Y += v * lookup_cmf(cmf, 1, lam[i])
            Z += v * lookup_cmf(cmf, 2, lam[i])
            if photometric:
                V += v * lookup_cmf(cmf, 3, lam[i])
    sq = V * V if photometric else Y * Y
    if not math.isfinite(X + Y + Z + V + sq):
        return False
    if n_bins > 0:
        for i in range(NW):
            if pdf_lam[i] > 0.0:
                b = int((lam[i] - LMIN) / bin_width)
                if b >= n_bins:
                    b = n_bins - 1
                spectral[y, x, b] += rad[i] / (pdf_lam[i] * NW) / bin_width
    film[y, x, 0] += X
    film[y, x, 1] += Y
    film[y, x, 2] += Z
    film[y, x, 3] += 1.0
    film[y, x, 4] += sq
    if photometric:
        film[y, x, 5] += V
    return True


class Scratch(NamedTuple):
    """The arrays render_rows works in (it allocates nothing: see core/jit.py ``kernel``);
    one set per concurrent call.

    work: float64 (WORK_ROWS, N_WAVELENGTHS) the path's per-wavelength state: λ, pdf(λ), β,
        L, ρa, ρb, η, κ, f, Le and the λ's 1 nm cell fraction.
    mw: float64 (MW_ROWS, N_WAVELENGTHS) the media code's per-wavelength state
        (core/media/kernel.py).
    pm_tex: float64 (MATERIAL_PARAMS,) a material's parameter row with textured roughness.
    lc: int64 (N_WAVELENGTHS,) the λ's 1 nm cell.
    stack: int32 (STACK_SIZE,) the BVH traversal's stack.
    """

    work: np.ndarray
    mw: np.ndarray
    pm_tex: np.ndarray
    lc: np.ndarray
    stack: np.ndarray


def scratch(n_params):
    """A :class:`Scratch` for material parameter rows of ``n_params`` entries."""
    return Scratch(np.empty((WORK_ROWS, NW)), np.empty((media.MW_ROWS, NW)), np.empty(max(int(n_params), 1)),
                   np.empty(NW, np.int64), np.empty(STACK_SIZE, np.int32))


@fragment
def _camera_sample(camr, st, smp, x, y, width, height, thin_lens, scr):
    """A new path of pixel (x, y): its wavelengths (dimension 0: a hero and equally offset
    companions, into the scratch rows λ, pdf(λ) and cells, with β = 1 and L = 0) and its
    camera ray (ox, oy, oz, dx, dy, dz): dimensions 1-2 the pixel filter, 3-4 the lens
    (drawn only for a thin lens: a pinhole ignores them, and each dimension is a pure
    function of its number, so skipping them changes nothing else). smp: the path's
    (key, pixel seed, sample index)."""
    sampler = st.sampler
    n_total = st.n_total
    key, pseed, s = smp
    work = scr.work
    lam = work[0]
    pdf_lam = work[1]
    beta = work[2]
    rad = work[3]
    lf = work[10]
    lc = scr.lc
    u0 = rnd_f(sampler, key, pseed, s, np.int64(0), n_total)
    for i in range(NW):
        up = u0 + i / NW
        if up >= 1.0:
            up -= 1.0
        lam[i], pdf_lam[i] = sample_visible(up)
        lc[i], lf[i] = lam_cell(lam[i])
        beta[i] = 1.0
        rad[i] = 0.0
    u3 = 0.5
    u4 = 0.5
    if thin_lens:
        u3 = rnd_f(sampler, key, pseed, s, np.int64(3), n_total)
        u4 = rnd_f(sampler, key, pseed, s, np.int64(4), n_total)
    return camera_ray(camr.cam, camr.filt, x, y, width, height,
                      rnd_f(sampler, key, pseed, s, np.int64(1), n_total),
                      rnd_f(sampler, key, pseed, s, np.int64(2), n_total), u3, u4)


@fragment
def _segment(geo, mat, emt, st, smp, cfg, scr, o, d, t_lo, medium, depth, dim, prev, vis, rc):
    """The ray (o, d) from t_lo: its closest hit (t, prim, bu, bv), in a medium the free-flight
    distance (t_end < t: a scattering event comes first; one dimension drawn), and the
    emission of the analytic lights it meets before t_end added to L (hit for their emission,
    never occluders, as in Cycles; prev = (the previous event was a delta one, its pdf); vis, rc:
    the visibility record and the ray's class and receiving triangle, ``_vis_hit``: triangles
    hidden from the ray's class are passed). Returns (t, prim, bu, bv, t_end, dim)."""
    do_nee = cfg[0]
    ox, oy, oz = o
    dx, dy, dz = d
    key, pseed, s = smp
    prev_delta, prev_pdf = prev
    t, prim, bu, bv = trace_closest(ox, oy, oz, dx, dy, dz, t_lo, np.inf, geo.nodes, geo.tris, scr.stack)
    if vis is not None:
        while prim >= 0 and (vis.tri_vis[prim] & (1 << rc[0])) != 0:  # hidden from rays of this class
            t, prim, bu, bv = trace_closest(ox, oy, oz, dx, dy, dz, t + cfg[1], np.inf, geo.nodes, geo.tris,
                                            scr.stack)
    t_end = t
    if medium >= 0:
        t_end = min(t, t_lo + media.free_flight(medium, scr.mw, rnd_f(st.sampler, key, pseed, s, dim, st.n_total)))
        dim += 1
    if emt.light_kind.shape[0] > 0:
        _light_hits(depth == 0 and st.sensor_mat >= 0, np.int64(depth), prim >= 0 or t_end < t, t_end, t_lo, o, d,
                    prev_delta or not do_nee, prev_pdf, medium, scr, mat.spec, emt, vis, rc)
    return t, prim, bu, bv, t_end, dim


@inline
def _roulette(st, smp, beta, q, depth, dim):
    """Russian roulette after a scattering event (``depth`` counts it): the path ends when its
    largest throughput ``q`` is 0 or not finite (NaN or Inf, which validated input cannot
    produce), and from rr_depth on it survives with probability min(q, RR_MAX_SURVIVAL), β
    divided by that probability (one dimension drawn). The cap keeps every path finite where
    the throughput does not fall: a closed room of reflectance 1, a chain of mirrors or total
    internal reflection, or the point measures' β = π, with no depth limit; as in Mitsuba 3's
    path integrator (src/integrators/path.cpp, survival min(max β η², 0.95)). Returns (alive,
    dim)."""
    key, pseed, s = smp
    if not 0.0 < q < math.inf:  # nothing left, or a non-finite throughput: never carried further
        return False, dim
    if depth >= st.rr_depth:
        p = min(q, RR_MAX_SURVIVAL)
        if rnd_f(st.sampler, key, pseed, s, dim, st.n_total) >= p:
            return False, dim
        for i in range(NW):
            beta[i] /= p
        dim += 1
    return True, dim


@function
def _medium_scatter(geo, mat, emt, med, st, smp, cfg, scr, o, d, seg, vol, depth, dim, vis):
    """A scattering event in the medium ``vol`` = (medium, outer) at t_end along (o, d)
    (seg = (t, t_end, t_lo), t_end < t): the transmittance and albedo of the flight, next-event
    estimation towards one emitter (three dimensions), a Henyey–Greenstein direction (two)
    and Russian roulette (vis: the visibility record, None: none; an emitter hidden from
    volume scattering is not sampled). Returns (alive, new origin, new direction, pdf of the
    direction, depth, dim); alive False: the path ends here."""
    do_nee = cfg[0]
    eps = cfg[1]
    ox, oy, oz = o
    dx, dy, dz = d
    t, t_end, t_lo = seg
    medium = vol[0]
    sampler = st.sampler
    n_total = st.n_total
    key, pseed, s = smp
    work = scr.work
    lam = work[0]
    pdf_lam = work[1]
    beta = work[2]
    rad = work[3]
    le = work[9]
    mw = scr.mw
    media.segment(medium, mw, beta, t_end - t_lo, t_end < t)  # True here, not as a literal
    if depth > st.max_depth:
        return False, ox, oy, oz, dx, dy, dz, 0.0, depth, dim
    px = ox + t_end * dx
    py = oy + t_end * dy
    pz = oz + t_end * dz
    g = med.med_g[medium]
    if do_nee:
        ei = media.pick(emt.emit_cdf, emt.emit_prob.shape[0], rnd_f(sampler, key, pseed, s, dim, n_total))
        wx, wy, wz, dist, lpdf, fac = _emitter_sample(
            ei, rnd_f(sampler, key, pseed, s, dim + 1, n_total),
            rnd_f(sampler, key, pseed, s, dim + 2, n_total), px, py, pz, lam, le, geo, mat, emt, st)
        if vis is not None:
            h = vis.emit_hide[ei]
            if (h & HIDE_VOLUME) != 0:
                fac = 0.0
            elif (h & NEE_ONLY) != 0 and lpdf != np.inf and lpdf > 0.0:
                fac = fac / lpdf
                lpdf = np.inf
        media.nee((px, py, pz), (dx, dy, dz), g, (wx, wy, wz, dist, lpdf, fac, emt.emit_prob[ei]), le, vol, lam,
                  beta, rad, mw, geo, mat.model, med, eps, scr.stack)
    dim += 3
    dx, dy, dz, prev_pdf = media.hg_sample(g, dx, dy, dz,
                                           rnd_f(sampler, key, pseed, s, dim, n_total),
                                           rnd_f(sampler, key, pseed, s, dim + 1, n_total))
    dim += 2
    depth += 1
    alive, dim = _roulette(st, smp, beta, media.live_max(beta, pdf_lam), depth, dim)
    return alive, px, py, pz, dx, dy, dz, prev_pdf, depth, dim


@inline
def _hit_point(geo, o, d, t, prim):
    """The surface hit at t along (o, d) on triangle ``prim``: (ok, px, py, pz, nx, ny, nz,
    area, cos_i) with n the unit geometric normal, area the triangle's, cos_i = -n·d; ok
    False for a degenerate triangle (the rest is then meaningless)."""
    ox, oy, oz = o
    dx, dy, dz = d
    px = ox + t * dx
    py = oy + t * dy
    pz = oz + t * dz
    nx, ny, nz = triangle_normal(geo.e1, geo.e2, prim)
    nlen = math.sqrt(nx * nx + ny * ny + nz * nz)
    if nlen == 0.0:
        return False, px, py, pz, nx, ny, nz, 0.0, 0.0
    area = 0.5 * nlen
    nx /= nlen
    ny /= nlen
    nz /= nlen
    cos_i = -(nx * dx + ny * dy + nz * dz)
    return True, px, py, pz, nx, ny, nz, area, cos_i


@inline
def _shading_normal(geo, prim, bu, bv, n, d, cos_i):
    """The shading normal at barycentrics (bu, bv) of ``prim``: the vertex normals
    interpolated, on the geometric normal n's side; n itself where the two disagree about the
    side the ray (direction d) comes from, and for flat shading."""
    nx, ny, nz = n
    dx, dy, dz = d
    tri_nrm = geo.tri_nrm
    snx = nx
    sny = ny
    snz = nz
    if tri_nrm.shape[0] > 0:
        b0 = 1.0 - bu - bv
        qx = b0 * tri_nrm[prim, 0] + bu * tri_nrm[prim, 3] + bv * tri_nrm[prim, 6]
        qy = b0 * tri_nrm[prim, 1] + bu * tri_nrm[prim, 4] + bv * tri_nrm[prim, 7]
        qz = b0 * tri_nrm[prim, 2] + bu * tri_nrm[prim, 5] + bv * tri_nrm[prim, 8]
        ql = math.sqrt(qx * qx + qy * qy + qz * qz)
        if ql > 0.0:
            if qx * nx + qy * ny + qz * nz < 0.0:
                ql = -ql
            qx /= ql
            qy /= ql
            qz /= ql
            if -(qx * dx + qy * dy + qz * dz) * cos_i > 0.0:
                snx = qx
                sny = qy
                snz = qz
    return snx, sny, snz


@inline
def _first_hit(fr, geo, st, x, y, prim, m, sn, d, t):
    """The camera ray's hit on ``prim`` (material m) at distance t: the normal, depth and hit
    count AOVs of pixel (x, y), then holdouts and sensors. Returns (material, transparent):
    transparent True ends the path, the pixel counting as transparent (a holdout, or in
    measuring mode anything but a sensor); a sensor's hit takes the sensors' material."""
    snx, sny, snz = sn
    dx, dy, dz = d
    aov = fr.aov
    tri_flag = geo.tri_flag
    sensor_mat = st.sensor_mat
    fs = 1.0 if snx * dx + sny * dy + snz * dz <= 0.0 else -1.0
    aov[y, x, 3] += fs * snx
    aov[y, x, 4] += fs * sny
    aov[y, x, 5] += fs * snz
    aov[y, x, 6] += t
    aov[y, x, 7] += 1.0
    if tri_flag.shape[0] > 0:
        if sensor_mat >= 0:
            if (tri_flag[prim] & 1) == 0:
                return m, True
            m = sensor_mat  # white two-sided Lambert, emission ignored
        elif (tri_flag[prim] & 2) != 0:  # holdout: a hole in the film
            return m, True
    return m, False


@fragment
def _emission(geo, mat, emt, st, cfg, scr, o, hit, t, prim, m, prev, vis, rc, txr, surf):
    """Material m's emitted radiance at the hit (hit = (px, py, pz, nx, ny, nz, area, cos_i),
    t along the ray from o) added to L: from both sides (Blender's Emission shader) or the
    front side only. Unless the previous vertex was a delta event or NEE is off, weighted by
    the power heuristic against the NEE's pdf of this direction, under the NEE's rule for
    (origin, triangle): 1/Ω when it samples the solid angle, else by area. vis, rc: the
    visibility record (None: none) and the ray's class and receiving triangle (``_vis_hit``).
    prev: (the previous vertex was a delta event, its pdf); txr, surf: the textures record and
    (shading normal, barycentrics) of the hit, for a material's emission program."""
    prev_delta, prev_pdf = prev
    do_nee = cfg[0]
    ox, oy, oz = o
    px, py, pz, nx, ny, nz, area, cos_i = hit
    mat_emis = mat.emis
    v0 = geo.v0
    sph_lo = st.sph_lo
    sph_hi = st.sph_hi
    beta = scr.work[2]
    rad = scr.work[3]
    lf = scr.work[10]
    lc = scr.lc
    seen = mat_emis[m] >= 0 and (cos_i > 0.0 or (cos_i < 0.0 and mat.emis_two[m] != 0))
    if vis is not None and seen and geo.tri_emitter[prim] >= 0:
        seen = _vis_hit(vis, geo.tri_emitter[prim], rc, prev_delta or not do_nee)
    if seen:
        w = 1.0
        if not prev_delta and do_nee:
            om = 0.0
            hp = (ox - v0[prim, 0]) * nx + (oy - v0[prim, 1]) * ny + (oz - v0[prim, 2]) * nz
            if sph_lo <= sph_hi and area >= sph_lo * hp * hp:  # Ω ≤ A / h², as in the NEE
                # np.int64: one signature of _sph_triangle for every caller
                om, _wx, _wy, _wz = _sph_triangle(np.int64(prim), ox, oy, oz, v0, geo.e1, geo.e2, sph_lo,
                                                  sph_hi, -1.0, 0.0)
            if om > 0.0:
                pl = emt.emit_prob[geo.tri_emitter[prim]] / om
            else:
                pl = emt.emit_prob[geo.tri_emitter[prim]] * t * t / (area * abs(cos_i))
            w = power_heuristic(prev_pdf, pl)
        for i in range(NW):
            rad[i] += beta[i] * w * mat.emis_scale[m] * at(mat.spec, mat_emis[m], lc[i], lf[i])
    if txr is not None:  # txr None: a scene without textures or programs (the branch is not compiled)
        sn, bary = surf
        _program_emission(txr.shading, txr, mat, scr, m, prim, bary, hit, o, sn)


@inline
def _pick_component(mat, st, smp, scr, m, dim, txr, surf):
    """Mixes: one component of material m picked (Mix: by weight, a mix program's at the
    hit; Add: either, counted twice), one dimension per level. txr, surf: the textures
    record (None: a scene without textures or programs, the branch is not compiled) and
    (prim, barycentrics, hit, ray direction, shading normal) for a mix program, whose registers are in scr. Returns
    (material, weight, dim). The camera/BSDF step, the NEE's BSDF evaluation and both MIS
    pdfs all use the one component picked, so they share the weight at this point."""
    key, pseed, s = smp
    mat_p = mat.params
    mix_w = 1.0
    for _ in range(C.MIX_DEPTH):
        mm = mat.model[m]
        if mm == C.MAT_MIX:
            w = mat_p[m, 0]
            if txr is not None:
                w = _mix_weight(txr.shading, txr, scr, m, w, surf)
            u = rnd_f(st.sampler, key, pseed, s, dim, st.n_total)
            m = int(mat_p[m, 1]) if u < w else int(mat_p[m, 2])
            dim += 1
        elif mm == C.MAT_ADD:
            m = int(mat_p[m, 1]) if rnd_f(st.sampler, key, pseed, s, dim, st.n_total) < 0.5 else int(mat_p[m, 2])
            mix_w *= 2.0
            dim += 1
        else:
            break
    return m, mix_w, dim


@function
def _mix_weight(shd, txr, scr, m, w, surf):
    """The weight of mix m's first component at the hit: its mix program's x clamped to
    [0, 1] (as Cycles clamps the Mix Shader's factor), else w. shd None: a scene without
    programs (nothing of this is compiled for it)."""
    if shd is not None:
        start = shd.mat_prog[m, 4]
        if start >= 0:
            prim, bary, hit, d, sn = surf
            ctx = (hit[0], hit[1], hit[2], sn[0], sn[1], sn[2], hit[3], hit[4], hit[5], -d[0], -d[1], -d[2])
            x, _y, _z = run_program(shd.prog_ops, shd.prog_consts, txr.tex_data, txr.tex_info, shd.tri_attr,
                                    np.int64(start), np.int64(prim), bary[0], bary[1], ctx, scr.stack.view(np.float32))
            w = clamp01(x)
    return w


@fragment
def _surface_material(mat, txr, cfg, scr, m, prim, bu, bv, sn, d, hit):
    """Material m at the hit: ρa, ρb, η and κ at the path's wavelengths into the scratch
    rows, then its image textures (base colour into ρa, roughness into the scratch parameter
    row, the normal map into the shading normal sn). Returns (base colour textured,
    roughness textured, r, g, b, shading normal)."""
    has_tex = cfg[3]
    work = scr.work
    lf = work[10]
    tex_base = False
    rough = False
    cr = 0.0
    cg = 0.0
    cb = 0.0
    snx, sny, snz = sn
    _lookup_material(m, scr.lc, lf, mat.spec, mat.ior_tab, mat.ra, mat.rb, mat.eta, mat.kappa, mat.ior,
                     work[4], work[5], work[6], work[7])
    if txr is not None and has_tex:  # txr None: a scene without textures (the branch is not compiled)
        mat_tex = txr.mat_tex
        if mat_tex[m, 0] >= 0 or mat_tex[m, 1] >= 0 or mat_tex[m, 2] >= 0:
            tex_base, rough, cr, cg, cb, snx, sny, snz = _textures(
                m, np.int64(prim), bu, bv, sn, d, hit[7], mat.params[m], scr, mat.spec, txr)
        tex_base, rough, cr, cg, cb, snx, sny, snz = _program_surface(
            txr.shading, txr, mat, scr, m, prim, (bu, bv), hit, d, (snx, sny, snz), (tex_base, rough, cr, cg, cb))
    return tex_base, rough, cr, cg, cb, snx, sny, snz


@function
def _program_surface(shd, txr, mat, scr, m, prim, bary, hit, d, sn, state):
    """Material m's shader programs for its shading normal (first: the others see it), base
    colour (uplifted into ρa with the reflectance basis, its rgb clamped to [0, 1]) and
    roughness (GGX α = r² on both axes in the scratch parameter row). Returns ``state`` (base
    colour textured, roughness textured, r, g, b) updated and the shading normal; shd None: a
    scene without programs (a function, so that numba prunes on the argument and compiles
    nothing of this for it)."""
    tex_base, rough, cr, cg, cb = state
    nx, ny, nz = sn
    if shd is not None:
        mp = shd.mat_prog
        if mp[m, 0] >= 0 or mp[m, 1] >= 0 or mp[m, 3] >= 0:
            regs = scr.stack.view(np.float32)
            if mp[m, 3] >= 0:
                ctx = (hit[0], hit[1], hit[2], nx, ny, nz, hit[3], hit[4], hit[5], -d[0], -d[1], -d[2])
                qx, qy, qz = run_program(shd.prog_ops, shd.prog_consts, txr.tex_data, txr.tex_info, shd.tri_attr,
                                         np.int64(mp[m, 3]), np.int64(prim), bary[0], bary[1], ctx, regs)
                ql = math.sqrt(qx * qx + qy * qy + qz * qz)
                if ql > 0.0:
                    nx = qx / ql
                    ny = qy / ql
                    nz = qz / ql
            ctx = (hit[0], hit[1], hit[2], nx, ny, nz, hit[3], hit[4], hit[5], -d[0], -d[1], -d[2])
            if mp[m, 0] >= 0:
                r, g, b = run_program(shd.prog_ops, shd.prog_consts, txr.tex_data, txr.tex_info, shd.tri_attr,
                                      np.int64(mp[m, 0]), np.int64(prim), bary[0], bary[1], ctx, regs)
                cr = clamp01(r)
                cg = clamp01(g)
                cb = clamp01(b)
                tex_base = True
                lc = scr.lc
                lf = scr.work[10]
                ra = scr.work[4]
                spec = mat.spec
                row = shd.refl_row
                for i in range(NW):
                    ra[i] = (cr * at(spec, row, lc[i], lf[i]) + cg * at(spec, row + 1, lc[i], lf[i])
                             + cb * at(spec, row + 2, lc[i], lf[i]))
            if mp[m, 1] >= 0:
                r, _g, _b = run_program(shd.prog_ops, shd.prog_consts, txr.tex_data, txr.tex_info, shd.tri_attr,
                                        np.int64(mp[m, 1]), np.int64(prim), bary[0], bary[1], ctx, regs)
                pm = mat.params[m]
                pm_tex = scr.pm_tex
                if not rough:
                    for k in range(pm_tex.shape[0]):
                        pm_tex[k] = pm[k]
                rr = clamp01(r)
                pm_tex[1] = max(rr * rr, ALPHA_MIN)
                pm_tex[2] = pm_tex[1]
                rough = True
    return tex_base, rough, cr, cg, cb, nx, ny, nz


@function
def _program_emission(shd, txr, mat, scr, m, prim, bary, hit, o, sn):
    """Material m's emission program at the hit added to L (rgb radiance, Blender's colour ×
    strength, through the emission basis rows: white 1 is 683 cd/m²), weight 1: an emitter
    driven by a program is not sampled by NEE. shd None: a scene without programs."""
    if shd is not None:
        e0 = shd.mat_prog[m, 2]
        if e0 >= 0 and (hit[7] > 0.0 or (hit[7] < 0.0 and mat.emis_two[m] != 0)):
            ix = o[0] - hit[0]
            iy = o[1] - hit[1]
            iz = o[2] - hit[2]
            il = math.sqrt(ix * ix + iy * iy + iz * iz)
            if il > 0.0:
                ix /= il
                iy /= il
                iz /= il
            ctx = (hit[0], hit[1], hit[2], sn[0], sn[1], sn[2], hit[3], hit[4], hit[5], ix, iy, iz)
            r, g, b = run_program(shd.prog_ops, shd.prog_consts, txr.tex_data, txr.tex_info, shd.tri_attr,
                                  np.int64(e0), np.int64(prim), bary[0], bary[1], ctx, scr.stack.view(np.float32))
            r = max(r, 0.0)
            g = max(g, 0.0)
            b = max(b, 0.0)
            beta = scr.work[2]
            rad = scr.work[3]
            lc = scr.lc
            lf = scr.work[10]
            spec = mat.spec
            row = shd.emit_row
            for i in range(NW):
                rad[i] += beta[i] * (r * at(spec, row, lc[i], lf[i]) + g * at(spec, row + 1, lc[i], lf[i])
                                     + b * at(spec, row + 2, lc[i], lf[i]))


@inline
def _shading_frame(sn, d):
    """The local frame around the shading normal sn (Duff et al. 2017) and the direction
    towards the ray's origin in it: (snx, sny, snz, tx, ty, tz, cx, cy, cz, wox, woy, woz)."""
    snx, sny, snz = sn
    dx, dy, dz = d
    sgn = 1.0 if snz >= 0.0 else -1.0
    aa = -1.0 / (sgn + snz)
    bb = snx * sny * aa
    tx = 1.0 + sgn * snx * snx * aa
    ty = sgn * bb
    tz = -sgn * snx
    cx = bb
    cy = sgn + sny * sny * aa
    cz = -sny
    wox = -(dx * tx + dy * ty + dz * tz)
    woy = -(dx * cx + dy * cy + dz * cz)
    woz = -(dx * snx + dy * sny + dz * snz)
    return snx, sny, snz, tx, ty, tz, cx, cy, cz, wox, woy, woz


@inline
def _albedo(mat, txr, m, tex_base, rgb, mix_w, axyz):
    """The albedo AOV's XYZ at the first diffuse or glossy hit: the textured base colour's
    (rgb weighing the reflectance basis rows) or material m's ρa, times the mix weight; axyz
    (the values so far) when it has neither; txr None: a scene without textures."""
    spec_alb = mat.spec_alb
    aX, aY, aZ = axyz
    if txr is not None and tex_base:
        tex_row = txr.tex_row
        cr, cg, cb = rgb
        aX = mix_w * (cr * spec_alb[tex_row, 0] + cg * spec_alb[tex_row + 1, 0]
                      + cb * spec_alb[tex_row + 2, 0])
        aY = mix_w * (cr * spec_alb[tex_row, 1] + cg * spec_alb[tex_row + 1, 1]
                      + cb * spec_alb[tex_row + 2, 1])
        aZ = mix_w * (cr * spec_alb[tex_row, 2] + cg * spec_alb[tex_row + 1, 2]
                      + cb * spec_alb[tex_row + 2, 2])
    elif mat.ra[m] >= 0:
        aX = mix_w * spec_alb[mat.ra[m], 0]
        aY = mix_w * spec_alb[mat.ra[m], 1]
        aZ = mix_w * spec_alb[mat.ra[m], 2]
    return aX, aY, aZ


@fragment
def _surface_nee(geo, mat, emt, med, st, smp, cfg, scr, dim, hit, shade, prim, bsdf, vol, vis):
    """Next-event estimation at a surface hit: one emitter picked in proportion to its power
    (dimension dim), a point or direction on it (dim + 1, dim + 2), the BSDF bsdf = (model,
    parameter row, mix weight) at the hit (hit = (px, py, pz, nx, ny, nz, area, cos_i); shade
    from ``_shading_frame``) and a shadow ray through the media ``vol`` = (medium, outer); the light's contribution, MIS
    weighted against BSDF sampling (delta lights: NEE only), added to L. vis: the visibility
    record (None: none): light and shadow linking, hidden emitters, shadowless lights."""
    eps = cfg[1]
    has_media = cfg[2]
    px, py, pz, nx, ny, nz, area, cos_i = hit
    snx, sny, snz, tx, ty, tz, cx, cy, cz, wox, woy, woz = shade
    model, pm, mix_w = bsdf
    key, pseed, s = smp
    sampler = st.sampler
    n_total = st.n_total
    work = scr.work
    lam = work[0]
    beta = work[2]
    rad = work[3]
    ra = work[4]
    fv = work[8]
    le = work[9]
    lf = work[10]
    lc = scr.lc
    v0 = geo.v0
    e1 = geo.e1
    e2 = geo.e2
    emit_tri = emt.emit_tri
    ue = rnd(sampler, key, pseed, s, dim, n_total)
    ei = media.pick(emt.emit_cdf, emt.emit_prob.shape[0], ue)
    ua, ub = rnd2(sampler, key, pseed, s, dim + 1, n_total)
    if emit_tri[ei] >= 0:  # emissive triangles inline: no function call
        wx, wy, wz, dist, lpdf, fac, l_row, l_scale = _triangle_sample(
            emit_tri[ei], ua, ub, px, py, pz, v0, e1, e2, geo.tri_mat, mat.emis, mat.emis_scale,
            mat.emis_two, st.sph_lo, st.sph_hi)
        for i in range(NW):
            le[i] = l_scale * at(mat.spec, l_row, lc[i], lf[i])
    else:
        wx, wy, wz, dist, lpdf, fac = _emitter_sample(ei, ua, ub, px, py, pz, lam, le, geo, mat, emt, st)
    cos_n = snx * wx + sny * wy + snz * wz
    no_shadow = False
    if vis is not None:
        fac, lpdf, no_shadow = _vis_nee(vis, ei, prim, model, pm, woz, cos_n, fac, lpdf)
    if fac > 0.0 and lpdf > 0.0 and cos_n * (nx * wx + ny * wy + nz * wz) > 0.0:
        wix = wx * tx + wy * ty + wz * tz
        wiy = wx * cx + wy * cy + wz * cz
        if model == C.MAT_LAMBERT:
            pb = _lambert_eval(pm, ra, woz, cos_n, fv)
        else:
            pb = bsdf_eval(model, pm, ra, work[5], work[6], work[7], wox, woy, woz, wix, wiy, cos_n, fv)
        fmax = 0.0
        for i in range(NW):
            fmax = max(fmax, fv[i])
        if fmax > 0.0:
            side = 1.0 if cos_n > 0.0 else -1.0
            sox = px + side * eps * nx
            soy = py + side * eps * ny
            soz = pz + side * eps * nz
            tmax_s = _shadow_tmax(dist, eps, emit_tri[ei], sox, soy, soz, wx, wy, wz, v0, e1, e2)
            if no_shadow:
                visible = True
            elif vis is not None and vis.masked != 0 and med is None:
                visible = not _occluded_linked(vis, vis.emit_sgrp[ei], (sox, soy, soz), (wx, wy, wz), tmax_s, eps,
                                               geo.nodes, geo.tris, scr.stack)
            elif med is None:  # a scene without media: the plain any-hit query (the media code is not compiled)
                visible = not trace_occluded(sox, soy, soz, wx, wy, wz, 0.0, tmax_s, geo.nodes, geo.tris, scr.stack)
            else:
                visible = media.unoccluded(has_media, (sox, soy, soz), (wx, wy, wz), tmax_s, vol,
                                           med.mat_medium[geo.tri_mat[prim]], cos_i, cos_n, lam, scr.mw, fv, geo,
                                           mat.model, med, eps, scr.stack)
            if visible:
                pe = emt.emit_prob[ei]
                if lpdf == np.inf:  # delta light: NEE only, no MIS
                    g = mix_w * abs(cos_n) * fac / pe
                else:
                    pl = pe * lpdf
                    g = mix_w * power_heuristic(pl, pb) * abs(cos_n) * fac / pl
                for i in range(NW):
                    rad[i] += beta[i] * fv[i] * g * le[i]


@fragment
def _bsdf_step(mat, st, smp, cfg, scr, dim, wo, model, pm, mix_w, dispersed):
    """BSDF sampling at a surface hit: a direction from the BSDF (model, pm) for the outgoing
    direction wo (local frame; dimensions dim .. dim + 2), β multiplied by f cos / pdf and
    the mix weight; after the first dispersive event only the hero wavelength goes on.
    Returns (flags, wix, wiy, wiz, pdf, largest live throughput, dispersed, dim); flags 0:
    the path ends."""
    has_media = cfg[2]
    wox, woy, woz = wo
    key, pseed, s = smp
    sampler = st.sampler
    n_total = st.n_total
    work = scr.work
    pdf_lam = work[1]
    beta = work[2]
    ra = work[4]
    fv = work[8]
    u1, u2 = rnd2(sampler, key, pseed, s, dim, n_total)
    if model == C.MAT_LAMBERT:
        wix, wiy, wiz, pdf, flags = _lambert_sample(pm, ra, woz, u1, u2, fv)
    else:
        wix, wiy, wiz, pdf, flags = bsdf_sample(model, pm, ra, work[5], work[6], work[7], wox, woy, woz, u1, u2,
                                                rnd(sampler, key, pseed, s, dim + 2, n_total), fv)
    dim += 3
    if flags == 0:
        return flags, wix, wiy, wiz, pdf, 0.0, dispersed, dim
    if (flags & BSDF_DISPERSIVE) != 0 and not dispersed:
        if has_media:
            media.drop_companions(beta, scr.mw)
        else:
            terminate_secondary(pdf_lam)
        dispersed = True
    q = 0.0
    for i in range(NW):
        beta[i] *= fv[i] * mix_w
        if pdf_lam[i] > 0.0:
            q = max(q, beta[i])
    return flags, wix, wiy, wiz, pdf, q, dispersed, dim


@inline
def _next_ray(geo, med, cfg, scr, hit, shade, wi, prim, vol):
    """The sampled direction wi (local frame of ``shade``) in world space and the next ray's
    origin, offset from the hit to the side it leaves; a transmitted ray crosses into or out
    of the interior medium of ``prim``'s material (vol = (medium, outer)). Returns (ok, ox,
    oy, oz, dx, dy, dz, medium, outer); ok False: wi lies below the geometric surface on the
    shading normal's side (a leak: the path ends)."""
    eps = cfg[1]
    has_media = cfg[2]
    px, py, pz, nx, ny, nz, area, cos_i = hit
    snx, sny, snz, tx, ty, tz, cx, cy, cz, wox, woy, woz = shade
    wix, wiy, wiz = wi
    medium, outer = vol
    dx = wix * tx + wiy * cx + wiz * snx
    dy = wix * ty + wiy * cy + wiz * sny
    dz = wix * tz + wiy * cz + wiz * snz
    cgeo = nx * dx + ny * dy + nz * dz
    if cgeo * wiz <= 0.0:
        return False, px, py, pz, dx, dy, dz, medium, outer
    side = 1.0 if cgeo > 0.0 else -1.0
    ox = px + side * eps * nx
    oy = py + side * eps * ny
    oz = pz + side * eps * nz
    if med is not None and has_media and (cgeo > 0.0) != (cos_i > 0.0):  # transmitted: into or out of the interior
        medium, outer = media.cross(medium, outer, med.mat_medium[geo.tri_mat[prim]], cgeo < 0.0, med.med_tab,
                                    scr.work[0], scr.mw)
    return True, ox, oy, oz, dx, dy, dz, medium, outer


@inline
def _film_add(fr, y, x, scr, axyz, transp, photometric):
    """The path's estimate into pixel (x, y) of the film record: XYZ, count, Y² and the
    spectral bins (``_splat``), the albedo AOV's XYZ and the transparent-sample count; none
    of them for a sample ``_splat`` leaves out."""
    work = scr.work
    aov = fr.aov
    if not _splat(fr.sums, fr.spectral, y, x, work[3], work[1], work[0], fr.cmf, photometric):
        return
    aov[y, x, 0] += axyz[0]
    aov[y, x, 1] += axyz[1]
    aov[y, x, 2] += axyz[2]
    aov[y, x, 8] += transp


@kernel(refcount=False)
def render_rows(y0, y1, s0, s1, fr, geo, mat, emt, med, txr, camr, st, scr, act, vis):
    """Add samples s0 .. s1-1 of every pixel of rows y0 .. y1-1 to the film record ``fr``
    (of the pixels where ``act``, uint8 (H, W), is not 0: adaptive sampling; act (0, 0): all).

    The records (each field documented where it is defined): fr core/film/record.py, geo
    core/geometry/record.py, mat core/bsdfs/record.py, emt core/lights/record.py, med
    core/media/record.py, txr core/textures/record.py, camr core/camera/record.py, st
    core/integrators/settings.py, scr ``Scratch``, vis core/geometry/visibility.py; med, txr,
    vis are None for a scene without media or null surfaces, image textures, visibility flags:
    numba prunes the branches on them at compile time (``render.kernel_records``, ``prepare``).

    A serial kernel that releases the GIL: the renderer runs blocks of rows on a pool of
    Python threads (compiling a prange kernel takes four times as long, and numba's
    threading layers abort the process on concurrent launches). Rows never overlap, so
    the film does not depend on the number of threads. Each bounce: ``_segment`` (trace,
    free flight, analytic lights), then ``_medium_scatter``, the world or a surface hit
    (``_first_hit``: AOVs, holdouts, sensors; ``_emission``, ``_surface_material``,
    ``_surface_nee``, ``_bsdf_step``, ``_roulette``). Large pieces are ``fragment``s inlined
    by numba, small ones ``inline``; ``_medium_scatter`` is a ``function`` (docs/design/numba.md).
    """
    height = fr.sums.shape[0]
    width = fr.sums.shape[1]
    # nee = 0: the naive reference integrator (BSDF and phase sampling only, every emitter hit
    # counted with weight 1), against which tests check the NEE + MIS estimator
    do_nee = st.nee != 0 and emt.emit_prob.shape[0] > 0
    eps = EPS_REL * st.scene_scale
    has_media = False
    cam_medium = np.int64(-1)
    if med is not None:
        has_media = med.med_tab.shape[0] > 0
        cam_medium = med.cam_medium
    has_tex = False
    if txr is not None:
        has_tex = txr.tri_tex.shape[0] > 0
    # (do NEE, ray offset, media present, textures present)
    cfg = (do_nee, eps, has_media, has_tex)
    thin_lens = camr.cam[CAM_LENS_R] > 0.0
    # a 4th cmf column is V(λ) (an observer other than CIE 1931): the film's channel 5 sums
    # the photometric Y and channel 4 its square; else Y is photometric (5 channels)
    photometric = fr.cmf.shape[1] > 3 and fr.sums.shape[2] > 5
    beta = scr.work[2]
    for y in range(y0, y1):
        for x in range(width):
            if act.shape[0] > 0 and act[y, x] == 0:  # converged (render.adaptive_mask)
                continue
            pix = y * width + x
            pseed = pixel_seed(st.seed, pix)
            for s in range(s0, s1):
                smp = (path_key(st.seed, pix, s), pseed, s)
                ox, oy, oz, dx, dy, dz = _camera_sample(camr, st, smp, x, y, width, height, thin_lens, scr)
                if dx == 0.0 and dy == 0.0 and dz == 0.0:  # outside a fisheye's image circle: black
                    _film_add(fr, y, x, scr, (0.0, 0.0, 0.0), 1.0 if st.film_transparent != 0 else 0.0, photometric)
                    continue
                dim = np.int64(5)
                depth = 0
                prev_pdf = 0.0
                prev_delta = True  # the camera ray: emitters seen directly get full weight
                dispersed = False
                alb_done = False
                axyz = (0.0, 0.0, 0.0)
                medium = cam_medium
                outer = np.int64(-1)  # np.int64: a literal -1 would compile media.shadow/nee/cross twice
                transp = 0.0
                t_lo = 0.0  # the ray goes on from here after passing null surfaces
                rc = (np.int64(RAY_CAMERA), np.int64(-1))  # the ray's class and receiving triangle (vis)
                if med is not None and has_media:
                    media.start_path(med.med_tab, medium, scr.work[0], scr.mw)
                while True:
                    t, prim, bu, bv, t_end, dim = _segment(geo, mat, emt, st, smp, cfg, scr, (ox, oy, oz),
                                                           (dx, dy, dz), t_lo, medium, depth, dim,
                                                           (prev_delta, prev_pdf), vis, rc)
                    if med is not None and medium >= 0:
                        if t_end < t:  # a scattering event in the medium
                            alive, ox, oy, oz, dx, dy, dz, prev_pdf, depth, dim = _medium_scatter(
                                geo, mat, emt, med, st, smp, cfg, scr, (ox, oy, oz), (dx, dy, dz), (t, t_end, t_lo),
                                (medium, outer), depth, dim, vis)
                            if not alive:
                                break
                            rc = (np.int64(RAY_VOLUME), np.int64(-1))
                            prev_delta = False
                            t_lo = 0.0
                            continue
                        media.segment(medium, scr.mw, beta, t - t_lo, t_end < t)  # False here, not as a literal
                    if prim < 0:
                        if depth == 0 and (st.film_transparent != 0 or st.sensor_mat >= 0):
                            transp = 1.0
                            break
                        if emt.world_par[3] > 0.0 or emt.world_spec >= 0:
                            _world_hit((dx, dy, dz), prev_delta or not do_nee, prev_pdf, scr, mat.spec, emt)
                        break
                    ok, px, py, pz, nx, ny, nz, area, cos_i = _hit_point(geo, (ox, oy, oz), (dx, dy, dz), t, prim)
                    if not ok:
                        break
                    if mat.model[geo.tri_mat[prim]] == C.MAT_NULL:  # only bounds a medium: go straight on
                        if med is not None:
                            medium, outer = media.cross(medium, outer, med.mat_medium[geo.tri_mat[prim]], cos_i > 0.0,
                                                        med.med_tab, scr.work[0], scr.mw)
                        t_lo = t + eps
                        continue
                    sn = _shading_normal(geo, prim, bu, bv, (nx, ny, nz), (dx, dy, dz), cos_i)
                    m = geo.tri_mat[prim]
                    if depth == 0:
                        m, transparent = _first_hit(fr, geo, st, x, y, prim, m, sn, (dx, dy, dz), t)
                        if transparent:
                            transp = 1.0
                            break
                    hit = (px, py, pz, nx, ny, nz, area, cos_i)
                    _emission(geo, mat, emt, st, cfg, scr, (ox, oy, oz), hit, t, prim, m, (prev_delta, prev_pdf),
                              vis, rc, txr, (sn, (bu, bv)))
                    if depth > st.max_depth:
                        break
                    m, mix_w, dim = _pick_component(mat, st, smp, scr, m, dim, txr,
                                                    (prim, (bu, bv), hit, (dx, dy, dz), sn))
                    model = mat.model[m]
                    if model == C.MAT_MIX or model == C.MAT_ADD:
                        break
                    tex_base, rough, cr, cg, cb, snx, sny, snz = _surface_material(mat, txr, cfg, scr, m, prim, bu, bv,
                                                                                   sn, (dx, dy, dz), hit)
                    pm = mat.params[m]
                    if rough:
                        pm = scr.pm_tex
                    shade = _shading_frame((snx, sny, snz), (dx, dy, dz))
                    flags_m = bsdf_flags(model, pm)
                    if not alb_done and (flags_m & (BSDF_DIFFUSE | BSDF_GLOSSY)) != 0:
                        alb_done = True
                        axyz = _albedo(mat, txr, m, tex_base, (cr, cg, cb), mix_w, axyz)
                    if do_nee and (flags_m & (BSDF_DIFFUSE | BSDF_GLOSSY)) != 0:
                        _surface_nee(geo, mat, emt, med, st, smp, cfg, scr, dim, hit, shade, prim, (model, pm, mix_w),
                                     (medium, outer), vis)
                    dim += 3
                    flags, wix, wiy, wiz, pdf, q, dispersed, dim = _bsdf_step(mat, st, smp, cfg, scr, dim, shade[9:],
                                                                              model, pm, mix_w, dispersed)
                    if flags == 0:
                        break
                    prev_delta = (flags & BSDF_DELTA) != 0
                    prev_pdf = pdf
                    if vis is not None:
                        rc = (np.int64(_ray_class(flags, wiz, shade[11])), np.int64(prim))
                    ok, ox, oy, oz, dx, dy, dz, medium, outer = _next_ray(geo, med, cfg, scr, hit, shade,
                                                                          (wix, wiy, wiz), prim, (medium, outer))
                    if not ok or not math.isfinite(dx + dy + dz):  # a NaN direction ends the path
                        break
                    t_lo = 0.0
                    depth += 1
                    alive, dim = _roulette(st, smp, beta, q, depth, dim)
                    if not alive:
                        break
                _film_add(fr, y, x, scr, axyz, transp, photometric)
