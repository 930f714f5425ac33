"""Radiosity of a diffuse scene: patches, form factors, direct light, the solve per
wavelength band, and illuminance and luminance per patch, per vertex and at any point.

The continuous radiosity equation (Dutré's compendium, item 53) for diffuse surfaces and
diffuse emitters, B(x) = B_e(x) + ρ(x) ∫ B(z) G(x, z) / π dA_z with B = π L, holds at
every wavelength on its own: reflection does not move light between wavelengths, so for a
fixed λ it is a linear equation in B(·, λ). The scene's spectra are Fourier-basis moments
(core/spectra), but the reflectance is *not* linear in its moments (a bounded spectrum is
reconstructed from them through a nonlinear map), and even for linear coefficients the
product ρ(λ) B(λ) of two truncated Fourier series is a convolution of their coefficients
whose truncation loses energy at every bounce. So the system is solved per wavelength
band, not per coefficient: the spectra are tabulated on the renderer's 1 nm grid and
averaged over bands of ``band_width`` nm, weighted by V(λ) so that emission and the first
reflection are photometrically exact; a band's answer is exact when ρ is constant across
it, and ``band_width=1`` is exact on the renderer's grid. The error of wider bands comes
from the variation of ρ within a band compounding over bounces (measured by the tests:
below 0.1 % of illuminance for the Cornell box's measured reflectances at 10 nm).

Cost: the bands with the same reflectance column over all patches have their right-hand
sides reduced to their rank by a singular value decomposition before the solve (exact: the
system is linear), so a grey scene lit by one spectrum solves one column, however many
bands; all columns are solved together, one matrix product per sweep.

Lights: emissive materials make emitting patches (B_e = π L_e on the sides that emit);
analytic lights (area, point, spot, sun, profiled) and a constant world light the patches
directly, by next-event sampling with shadow rays from every patch's sample points
(``kernel.OP_DIRECT``), and from there enter the system as E = B_e + ρ H_direct. A world
image is not supported (a warning says so). Photometry: illuminance E_v = K_m Σ_b H_b V_b
(lux) and luminance L_v = K_m Σ_b B_b V_b / π (cd/m²), K_m = 683 lm/W and V(λ) the
CIE 1931 photometric observer, with H the irradiance arriving at the patch and B the
radiosity leaving it, both W/(m² nm) per band, as core/integrators/illuminance.py measures.

Materials: Lambert materials are exact; any other model is replaced by its diffuse albedo,
taken as its reflectance spectrum (the model's base colour), with a warning naming the
materials; textures are ignored (their material's reflectance spectrum is used).
"""
from __future__ import annotations

import math
import threading
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from ... import constants as C
from ...camera.kernel import CAM_SIZE
from ...geometry import accel
from ...geometry.bvh import STACK_SIZE
from ...scene import SceneError, validate
from . import kernel as K
from . import meshing, solvers

DENSE_LIMIT_BYTES = 4 << 30  # the dense solvers refuse a form-factor matrix larger than this


@dataclass
class RadiositySolution:
    """The result of :func:`radiosity`.

    patches: meshing.Patches; mesh: meshing.DisplayMesh (one face per patch);
    band_edges: float64 (K + 1,) nm; radiosity: float64 (n, K) B per band, W/(m² nm)
    leaving each patch; irradiance: float64 (n, K) H per band, W/(m² nm) arriving;
    illuminance, luminance: float64 (n,) lux and cd/m² per patch; vertex_illuminance,
    vertex_luminance: (V,) on the display mesh's vertices (area-weighted means of the
    patches meeting there); xyz: float64 (n, 3) the absolute CIE XYZ of each patch's
    radiance (Y in cd/m²); stats: solvers.SolveStats per band group; warnings: what was
    approximated.
    """

    patches: meshing.Patches
    mesh: meshing.DisplayMesh
    band_edges: np.ndarray
    radiosity: np.ndarray
    irradiance: np.ndarray
    illuminance: np.ndarray
    luminance: np.ndarray
    vertex_illuminance: np.ndarray
    vertex_luminance: np.ndarray
    xyz: np.ndarray
    stats: list
    direct_illuminance: np.ndarray = None  # (n,) lux from the analytic lights, the world and the emitting patches
    emitted: np.ndarray = None  # (n, K) B_e, W/(m² nm): the emitted part of the radiosity
    reflectance: np.ndarray = None  # (n, K) ρ per band
    warnings: list = field(default_factory=list)
    seconds: dict = field(default_factory=dict)
    _ctx: object = None  # what illuminance_at needs: records, band tables


@dataclass
class _Context:
    pat: K.PatchRecord
    lit: K.LightRecord
    light_bands: np.ndarray  # (L + 1, K): each light's (and the sky's) spectral scale per band
    v_band: np.ndarray  # (K,) ∫_band V dλ
    eps: float
    seed: int
    n_light: int
    n_vis: int
    threads: int
    xyz_band: np.ndarray = None  # (K, 3) ∫_band x̄, ȳ, z̄ dλ
    n_emit: int = 0  # shadow rays per (point, emitting patch) pair in a penumbra (0: no visibility)


