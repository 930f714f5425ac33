"""Final gather: a camera image from a radiosity solution, by the path tracer's first bounce.

Each camera ray (the path tracer's camera and pixel filter, ``kernel.OP_CAMERA``) finds
the patch it sees; there the reflected radiance is ρ/π times the irradiance, which is
gathered in two parts:

* direct, exactly as the path tracer's next-event estimation does it: every analytic light
  (and a constant world) by light sampling with shadow rays (``kernel.OP_DIRECT``), and
  every emitting patch by Lambert's closed form with shadow rays (``kernel.OP_FORM_FACTORS``
  with the emitters as columns, item 58);
* indirect: ``gather`` cosine-distributed rays (``kernel.OP_GATHER``) each read the
  reflected radiosity B − B_e of the patch they reach, interpolated across the patch from
  the display mesh's vertices (meshing.to_vertices), and H = mean(B − B_e) (the cosine
  weight and π cancel against the cosine-distributed directions).

A camera ray that reaches an emitting side adds its emitted radiance B_e/π; one that leaves
the scene sees the constant world's radiance. So the image's error is the path tracer's
noise in the direct light and the gather, plus the mesh's error one bounce removed, where
it is smoothed by the gather (the patches' error enters only through the light they send
to the visible points). Spectra are the solution's wavelength bands; the film holds
Σ_b L_b ∫_band x̄, ȳ, z̄ dλ as the path tracer's film holds ∫ L x̄, ȳ, z̄ dλ, so the same
develop and outputs (EXR, PNG) apply. Materials are the solve's: diffuse albedo (see
solve.py); the image shows no gloss, no transparency and no textures.

Random numbers: each camera sample's from (seed, pixel, sample), its gather rays' and
light samples' from the tile of pixels it belongs to, whose size does not depend on the
threads; the same scene, solution, seed and samples give the same image for any number
of threads.
"""
from __future__ import annotations

import math
import time

import numpy as np

from ...scene import SceneError
from . import kernel as K
from . import meshing

TILE_SAMPLES = 4096  # camera samples per tile (the unit of progress, cancel and random numbers)


def _rays(out, spp_or_g):
    """(patch int64 (R·k,), b1, b2) of the OP_CAMERA / OP_GATHER output (R, 3k)."""
    o = out.reshape(-1, spp_or_g, 3).reshape(-1, 3).astype(np.float64)
    return o[:, 0].astype(np.int64), o[:, 1], o[:, 2]


def _interpolate(table, which, faces, patch, b1, b2):
    """Per-vertex values ``table[which]`` (tables (M, V, C), one index per ray) at barycentric
    (b1, b2) of each ray's patch (−1: 0): (R, C)."""
    ok = patch >= 0
    f = faces[np.maximum(patch, 0)]
    v = ((1.0 - b1 - b2)[:, None] * table[which, f[:, 0]] + b1[:, None] * table[which, f[:, 1]]
         + b2[:, None] * table[which, f[:, 2]])
    v[~ok] = 0.0
    return v


