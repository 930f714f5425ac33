"""Render a scene: prepare arrays, build the BVH, run passes of the path tracer.

``render(scene, progress=, should_cancel=, on_pass=)`` is what the CLI and the
Blender add-on call. Progress and cancellation cross as plain callables. The path
kernel is serial and releases the GIL; a pool of Python threads runs blocks of rows.
The few parallel (prange) kernels that remain, the batch tools in ``accel``, are
launched under one process-wide lock: numba's threading layers abort the process when
two threads launch parallel kernels at once, which would take Blender down with them.
"""
from __future__ import annotations

import gc
import math
import os
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from . import settings as settings_record
from . import warmup
from ..bsdfs import record as bsdfs_record
from ..camera import record as camera_record
from ..film import Film
from ..film import record as film_record
from ..geometry import record as geometry_record
from ..geometry import visibility as visibility_record
from ..geometry.accel import build as build_bvh
from ..lights import record as lights_record
from ..media import record as media_record
from ..scene import Scene, SceneError, validate
from ..textures import record as textures_record
from .warmup import kernels_compiled


# Target wall time of one pass, so progress and cancel stay live (architecture: 0.1–0.5 s).
PASS_SECONDS = 0.3
CHECKPOINT_SECONDS = 10.0  # a local render's checkpoint file is rewritten this often (and at the end)


@dataclass
class Prepared:
    """Everything the path kernel reads but the film, as its records (each record's fields
    are documented where it is defined)."""

    scene: Scene
    bvh: object
    build_seconds: float
    cmf: np.ndarray  # the observer's table (core/film/record.py cmf_table)
    geometry: geometry_record.GeometryRecord
    materials: bsdfs_record.MaterialRecord
    emitters: lights_record.EmitterRecord
    media: media_record.MediaRecord
    textures: textures_record.TextureRecord
    camera: camera_record.CameraRecord
    settings: settings_record.SettingsRecord
    visibility: visibility_record.VisibilityRecord | None = None  # None: no visibility flags nor links


def prepare(scene: Scene, measure=False, bvh=None) -> Prepared:
    """The kernel's records for ``scene``. measure=True prepares the illuminance render of
    its sensor meshes (core/integrators/sensors.py): one more material, a white (ρ = 1)
    two-sided Lambert, that the camera ray's first hit on a sensor takes instead of its own.
    ``bvh``: a BVH built over exactly this scene's triangles (the same corners, in the same
    order), used instead of building one (an interactive render whose geometry did not change).

    The spectrum table grows as the domains add their rows: the scene's spectra, the world
    image's emission basis, the textures' reflectance basis, the sensors' ρ = 1."""
    validate(scene)
    t0 = time.perf_counter()
    cmf = film_record.cmf_table(scene.settings.observer)
    spec = bsdfs_record.spectrum_table(scene)
    v0, v1, v2, tri_mat_orig = geometry_record.triangles(scene)
    if bvh is None or len(bvh.prims) != v0.shape[0]:
        bvh = build_bvh(v0, v1, v2)
    tri_mat = np.ascontiguousarray(tri_mat_orig[bvh.prims], np.int32)
    materials = bsdfs_record.pack(scene, spec, cmf)
    emitters, tri_emitter, spec = lights_record.pack(scene, spec, cmf, bvh, tri_mat, materials.emis,
                                                     materials.emis_two, geometry_record.scene_radius(v0, v1, v2))
    textures, spec = textures_record.pack(scene, bvh.prims, spec, cmf)
    sensor_mat = -1
    if measure:
        materials, spec, sensor_mat = bsdfs_record.add_sensor(materials, spec)
        textures = textures_record.add_sensor(textures)
    materials = bsdfs_record.finish(materials, spec, cmf)
    scale = settings_record.scene_scale(v0, v1, v2, emitters.light_kind, emitters.light_geo)
    media = media_record.pack(scene, spec, v0, v1, v2, tri_mat_orig, measure)
    geometry = geometry_record.pack(scene, bvh, tri_mat, tri_emitter, tri_mat_orig, measure)
    visibility = visibility_record.pack(scene, bvh, emitters)
    return Prepared(scene, bvh, time.perf_counter() - t0, cmf, geometry, materials, emitters, media, textures,
                    camera_record.pack(scene), settings_record.pack(scene.settings, sensor_mat, scale), visibility)


