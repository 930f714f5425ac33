"""Illuminance (lux) and luminance (cd/m²) at arbitrary points, estimated at the point.

The illuminance at a point x with unit normal n is the cosine-weighted integral of the
radiance arriving there over the hemisphere about n (Dutré's Global Illumination
Compendium, items 31–36: irradiance as an integral of incident radiance over solid angle,
or over the area of the emitters with the geometry term):

    E(x) = ∫_{H(n)} L(x ← ω) cos θ dω,        cos θ = n · ω,

and photometrically E_v = K_m ∫ E_λ(x) V(λ) dλ with K_m = 683 lm/W and V(λ) the CIE 1931
photometric observer ȳ (also when the scene's colour observer is CIE 1964).

Monte Carlo form (one sample = one hero-wavelength set and one path), two strategies
combined by the power heuristic (items 51–52), as the path kernel combines NEE and BSDF
sampling:

* next-event estimation: an emitter picked with probability p_e (in proportion to its
  luminous flux), a direction ω_l on it with solid-angle pdf p_l(ω_l), a shadow ray:
      L_e(ω_l) cos θ_l · w_l / (p_e p_l),     w_l = (p_e p_l)² / ((p_e p_l)² + (cos θ_l/π)²);
  delta lights (point, spot, profiled IES/LDT point and spot lights, the sun of angle 0)
  have no solid-angle pdf and take weight 1: I(ω) cos θ / (d² p_e), or E_sun cos θ / p_e —
  the contribution an irradiance meter that only samples directions misses (Mitsuba 3 #365);
* cosine-weighted hemisphere sampling about n (item 20: p(ω) = cos θ / π), so the estimate
  of the first direction is π L(x ← ω); L is the radiance the path kernel's continuation
  brings back along ω: emitters hit there are MIS-weighted against their NEE pdf seen from
  x, and every further vertex is the path kernel's own (its fragments: surfaces, BSDFs,
  textures, mixes, null surfaces and media, emitters and the world; NEE + MIS at each
  vertex), except its Russian roulette at surfaces: a weight window on the throughput
  relative to the sample's starting β₀ (π here), survival min(1, β/β₀ γ^depth / t) with
  t = 0.01 and γ = 0.99 (``_point_roulette``). A path keeps its full weight while that is
  above t γ^-depth, so in a room of high reflectance its length adds little noise, and where
  nothing absorbs the survival settles at γ: every path ends, no bounce limit is needed and
  none is set unless ``max_depth`` asks for one. (The camera kernel's survival of at most
  0.95 with β held near β₀ makes a path's length in a room of reflectance 0.95 geometric,
  mean and spread 20, and that spread dominates the point estimate's noise: on CIE 171's
  cube at ρ = 0.95 the window is about 20 times as efficient, error² × time.) Scattering in
  media keeps the path kernel's roulette.

What is spectral: each sample carries N_WAVELENGTHS wavelengths (a hero drawn from the
visible-wavelength density and equally offset companions, Wilkie et al. 2014, as the path
kernel), every spectrum (emission, reflectance, IOR, media) is read at them, and the sample
is E_v = K_m Σ_i E_λi V(λ_i) / (N p(λ_i)); after a dispersive event only the hero goes on.

The point is not part of the scene: it neither blocks nor reflects light. Its rays start at
x moved by the scene's ray epsilon along the ray's own direction, so a point on a floor
measures the light arriving at the floor and the floor itself does not shadow it. Points
are assumed to be in clear air (outside participating media); rays that enter a medium
through its null boundary are tracked as the path kernel tracks them.

Random numbers: sample s of point i draws dimension d as the path kernel draws it for
pixel i (core/sampling/rng.py, core/sampling/qmc.py: a pure function of (seed, i, s, d),
with the scene's sampler): dimension 0 the wavelengths; 1–2 the hemisphere direction (for
the stratified sampler, points of a digitally shifted Sobol (0, 2)-sequence: stratified
directions); 3–4 the point on the emitter and 5 the emitter; 6 the normal's azimuth
(cylindrical measures); from 7 the path kernel's own sequence. Each sample's value is
stored and the per-point sums are taken in sample order by NumPy over fixed batches, so
the result is bit-identical for any number of threads and any split into chunks.

Luminance at a point in a direction: one camera-like path per sample from x along the
direction (lights are seen by it whatever their camera visibility), L_v = K_m Σ L_λ V / (N p).
Cylindrical and semi-cylindrical illuminance: the mean of the vertical illuminance over
the azimuths of the normal (all of them; or the half circle about the facing direction),
by drawing the horizontal normal's azimuth per sample (dimension 6).
"""
from __future__ import annotations

