"""Render farms on Dask: one image's samples, an animation's frames or a lux grid's points
spread over the workers of a ``dask.distributed`` scheduler.

One image: the samples are split into batches of whole chunks (core/film ``CHUNK_SPP``);
each batch is a task (the scene, its sample range) whose result is the sums of each of its
chunks, summed from zero. The client adds them to the film in chunk order
(``Film.merge_chunk``, the additions a render on one machine makes), so the farm's image
is bit-identical to ``render`` with the same seed and samples, whatever the number of
workers and the order batches finish in. A result is fetched from its worker only when it
is the next to merge, so the client holds one batch at a time. The scene is scattered to
the workers once; each worker prepares it (BVH, records) once per render and keeps it for
the render's other tasks. A task's samples are a pure function of the scene and their
indices, so a task lost with its worker is rerun elsewhere by Dask with the same result.

Lux grids: the points are split across tasks; each point's random numbers are keyed by its
index in the whole grid and its sums are its own, so the values are those of one machine.

Dask is optional (``pip install "spectral-gi[farm]"``) and imported only here, inside the
functions. The engine's functions (prepare, run_pass, ...) are handed in by its callers
(core/integrators/render.py, illuminance.py), which import this module lazily.
"""
from __future__ import annotations

import os
import socket
import time
import uuid

import numpy as np

from ..film import CHUNK_SPP, chunk_spans

INSTALL = 'the render farm needs Dask: pip install "spectral-gi[farm]" (dask[distributed])'
POLL_SECONDS = 0.1  # how often the client checks should_cancel while it waits for a batch


class FarmError(RuntimeError):
    """A farm problem in one line: no Dask, a bad scheduler address, a task that failed on a worker."""


def _distributed():
    try:
        import distributed
    except ImportError:
        raise FarmError(INSTALL) from None
    return distributed


def source_key():
    """The hash of this installation's core sources (core/jit.py): workers with other sources
    would not give the same bits, so a task checks it against the client's."""
    from .. import jit

    return jit.CACHE_DIR.name


