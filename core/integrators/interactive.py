"""Interactive rendering: a progressive image of a scene that keeps changing (Blender's viewport).

``InteractiveRender`` renders on a worker thread of its own. ``update(scene=, camera=)``
may be called from any thread at any time: the pass in progress stops at its next block
of rows, the new scene or camera is prepared, and the image starts again, first coarse
(one sample per pixel at a pixel size of 4, then 2, as Cycles' viewport does), then at full
resolution, refining until ``max_spp``. ``frame()`` returns the latest image.

What a change costs: a new camera repacks the camera record only; a new scene prepares
the kernel's records again but keeps the BVH when the triangles' corners are those the
BVH was built over (a material, light or world change), so only moved or edited geometry
rebuilds it. The path kernel is serial and releases the GIL (a pool of Python threads runs
blocks of rows); the BVH builder's parallel kernels take ``jit.KERNEL_LOCK`` themselves,
so a final render and this one can run in one process. ``should_pause()`` → True holds
the worker between blocks (the add-on pauses its viewport during a final render).
"""
from __future__ import annotations

import dataclasses
import math
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from typing import NamedTuple

import numpy as np

from . import warmup
from ..camera import record as camera_record
from ..film import Film, XYZ_to_output
from ..geometry import record as geometry_record
from .render import PASS_SECONDS, _rows, prepare, thread_count

PIXEL_SIZES = (4, 2, 1)  # the coarse passes' pixel sizes, then full resolution (1)
PASS_TARGET = 0.5 * PASS_SECONDS  # seconds a full-resolution pass aims at
# pixels of one block of rows, at most: an update stops a pass at its next block, so the
# blocks in progress are what a restart waits for (8192 one-sample paths of the Cornell box:
# about 0.04 s on one loaded core; a block of 1/16 of a 960 × 540 pass took 0.15 s)
BLOCK_PIXELS = 8192


class Frame(NamedTuple):
    """One published image."""

    generation: int  # counts the updates: a frame of an older generation is stale
    rgba: np.ndarray  # float32 (H, W, 4): linear Rec.709, alpha (transparent film); row 0 at the top
    pixel_size: int  # 1: full resolution; 2, 4: one pixel of the image covers 2×2, 4×4 of the view
    spp: int  # samples per pixel
    restart_seconds: float  # from the update that started this generation to its first frame
    seconds: float  # from that update to this frame


@dataclasses.dataclass
class Counters:
    """What the worker has done (read by tests and status lines)."""

    prepares: int = 0  # scenes prepared (kernel records packed)
    bvh_builds: int = 0  # of which built a BVH (the others kept the previous one)
    camera_updates: int = 0  # cameras repacked without preparing the scene
    passes: int = 0  # passes completed
    aborted: int = 0  # passes stopped by an update


def scaled_camera(camera, pixel_size):
    """``camera`` rendering 1/pixel_size of its resolution (rounded up), with the same field of view."""
    p = int(pixel_size)
    if p <= 1:
        return camera
    return dataclasses.replace(camera, width=max(1, math.ceil(camera.width / p)),
                               height=max(1, math.ceil(camera.height / p)))


def preview_rgba(film):
    """(H, W, 4) float32 of ``film``: linear Rec.709 (the film's XYZ per sample) and alpha, row 0 at the top."""
    n = film.sums[..., 3]
    safe = np.maximum(n, 1.0)
    XYZ = film.sums[..., :3] / safe[..., None]
    out = np.empty((film.height, film.width, 4), np.float32)
    out[..., :3] = XYZ_to_output(XYZ, "rec709", film.observer)
    out[..., 3] = np.where(n > 0, 1.0 - film.aov[..., 8] / safe, 0.0)
    out[n == 0, :3] = 0.0
    return out