import itertools
import math
import threading
import warnings
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .. import constants as C
from ..bsdfs.params import BSDF_DELTA, BSDF_DIFFUSE, BSDF_GLOSSY
from ..bsdfs.dispatch import bsdf_flags
from ..bsdfs.phong import lambert_sample_dir
from ..film import record as film_record
from ..geometry.bvh import uidx
from ..jit import inline, kernel
from ..media import kernel as media
from ..sampling.qmc import pixel_seed
from ..sampling.rng import path_key
from ..scene import SceneError
from ..geometry.visibility import NEE_ONLY, NO_SHADOW, RAY_CAMERA, RAY_DIFFUSE, RAY_VOLUME
from .path import (
    EPS_REL, INV_PI, NW, _bsdf_step, _emission, _emitter_sample, _hit_point, _medium_scatter, _next_ray,
    _occluded_linked, _pick_component, _ray_class, _segment, _shading_frame, _shading_normal, _shadow_tmax,
    _surface_material, _surface_nee, _vis_hit, _world_hit, lam_cell, power_heuristic, rnd_f, sample_visible)

# measures (the kernel's ``mode``): integer tags, never reordered
MODE_ILLUMINANCE = 0  # on the plane with the given normal
MODE_LUMINANCE = 1  # along the given direction (cd/m²)
MODE_CYLINDRICAL = 2  # mean vertical illuminance over every azimuth
MODE_SEMICYLINDRICAL = 3  # mean vertical illuminance over the half circle about the given facing direction


class NonFiniteSamples(RuntimeWarning):
    """Some samples of a point measure were NaN or Inf (which validated input cannot
    produce) and were left out of its mean; the samples used are returned per point."""


NO_DEPTH_LIMIT = 1 << 30  # max_depth=None: Russian roulette alone ends paths
FIRST_BATCH = 16  # samples per point in the first batch; batches double up to MAX_BATCH
MAX_BATCH = 256
MIN_SAMPLES_REL = 32  # rel_error: the fewest samples a point stops with
DIM_AZIMUTH = 6
# the continuation's Russian roulette (_point_roulette): survival min(1, β/β₀ γ^depth / t)
RR_FLOOR = 0.01  # t
RR_DECAY = 0.99  # γ
DIM_PATH = 7  # the continuation's first dimension (odd, as the path kernel's first hit: aligned pairs)


@inline
def _wavelengths(st, smp, scr, b0):
    """The sample's wavelengths (dimension 0, as the path kernel's camera sample) into the
    scratch rows λ, pdf(λ), cells, with β = b0 and L = 0."""
    key, pseed, s = smp
    work = scr.work
    u0 = rnd_f(st.sampler, key, pseed, s, np.int64(0), st.n_total)
    for i in range(NW):
        up = u0 + i / NW
        if up >= 1.0:
            up -= 1.0
        work[0, i], work[1, i] = sample_visible(up)
        scr.lc[i], work[10, i] = lam_cell(work[0, i])
        work[2, i] = b0
        work[3, i] = 0.0


@inline
def _normal(st, smp, mode, q):
    """The sample's unit normal: q itself, or for the (semi-)cylindrical measures the
    horizontal normal at an azimuth drawn about q's (dimension DIM_AZIMUTH)."""
    key, pseed, s = smp
    if mode != MODE_CYLINDRICAL and mode != MODE_SEMICYLINDRICAL:
        return q
    spread = 2.0 * math.pi if mode == MODE_CYLINDRICAL else math.pi
    a = spread * (rnd_f(st.sampler, key, pseed, s, np.int64(DIM_AZIMUTH), st.n_total) - 0.5)
    ca = math.cos(a)
    sa = math.sin(a)
    fx, fy, fz = q
    return ca * fx - sa * fy, ca * fy + sa * fx, 0.0