# ------------------------------------------------------------------------------ bands

def band_tables(cmf, band_width):
    """(edges (K+1,), index of each 1 nm sample's band (N_LAMBDA,), V weight per sample,
    ∫_band V dλ (K,), ∫_band x̄, ȳ, z̄ dλ (K, 3))."""
    from ...film.record import v_lambda
    from ...spectra import moments

    if not (float(band_width) >= C.LAMBDA_STEP):
        raise SceneError(f"radiosity band_width: expected at least {C.LAMBDA_STEP:g} nm, got {band_width!r}")
    grid = moments.grid()
    k = max(1, int(round((C.LAMBDA_MAX - C.LAMBDA_MIN + C.LAMBDA_STEP) / float(band_width))))
    edges = np.linspace(C.LAMBDA_MIN - 0.5 * C.LAMBDA_STEP, C.LAMBDA_MAX + 0.5 * C.LAMBDA_STEP, k + 1)
    idx = np.clip(np.searchsorted(edges, grid, side="right") - 1, 0, k - 1)
    v = v_lambda(cmf).astype(np.float64) * C.LAMBDA_STEP
    xyz = np.zeros((k, 3))
    for c in range(3):
        xyz[:, c] = np.bincount(idx, weights=cmf[:, c].astype(np.float64) * C.LAMBDA_STEP, minlength=k)
    return edges, idx, v, np.bincount(idx, weights=v, minlength=k), xyz


def band_means(rows, idx, w, k):
    """V-weighted means of spectra ``rows`` (S, N_LAMBDA) over the bands: (S, K); where a
    band has no V (the ends of the range), the plain mean."""
    rows = np.asarray(rows, np.float64).reshape(-1, idx.size)
    ww = w + 1e-12 * (w.max() if w.size else 1.0)
    num = np.stack([np.bincount(idx, weights=r * ww, minlength=k) for r in rows])
    den = np.bincount(idx, weights=ww, minlength=k)
    return num / den


# ------------------------------------------------------------------------------ kernel driver

def _pool_run(fn, n_rows, threads, block=None):
    """fn(r0, r1) over [0, n_rows) in blocks (``block`` rows; None: about 8 per thread), on a
    pool of ``threads`` threads. An exception in the calling thread (Ctrl-C) drops the blocks
    not yet started, so the call ends after the blocks running."""
    if n_rows == 0:
        return
    block = block or max(1, -(-n_rows // (8 * max(threads, 1))))
    if threads <= 1:
        for a in range(0, n_rows, block):
            fn(a, min(n_rows, a + block))
        return
    pool = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="spectral-gi-radiosity")
    try:
        futs = [pool.submit(fn, a, min(n_rows, a + block)) for a in range(0, n_rows, block)]
        for f in futs:
            f.result()
    except BaseException:
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)


def _scratch():
    return np.zeros((8, 3)), np.zeros(STACK_SIZE, np.int32)


_EMPTY_I = np.zeros(1, np.int32)
ROW_BLOCK = 64