class Farm:
    """A connection to a Dask scheduler, from ``address``: ``tcp://host:8786`` (or any address
    ``distributed.Client`` takes), or ``local:N`` for a LocalCluster of N worker processes
    started here (one thread each; each task runs the kernel on cores / N threads).
    ``with Farm(address) as farm: render(scene, client=farm.client)``; closing it stops the
    cluster it started."""

    def __init__(self, address, timeout=30):
        distributed = _distributed()
        self.cluster = None
        self.threads = None  # kernel threads per task (None: the worker's cores / its Dask threads)
        text = str(address).strip()
        if text.lower().startswith("local:"):
            try:
                n = int(text.split(":", 1)[1])
            except ValueError:
                n = 0
            if n < 1:
                raise FarmError(f"--scheduler {address}: expected local:N with N ≥ 1 workers")
            import logging

            self.cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                                    dashboard_address=None, silence_logs=logging.CRITICAL)
            self.threads = max(1, (os.cpu_count() or 1) // n)
            self.client = distributed.Client(self.cluster)
        else:
            try:
                self.client = distributed.Client(text, timeout=timeout)
            except (OSError, TimeoutError, ValueError) as e:
                raise FarmError(f"--scheduler {address}: cannot reach the scheduler ({e})") from None

    def close(self):
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _connect(client):
    """(Client, kernel threads per task, the Farm to close or None) of a Client, a Farm or an address."""
    distributed = _distributed()
    if isinstance(client, Farm):
        return client.client, client.threads, None
    if isinstance(client, distributed.Client):
        return client, None, None
    farm = Farm(client)
    return farm.client, farm.threads, farm


def _n_workers(client):
    return len(client.scheduler_info().get("workers", {})) or 1


def _check_worker(key):
    if key != source_key():
        raise FarmError(f"worker {socket.gethostname()}: its spectral-gi sources differ from the client's "
                        f"({source_key()} here, {key} there); install the same version on every machine")


def _task_threads(threads):
    if threads:
        return int(threads)
    try:
        from distributed import get_worker

        slots = get_worker().state.nthreads
    except (ImportError, ValueError, AttributeError):
        slots = 1
    return max(1, (os.cpu_count() or 1) // max(1, slots))


# per worker process: the prepared scene of the render in progress, by its token
_PREPARED = {}


def _prepared(prepare, scene, token, measure):
    prep = _PREPARED.get(token)
    if prep is None:
        _PREPARED.clear()  # one render at a time per worker: drop the previous scene
        try:
            prep = prepare(scene, measure=measure)
        except Exception as e:
            raise FarmError(f"worker {socket.gethostname()}: cannot prepare the scene: {e}") from None
        _PREPARED[token] = prep
    return prep


def render_batch(prepare, run_pass, scene, token, key, spans, start, spectral_bins, measure, threads):
    """A farm task: the chunks ``spans`` [(a, b), ...] of the scene's samples, each summed from
    zero (the first from ``start``, the samples of an incomplete chunk so far, when given).
    Returns [(a, b, Film), ...]."""
    from concurrent.futures import ThreadPoolExecutor

    from ..film import Film

    _check_worker(key)
    prep = _prepared(prepare, scene, token, measure)
    n = _task_threads(threads)
    cam = scene.camera
    out = []
    pool = ThreadPoolExecutor(max_workers=n, thread_name_prefix="spectral-gi-farm") if n > 1 else None
    try:
        for i, (a, b) in enumerate(spans):
            part = start if (i == 0 and start is not None) else \
                Film(cam.width, cam.height, spectral_bins, observer=scene.settings.observer)
            run_pass(prep, part, a, b, pool)
            out.append((a, b, part))
    finally:
        if pool is not None:
            pool.shutdown(wait=True)
    return out


def batches(s0, s1, batch_spp=None):
    """The tasks of samples [s0, s1): lists of chunk spans, ``batch_spp`` samples (whole chunks,
    a multiple of CHUNK_SPP; None: one chunk) a task."""
    per = 1 if batch_spp is None else int(batch_spp) // CHUNK_SPP
    if batch_spp is not None and (int(batch_spp) < CHUNK_SPP or int(batch_spp) % CHUNK_SPP):
        raise FarmError(f"batch_spp: expected a multiple of {CHUNK_SPP} samples, got {batch_spp}")
    spans = chunk_spans(s0, s1)
    return [spans[i:i + per] for i in range(0, len(spans), per)]


def _raise_task_error(future):
    exc = future.exception()
    text = " ".join(str(exc).split()) or type(exc).__name__
    if isinstance(exc, FarmError):
        raise FarmError(text) from None
    raise FarmError(f"a farm task failed: {type(exc).__name__}: {text}") from None


def render_farm(scene, client, *, engine, progress=None, should_cancel=None, on_pass=None, status=None,
                spectral_bins=0, resume=None, measure=False, batch_spp=None, checkpoint=None):
    """``render`` on a farm (see the module text); ``engine``: the render module
    (core/integrators/render.py), whose prepare, run_pass, start_film, relative_error and
    RenderStats this uses. Returns (film, RenderStats)."""
    from ..scene import validate

    say = status or (lambda text: None)
    validate(scene)
    film = engine.start_film(scene, resume, spectral_bins)
    spectral_bins = film.spectral_bins  # a resumed film's
    total = int(scene.settings.spp)
    st = scene.settings
    cam = scene.camera
    jobs = batches(film.spp, total, batch_spp)
    say("Connecting to the farm")
    dclient, threads, owned = _connect(client)
    distributed = _distributed()
    t0 = time.perf_counter()
    start = film.spp
    reason = "spp"
    futures = []
    try:
        say(f"Sending the scene to {_n_workers(dclient)} workers")
        scene_f = dclient.scatter(scene, broadcast=True, hash=False)
        token = uuid.uuid4().hex
        key = source_key()
        tail = film.open_chunk().copy() if film.tail_spp else None
        for i, spans in enumerate(jobs):
            futures.append(dclient.submit(render_batch, engine.prepare, engine.run_pass, scene_f, token, key, spans,
                                          tail if i == 0 else None, spectral_bins, measure, threads,
                                          key=f"spectral-gi-batch-{token}-{i}", priority=len(jobs) - i,
                                          pure=False))
        say(f"Rendering on {_n_workers(dclient)} workers")
        for i, fut in enumerate(futures):
            while True:
                if should_cancel is not None and should_cancel():
                    reason = "cancelled"
                    break
                if st.time_limit > 0 and time.perf_counter() - t0 >= st.time_limit:
                    reason = "time_limit"
                    break
                failed = next((f for f in futures[i:] if f.status == "error"), None)
                if failed is not None:
                    _raise_task_error(failed)
                try:
                    distributed.wait(fut, timeout=POLL_SECONDS)
                    break
                except (TimeoutError, distributed.TimeoutError):
                    continue
            if reason != "spp":
                break
            if fut.status == "error":
                _raise_task_error(fut)
            for a, b, part in fut.result():
                film.merge_chunk(part, b)
            fut.release()
            futures[i] = None
            if checkpoint is not None:
                film.save(checkpoint)
            elapsed = time.perf_counter() - t0
            if progress is not None:
                progress(film.spp, total, (film.spp - start) * cam.width * cam.height / max(elapsed, 1e-9))
            if on_pass is not None:
                on_pass(film)
            if film.spp < total and engine.noise_reached(film, st.noise_target):
                reason = "noise_target"
                break
    finally:
        pending = [f for f in futures if f is not None]
        if pending:
            dclient.cancel(pending)
        if owned is not None:
            owned.close()
    elapsed = time.perf_counter() - t0
    stats = engine.RenderStats(film.spp, elapsed, (film.spp - start) * cam.width * cam.height / max(elapsed, 1e-9),
                               reason == "cancelled", 0.0, 0.0, reason, engine.relative_error(film),
                               film.dropped_samples())
    return film, stats


def measure_points(measure, scene, token, key, mode, pts, q, spp, rel_error, max_depth, seed, idx, threads):
    """A farm task: the estimator ``measure`` (core/integrators/illuminance ``_measure``) at
    the points ``idx`` of the whole grid (pts, q). Returns (idx, values, errors, samples)."""
    _check_worker(key)
    try:
        mean, se, cnt = measure(scene, mode, pts, q, spp, rel_error, max_depth, seed, _task_threads(threads), None,
                                None, subset=idx)
    except FarmError:
        raise
    except Exception as e:
        raise FarmError(f"worker {socket.gethostname()}: {type(e).__name__}: {e}") from None
    return idx, mean[idx], se[idx], cnt[idx]


def measure_farm(scene, client, mode, pts, q, *, measure, spp, rel_error, max_depth, seed, should_cancel=None,
                 progress=None, points_per_task=None):
    """The illuminance estimator on a farm: the points split into tasks (points_per_task a
    task; None: four tasks a worker), the values bit-identical to one machine's. Returns
    (values, standard errors, samples used), as ``measure``."""
    distributed = _distributed()
    n = pts.shape[0]
    dclient, threads, owned = _connect(client)
    mean = np.full(n, np.nan)
    se = np.full(n, np.inf)
    cnt = np.zeros(n, np.int64)
    futures = []
    try:
        if points_per_task is None:
            n_tasks = max(1, min(n, 4 * _n_workers(dclient)))
        else:
            n_tasks = max(1, -(-n // int(points_per_task)))
        groups = [g for g in np.array_split(np.arange(n, dtype=np.int64), n_tasks) if g.size]
        scene_f, pts_f, q_f = dclient.scatter([scene, pts, q], broadcast=True, hash=False)
        token = uuid.uuid4().hex
        key = source_key()
        futures = [dclient.submit(measure_points, measure, scene_f, token, key, mode, pts_f, q_f, spp, rel_error,
                                  max_depth, seed, g, threads, key=f"spectral-gi-lux-{token}-{i}", pure=False)
                   for i, g in enumerate(groups)]
        done = 0
        for fut in distributed.as_completed(futures):
            if fut.status == "error":
                _raise_task_error(fut)
            idx, m, e, c = fut.result()
            mean[idx], se[idx], cnt[idx] = m, e, c
            done += idx.size
            fut.release()
            if progress is not None:
                progress(done * int(spp), n * int(spp))
            if should_cancel is not None and should_cancel():
                break
    finally:
        pending = [f for f in futures if f.status == "pending"]
        if pending:
            dclient.cancel(pending)
        if owned is not None:
            owned.close()
    return mean, se, cnt