@inline
def _point_nee(geo, mat, emt, med, st, smp, cfg, scr, p, n, vis):
    """Next-event estimation at the point p (unit normal n): one emitter (dimension 5), a
    point or direction on it (3, 4), a shadow ray from p moved eps along the sample's
    direction; the light's L cos θ / pdf, MIS weighted against cosine sampling (delta
    lights: weight 1), added to L. vis: the visibility record (None: none): the point is a
    diffuse receiver of no mesh (no light linking), and the shadow ray follows the shadow
    flags (shadow visibility, shadow linking, lights that cast no shadow)."""
    do_nee = cfg[0]
    eps = cfg[1]
    has_media = cfg[2]
    px, py, pz = p
    nx, ny, nz = n
    key, pseed, s = smp
    work = scr.work
    rad = work[3]
    fv = work[8]
    le = work[9]
    if not do_nee:
        return
    ei = media.pick(emt.emit_cdf, emt.emit_prob.shape[0],
                    rnd_f(st.sampler, key, pseed, s, np.int64(5), st.n_total))
    ua = rnd_f(st.sampler, key, pseed, s, np.int64(3), st.n_total)
    ub = rnd_f(st.sampler, key, pseed, s, np.int64(4), st.n_total)
    wx, wy, wz, dist, lpdf, fac = _emitter_sample(ei, ua, ub, px, py, pz, work[0], le, geo, mat, emt, st)
    cos_n = nx * wx + ny * wy + nz * wz
    if not (fac > 0.0 and lpdf > 0.0 and cos_n > 0.0):
        return
    no_shadow = False
    if vis is not None:
        if not _vis_hit(vis, ei, (np.int64(RAY_DIFFUSE), np.int64(-1)), True):
            return
        h = vis.emit_hide[ei]
        no_shadow = (h & NO_SHADOW) != 0
        if (h & NEE_ONLY) != 0 and lpdf != np.inf:
            fac = fac / lpdf
            lpdf = np.inf
    ox = px + eps * wx
    oy = py + eps * wy
    oz = pz + eps * wz
    tmax = _shadow_tmax(dist, eps, emt.emit_tri[ei], ox, oy, oz, wx, wy, wz, geo.v0, geo.e1, geo.e2)
    for i in range(NW):
        fv[i] = 1.0
    if no_shadow:
        pass
    elif vis is not None and vis.masked != 0 and not has_media:
        if _occluded_linked(vis, vis.emit_sgrp[ei], (ox, oy, oz), (wx, wy, wz), tmax, eps, geo.nodes, geo.tris,
                            scr.stack):
            return
    elif not media.unoccluded(has_media, (ox, oy, oz), (wx, wy, wz), tmax, (np.int64(-1), np.int64(-1)),
                              np.int64(-1), 1.0, 1.0, work[0], scr.mw, fv, geo, mat.model, med, eps, scr.stack):
        return
    pe = emt.emit_prob[ei]
    if lpdf == np.inf:  # delta light: NEE only
        g = cos_n * fac / pe
    else:
        pl = pe * lpdf
        g = power_heuristic(pl, cos_n * INV_PI) * cos_n * fac / pl
    for i in range(NW):
        rad[i] += fv[i] * g * le[i]


@inline
def _point_roulette(st, smp, beta, q, depth, dim, rr):
    """Russian roulette after a scattering event (``depth`` counts it) on the throughput
    relative to the estimator's scale: rr = (β₀, t, γ), β₀ the sample's starting throughput
    (π for the illuminance measures, 1 for luminance), t the weight window's floor and γ < 1
    a decay per bounce. From rr_depth on the path survives with probability
    p = min(1, (q / β₀) γ^depth / t), q its largest throughput, and β is divided by p (one
    dimension per bounce from rr_depth). A path whose relative throughput is above t γ^-depth
    goes on with its weight intact (no variance from its length, which a survival of at most
    0.95 with β kept near β₀ would add where the walls reflect 0.95: a geometric length of mean
    20 and spread 20); below it, the weight is held near t γ^-depth. Where nothing is lost
    (a closed room of reflectance 1) p settles at γ and every path ends; the variance stays
    finite for reflectances below γ. Returns (alive, dim); a throughput of 0 or not finite
    ends the path."""
    key, pseed, s = smp
    if not 0.0 < q < math.inf:
        return False, dim
    if depth >= st.rr_depth:
        b0, floor, decay = rr
        p = (q / b0) * decay ** depth / floor
        if p < 1.0:
            if rnd_f(st.sampler, key, pseed, s, dim, st.n_total) >= p:
                return False, dim
            for i in range(NW):
                beta[i] /= p
        dim += 1
    return True, dim