def kernel_records(prep):
    """The media and texture records as the path kernel takes them: None for a scene without
    media (and null surfaces) or without image textures, so that its kernel is compiled
    without their code (numba prunes the branches on a None argument and compiles one
    specialisation per combination, each cached)."""
    med = prep.media if prep.media.med_tab.shape[0] > 0 else None
    txr = prep.textures if prep.textures.tri_tex.shape[0] > 0 else None
    return med, txr


# The path kernel's pixel mask when every pixel is sampled: an empty array (one type for both
# cases, so that adaptive sampling compiles no second kernel; see adaptive_mask)
ALL_PIXELS = np.zeros((0, 0), np.uint8)


def _rows(prep, film, y0, y1, s0, s1, active=None):
    from .path import render_rows, scratch

    med, txr = kernel_records(prep)
    render_rows(int(y0), int(y1), int(s0), int(s1), film_record.pack(film, prep.cmf), prep.geometry,
                prep.materials, prep.emitters, med, txr, prep.camera, prep.settings,
                scratch(prep.materials.params.shape[1]), ALL_PIXELS if active is None else active,
                prep.visibility)


def thread_count(threads=None):
    """Worker threads for a render: ``threads`` if given (> 0), else one per core."""
    if threads is not None and int(threads) > 0:
        return int(threads)
    return max(1, os.cpu_count() or 1)