def run_op(op, pat, qry, lit, n_out_cols, n_vis, seed, eps, threads, n_rows=None, should_cancel=None,
           report=None):
    """Run kernel operation ``op`` over every row of ``qry`` (or ray, for OP_SHOOT):
    returns out float32 (R, n_out_cols), or for OP_SHOOT hits int32 (N,). ``report(done,
    total)`` is called after each block of rows (from the worker threads, one at a time)."""
    shoot = op == K.OP_SHOOT
    n_rows = (qry.src.shape[0] if shoot else qry.pts.shape[0]) if n_rows is None else n_rows
    out = np.zeros((1, 1) if shoot else (qry.pts.shape[0], n_out_cols), np.float32)
    hits = np.full(n_rows if shoot else 1, -1, np.int32)
    lock = threading.Lock()
    done = [0]

    def fn(r0, r1):
        if should_cancel is not None and should_cancel():
            return
        poly, stack = _scratch()
        K.radiosity_rays(int(op), int(r0), int(r1), pat, qry, lit, int(n_vis), int(seed), float(eps), out, hits,
                         poly, stack)
        if report is not None:
            with lock:
                done[0] += r1 - r0
                report(done[0], n_rows)

    # rows of form factors or direct light in blocks of at most ROW_BLOCK (Ctrl-C and cancel act soon), and
    # of at least a share of the rows per thread or 32 (each call of the kernel costs its dispatch)
    t = max(threads, 1)
    block = max(min(32, -(-n_rows // t)), min(ROW_BLOCK, -(-n_rows // (8 * t))))
    _pool_run(fn, n_rows, threads, None if shoot else block)
    return hits if shoot else out


_NO_CAMERA = np.zeros(CAM_SIZE)  # the camera vector of the ops that have none
_NO_FILTER = np.zeros(2)


def _query(pts, nrm, own, cols=None, src=None, cam=None, filt=None):
    return K.QueryRecord(np.ascontiguousarray(pts, np.float64), np.ascontiguousarray(nrm, np.float64),
                         np.ascontiguousarray(own, np.int32),
                         np.ascontiguousarray(np.zeros(0, np.int32) if cols is None else cols, np.int32),
                         np.ascontiguousarray(_EMPTY_I if src is None else src, np.int32),
                         np.ascontiguousarray(_NO_CAMERA if cam is None else cam, np.float64),
                         np.ascontiguousarray(_NO_FILTER if filt is None else filt, np.float64))


def _no_lights():
    from ...lights import kernel as LG

    return K.LightRecord(np.zeros(0, np.int32), np.zeros((0, LG.LG_SIZE)), np.zeros(1), np.zeros(0, np.int32))


def patch_record(corners, geometry=None, tri_patch=None, occluders=None):
    """The kernel's PatchRecord of oriented triangles ``corners`` (n, 3, 3), occluded by
    ``geometry`` (T, 3, 3) (default: the patches themselves, one patch per triangle); shadow
    rays test ``occluders`` (triangles covering the same surface as ``geometry``, e.g. the
    scene's before subdivision; None: ``geometry``)."""
    corners = np.ascontiguousarray(corners, np.float64)
    if geometry is None:
        geometry = corners
        tri_patch = np.stack([np.arange(corners.shape[0]), np.full(corners.shape[0], -1)], 1)
    geometry = np.asarray(geometry, np.float64)
    bvh = accel.build(geometry[:, 0], geometry[:, 1], geometry[:, 2])
    e1 = corners[:, 1] - corners[:, 0]
    e2 = corners[:, 2] - corners[:, 0]
    cr = np.cross(e1, e2)
    nrm = cr / np.linalg.norm(cr, axis=1, keepdims=True)
    ge = np.cross(geometry[:, 1] - geometry[:, 0], geometry[:, 2] - geometry[:, 0])
    gn = ge / np.maximum(np.linalg.norm(ge, axis=1, keepdims=True), 1e-300)
    occ = bvh
    if occluders is not None:
        o = np.asarray(occluders, np.float64)
        occ = accel.build(o[:, 0], o[:, 1], o[:, 2])
    return K.PatchRecord(np.ascontiguousarray(corners[:, 0]), np.ascontiguousarray(e1), np.ascontiguousarray(e2),
                         np.ascontiguousarray(nrm), bvh.nodes, bvh.tris,
                         np.ascontiguousarray(np.asarray(tri_patch)[bvh.prims], np.int32),
                         np.ascontiguousarray(gn[bvh.prims]), occ.nodes, occ.tris)


def sample_points(corners, n_points):
    """float64 (n, k, 3): the centroids of each triangle's 4^m congruent sub-triangles, k =
    4^m the largest power of four ≤ ``n_points`` (1: the centroid)."""
    c = np.asarray(corners, np.float64)
    m = 0
    while 4 ** (m + 1) <= max(int(n_points), 1):
        m += 1
    sub = c
    for _ in range(m):
        sub = meshing.split4(sub)
    return sub.mean(axis=1).reshape(c.shape[0], 4 ** m, 3)


def _eps(geometry):
    span = float(np.ptp(np.asarray(geometry).reshape(-1, 3), axis=0).max()) if np.size(geometry) else 1.0
    return 1e-6 * max(span, 1e-3)


def element_form_factors(receivers, senders, occluders=None, *, n_points=16, n_vis=16, seed=0, threads=None):
    """Item 58: form factors F_{r→s} (R, S) from every receiving triangle r to every sending
    triangle s (each (·, 3, 3), counter-clockwise seen from its front), with visibility
    through ``occluders`` (triangles (T, 3, 3); None: the receivers and senders themselves;
    an empty array: none): Lambert's formula (item 57) at k = 4^m ≤ n_points points of r,
    times the visible share of n_vis stratified shadow rays from each point to s, each
    weighted by its differential form factor (0: no visibility test). Exact without
    occlusion as the points grow; a patch never sees itself, so pass each triangle once."""
    from ..render import thread_count

    rec = np.asarray(receivers, np.float64).reshape(-1, 3, 3)
    snd = np.asarray(senders, np.float64).reshape(-1, 3, 3)
    occ = np.concatenate([rec, snd]) if occluders is None else np.asarray(occluders, np.float64).reshape(-1, 3, 3)
    if occ.shape[0] == 0:
        occ = np.zeros((1, 3, 3))
        n_vis = 0
    pat = patch_record(snd, occ, np.full((occ.shape[0], 2), -1))
    e = np.cross(rec[:, 1] - rec[:, 0], rec[:, 2] - rec[:, 0])
    nrm = e / np.linalg.norm(e, axis=1, keepdims=True)
    qry = _query(sample_points(rec, n_points), nrm, np.full(rec.shape[0], -1), np.arange(snd.shape[0]))
    return run_op(K.OP_FORM_FACTORS, pat, qry, _no_lights(), snd.shape[0], n_vis, seed, _eps(occ),
                  thread_count(threads)).astype(np.float64)


def emitter_pairs(F, rows, emit, pat, pts, nrm, own, lit, n_emit, seed, eps, threads, should_cancel=None):
    """Replace in ``F`` (R, n), the form factors of receivers ``rows`` (their points
    ``pts``, normals ``nrm``, own patches ``own``) to every patch, the pairs that carry
    direct light by their adaptive estimate (``kernel.OP_EMITTERS``, up to ``n_emit``
    shadow rays where a pair is in a penumbra): the columns of the emitting patches
    ``emit``, and the whole rows of the receivers that emit (so the shooting solvers, which
    read an emitter's row, see the same visibility). ``rows``: the patch of each row of F,
    or None for points that are no patch. Returns F."""
    if emit.size == 0 or n_emit <= 0 or F.shape[0] == 0:
        return F
    F[:, emit] = run_op(K.OP_EMITTERS, pat, _query(pts, nrm, own, emit), lit, emit.size, n_emit, seed, eps,
                        threads, should_cancel=should_cancel)
    if rows is not None:
        hit = np.nonzero(np.isin(rows, emit))[0]
        if hit.size:
            cols = np.arange(F.shape[1], dtype=np.int32)
            F[hit] = run_op(K.OP_EMITTERS, pat, _query(pts[hit], nrm[hit], own[hit], cols), lit, F.shape[1],
                            n_emit, seed, eps, threads, should_cancel=should_cancel)
    return F


# ------------------------------------------------------------------------------ the scene's inputs

def _materials(scene, spec, cmf, patches):
    """Per-material reflectance and emitted radiance spectra (M, N_LAMBDA) and which sides
    emit, and the warnings about approximations."""
    from ...photometry.units import luminance_scale

    n_m = max(1, len(scene.materials))
    rho = np.zeros((n_m, C.N_LAMBDA))
    le = np.zeros((n_m, C.N_LAMBDA))
    two = np.zeros(n_m, bool)
    used = set(np.unique(patches.material).tolist())
    replaced, textured = [], []
    for i, m in enumerate(scene.materials):
        if m.reflectance >= 0:
            rho[i] = spec[m.reflectance]
        elif m.model != C.MAT_LAMBERT:
            rho[i] = 0.0
        if m.emission >= 0 and m.emission_luminance > 0:
            le[i] = luminance_scale(spec[m.emission], cmf, m.emission_luminance,
                                    f"materials[{i}] ({m.name!r})") * spec[m.emission]
        two[i] = bool(m.two_sided)
        if i in used and m.model != C.MAT_LAMBERT:
            replaced.append(m.name)
        if i in used and (m.base_colour_texture >= 0 or m.normal_texture >= 0 or m.roughness_texture >= 0):
            textured.append(m.name)
    notes = []
    if replaced:
        notes.append("radiosity: non-diffuse materials replaced by their diffuse albedo (their reflectance "
                     "spectrum): " + ", ".join(replaced))
    if textured:
        notes.append("radiosity: textures ignored (the material's reflectance spectrum is used): "
                     + ", ".join(textured))
    return np.clip(rho, 0.0, 1.0), le, two, notes


def _lights(scene, spec, cmf, geometry):
    from ...geometry.record import scene_radius
    from ...lights.record import analytic_lights, world_constant

    g = geometry.reshape(-1, 3, 3)
    kind, geo, lspec, lscale, two, _vis, _power, prof_parts = analytic_lights(
        scene, spec, cmf, scene_radius(g[:, 0], g[:, 1], g[:, 2]))
    prof = np.ascontiguousarray(np.concatenate(prof_parts) if prof_parts else np.zeros(1))
    lit = K.LightRecord(np.ascontiguousarray(kind), np.ascontiguousarray(geo), prof, np.ascontiguousarray(two))
    shapes = [lscale[i] * spec[lspec[i]].astype(np.float64) for i in range(kind.size)]
    w_spec, w_scale = world_constant(scene, spec, cmf)
    shapes.append(w_scale * spec[w_spec].astype(np.float64) if w_spec >= 0 else np.zeros(C.N_LAMBDA))
    notes = []
    if scene.world.image is not None:
        notes.append("radiosity: the world image is not supported and gives no light")
    return lit, np.array(shapes), notes


# ------------------------------------------------------------------------------ the solve

def _solve_groups(method, F, rho_b, E_b, area, tol, max_iter, weights, progress, should_cancel):
    """Solve B = E + ρ F B for every band in one multi-column solve: the bands with equal ρ
    columns have their right-hand sides reduced to their rank (SVD) first."""
    n, k = E_b.shape
    _, group = np.unique(np.round(rho_b.T, 12), axis=0, return_inverse=True)
    group = group.reshape(-1)
    rhs, rho, back, wts = [], [], [], []
    for g in np.unique(group):
        cols = np.nonzero(group == g)[0]
        Eg = E_b[:, cols]
        if not np.any(Eg):
            continue
        u, s, vt = np.linalg.svd(Eg, full_matrices=False)
        r = int(np.sum(s > 1e-12 * s[0]))
        rhs.append(u[:, :r] * s[:r])
        rho.append(np.repeat(rho_b[:, cols[:1]], r, axis=1))
        back.append((cols, vt[:r]))
        wts.append(np.abs(vt[:r]) @ weights[cols])
    B = np.zeros((n, k))
    if not rhs:
        st = solvers.SolveStats(method, 0, 0.0, 0.0, True, columns=0)
        st.received = np.zeros((n, k)) if method == "southwell" else None
        return B, [st]
    kw = dict(tol=tol, progress=progress, should_cancel=should_cancel)
    if max_iter is not None:
        kw["max_iter"] = max_iter
    if method == "southwell":
        kw["weights"] = np.concatenate(wts)
    X, st = solvers.solve_dense(method, F, np.concatenate(rho, axis=1), np.concatenate(rhs, axis=1), area, **kw)
    st.columns = X.shape[1]
    recv = None if st.received is None else np.zeros((n, k))
    c0 = 0
    for cols, vt in back:
        B[:, cols] = X[:, c0:c0 + vt.shape[0]] @ vt
        if recv is not None:
            recv[:, cols] = st.received[:, c0:c0 + vt.shape[0]] @ vt
        c0 += vt.shape[0]
    st.received = recv
    return B, [st]


def _stochastic(ctx, patches, rho_b, Be_b, H0_b, v_band, rays, tol, max_iter, seed, progress, should_cancel,
                threads):
    """Matrix-free stochastic Jacobi (shooting rays through the BVH): the emitters' light is
    gathered exactly first (form factors to the emitting patches only), then each iteration
    shoots the power received in the previous one with ``rays`` rays, each patch's share in
    proportion to its unshot luminous power; a ray leaving patch i carries ΔP_i / N_i to
    the patch it hits first. Stops when the unshot luminous power is at most ``tol`` of
    the power reflected so far. Returns (B, H, direct H, stats)."""
    t0 = time.perf_counter()
    n, k = Be_b.shape
    area = patches.area
    emit = np.nonzero(np.any(Be_b > 0, axis=1))[0]
    H = H0_b.copy()
    if emit.size:
        pts = sample_points(patches.corners, 4)
        block = max(1, int(2e8 // max(emit.size * 4, 1)))
        for a in range(0, n, block):
            sl = slice(a, min(n, a + block))
            qry = _query(pts[sl], patches.normal[sl], np.arange(n, dtype=np.int32)[sl], emit)
            op, nv = (K.OP_EMITTERS, ctx.n_emit) if ctx.n_emit > 0 else (K.OP_FORM_FACTORS, ctx.n_vis)
            fe = run_op(op, ctx.pat, qry, ctx.lit, emit.size, nv, seed, ctx.eps, threads)
            H[sl] += fe.astype(np.float64) @ Be_b[emit]
    Hd = H.copy()
    dP = area[:, None] * rho_b * H
    total = dP @ v_band
    it = 0
    unshot = float(dP.sum(axis=0) @ v_band)
    done = not unshot > 0  # nothing to shoot, or a power that is not finite (never converged)
    cancelled = False
    rng = np.random.default_rng(seed)
    while not done and it < max_iter:
        if should_cancel is not None and should_cancel():
            cancelled = True
            break
        w = np.maximum(dP @ v_band, 0.0)
        # rays per patch: stratified rounding of rays · w / Σw
        share = rays * w / w.sum()
        cnt = np.floor(share + rng.random(n)).astype(np.int64)
        src = np.repeat(np.arange(n, dtype=np.int32), cnt)
        if src.size == 0:
            break
        qry = _query(np.zeros((1, 1, 3)), np.zeros((1, 3)), np.zeros(1), None, src)
        hits = run_op(K.OP_SHOOT, ctx.pat, qry, ctx.lit, 0, 0, seed * 7919 + it + 1, ctx.eps, threads)
        carry = dP[src] / cnt[src][:, None]
        ok = hits >= 0
        got = np.zeros((n, k))
        np.add.at(got, hits[ok], carry[ok])
        dH = got / area[:, None]
        H += dH
        dP = area[:, None] * rho_b * dH
        total = total + dP @ v_band
        unshot = float(dP.sum(axis=0) @ v_band)
        it += 1
        res = unshot / max(float(total.sum()), 1e-300)
        if progress is not None:
            progress(it, res)
        done = res <= tol or not math.isfinite(res)
    B = Be_b + rho_b * H
    res = unshot / max(float(total.sum()), 1e-300)
    return B, H, Hd, [solvers.SolveStats("stochastic", it, res, time.perf_counter() - t0, res <= tol, cancelled)]


def radiosity(scene, *, max_edge=None, sides="both", method="gauss-seidel", tol=1e-5, max_iter=None,
              band_width=10.0, n_points=4, n_vis=8, n_emit=1024, n_light=64, rays=None, refine_threshold=None,
              refine_steps=2, min_area=0.0, seed=0, threads=None, progress=None, should_cancel=None):
    """Solve ``scene`` by radiosity (see the module text) and return a :class:`RadiositySolution`.

    max_edge: patch size, m (None: the scene's triangles); sides: "both" or "front"
    (meshing.build_patches); method: "jacobi", "jacobi-power", "gauss-seidel", "southwell"
    (dense form-factor matrix) or "stochastic" (matrix-free shooting); tol: the relative
    residual to stop at (solvers); max_iter: iterations (None: each solver's default);
    band_width: nm per band (1: the renderer's grid, exact); n_points: sample points per
    receiving patch (4^m ≤ n_points); n_vis: shadow rays per pair of point and patch (0:
    no occlusion, for convex rooms); n_emit: shadow rays per pair of point and emitting
    patch where the first 16 of them disagree (a penumbra; kernel.OP_EMITTERS), the direct
    light's visibility; n_light: samples per point per analytic light;
    rays: rays per stochastic iteration (None: 64 per patch); refine_threshold: split
    patches whose luminance differs from a neighbour's by more than this fraction and solve
    again, up to refine_steps times, down to min_area m²; progress(stage, a, b):
    ("patches", n, max_edge) once meshed, ("direct", done, total) after that stage,
    ("form factors", rows done, rows) after each block of rows (Southwell computes its rows
    while it solves), ("solve", iteration, residual) after each iteration (for Southwell
    each step; iteration counts the shots); should_cancel(): checked between stages,
    blocks of rows and iterations (True: the solution so far is returned, flagged in its
    stats)."""
    from ...film.record import cmf_table
    from ...bsdfs.record import spectrum_table
    from ..render import thread_count

    validate(scene)
    if method not in ("jacobi", "jacobi-power", "gauss-seidel", "southwell", "stochastic"):
        raise SceneError(f"radiosity method: unknown {method!r}; use jacobi, jacobi-power, gauss-seidel, "
                         "southwell or stochastic")
    if not (float(tol) > 0):
        raise SceneError(f"radiosity tol: expected a positive number, got {tol!r}")
    if isinstance(n_emit, bool) or not isinstance(n_emit, (int, np.integer)) or n_emit < 1:
        raise SceneError(f"radiosity n_emit: expected a whole number of shadow rays ≥ 1, got {n_emit!r}")
    n_threads = thread_count(threads)
    cmf = cmf_table(scene.settings.observer)
    spec = spectrum_table(scene)
    edges, bidx, vw, v_band, xyz_band = band_tables(cmf, band_width)
    nb = v_band.size
    patches = meshing.build_patches(scene, max_edge, sides)
    if progress is not None:
        progress("patches", patches.n, 0.0 if max_edge is None else float(max_edge))
    lit, light_shapes, notes = _lights(scene, spec, cmf, patches.geometry)
    light_bands = band_means(light_shapes, bidx, vw, nb)
    for step in range(int(refine_steps) + 1 if refine_threshold else 1):
        sol = _solve_patches(scene, spec, cmf, patches, lit, light_bands, bidx, vw, v_band, xyz_band, edges,
                             method, tol, max_iter, n_points, n_vis, n_light, rays, seed, n_threads, progress,
                             should_cancel, 0 if n_vis == 0 else max(int(n_emit), int(n_vis)))
        if not refine_threshold or step == int(refine_steps) or any(s.cancelled for s in sol.stats):
            break
        patches, n_split = meshing.refine(sol.patches, sol.luminance, refine_threshold, min_area)
        if n_split == 0:
            break
    sol.warnings = notes + sol.warnings
    for w in sol.warnings:
        warnings.warn(w, stacklevel=2)
    return sol


def _solve_patches(scene, spec, cmf, patches, lit, light_bands, bidx, vw, v_band, xyz_band, edges, method, tol,
                   max_iter, n_points, n_vis, n_light, rays, seed, threads, progress, should_cancel, n_emit):
    t_start = time.perf_counter()
    seconds = {}
    nb = v_band.size
    rho_m, le_m, two_m, notes = _materials(scene, spec, cmf, patches)
    rho_mb = band_means(rho_m, bidx, vw, nb)
    be_mb = math.pi * band_means(le_m, bidx, vw, nb)
    eps = _eps(patches.geometry)
    pat = patch_record(patches.corners, patches.geometry, patches.tri_patch, patches.occluders)
    pts = sample_points(patches.corners, n_points)
    own = np.arange(patches.n, dtype=np.int32)
    # direct light from the analytic lights and the sky, which also finds the sides that see nothing
    t0 = time.perf_counter()
    qry = _query(pts, patches.normal, own)
    direct = run_op(K.OP_DIRECT, pat, qry, lit, lit.kind.size + 1, n_light, seed, eps, threads,
                    should_cancel=should_cancel).astype(np.float64)
    seconds["direct"] = time.perf_counter() - t0
    if progress is not None:
        progress("direct", patches.n, patches.n)
    emits = np.any(le_m[patches.material] > 0, axis=1) & ((patches.side == 0) | two_m[patches.material])
    lit_direct = np.any(direct[:, :-1] > 0, axis=1) | ((direct[:, -1] > 0) & np.any(light_bands[-1] > 0))
    sees_something = direct[:, -1] < math.pi * (1.0 - 1e-9)
    keep = emits | lit_direct | sees_something
    if not keep.all():
        patches = patches.subset(keep)
        pat = patch_record(patches.corners, patches.geometry, patches.tri_patch, patches.occluders)
        pts = pts[keep]
        direct = direct[keep]
        emits = emits[keep]
        own = np.arange(patches.n, dtype=np.int32)
    n = patches.n
    rho_b = rho_mb[patches.material]
    be_b = np.where(emits[:, None], be_mb[patches.material], 0.0)
    H0 = direct @ light_bands  # (n, K) W/(m² nm)
    ctx = _Context(pat, lit, light_bands, v_band, eps, seed, n_light, n_vis, threads, xyz_band, n_emit)
    emit_idx = np.nonzero(emits)[0].astype(np.int32)
    if method == "stochastic":
        B, H, Hd, stats = _stochastic(ctx, patches, rho_b, be_b, H0, v_band, 64 * n if rays is None else int(rays),
                                  tol, 10000 if max_iter is None else int(max_iter), seed,
                                  None if progress is None else (lambda i, r: progress("solve", i, r)),
                                  should_cancel, threads)
        seconds["solve"] = stats[0].seconds
    else:
        if 4 * n * n > DENSE_LIMIT_BYTES:
            raise SceneError(f"radiosity: {n} patches need a {4 * n * n / 2 ** 30:.1f} GiB form-factor matrix; "
                             "use method='stochastic' (matrix-free) or larger patches")
        t0 = time.perf_counter()
        cols = np.arange(n, dtype=np.int32)
        if method == "southwell":  # rows on demand: only the patches that shoot need theirs
            def compute(idx):
                q = _query(pts[idx], patches.normal[idx], own[idx], cols)
                rows = run_op(K.OP_FORM_FACTORS, pat, q, lit, n, n_vis, seed, eps, threads,
                              should_cancel=should_cancel)
                return emitter_pairs(rows, own[idx], emit_idx, pat, pts[idx], patches.normal[idx], own[idx], lit,
                                     n_emit, seed, eps, threads, should_cancel)

            F = solvers.RowCache(n, compute)
        else:
            F = run_op(K.OP_FORM_FACTORS, pat, _query(pts, patches.normal, own, cols), lit, n, n_vis, seed, eps,
                       threads, should_cancel=should_cancel,
                       report=None if progress is None else (lambda a, b: progress("form factors", a, b)))
            emitter_pairs(F, own, emit_idx, pat, pts, patches.normal, own, lit, n_emit, seed, eps, threads,
                          should_cancel)
            seconds["form factors"] = time.perf_counter() - t0
        E = be_b + rho_b * H0
        B, stats = _solve_groups(method, F, rho_b, E, patches.area, tol, max_iter, v_band,
                                 None if progress is None else (lambda i, r: progress("solve", i, r)),
                                 should_cancel)
        seconds["solve"] = sum(s.seconds for s in stats)
        if method == "southwell":  # the rows no patch shot are computed for the gather below
            seconds["solve"] -= F.seconds
            F(np.nonzero(~F.have)[0])
            seconds["form factors"] = F.seconds
            F = F.F
        H = H0 + (F @ B.astype(np.float32)).astype(np.float64)
        Hd = H0 + (F @ be_b.astype(np.float32)).astype(np.float64)
    illum = C.K_M * (H @ v_band)
    lum = C.K_M * (B @ v_band) / math.pi
    xyz = C.K_M * (B @ xyz_band) / math.pi
    mesh = meshing.display_mesh(patches)
    seconds["total"] = time.perf_counter() - t_start
    return RadiositySolution(patches, mesh, edges, B, H, illum, lum, meshing.to_vertices(mesh, patches, illum),
                             meshing.to_vertices(mesh, patches, lum), xyz, stats, C.K_M * (Hd @ v_band), be_b, rho_b,
                             notes, seconds, ctx)


def illuminance_at(solution, points, normals, *, direct=True, indirect=True, n_points=None):
    """Illuminance (lux) at ``points`` (N, 3) on planes with unit ``normals`` (N, 3), from a
    solution: the analytic lights (and a constant world) by next-event sampling with shadow
    rays, as the patches received them, plus Σ_j F_{x→j} B_j over every patch (the
    emitting patches' light is the direct part, the others' the indirect), with
    visibility (to the emitting patches adaptive, up to the solution's ``n_emit`` shadow
    rays where a point is in a penumbra). ``direct``/``indirect``: include the analytic lights and emitting patches
    (direct) or the reflected light (indirect). Returns (N,) lux."""
    from ...integrators.illuminance import _points, _unit

    ctx = solution._ctx
    p = _points("points", points)
    nrm = _unit("normals", _points("normals", normals), "normal")
    if nrm.shape[0] != p.shape[0]:
        raise SceneError(f"normals: {nrm.shape[0]} normals for {p.shape[0]} points")
    n = solution.patches.n
    pts = p[:, None, :]
    own = np.full(p.shape[0], -1, np.int32)
    H = np.zeros((p.shape[0], ctx.v_band.size))
    if direct:
        d = run_op(K.OP_DIRECT, ctx.pat, _query(pts, nrm, own), ctx.lit, ctx.lit.kind.size + 1, ctx.n_light,
                   ctx.seed + 1, ctx.eps, ctx.threads).astype(np.float64)
        H += d @ ctx.light_bands
    F = run_op(K.OP_FORM_FACTORS, ctx.pat, _query(pts, nrm, own, np.arange(n, dtype=np.int32)), ctx.lit, n,
               ctx.n_vis, ctx.seed + 1, ctx.eps, ctx.threads)
    Be = solution.emitted
    emit = np.nonzero(np.any(Be > 0, axis=1))[0].astype(np.int32)
    F = emitter_pairs(F, None, emit, ctx.pat, pts, nrm, own, ctx.lit, ctx.n_emit, ctx.seed + 1, ctx.eps,
                      ctx.threads).astype(np.float64)
    if direct:
        H += F @ Be
    if indirect:
        H += F @ (solution.radiosity - Be)
    return C.K_M * (H @ ctx.v_band)


DEFAULT_PATCHES = 2500


def default_max_edge(scene, patches=DEFAULT_PATCHES):
    """The patch size a lighting analysis uses without one: the largest ``max_edge`` (m) that
    cuts the scene's triangles into at least ``patches`` pieces (one side of each; the
    sides that see nothing are dropped in the solve, the others make about this many
    patches), so the cost follows the scene's detail, not its size."""
    tri, _, _ = meshing.scene_triangles(scene)
    if tri.shape[0] == 0:
        raise SceneError("radiosity: the scene has no surfaces to mesh into patches")
    edge = np.max(np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2), axis=1)

    def count(h):
        return float(np.sum(np.maximum(1.0, np.ceil(edge / h - 1e-9)) ** 2))

    hi = float(edge.max())
    if count(hi) >= patches:
        return hi
    lo = hi / max(2.0, math.sqrt(patches))
    while count(lo) < patches:
        lo *= 0.5
    for _ in range(40):  # count(lo) ≥ patches > count(hi)
        mid = 0.5 * (lo + hi)
        if count(mid) >= patches:
            lo = mid
        else:
            hi = mid
    return lo


LUX_DEFAULTS = dict(method="jacobi", n_points=1, n_vis=4, tol=1e-4)


def lux_integrator(progress=None, should_cancel=None, **options):
    """An illuminance integrator for the lighting analysis (core/lux/calculate.py): a callable
    ``(scene, points, normals) → (lux, std_error)`` that solves the scene by :func:`radiosity`
    with ``options`` once per scene and gathers at the points the analytic lights and
    emitting patches directly plus the solution's reflected light (:func:`illuminance_at`).
    Options not given take ``LUX_DEFAULTS`` (Jacobi to a residual of 1e-4, one sample point
    per patch, four shadow rays per pair) and max_edge ``default_max_edge`` (about
    ``DEFAULT_PATCHES`` patches). ``progress(stage, a, b)``, ``should_cancel()``: as
    :func:`radiosity`, plus ("patches", n, max_edge) once the scene is meshed and
    ("gather", points, 0) before the gather. The error of radiosity is the mesh's, not
    sampling noise: the standard errors returned are 0."""
    cache = {}

    def integrate(scene, points, normals):
        key = id(scene)
        if key not in cache:
            opts = {**LUX_DEFAULTS, **{k: v for k, v in options.items() if v is not None}}
            if opts.get("max_edge") is None:
                opts["max_edge"] = default_max_edge(scene)
            cache.clear()
            cache[key] = (scene, radiosity(scene, progress=progress, should_cancel=should_cancel, **opts))
        if progress is not None:
            progress("gather", int(np.asarray(points).reshape(-1, 3).shape[0]), 0)
        lux = illuminance_at(cache[key][1], points, normals)
        return lux, np.zeros_like(lux)

    return integrate