@inline
def _trace_on(geo, mat, emt, med, txr, st, smp, cfg, scr, ray, state, rr, vis, rc):
    """The path kernel's loop from the ray ``ray`` = (ox, oy, oz, dx, dy, dz) in clear air,
    with state = (depth, dim, prev_delta, prev_pdf) and rr the roulette's (β₀, t, γ)
    (``_point_roulette``): segments, media, the world, surface hits
    (emission, mixes, materials and textures, NEE, BSDF sampling, the next ray, Russian
    roulette), adding to the scratch's L. The same fragments in the same order as
    render_rows, without the camera's AOVs, holdouts and sensors; analytic lights are seen
    by the first segment too (they are hidden from cameras only). vis, rc: the visibility
    record (None: none) and the first ray's class and receiving triangle."""
    do_nee = cfg[0]
    eps = cfg[1]
    has_media = cfg[2]
    ox, oy, oz, dx, dy, dz = ray
    depth, dim, prev_delta, prev_pdf = state
    beta = scr.work[2]
    dispersed = False
    medium = np.int64(-1)
    outer = np.int64(-1)
    t_lo = 0.0
    if has_media:
        media.start_path(med.med_tab, medium, scr.work[0], scr.mw)
    while True:
        t, prim, bu, bv, t_end, dim = _segment(geo, mat, emt, st, smp, cfg, scr, (ox, oy, oz), (dx, dy, dz), t_lo,
                                               medium, max(depth, 1), dim, (prev_delta, prev_pdf), vis, rc)
        if medium >= 0:
            if t_end < t:
                alive, ox, oy, oz, dx, dy, dz, prev_pdf, depth, dim = _medium_scatter(
                    geo, mat, emt, med, st, smp, cfg, scr, (ox, oy, oz), (dx, dy, dz), (t, t_end, t_lo),
                    (medium, outer), depth, dim, vis)
                if not alive:
                    break
                rc = (np.int64(RAY_VOLUME), np.int64(-1))
                prev_delta = False
                t_lo = 0.0
                continue
            media.segment(medium, scr.mw, beta, t - t_lo, t_end < t)
        if prim < 0:
            if emt.world_par[3] > 0.0 or emt.world_spec >= 0:
                _world_hit((dx, dy, dz), prev_delta or not do_nee, prev_pdf, scr, mat.spec, emt)
            break
        ok, px, py, pz, nx, ny, nz, area, cos_i = _hit_point(geo, (ox, oy, oz), (dx, dy, dz), t, prim)
        if not ok:
            break
        if mat.model[geo.tri_mat[prim]] == C.MAT_NULL:
            medium, outer = media.cross(medium, outer, med.mat_medium[geo.tri_mat[prim]], cos_i > 0.0,
                                        med.med_tab, scr.work[0], scr.mw)
            t_lo = t + eps
            continue
        sn = _shading_normal(geo, prim, bu, bv, (nx, ny, nz), (dx, dy, dz), cos_i)
        m = geo.tri_mat[prim]
        hit = (px, py, pz, nx, ny, nz, area, cos_i)
        _emission(geo, mat, emt, st, cfg, scr, (ox, oy, oz), hit, t, prim, m, (prev_delta, prev_pdf), vis, rc, txr,
                  (sn, (bu, bv)))
        if depth > st.max_depth:
            break
        m, mix_w, dim = _pick_component(mat, st, smp, scr, m, dim, txr, (prim, (bu, bv), hit, (dx, dy, dz), sn))
        model = mat.model[m]
        if model == C.MAT_MIX or model == C.MAT_ADD:
            break
        _tb, rough, _r, _g, _b, snx, sny, snz = _surface_material(mat, txr, cfg, scr, m, prim, bu, bv, sn,
                                                                  (dx, dy, dz), hit)
        pm = mat.params[m]
        if rough:
            pm = scr.pm_tex
        shade = _shading_frame((snx, sny, snz), (dx, dy, dz))
        flags_m = bsdf_flags(model, pm)
        if do_nee and (flags_m & (BSDF_DIFFUSE | BSDF_GLOSSY)) != 0:
            _surface_nee(geo, mat, emt, med, st, smp, cfg, scr, dim, hit, shade, prim, (model, pm, mix_w),
                         (medium, outer), vis)
        dim += 3
        flags, wix, wiy, wiz, pdf, q, dispersed, dim = _bsdf_step(mat, st, smp, cfg, scr, dim, shade[9:], model, pm,
                                                                  mix_w, dispersed)
        if flags == 0:
            break
        prev_delta = (flags & BSDF_DELTA) != 0
        prev_pdf = pdf
        if vis is not None:
            rc = (np.int64(_ray_class(flags, wiz, shade[11])), np.int64(prim))
        ok, ox, oy, oz, dx, dy, dz, medium, outer = _next_ray(geo, med, cfg, scr, hit, shade, (wix, wiy, wiz), prim,
                                                              (medium, outer))
        if not ok or not math.isfinite(dx + dy + dz):  # a NaN direction ends the path
            break
        t_lo = 0.0
        depth += 1
        alive, dim = _point_roulette(st, smp, beta, q, depth, dim, rr)
        if not alive:
            break


@inline
def _photometric(scr, vcmf):
    """K_m Σ_i L_i V(λ_i) / (N p(λ_i)) of the scratch's L (companions dropped after a
    dispersive event have p = 0)."""
    work = scr.work
    v = 0.0
    for i in range(NW):
        if work[1, i] > 0.0:
            c = uidx(scr.lc[i])
            f = work[10, i]
            vl = vcmf[c] * (1.0 - f) + vcmf[c + uidx(1)] * f
            v += work[3, i] * vl / (work[1, i] * NW)
    return C.K_M * v