class InteractiveRender:
    """Progressive rendering of a changing scene on a worker thread (see the module doc).

    threads: worker threads for the kernel (None: one per core); pixel_sizes: the coarse
    levels before full resolution; max_spp: samples per pixel after which it idles (None:
    the scene's ``settings.spp``); on_frame(frame): called on the worker thread after each
    published frame (keep it short; the add-on tags its viewport for a redraw);
    should_pause(): True holds the worker; status(text): phase messages.
    """

    def __init__(self, threads=None, pixel_sizes=PIXEL_SIZES, max_spp=None, on_frame=None, should_pause=None,
                 status=None):
        sizes = [int(p) for p in pixel_sizes if int(p) > 1]
        self.pixel_sizes = tuple(sorted(set(sizes), reverse=True)) + (1,)
        self.max_spp = None if max_spp is None else max(1, int(max_spp))
        self.n_threads = thread_count(threads)
        self.on_frame = on_frame
        self.should_pause = should_pause
        self.status = status or (lambda text: None)
        self.counters = Counters()
        self.error = None  # "Type: message" of the last failure (the worker keeps waiting for updates)
        self._cv = threading.Condition()
        self._generation = 0
        self._updated_at = time.perf_counter()
        self._pending_scene = None
        self._pending_camera = None
        self._stop = False
        self._frame = None
        self._thread = None
        self._pool = None
        # the worker's own state
        self._scene = None
        self._prep = None
        self._corners = None  # the triangles the BVH was built over

    # ------------------------------------------------------------------ any thread

    def update(self, scene=None, camera=None):
        """Restart with a new scene and/or camera (the camera replaces the scene's). Returns the generation."""
        with self._cv:
            if scene is not None:
                self._pending_scene = scene
            if camera is not None:
                self._pending_camera = camera
            self._generation += 1
            self._updated_at = time.perf_counter()
            self._cv.notify_all()
            return self._generation

    def frame(self):
        """The latest Frame, or None before the first one."""
        return self._frame

    @property
    def generation(self):
        return self._generation

    @property
    def converged(self):
        """True when the latest frame is of the latest update and has all its samples."""
        f = self._frame
        return (f is not None and f.generation == self._generation and f.pixel_size == 1
                and self._prep is not None and f.spp >= self._target_spp())

    def start(self):
        if self._thread is None or not self._thread.is_alive():
            self._stop = False
            if self.n_threads > 1:
                self._pool = ThreadPoolExecutor(max_workers=self.n_threads, thread_name_prefix="spectral-gi-view")
            self._thread = threading.Thread(target=self._work, name="spectral-gi-interactive", daemon=True)
            self._thread.start()
        return self

    def stop(self, wait=5.0):
        """Stop the worker (the block of rows in progress finishes first); True if it has ended."""
        with self._cv:
            self._stop = True
            self._cv.notify_all()
        t = self._thread
        if t is not None and wait:
            t.join(timeout=wait)
        return t is None or not t.is_alive()

    def wait_frame(self, generation=None, spp=1, pixel_size=None, timeout=60.0):
        """Block until a frame of ``generation`` (default: the latest) with at least ``spp`` samples
        (and at most ``pixel_size``) is published; returns it, or None after ``timeout`` seconds."""
        gen = self._generation if generation is None else int(generation)
        end = time.perf_counter() + timeout
        while time.perf_counter() < end:
            f = self._frame
            if f is not None and f.generation >= gen and f.spp >= spp and \
                    (pixel_size is None or f.pixel_size <= pixel_size):
                return f
            if self.error is not None and self._failed_generation >= gen:
                return None
            time.sleep(0.002)
        return None

    # ------------------------------------------------------------------ the worker

    _failed_generation = -1

    def _target_spp(self):
        if self.max_spp is not None:
            return self.max_spp
        return int(self._prep.scene.settings.spp) if self._prep is not None else 1

    def _stale(self, generation):
        return self._stop or self._generation != generation

    def _take(self):
        """Wait for work; returns (generation, update time, scene, camera) of pending changes, or None to stop."""
        with self._cv:
            while True:
                if self._stop:
                    return None
                pending = self._pending_scene is not None or self._pending_camera is not None
                if pending or (self._prep is not None and not self.converged and not self._paused()):
                    break
                self._cv.wait(timeout=0.05 if self._paused() else None)
            out = (self._generation, self._updated_at, self._pending_scene, self._pending_camera)
            self._pending_scene = self._pending_camera = None
            return out

    def _paused(self):
        return self.should_pause is not None and bool(self.should_pause())

    def _apply(self, scene, camera):
        if scene is not None:
            if camera is not None:
                scene = dataclasses.replace(scene, camera=camera)
            v0, v1, v2, _ = geometry_record.triangles(scene)
            bvh = None
            if self._prep is not None and self._corners is not None and all(
                    a.shape == b.shape and np.array_equal(a, b) for a, b in zip(self._corners, (v0, v1, v2))):
                bvh = self._prep.bvh
            prep = prepare(scene, bvh=bvh)
            self.counters.prepares += 1
            if prep.bvh is not bvh:
                self.counters.bvh_builds += 1
                self._corners = (v0, v1, v2)
            self._scene, self._prep = scene, prep
        elif camera is not None and self._prep is not None:
            scene = dataclasses.replace(self._scene, camera=camera)
            if scene.media:  # the medium around the camera depends on where it is
                self._apply(scene, None)
                return
            self._scene = scene
            self._prep = dataclasses.replace(self._prep, scene=scene, camera=camera_record.pack(scene))
            self.counters.camera_updates += 1

    def _level_prep(self, pixel_size):
        if pixel_size == 1:
            return self._prep
        scene = dataclasses.replace(self._scene, camera=scaled_camera(self._scene.camera, pixel_size))
        return dataclasses.replace(self._prep, scene=scene, camera=camera_record.pack(scene))

    def _compile(self, prep):
        """Compile (or load) the kernels unless loaded; False if stopped while another thread compiled them."""
        if warmup.kernels_compiled():
            return True
        if not warmup.hold_compile(self.status, lambda: self._stop):
            return False
        try:
            if warmup.kernels_compiled():  # compiled by the thread this one waited for
                return True
            self.status("Compiling kernels (first run only)" if not warmup.kernel_cached()
                        else "Loading compiled kernels")
            t0 = time.perf_counter()
            helper = warmup.start()
            try:
                if helper is not None:  # this process's share of the helpers, then the second one's
                    warmup.compile_group(False)
                    warmup.finish(helper, grace=time.perf_counter() - t0)
                _rows(prep, Film(1, 1, observer=prep.scene.settings.observer), 0, 1, 0, 1)
            finally:
                warmup.finish(helper)
            return True
        finally:
            warmup.release_compile()

    def _pass(self, prep, film, s0, s1, generation):
        """Samples [s0, s1) into ``film`` in blocks of rows; False if an update stopped it."""
        h = film.height
        pool = self._pool
        workers = getattr(pool, "_max_workers", 1) if pool is not None else 1
        # an update waits for the blocks in progress: at most BLOCK_PIXELS paths a block
        block = max(1, min(h // (8 * workers), BLOCK_PIXELS // max(1, film.width)))
        starts = range(0, h, block)
        if pool is None:
            for y in starts:
                if self._stale(generation):
                    return False
                while self._paused() and not self._stale(generation):
                    time.sleep(0.02)
                _rows(prep, film, y, min(h, y + block), s0, s1)
        else:
            def run(y):
                while self._paused() and not self._stale(generation):
                    time.sleep(0.02)
                if not self._stale(generation):
                    _rows(prep, film, y, min(h, y + block), s0, s1)

            futures = [pool.submit(run, y) for y in starts]
            for f in futures:
                f.result()
        if self._stale(generation):
            return False
        film.spp = s1
        return True

    def _publish(self, film, generation, updated_at, pixel_size, first):
        now = time.perf_counter()
        prev = self._frame
        restart = now - updated_at if first or prev is None else prev.restart_seconds
        frame = Frame(generation, preview_rgba(film), int(pixel_size), int(film.spp), restart, now - updated_at)
        self._frame = frame
        if self.on_frame is not None:
            try:
                self.on_frame(frame)
            except Exception:  # noqa: BLE001 - a display callback never stops the renderer
                pass

    def _work(self):
        try:
            self._loop()
        finally:
            pool, self._pool = self._pool, None
            if pool is not None:
                pool.shutdown(wait=False, cancel_futures=True)

    def _loop(self):
        generation, updated_at, level, film, step, first = -1, 0.0, 0, None, 1, True
        while True:
            took = self._take()
            if took is None:
                return
            gen, at, scene, camera = took
            try:
                if scene is not None or camera is not None or gen != generation:
                    self._apply(scene, camera)
                    generation, updated_at, level, film, step, first = gen, at, 0, None, 1, True
                if self._prep is None:
                    continue
                if not self._compile(self._prep):
                    continue  # stopped while waiting: _take returns None
                self.status("Rendering")
                pixel_size = self.pixel_sizes[level]
                prep = self._level_prep(pixel_size)
                cam = prep.scene.camera
                if film is None or (film.width, film.height) != (cam.width, cam.height):
                    film = Film(cam.width, cam.height, observer=prep.scene.settings.observer)
                s0 = film.spp
                s1 = min(self._target_spp(), s0 + (1 if pixel_size > 1 else step))
                t0 = time.perf_counter()
                if not self._pass(prep, film, s0, s1, generation):
                    self.counters.aborted += 1
                    continue
                dt = time.perf_counter() - t0
                self.counters.passes += 1
                self._publish(film, generation, updated_at, pixel_size, first)
                first = False
                if pixel_size > 1:
                    level += 1
                    film = None
                elif dt > 0:
                    step = int(max(1, min(step * 2, round((s1 - s0) * PASS_TARGET / dt))))
            except Exception as exc:  # noqa: BLE001 - reported through .error; wait for the next update
                self.error = f"{type(exc).__name__}: {exc}"
                self._failed_generation = gen
                self._prep = None
                self.status(f"Failed: {self.error}")