def run_pass(prep: Prepared, film: Film, s0: int, s1: int, pool=None, active=None):
    """Add samples [s0, s1) of every pixel to ``film`` (of the pixels where ``active``, a
    uint8 (H, W) mask, is not 0, when given: adaptive sampling).

    With a ``concurrent.futures`` ``pool``, blocks of rows run on its threads (the kernel
    releases the GIL); without one, on the calling thread. The result is the same. The
    samples are summed one by one into the film's arrays: a render adds its samples with
    :func:`add_samples`, chunk by chunk.
    """
    if film.tail_spp:
        raise ValueError("run_pass: the film holds an incomplete chunk apart; add samples with add_samples")
    h = film.height
    if active is not None:
        active = np.ascontiguousarray(active, np.uint8)
        if active.shape != (h, film.width):
            raise ValueError(f"run_pass: the mask is {active.shape}, the film {(h, film.width)}")
    if pool is None:
        _rows(prep, film, 0, h, s0, s1, active)
    else:
        workers = getattr(pool, "_max_workers", 1)
        rows = np.arange(h) if active is None else np.flatnonzero(active.any(axis=1))
        block = max(1, len(rows) // (8 * workers))  # several blocks per thread balance the load
        spans = [(int(rows[i]), int(rows[min(i + block, len(rows)) - 1]) + 1) for i in range(0, len(rows), block)]
        futures = [pool.submit(_rows, prep, film, a, b, s0, s1, active) for a, b in spans]
        for f in futures:
            f.result()
    film.spp = s1


def add_samples(prep: Prepared, film: Film, s0: int, s1: int, pool=None, active=None):
    """Add samples [s0, s1) (s0 = film.spp) to ``film`` in the film's order of additions
    (core/film ``Film``: each chunk's samples summed from zero, the chunks added in order),
    so the image is the same for any split of the samples into passes or farm tasks.
    ``active``: the pixels to sample (``run_pass``); the others' samples are counted in
    ``film.skipped_samples``."""
    from ..film import chunk_spans

    if s0 != film.spp:
        raise ValueError(f"add_samples: the film has {film.spp} spp, the samples start at {s0}")
    for a, b in chunk_spans(s0, s1):
        part = film.open_chunk()
        run_pass(prep, part, a, b, pool, active)
        film.merge_chunk(part, b)
    if active is not None:
        film.skipped_samples += (s1 - s0) * int(active.size - np.count_nonzero(active))


@dataclass
class RenderStats:
    spp: int
    seconds: float
    samples_per_second: float
    cancelled: bool
    build_seconds: float
    compile_seconds: float
    stop_reason: str = "spp"  # "spp" (all samples), "time_limit", "noise_target" or "cancelled"
    relative_error: float = float("nan")  # the noise target's measure (relative_error): per-pixel, 95th percentile
    dropped_samples: int = 0  # samples the film does not hold for not being finite (Film.dropped_samples)
    skipped_samples: int = 0  # samples of spp × pixels that adaptive sampling did not take (converged pixels)


# The noise target judges each pixel's relative standard error of luminance (as Cycles'
# adaptive sampling judges each pixel): adaptive sampling stops each pixel within it (below);
# stopping the whole image, the render stops once NOISE_QUANTILE of the pixels are within the
# target (the measure RenderStats reports in either case). A pixel darker than NOISE_DARK × the
# image's mean luminance is judged against that luminance instead of its own (a black or nearly
# black pixel's relative error is no measure of visible noise; Cycles likewise relaxes its
# criterion in dark pixels).
NOISE_QUANTILE = 0.95
NOISE_DARK = 0.05


def noise_min_samples(target):
    """The samples taken before the noise target is first judged: Cycles' automatic minimum,
    max(4, ⌈16 / target^0.3⌉) (intern/cycles/scene/integrator.cpp, get_adaptive_sampling:
    0.1 → 32, 0.01 → 64)."""
    if not target > 0:
        return 0
    return max(4, math.ceil(16.0 / target ** 0.3))


def pixel_relative_errors(film):
    """(H, W) relative standard error of each pixel's mean luminance, from the film's per-pixel
    sums of Y and Y² (sample variance / n, over max(pixel mean, NOISE_DARK × image mean));
    inf where a pixel has fewer than 2 samples."""
    from ..film import photometric_y_sums

    sums = film.sums
    n = sums[..., 3]
    if n.size == 0 or n.min() < 2:
        return np.full(n.shape, np.inf)
    mean = photometric_y_sums(sums) / n
    var = np.maximum(sums[..., 4] / n - mean * mean, 0.0) / (n - 1.0)
    floor = NOISE_DARK * max(float(mean.mean()), 0.0)
    ref = np.maximum(mean, floor)
    se = np.sqrt(var)
    with np.errstate(divide="ignore", invalid="ignore"):
        err = np.where(ref > 0.0, se / np.where(ref > 0.0, ref, 1.0), np.where(se > 0.0, np.inf, 0.0))
    return err


def relative_error(film):
    """The noise target's measure of ``film``: the NOISE_QUANTILE quantile of the pixels'
    relative standard errors of luminance (pixel_relative_errors)."""
    err = pixel_relative_errors(film)
    if err.size == 0:
        return float("inf")
    return float(np.quantile(err, NOISE_QUANTILE, method="higher"))


def noise_samples_needed(film, target):
    """The samples at which ``film`` should meet the noise target: Cycles' minimum, or past it the
    count at which the error, falling as 1/√n, reaches the target (never fewer than one more)."""
    first = noise_min_samples(target)
    if film.spp < first:
        return first
    err = relative_error(film)
    if not math.isfinite(err):
        return film.spp + 1
    return max(film.spp + 1, math.ceil(film.spp * (err / target) ** 2))


# Adaptive sampling (settings.noise_target, as Cycles'): past the minimum samples, and then every
# ADAPTIVE_STEP samples, each pixel whose relative standard error is within the target stops
# receiving samples, unless a neighbour (3 × 3) still needs them. Cycles checks every 16 samples
# (intern/cycles/scene/integrator.cpp, get_adaptive_sampling) and dilates its unconverged pixels
# by one pixel in x, then in y (intern/cycles/kernel/film/adaptive_sampling.h). 16 is the film's
# CHUNK_SPP too, so the mask changes only between chunks.
ADAPTIVE_STEP = 16


def adaptive_check_at(film, target):
    """The sample count at which the adaptive mask is next judged: the first multiple of
    ADAPTIVE_STEP at or past both Cycles' minimum samples and one more than ``film.spp``."""
    first = max(noise_min_samples(target), film.spp + 1)
    return -(-first // ADAPTIVE_STEP) * ADAPTIVE_STEP


def adaptive_mask(film, target, active=None):
    """uint8 (H, W): the pixels that go on receiving samples under the noise ``target``: those
    of ``active`` (all when None) whose relative standard error (pixel_relative_errors) is above
    the target, with their eight neighbours (a converged pixel next to a noisy one goes on,
    as Cycles' filter of its convergence mask)."""
    need = pixel_relative_errors(film) > target
    if active is not None:
        need &= active != 0
    out = need.copy()
    out[:, 1:] |= need[:, :-1]
    out[:, :-1] |= need[:, 1:]
    rows = out.copy()
    out[1:] |= rows[:-1]
    out[:-1] |= rows[1:]
    return out.astype(np.uint8)


def noise_reached(film, target):
    """True when ``film`` meets the noise target: at least noise_min_samples(target) samples and
    relative_error(film) ≤ target."""
    return target > 0 and film.spp >= noise_min_samples(target) and relative_error(film) <= target


def start_film(scene, resume=None, spectral_bins=0):
    """The film a render of ``scene`` starts from: a zero film, or a copy of ``resume``
    once it is checked against the scene (SceneError naming the mismatch)."""
    cam = scene.camera
    if resume is None:
        return Film(cam.width, cam.height, spectral_bins, observer=scene.settings.observer)
    if (resume.width, resume.height) != (cam.width, cam.height):
        raise SceneError(f"resume: the film is {resume.width}x{resume.height}, the scene renders "
                         f"{cam.width}x{cam.height}")
    if getattr(resume, "observer", "1931") != scene.settings.observer:
        raise SceneError(f"resume: the film was rendered with the CIE {resume.observer} observer, the "
                         f"scene asks for {scene.settings.observer}")
    if resume.spp > scene.settings.spp:
        raise SceneError(f"resume: the film already has {resume.spp} spp, more than settings.spp = "
                         f"{scene.settings.spp}")
    return resume.copy()


def render(scene: Scene, *, threads=None, progress=None, should_cancel=None, on_pass=None, status=None,
           spectral_bins=0, resume=None, measure=False, client=None, batch_spp=None, checkpoint=None,
           adaptive=True):
    """Render ``scene`` to a :class:`Film`.

    progress(done_spp, total_spp, samples_per_second) after each pass;
    should_cancel() → True stops after the current pass (the film keeps what was done);
    on_pass(film) after each pass (for progressive display);
    status(text) for phase messages ("Compiling kernels (first run only)" when numba's cache
    lacks them, "Loading compiled kernels" otherwise, "Rendering");
    spectral_bins > 0 also records the spectral radiance in that many bins;
    resume: a Film of this scene (e.g. from Film.load) to continue from its spp up to the
    scene's; the result is bit-identical to rendering all samples at once (the Hammersley
    sampler excepted: its points depend on the total). The given film is not modified.
    The scene's settings.time_limit (s) and settings.noise_target stop the render early;
    RenderStats.stop_reason says why. The noise target is each pixel's relative standard error
    of luminance (``pixel_relative_errors``): with ``adaptive`` (the default) a pixel stops
    receiving samples once it and its neighbours are within it, judged every ADAPTIVE_STEP
    samples after Cycles' minimum (``adaptive_mask``; the film counts each pixel's samples),
    and the render stops when no pixel is left; adaptive=False (and a farm) stops the whole
    image at once when NOISE_QUANTILE of the pixels are within it (``relative_error``).
    measure=True renders the illuminance of the scene's sensor meshes instead (see
    core/sensors.py, which turns the film into lux).
    client: a dask.distributed Client (or a scheduler address, or "local:N"): the samples
    are rendered on its workers, ``batch_spp`` samples a task (a multiple of CHUNK_SPP;
    None: one chunk), and merged in order into the same bits as here (core/farm);
    checkpoint: a file the film is saved to (Film.save) after each batch on a farm, every
    CHECKPOINT_SECONDS here, and at the end (pass it back as ``resume`` to go on).
    Returns (film, RenderStats).
    """
    validate(scene)
    check_render_inputs(scene, spectral_bins, resume)
    if client is not None:
        from ..farm import render_farm

        return render_farm(scene, client, engine=sys.modules[__name__], progress=progress,
                           should_cancel=should_cancel, on_pass=on_pass,
                           status=status, spectral_bins=spectral_bins, resume=resume, measure=measure,
                           batch_spp=batch_spp, checkpoint=checkpoint)
    say = status or (lambda text: None)
    n_threads = thread_count(threads)
    held = [False]
    if not kernels_compiled():  # a cold start: one compile at a time in this process
        if not warmup.hold_compile(say, should_cancel):  # cancelled while another thread compiled
            film = start_film(scene, resume, spectral_bins)
            return film, RenderStats(film.spp, 0.0, 0.0, True, 0.0, 0.0, "cancelled", relative_error(film))
        held[0] = True

    def release():
        if held[0]:
            held[0] = False
            warmup.release_compile()

    try:
        if kernels_compiled():  # compiled by the thread this one waited for
            release()
        # a cold cache: a second process compiles part of the kernel's helpers meanwhile
        helper = warmup.start()
        try:
            return _render(scene, n_threads, say, helper, progress, should_cancel, on_pass, spectral_bins, resume,
                           measure, checkpoint, release, adaptive)
        finally:
            warmup.finish(helper)
    finally:
        release()


def warm_up(status=None, should_cancel=None):
    """Compile (or load from numba's cache) the kernels a render of the Cornell box needs (the
    BVH builder, the path kernel and its helpers), by rendering a tiny one: what the add-on
    runs in the background when it is enabled, so the first F12 finds them loaded. A render
    started meanwhile in this process waits for it (``jit.COMPILE_LOCK``). Returns False when
    they were loaded already, True otherwise."""
    if kernels_compiled():
        return False
    from ..scene.builtin import cornell_box

    render(cornell_box(8, 8, spp=1, max_depth=2), threads=1, status=status, should_cancel=should_cancel)
    return True


def physical_memory():
    """Bytes of physical memory of this machine, or None where the system does not say."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return None


def memory_needed(scene, spectral_bins=0):
    """An estimate (bytes) of the memory a render of ``scene`` needs beyond the scene itself:
    the film (sums, AOVs, spectral bins, float64), its development and the EXR's float32
    channels, and the BVH and kernel records (a few hundred bytes a triangle)."""
    from ..film import AOV_CHANNELS, film_channels

    pixels = int(scene.camera.width) * int(scene.camera.height)
    bins = int(spectral_bins)
    film = 8 * (film_channels(scene.settings.observer) + AOV_CHANNELS + bins)
    develop = 8 * 48 + 4 * (24 + bins)
    texels = sum(int(t.image.size) for t in scene.textures)
    if scene.world.image is not None:
        texels += int(scene.world.image.size)
    return pixels * (film + develop) + 400 * scene.n_triangles + 16 * texels


def check_render_inputs(scene, spectral_bins=0, resume=None):
    """Raise SceneError (naming the input) unless a render of the validated ``scene`` with
    ``spectral_bins`` and ``resume`` can run: the bins within what the spectral EXR layout
    stores (one per nanometre of the grid), the resumed film shaped for this scene, and the
    memory the render needs within this machine's physical memory."""
    from ..film import MAX_SPECTRAL_BINS, check_film

    if isinstance(spectral_bins, bool) or not isinstance(spectral_bins, (int, np.integer)) or \
            not 0 <= spectral_bins <= MAX_SPECTRAL_BINS:
        raise SceneError(f"spectral_bins: expected an integer in [0, {MAX_SPECTRAL_BINS}] (one bin per nanometre "
                         f"of 360-830 nm at most), got {spectral_bins!r}")
    if resume is not None:
        try:
            check_film(resume, scene.camera.width, scene.camera.height, scene.settings.observer, "resume")
        except ValueError as e:
            raise SceneError(str(e)) from None
        if resume.spp > scene.settings.spp:
            raise SceneError(f"resume: the film already has {resume.spp} spp, more than settings.spp = "
                             f"{scene.settings.spp}")
        spectral_bins = resume.spectral_bins
    need = memory_needed(scene, spectral_bins)
    have = physical_memory()
    if have is not None and need > have:
        raise SceneError(f"camera.width x camera.height: a {scene.camera.width}x{scene.camera.height} render"
                         + (f" with {spectral_bins} spectral bins" if spectral_bins else "")
                         + f" needs about {need / 2**30:.1f} GiB, more than this machine's {have / 2**30:.1f} GiB")


def _render(scene, n_threads, say, helper, progress, should_cancel, on_pass, spectral_bins, resume, measure,
            checkpoint=None, release=None, adaptive=True):
    t_start = time.perf_counter()
    say("Preparing scene" if helper is None else "Compiling kernels (first run only): preparing scene")
    cold = not kernels_compiled()
    t_compile = 0.0
    # on a cold start, Python's cyclic garbage collector is paused from ``prepare`` (which
    # compiles the BVH builder) to the end of the kernel's compile: numba's compiler makes
    # millions of short-lived objects and the collector's sweeps took ~10 % of the compile time
    gc_was_on = gc.isenabled()
    if cold:
        gc.disable()
    try:
        prep = prepare(scene, measure=measure)
        film = start_film(scene, resume, spectral_bins)
        total = int(scene.settings.spp)
        if cold:
            # numba's cache on disk holds the kernels unless this start had to compile them
            say("Compiling kernels (first run only)" if helper is not None or not warmup.kernel_cached()
                else "Loading compiled kernels")
            tc = time.perf_counter()
            # compile (or load from numba's cache) with a 1-sample pass on a scratch film
            if helper is not None:  # this process's share of the helpers, then the kernel
                warmup.compile_group(False)
                # the second process's share: given as long as this process has worked
                warmup.finish(helper, grace=time.perf_counter() - t_start)
            run_pass(prep, Film(1, 1, observer=scene.settings.observer), 0, 1)
            t_compile = time.perf_counter() - tc
    finally:
        if gc_was_on:
            gc.enable()
        if release is not None:  # the kernels are loaded: another render may go on
            release()
    say("Rendering")
    pool = ThreadPoolExecutor(max_workers=n_threads, thread_name_prefix="spectral-gi") if n_threads > 1 else None
    try:
        film, stats = _progressive(prep, film, pool, total, progress, should_cancel, on_pass, t_compile, checkpoint,
                                   adaptive)
        if checkpoint is not None:
            film.save(checkpoint)
        return film, stats
    finally:
        if pool is not None:
            pool.shutdown(wait=True)


def _progressive(prep, film, pool, total, progress, should_cancel, on_pass, t_compile, checkpoint=None,
                 adaptive=True):
    cam = prep.scene.camera
    st = prep.scene.settings
    t0 = time.perf_counter()
    start = done = int(film.spp)
    skipped0 = film.skipped_samples
    saved = t0
    step = 1
    reason = "spp"
    per_pixel = adaptive and st.noise_target > 0  # adaptive sampling (adaptive_mask)
    active = None  # the pixels still sampled; None: all
    check = adaptive_check_at(film, st.noise_target) if per_pixel else 0
    while done < total:
        if should_cancel is not None and should_cancel():
            reason = "cancelled"
            break
        n = min(step, total - done)
        if per_pixel:  # a pass ends where the mask is judged
            n = min(n, check - done)
        if st.time_limit > 0:  # aim the pass at what is left of the time
            left = st.time_limit - (time.perf_counter() - t0)
            if left <= 0:
                reason = "time_limit"
                break
        tp = time.perf_counter()
        add_samples(prep, film, done, done + n, pool, active)
        dt = time.perf_counter() - tp
        done += n
        elapsed = time.perf_counter() - t0
        taken = (done - start) * cam.width * cam.height - (film.skipped_samples - skipped0)
        rate = taken / max(elapsed, 1e-9)
        if progress is not None:
            progress(done, total, rate)
        if on_pass is not None:
            on_pass(film)
        if checkpoint is not None and time.perf_counter() - saved >= CHECKPOINT_SECONDS:
            film.save(checkpoint)
            saved = time.perf_counter()
        if done >= total:
            break
        if st.time_limit > 0 and elapsed >= st.time_limit:
            reason = "time_limit"
            break
        if per_pixel:
            if done >= check:
                active = adaptive_mask(film, st.noise_target, active)
                check = adaptive_check_at(film, st.noise_target)
                if not active.any():
                    reason = "noise_target"
                    break
        elif noise_reached(film, st.noise_target):
            reason = "noise_target"
            break
        # adapt the pass length towards PASS_SECONDS (and within a time limit)
        if dt > 0:
            target = PASS_SECONDS
            if st.time_limit > 0:
                target = min(target, max(st.time_limit - elapsed, 0.0))
            step = int(max(1, min(step * 4, round(n * target / dt))))
        if st.noise_target > 0 and not per_pixel:  # end the next pass where the target should be met
            step = min(step, max(1, noise_samples_needed(film, st.noise_target) - done))
    elapsed = time.perf_counter() - t0
    taken = (done - start) * cam.width * cam.height - (film.skipped_samples - skipped0)
    stats = RenderStats(done, elapsed, taken / max(elapsed, 1e-9),
                        reason == "cancelled", prep.build_seconds, t_compile, reason, relative_error(film),
                        film.dropped_samples(), film.skipped_samples)
    return film, stats