@inline
def _point_sample(geo, mat, emt, med, txr, st, smp, cfg, scr, pq, mode, window, vis):
    """One sample of the measure ``mode`` at p, pq = (p, q) with q its unit normal, viewing
    direction or facing direction: its L (radiance, or for the illuminance measures π L
    along a cosine-sampled direction plus the point's NEE) in the scratch. window: the
    roulette's (t, γ) (``_point_roulette``); vis: the visibility record (None: none), under
    which a luminance path is a camera ray and the illuminance measures' point a diffuse
    receiver of no mesh."""
    eps = cfg[1]
    key, pseed, s = smp
    px, py, pz, qx, qy, qz = pq
    luminance = mode == MODE_LUMINANCE
    go = True
    if luminance:  # a camera-like path along q: emitters seen at full weight
        _wavelengths(st, smp, scr, 1.0)
        dx, dy, dz = qx, qy, qz
        depth = np.int64(0)
        dim = np.int64(5)
        prev_pdf = 0.0
        b0 = 1.0
    else:
        b0 = math.pi
        _wavelengths(st, smp, scr, b0)  # β = cos θ / (cos θ / π)
        nx, ny, nz = _normal(st, smp, mode, (qx, qy, qz))
        _point_nee(geo, mat, emt, med, st, smp, cfg, scr, (px, py, pz), (nx, ny, nz), vis)
        x, y, z, fl = lambert_sample_dir(rnd_f(st.sampler, key, pseed, s, np.int64(1), st.n_total),
                                         rnd_f(st.sampler, key, pseed, s, np.int64(2), st.n_total))
        go = fl != 0
        _sn, _sy, _sz, tx, ty, tz, cx, cy, cz, _wx, _wy, _wz = _shading_frame((nx, ny, nz), (0.0, 0.0, 0.0))
        dx = x * tx + y * cx + z * nx
        dy = x * ty + y * cy + z * ny
        dz = x * tz + y * cz + z * nz
        depth = np.int64(1)  # the point is the path's first vertex
        dim = np.int64(DIM_PATH)
        prev_pdf = z * INV_PI
    if go:
        _trace_on(geo, mat, emt, med, txr, st, smp, cfg, scr, (px + eps * dx, py + eps * dy, pz + eps * dz, dx, dy, dz),
                  (depth, dim, luminance, prev_pdf), (b0, window[0], window[1]), vis,
                  (np.int64(RAY_CAMERA if luminance else RAY_DIFFUSE), np.int64(-1)))


@kernel(refcount=False)
def point_samples(jobs, j0, j1, pts, mode, vcmf, vals, geo, mat, emt, med, txr, st, scr, window, vis):
    """Samples of jobs j0 .. j1-1, each job a row (point, s0, s1, offset) of ``jobs``: the
    measure ``mode`` (MODE_*) of samples s0 .. s1-1 at point ``point`` (pts: float64 (N, 6),
    position and unit normal or direction) into vals[offset + s - s0] (lux or cd/m²).
    vcmf: float32 (N_LAMBDA,) V(λ); geo, mat, emt, med, txr, st: the path kernel's records
    (st.seed, st.max_depth set by the caller); scr: a path.Scratch; window: (t, γ) of the roulette
    (``_point_roulette``); vis: the visibility record (core/geometry/visibility.py), None when
    the scene has no visibility flags nor links.

    A serial kernel that releases the GIL (the caller runs slices of jobs on a pool of
    threads); each value is a pure function of (seed, point, sample), so the values do not
    depend on the split."""
    do_nee = st.nee != 0 and emt.emit_prob.shape[0] > 0
    eps = EPS_REL * st.scene_scale
    cfg = (do_nee, eps, med.med_tab.shape[0] > 0, txr.tri_tex.shape[0] > 0)
    for j in range(j0, j1):
        p = jobs[j, 0]
        s0 = jobs[j, 1]
        off = jobs[j, 3]
        pseed = pixel_seed(st.seed, p)
        pq = (pts[p, 0], pts[p, 1], pts[p, 2], pts[p, 3], pts[p, 4], pts[p, 5])
        for s in range(s0, jobs[j, 2]):
            smp = (path_key(st.seed, p, s), pseed, s)
            _point_sample(geo, mat, emt, med, txr, st, smp, cfg, scr, pq, mode, window, vis)
            vals[off + s - s0] = _photometric(scr, vcmf)


# ------------------------------------------------------------------------------ Python side

