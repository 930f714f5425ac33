"""Illuminance jobs: ``core.point_illuminance`` on the calculation surfaces, on a worker thread
(or on the calling thread), with progress and cancel: a ``jobs.BackgroundJob``, as the render job.

The worker thread never touches bpy: the operator builds the surfaces and exports the scene
on the main thread, the worker only calls core, and the main thread stores the results
(statistics, colours, images) once the job has finished. A cancelled or failed job stores
nothing, so the results of an earlier calculation stay as they were.

Each surface's points go to core in one call, so its values are those core gives for the
same points, seed and samples (bit-identical for any number of threads).

With ``method="RADIOSITY"`` the job solves the whole scene once by radiosity
(``core.radiosity`` with the lighting analysis' defaults) and each surface's points gather
from the solution (``core.radiosity_illuminance``: direct light exact, the solution for
the rest); the solution is kept in ``job.radiosity`` for the overlay on every surface.
"""
import time

from .jobs import BackgroundJob, JobSlot, status_line

SLOT = JobSlot()
STATE = SLOT.state  # what the panel and the status bar show about the current (or last) calculation
current_job = SLOT.current
busy = SLOT.busy  # True while an illuminance job runs
cancel_current = SLOT.cancel  # stop a running job (the add-on is unregistered); cancel_current(wait=seconds)


class SurfaceTask:
    """One surface to calculate: the object's name, its core CalculationSurface and the sampling."""

    def __init__(self, name, surface, spp, rel_error=None, seed=None):
        self.name = name
        self.surface = surface
        self.spp = int(spp)
        self.rel_error = rel_error or None
        self.seed = seed

    @property
    def samples(self):
        return self.surface.n_points * self.spp


def lux_status_line():
    return status_line(STATE)


class LuxJob(BackgroundJob):
    """The illuminance at every task's points in one exported core scene."""

    slot = SLOT
    thread_name = "spectral-gi-lux"
    on_progress = None  # optional method (done, total) called on the worker thread after each batch

    def __init__(self, scene, tasks, threads=0, luminaires=(), method="PATH", max_edge=None):
        super().__init__()
        self.method = method
        self.max_edge = max_edge or None
        self.radiosity = None  # the core.RadiositySolution of a radiosity job
        self.radiosity_warnings = []  # what the solve approximated (non-diffuse materials, ...)
        self.scene = scene
        self.tasks = list(tasks)
        self.threads = int(threads) if threads else None
        self.luminaires = list(luminaires)
        self.results = {}  # task name → (lux (N,), std_error (N,), samples used (N,))
        self.unlit = {}  # task name → core.unlit_points(...) of its result
        self.seconds = 0.0
        self.total = sum(t.samples for t in self.tasks)

    # ------------------------------------------------------------------ worker (any thread)

    def _run(self):
        if self.method == "RADIOSITY":
            return self._run_radiosity()
        t0 = time.monotonic()
        try:
            from ..core import point_illuminance, unlit_points

            offset = 0
            for task in self.tasks:
                if self.cancel_requested:
                    break
                STATE.phase = f"Illuminance on {task.name}"

                def progress(done, total, offset=offset):
                    STATE.done = offset + int(done)
                    STATE.rate = STATE.done / max(time.monotonic() - t0, 1e-9)
                    if self.on_progress is not None:
                        self.on_progress(STATE.done, self.total)

                s = task.surface
                e, se, used = point_illuminance(self.scene, s.points, s.normals, spp=task.spp,
                                                rel_error=task.rel_error, seed=task.seed, threads=self.threads,
                                                should_cancel=self.should_cancel, progress=progress)
                if self.cancel_requested:
                    break  # a partial result is not a result
                self.results[task.name] = (e, se, used)
                self.unlit[task.name] = unlit_points(self.scene, s.points, s.normals, e, se)
                offset += task.samples
        except Exception as exc:  # reported by the operator on the main thread
            self._capture(exc)
        finally:
            self.seconds = time.monotonic() - t0
            self.finished = True

    def _run_radiosity(self):
        t0 = time.monotonic()
        try:
            import warnings

            import numpy as np

            from ..core import radiosity, radiosity_illuminance, unlit_points
            from ..core import radiosity_solve as solve

            opts = dict(solve.LUX_DEFAULTS, threads=self.threads,
                        max_edge=self.max_edge or solve.default_max_edge(self.scene))

            def stage(name, a, b):
                if name == "patches":
                    STATE.phase = f"Radiosity: {a} patches"
                elif name == "form factors":
                    STATE.phase = "Radiosity: form factors"
                    STATE.done, STATE.total = int(a), int(b)
                elif name == "solve":
                    STATE.phase = f"Radiosity: iteration {a}, residual {b:.2g}"
                STATE.rate = STATE.done / max(time.monotonic() - t0, 1e-9)
                if self.on_progress is not None:
                    self.on_progress(STATE.done, max(STATE.total, 1))

            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # kept in the solution and reported by the operator
                sol = radiosity(self.scene, progress=stage, should_cancel=self.should_cancel, **opts)
            if self.cancel_requested or any(st.cancelled for st in sol.stats):
                return
            self.radiosity_warnings = list(sol.warnings)
            for task in self.tasks:
                if self.cancel_requested:
                    return
                STATE.phase = f"Radiosity: gathering on {task.name}"
                s = task.surface
                e = radiosity_illuminance(sol, s.points, s.normals)
                se = np.zeros_like(e)
                self.results[task.name] = (e, se, np.zeros(e.shape, np.int64))
                self.unlit[task.name] = unlit_points(self.scene, s.points, s.normals, e, se)
            self.radiosity = sol
        except Exception as exc:  # reported by the operator on the main thread
            self._capture(exc)
        finally:
            self.seconds = time.monotonic() - t0
            self.finished = True

    # ------------------------------------------------------------------ main thread

    def _total(self):
        return self.total

    def _begin(self):
        super()._begin()
        STATE.phase = "Illuminance"

    def run_sync(self):
        """Calculate on the calling thread."""
        self._begin()
        self._run()
        self.conclude()

    def summary(self):
        if self.error is not None:
            return f"Calculation failed: {self.error}"
        if self.cancelled:
            return f"Cancelled after {self.seconds:.1f} s; the earlier results are kept"
        n = sum(t.surface.n_points for t in self.tasks)
        how = f" by radiosity ({self.radiosity.patches.n} patches)" if self.radiosity is not None else ""
        return f"{len(self.tasks)} surface(s), {n} points{how} in {self.seconds:.1f} s"