def final_gather(solution, scene, *, spp=None, gather=64, n_light=None, n_shadow=16, seed=None, threads=None,
                 progress=None, should_cancel=None):
    """Render ``scene``'s camera from ``solution`` (:func:`solve.radiosity` of the same scene)
    by final gather (see the module text). spp: camera samples per pixel (None: the scene's
    settings); gather: gather rays per camera sample; n_light: light samples per camera
    sample per analytic light (None: the solution's); n_shadow: shadow rays per camera
    sample to each emitting patch; seed: None, the scene's. ``progress(done, total, rate)``:
    camera samples per pixel done so far (fractional tiles rounded down) of ``spp``, and
    samples per second, after each tile; ``should_cancel()`` between tiles. Returns
    (core.film.Film, seconds, cancelled); a cancelled film holds the tiles done (the
    others have no samples). The film's passes: normals and hits as the path tracer's, depth
    the distance of the first hit from the camera's position (the path tracer's distance
    along the ray for a pinhole), no albedo."""
    from ...camera import record as camera_record
    from ...film import Film
    from .solve import _query, run_op

    from ..render import thread_count

    ctx = solution._ctx
    nt = ctx.threads if threads is None else thread_count(threads)
    st = scene.settings
    spp = int(st.spp if spp is None else spp)
    gather = int(gather)
    if spp < 1 or gather < 0:
        raise SceneError(f"final gather: expected spp ≥ 1 and gather ≥ 0, got {spp} and {gather}")
    seed = int(st.seed if seed is None else seed)
    n_light = int(ctx.n_light if n_light is None else n_light)
    cam = camera_record.pack(scene)
    origin = np.asarray(scene.camera.to_world, np.float64)[:3, 3]  # the depth pass: distance from here
    w, h = int(scene.camera.width), int(scene.camera.height)
    film = Film(w, h, observer=st.observer)
    sums = np.zeros_like(film.sums)
    aov = np.zeros_like(film.aov)
    patches = solution.patches
    mesh = solution.mesh
    be = solution.emitted
    rho = solution.reflectance
    reflected_v = meshing.to_vertices(mesh, patches, solution.radiosity - be)  # (V, K)
    emit = np.nonzero(np.any(be > 0, axis=1))[0].astype(np.int32)
    sky = ctx.light_bands[-1]
    photometric = sums.shape[-1] > 5
    # the film's channels of a radiance per band: X, Y, Z and the V-weighted Y
    basis = np.concatenate([ctx.xyz_band, ctx.v_band[:, None]], axis=1)  # (K, 4)
    # a gather ray's reading, already in film channels for each reflectance of the scene: the
    # reflected radiosity at each vertex times ρ/π of the gathering patch (one table per distinct ρ)
    rho_u, rho_of = np.unique(rho, axis=0, return_inverse=True)
    rho_of = rho_of.reshape(-1)
    table = np.einsum("vk,mk,kc->mvc", reflected_v, rho_u, basis) / math.pi  # (M, V, 4)
    sky_c = sky @ basis
    need_direct = ctx.lit.kind.size > 0 or bool(np.any(sky > 0))
    n_pix = w * h
    tile = max(1, TILE_SAMPLES // spp)
    t0 = time.perf_counter()
    cancelled = False
    done = 0
    for ti, p0 in enumerate(range(0, n_pix, tile)):
        if should_cancel is not None and should_cancel():
            cancelled = True
            break
        p1 = min(n_pix, p0 + tile)
        pix = np.arange(p0, p1, dtype=np.int32)
        tseed = (seed * 1000003 + ti + 1) % (1 << 62)
        q = _query(np.zeros((pix.size, 1, 3)), np.zeros((pix.size, 3)), pix, np.array([w, h], np.int32), cam=cam.cam,
                   filt=cam.filt)
        patch, b1, b2 = _rays(run_op(K.OP_CAMERA, ctx.pat, q, ctx.lit, 3 * spp, spp, seed, ctx.eps, nt),
                              spp)
        out = np.broadcast_to(sky_c, (patch.size, 4)).copy()  # film channels per sample
        hit = np.nonzero(patch >= 0)[0]
        nrm_s = np.zeros((patch.size, 3))
        dist = np.zeros(patch.size)
        if hit.size:
            j = patch[hit]
            c = patches.corners[j]
            x = c[:, 0] + b1[hit, None] * (c[:, 1] - c[:, 0]) + b2[hit, None] * (c[:, 2] - c[:, 0])
            nrm = patches.normal[j]
            nrm_s[hit] = nrm
            dist[hit] = np.linalg.norm(x - origin, axis=1)
            own = np.full(hit.size, -1, np.int32)  # light samples and shadow rays keyed by the row
            H = np.zeros((hit.size, sky.size))
            if n_light > 0 and need_direct:
                d = run_op(K.OP_DIRECT, ctx.pat, _query(x[:, None], nrm, own), ctx.lit, ctx.lit.kind.size + 1,
                           n_light, tseed, ctx.eps, nt).astype(np.float64)
                H += d @ ctx.light_bands
            if emit.size and n_shadow > 0:
                fe = run_op(K.OP_FORM_FACTORS, ctx.pat, _query(x[:, None], nrm, own, emit), ctx.lit, emit.size,
                            int(n_shadow), tseed, ctx.eps, nt).astype(np.float64)
                H += fe @ be[emit]
            res = (rho[j] * H / math.pi + be[j] / math.pi) @ basis
            if gather > 0:
                key = ((p0 * spp + hit) % (1 << 31)).astype(np.int32)
                og = run_op(K.OP_GATHER, ctx.pat, _query(x[:, None], nrm, key), ctx.lit, 3 * gather, gather, tseed,
                            ctx.eps, nt)
                gp, g1, g2 = _rays(og, gather)
                res += _interpolate(table, rho_of[np.repeat(j, gather)], mesh.faces, gp, g1, g2).reshape(
                    hit.size, gather, 4).mean(axis=1)
            out[hit] = res
        xyz = out[:, :3]
        y = out[:, 3] if photometric else xyz[:, 1]
        m = p1 - p0
        blk = sums[p0 // w: (p1 - 1) // w + 1].reshape(-1, sums.shape[-1])
        off = p0 - (p0 // w) * w
        part = blk[off:off + m]
        part[:, :3] += xyz.reshape(m, spp, 3).sum(axis=1)
        part[:, 3] += spp
        part[:, 4] += (y * y).reshape(m, spp).sum(axis=1)
        if photometric:
            part[:, 5] += y.reshape(m, spp).sum(axis=1)
        ablk = aov[p0 // w: (p1 - 1) // w + 1].reshape(-1, aov.shape[-1])[off:off + m]
        ablk[:, 3:6] += nrm_s.reshape(m, spp, 3).sum(axis=1)
        ablk[:, 6] += dist.reshape(m, spp).sum(axis=1)
        ablk[:, 7] += (patch >= 0).reshape(m, spp).sum(axis=1)
        done = p1
        if progress is not None:
            el = max(time.perf_counter() - t0, 1e-9)
            progress(spp * done // n_pix, spp, done * spp / el)
    film.sums = sums
    film.aov = aov
    film.spp = spp if done else 0
    return film, time.perf_counter() - t0, cancelled


def render(scene, *, solution=None, spp=None, gather=64, n_light=None, n_shadow=16, seed=None, threads=None,
           progress=None, status=None, should_cancel=None, **options):
    """Render ``scene`` by radiosity and final gather: solve it (:func:`solve.radiosity` with
    ``options``; those not given take the lighting analysis' ``solve.LUX_DEFAULTS`` and
    ``solve.default_max_edge``), or take ``solution``, then :func:`final_gather`.
    ``status(text)``: one line per stage of the solve; ``progress``, ``should_cancel``: as
    :func:`final_gather` (cancel also stops the solve). Returns (film, RenderStats,
    solution); a cancelled render's stats have ``cancelled`` set and its film no samples
    (``spp`` 0) if the solve was cut short."""
    from ..render import RenderStats, thread_count
    from . import solve

    t0 = time.perf_counter()
    if solution is None:
        opts = {**solve.LUX_DEFAULTS, **{k: v for k, v in options.items() if v is not None}}
        if opts.get("max_edge") is None:
            opts["max_edge"] = solve.default_max_edge(scene)
        opts.setdefault("threads", thread_count(threads))

        def stage(name, a, b):
            if status is None:
                return
            if name == "patches":
                status(f"radiosity: {a} patches of at most {b:.3g} m")
            elif name == "solve":
                status(f"radiosity: iteration {a}, residual {b:.3g}")
            elif name == "direct":
                status("radiosity: direct light done")

        solution = solve.radiosity(scene, progress=stage, should_cancel=should_cancel, **opts)
        if any(s.cancelled for s in solution.stats):
            from ...film import Film

            film = Film(scene.camera.width, scene.camera.height, observer=scene.settings.observer)
            return film, RenderStats(0, time.perf_counter() - t0, 0.0, True, 0.0, 0.0, "cancelled"), solution
    t_solve = time.perf_counter() - t0
    if status is not None:
        status(f"final gather: {gather} gather rays a sample")
    film, seconds, cancelled = final_gather(solution, scene, spp=spp, gather=gather, n_light=n_light,
                                            n_shadow=n_shadow, seed=seed, threads=threads, progress=progress,
                                            should_cancel=should_cancel)
    rate = film.spp * film.width * film.height / max(seconds, 1e-9)
    return film, RenderStats(film.spp, seconds, rate, cancelled, t_solve, 0.0,
                             "cancelled" if cancelled else "spp"), solution