def _points(name, a):
    """(N, 3) float64 of ``a``, or SceneError naming the problem (and the first bad row)."""
    try:
        arr = np.array(a, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise SceneError(f"{name}: expected an (N, 3) array of numbers ({exc})") from None
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise SceneError(f"{name}: expected shape (N, 3), got {arr.shape}")
    bad = ~np.all(np.isfinite(arr), axis=1)
    if bad.any():
        i = int(np.argmax(bad))
        raise SceneError(f"{name}[{i}]: contains NaN or Inf ({arr[i].tolist()})")
    return arr


def _unit(name, v, what):
    """The rows of v normalised; SceneError naming the first zero row."""
    ln = np.sqrt(np.sum(v * v, axis=1))
    bad = ~(ln > 0.0)
    if bad.any():
        i = int(np.argmax(bad))
        raise SceneError(f"{name}[{i}]: a zero vector (a {what} must have a length)")
    return v / ln[:, None]


def _horizontal(name, v):
    """Facing directions turned horizontal (their z dropped) and normalised."""
    h = v.copy()
    h[:, 2] = 0.0
    return _unit(name, h, "facing direction with a horizontal part")


def batches(spp):
    """The sample ranges [b0, b1) of the batches: FIRST_BATCH samples, then doubling up to
    MAX_BATCH per batch, the last one cut at ``spp``. A function of spp only, so the sums
    (taken batch by batch, in order) do not depend on threads or chunks."""
    out = []
    b0 = 0
    size = FIRST_BATCH
    while b0 < spp:
        b1 = min(spp, b0 + size)
        out.append((b0, b1))
        b0 = b1
        size = min(b0, MAX_BATCH)
    return out


SERIAL_SAMPLES = 512  # a batch of at most this many samples (all points) runs on the calling thread
TASK_SAMPLES = 2048  # samples per task handed to a thread, at the least (up to 8 tasks a thread)


class _PoolLease:
    """The n_threads − 1 worker threads that join the calling thread in one measurement:
    ``submit`` as an executor's, and ``shutdown`` hands the threads back for the next
    measurement instead of stopping them (starting and joining threads costs more than a
    small measurement's samples)."""

    _idle = {}  # thread count → executors not lent
    _lock = threading.Lock()

    def __init__(self, n_threads):
        self.n_threads = n_threads
        with self._lock:
            idle = self._idle.setdefault(n_threads, [])
            self._pool = idle.pop() if idle else None
        if self._pool is None:
            self._pool = ThreadPoolExecutor(max_workers=n_threads - 1, thread_name_prefix="spectral-gi-lux")

    def submit(self, fn, *args):
        return self._pool.submit(fn, *args)

    def shutdown(self, wait=True):
        with self._lock:
            self._idle[self.n_threads].append(self._pool)


def _jobs(idx, b0, b1, chunk):
    """Rows (point, s0, s1, offset) splitting samples [b0, b1) of each point in ``idx`` into
    chunks of ``chunk``; offset into a (len(idx), b1 - b0) block of values."""
    starts = np.arange(b0, b1, chunk, dtype=np.int64)
    nb = b1 - b0
    pts = np.repeat(idx.astype(np.int64), starts.size)
    row = np.repeat(np.arange(idx.size, dtype=np.int64), starts.size)
    s0 = np.tile(starts, idx.size)
    s1 = np.minimum(s0 + chunk, b1)
    return np.ascontiguousarray(np.stack([pts, s0, s1, row * nb + (s0 - b0)], axis=1))


def _run_batch(prep, st, pts, mode, vcmf, idx, span, pool, n_threads, chunk):
    """Samples span = [b0, b1) of the points ``idx``: (len(idx), b1 - b0) values."""
    from .path import scratch

    b0, b1 = span
    nb = b1 - b0
    tasks = max(1, min(8 * n_threads, -(-idx.size * nb // TASK_SAMPLES)))  # several per thread if there is work
    if chunk is None:  # several jobs per task even for one point
        chunk = max(1, min(nb, -(-idx.size * nb // tasks)))
    jobs = _jobs(idx, b0, b1, int(chunk))
    vals = np.empty(idx.size * nb)
    n_par = prep.materials.params.shape[1]

    def run(j0, j1):
        point_samples(jobs, int(j0), int(j1), pts, int(mode), vcmf, vals, prep.geometry, prep.materials,
                      prep.emitters, prep.media, prep.textures, st, scratch(n_par), (RR_FLOOR, RR_DECAY),
                      prep.visibility)

    if pool is None or idx.size * nb <= SERIAL_SAMPLES or tasks == 1:  # too little work to hand to threads
        run(0, jobs.shape[0])
    else:  # the calling thread and the pool's n_threads − 1 take the tasks in turn
        cuts = np.unique(np.linspace(0, jobs.shape[0], max(tasks, 2) + 1).astype(np.int64))
        turn = itertools.count()  # next() is atomic: each task is taken once

        def take():
            while (k := next(turn)) + 1 < cuts.size:
                run(cuts[k], cuts[k + 1])

        futures = [pool.submit(take) for _ in range(n_threads - 1)]
        try:
            take()
        finally:
            for f in futures:
                f.result()
    return vals.reshape(idx.size, nb)


def _measure(scene, mode, pts, q, spp, rel_error, max_depth, seed, threads, should_cancel, progress, chunk=None,
             subset=None, client=None):
    """The estimator's loop: batches of samples for the points not yet done. Returns
    (values, standard errors, samples used). subset: indices of the points to measure (the
    others are left with no samples); a point's value is the same measured alone, in any
    subset or with all (its random numbers are keyed by its index, its sums are its own).
    client: a dask.distributed Client (or scheduler address, "local:N"): the points are
    split across its workers (core/farm), with the same values."""
    from .render import prepare, thread_count

    if client is not None:
        from ..farm import measure_farm

        return measure_farm(scene, client, mode, pts, q, measure=_measure, spp=spp, rel_error=rel_error,
                            max_depth=max_depth, seed=seed, should_cancel=should_cancel, progress=progress)

    if isinstance(spp, bool) or int(spp) != spp or int(spp) < 1:
        raise SceneError(f"spp: expected a positive integer, got {spp!r}")
    spp = int(spp)
    if rel_error is not None and not (float(rel_error) > 0.0 and math.isfinite(float(rel_error))):
        raise SceneError(f"rel_error: expected a positive number, got {rel_error!r}")
    if max_depth is not None and (int(max_depth) != max_depth or int(max_depth) < 0):
        raise SceneError(f"max_depth: expected an integer ≥ 0 or None, got {max_depth!r}")
    prep = prepare(scene)
    st = prep.settings._replace(
        seed=int(scene.settings.seed if seed is None else seed), n_total=spp, sensor_mat=-1, film_transparent=0,
        max_depth=NO_DEPTH_LIMIT if max_depth is None else int(max_depth))
    vcmf = np.ascontiguousarray(film_record.v_lambda(prep.cmf), np.float32)
    pq = np.ascontiguousarray(np.concatenate([pts, q], axis=1), np.float64)
    n = pq.shape[0]
    s1 = np.zeros(n)
    s2 = np.zeros(n)
    cnt = np.zeros(n, np.int64)  # the finite samples each sum holds
    drawn = np.zeros(n, np.int64)  # the samples drawn
    active = np.ones(n, bool)
    if subset is not None:
        active[:] = False
        active[np.asarray(subset, np.int64)] = True
    n_measured = int(active.sum())
    n_threads = thread_count(threads)
    pool = _PoolLease(n_threads) if n_threads > 1 else None
    try:
        for span in batches(spp):
            idx = np.flatnonzero(active)
            if idx.size == 0 or (should_cancel is not None and should_cancel()):
                break
            vals = _run_batch(prep, st, pq, mode, vcmf, idx, span, pool, n_threads, chunk)
            with np.errstate(over="ignore", invalid="ignore"):
                sq = vals * vals
            ok = np.isfinite(vals) & np.isfinite(sq)  # a sample that is not finite is dropped
            vals[~ok] = 0.0
            sq[~ok] = 0.0
            s1[idx] += vals.sum(axis=1)
            s2[idx] += sq.sum(axis=1)
            cnt[idx] += ok.sum(axis=1)
            drawn[idx] = span[1]
            if rel_error is not None and span[1] >= MIN_SAMPLES_REL:
                mean, se = _stats(s1[idx], s2[idx], cnt[idx])
                done = (se <= float(rel_error) * np.abs(mean)) | ((mean == 0.0) & (se == 0.0))
                # no target to reach: every sample dropped, or sums that overflowed
                done |= np.isnan(mean) | np.isnan(se) | ~np.isfinite(s1[idx] + s2[idx])
                active[idx[done]] = False
            if progress is not None:
                progress(int(np.where(active, drawn, spp).sum()) - (n - n_measured) * spp, n_measured * spp)
    finally:
        if pool is not None:
            pool.shutdown(wait=True)
    dropped = int((drawn - cnt).sum())
    if dropped:
        bad = np.flatnonzero(drawn > cnt)
        warnings.warn(f"{dropped} of {int(drawn.sum())} samples were not finite (NaN or Inf) and were dropped, "
                      f"at {bad.size} point(s) from index {int(bad[0])}; the samples used are returned per point",
                      NonFiniteSamples, stacklevel=3)
    mean, se = _stats(s1, s2, cnt)
    return mean, se, cnt


def _stats(s1, s2, cnt):
    """Mean and its standard error from the sums of the values and their squares."""
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.maximum(cnt, 1).astype(np.float64)
        mean = np.where(cnt > 0, s1 / c, np.nan)
        var = np.maximum(s2 / c - mean * mean, 0.0)
        se = np.where(cnt > 1, np.sqrt(var / np.maximum(c - 1.0, 1.0)), np.inf)
    return mean, se


_DOC_ARGS = """
    spp: samples per point (a cap when rel_error is given); rel_error: a target relative
    standard error per point: batches of samples (16, 16, 32, ... up to 256 at a time) are
    added to the points that have not reached it (at least 32 samples each); max_depth: the
    most bounces after the first (None: no limit, Russian roulette ends paths); seed: the RNG
    seed (None: the scene's); threads: worker threads (None: one per core);
    should_cancel(): checked between batches (True: stop, the result holds what was done);
    progress(done, total): after each batch, in samples (a stopped point counts as done);
    client: a dask.distributed Client, scheduler address or "local:N" to split the points
    across a farm's workers (core/farm; the same values).
    Returns (values (N,), standard errors (N,), samples used (N,) int64). Bit-identical for
    any number of threads. A sample that is not finite (NaN or Inf, which validated input
    cannot produce) is dropped: the samples used count only the finite ones, and a
    NonFiniteSamples warning says how many were dropped."""


def illuminance(scene, points, normals, *, spp=256, rel_error=None, max_depth=None, seed=None, threads=None,
                should_cancel=None, progress=None, client=None, _chunk=None):
    """Illuminance (lux) at ``points`` (N, 3), m, on the planes with ``normals`` (N, 3;
    normalised here), estimated at the points (see the module text)."""
    pts = _points("points", points)
    nrm = _unit("normals", _points("normals", normals), "normal")
    if nrm.shape[0] != pts.shape[0]:
        raise SceneError(f"normals: {nrm.shape[0]} normals for {pts.shape[0]} points")
    return _measure(scene, MODE_ILLUMINANCE, pts, nrm, spp, rel_error, max_depth, seed, threads, should_cancel,
                    progress, _chunk, client=client)


def luminance(scene, points, directions, *, spp=256, rel_error=None, max_depth=None, seed=None, threads=None,
              should_cancel=None, progress=None, client=None):
    """Luminance (cd/m²) seen from ``points`` (N, 3) looking along ``directions`` (N, 3):
    the radiance arriving at each point from that direction (one camera-like path per
    sample, lights seen whatever their camera visibility)."""
    pts = _points("points", points)
    d = _unit("directions", _points("directions", directions), "direction")
    if d.shape[0] != pts.shape[0]:
        raise SceneError(f"directions: {d.shape[0]} directions for {pts.shape[0]} points")
    return _measure(scene, MODE_LUMINANCE, pts, d, spp, rel_error, max_depth, seed, threads, should_cancel,
                    progress, client=client)


def vertical_illuminance(scene, points, facing, **kw):
    """Illuminance on vertical planes facing the horizontal part of ``facing`` (N, 3)."""
    pts = _points("points", points)
    return illuminance(scene, pts, _horizontal("facing", _points("facing", facing)), **kw)


def cylindrical_illuminance(scene, points, **kw):
    """Cylindrical illuminance (lux): the mean vertical illuminance over every azimuth at
    ``points`` (N, 3), the normal's azimuth drawn per sample."""
    pts = _points("points", points)
    q = np.zeros_like(pts)
    q[:, 0] = 1.0
    return _measure(scene, MODE_CYLINDRICAL, pts, q, kw.pop("spp", 256), kw.pop("rel_error", None),
                    kw.pop("max_depth", None), kw.pop("seed", None), kw.pop("threads", None),
                    kw.pop("should_cancel", None), kw.pop("progress", None), client=kw.pop("client", None))


def semicylindrical_illuminance(scene, points, facing, **kw):
    """Semi-cylindrical illuminance (lux): the mean vertical illuminance over the half
    circle of azimuths within 90° of the horizontal part of ``facing`` (N, 3)."""
    pts = _points("points", points)
    q = _horizontal("facing", _points("facing", facing))
    return _measure(scene, MODE_SEMICYLINDRICAL, pts, q, kw.pop("spp", 256), kw.pop("rel_error", None),
                    kw.pop("max_depth", None), kw.pop("seed", None), kw.pop("threads", None),
                    kw.pop("should_cancel", None), kw.pop("progress", None), client=kw.pop("client", None))


for _f in (illuminance, luminance, vertical_illuminance, cylindrical_illuminance, semicylindrical_illuminance):
    _f.__doc__ += "\n" + _DOC_ARGS
