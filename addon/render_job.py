"""Render jobs: ``core.render`` on a worker thread (or on the calling thread), shown progressively.

The worker thread never touches bpy. It reports through plain callbacks into this
module's state (``STATE``, read by the panel and the status bar) and leaves copies of
the film for the main thread, which develops them into the result image at most every
``DISPLAY_INTERVAL`` seconds and once at the end.
"""
import math
import threading
import time
import traceback

from .export import ExportCancelled, export_scene
from .imageio import (RESULT_IMAGE, enabled_passes, illuminance_pass, pass_arrays, sensors_enabled, write_result_passes,
                      write_rgb)
from .jobs import BackgroundJob, JobSlot, status_line as _status_line
from .properties.scene import COLOUR_OUTPUT_PASS

DISPLAY_INTERVAL = 1.0  # seconds between progressive updates of the result image

SLOT = JobSlot()
STATE = SLOT.state  # what the panel and the status bar show about the current (or last) render
current_job = SLOT.current  # the RenderJob in progress (or the last one)
busy = SLOT.busy  # True while a render job runs (worker thread alive or a synchronous render in progress)
cancel_current = SLOT.cancel  # stop a running job (the add-on is unregistered); cancel_current(wait=seconds)


def status_line(state=STATE):
    """One line for the status bar: phase, samples done/total, speed, cancel hint."""
    return _status_line(state)


def dropped_samples_warning(stats):
    """The warning for the samples a render left out of their pixels for not being finite
    (``RenderStats.dropped_samples``, which validated input cannot make); None when there are none."""
    n = int(getattr(stats, "dropped_samples", 0) or 0)
    if n <= 0:
        return None
    was = "was" if n == 1 else "were"
    return f"{n} sample{'' if n == 1 else 's'} {was} not finite (NaN or Inf) and {was} left out of their pixels"


class RenderJob(BackgroundJob):
    """One render of an exported core scene into the image ``image_name``."""

    slot = SLOT
    thread_name = "spectral-gi-render"

    def __init__(self, scene, threads=0, image_name=RESULT_IMAGE):
        super().__init__()
        self.scene = scene
        self.threads = int(threads) if threads else None
        self.image_name = image_name
        self.passes = 0
        self.film = None
        self.stats = None
        self._lock = threading.Lock()
        self._pending = None  # latest film copy not yet shown
        self._last_copy = -1e9
        self._last_display = -1e9
        self._shown_spp = 0

    # ------------------------------------------------------------------ callbacks (any thread)

    def _status(self, text):
        STATE.phase = str(text)

    def _progress(self, done, total, rate):
        STATE.done = int(done)
        STATE.total = int(total)
        STATE.rate = float(rate)

    def _on_pass(self, film):
        self.passes += 1
        now = time.monotonic()
        if now - self._last_copy >= DISPLAY_INTERVAL:
            copy = film.copy()
            with self._lock:
                self._pending = copy
            self._last_copy = now

    def _worker_args(self):
        return (self._on_pass,)

    def _run(self, on_pass):
        try:
            from ..core import render

            self.film, self.stats = render(self.scene, threads=self.threads, progress=self._progress,
                                           should_cancel=self.should_cancel, on_pass=on_pass,
                                           status=self._status)
        except Exception as exc:  # reported by the operator on the main thread
            self._capture(exc)
        finally:
            self.finished = True

    # ------------------------------------------------------------------ main thread

    def _total(self):
        return self.scene.settings.spp

    def run_sync(self):
        """Render on the calling (main) thread, updating the image as passes complete."""
        self._begin()

        def on_pass(film):
            self._on_pass(film)
            self.display_pending()

        self._run(on_pass)
        return self.conclude()

    def display_pending(self, force=False):
        """Develop the latest film copy into the result image (throttled). Returns the image or None."""
        now = time.monotonic()
        if not force and now - self._last_display < DISPLAY_INTERVAL:
            return None
        with self._lock:
            film, self._pending = self._pending, None
        if film is None:
            return None
        self._last_display = now
        return self._show(film)

    def _show(self, film):
        img = write_rgb(film.develop().rgb, self.image_name)
        self.image_name = img.name
        self._shown_spp = film.spp
        return img

    def _while_running(self):
        self.display_pending()

    def _hand_over(self):
        """Show the final (or last partial) film. Returns the image."""
        film = self.film
        if film is None:
            with self._lock:
                film, self._pending = self._pending, None
        if film is not None and film.spp > 0:
            return self._show(film)
        return None

    def _concluded(self):
        return self.result_image()

    def end_phase(self):
        return "Finished" if self.error is None else "Failed"  # a cancelled render says so in its message

    def result_image(self):
        import bpy

        return bpy.data.images.get(self.image_name)

    @property
    def cancelled(self):
        return bool(self.stats is not None and self.stats.cancelled)

    @property
    def dropped_warning(self):
        """The warning for samples the render left out for not being finite, or None."""
        return dropped_samples_warning(self.stats)

    def message(self):
        dropped = self.dropped_warning
        return self.summary() + (f" | {dropped}" if dropped else "")

    def summary(self):
        if self.error is not None:
            return f"Render failed: {self.error}"
        st = self.stats
        if st is None:
            return "Render did not start"
        total = self.scene.settings.spp
        if st.cancelled:
            return f"Cancelled after {st.spp} of {total} samples ({st.seconds:.1f} s)"
        return (f"Rendered {st.spp} samples in {st.seconds:.1f} s "
                f"({st.samples_per_second / 1e6:.2f} M samples/s)")


# ----------------------------------------------------------------------------- the RenderEngine's loop

ENGINE_MIN_UPDATE = 0.2  # seconds between partial results, at least (more if developing is slow)


def colour_output_arrays(developed, arrays):
    """Add the Colour Output pass (the image in the render's output space, ACEScg or XYZ) to
    ``arrays``: Combined stays linear Rec.709, which Blender's colour management displays."""
    if developed.colour_space != "rec709":
        import numpy as np

        arrays[COLOUR_OUTPUT_PASS] = np.asarray(developed.output, dtype=np.float32)
    return arrays


def engine_threads(scene):
    """Worker threads for an engine render: the add-on's setting, else Blender's fixed thread count, else all."""
    settings = getattr(scene, "spectral_gi", None)
    n = int(getattr(settings, "threads", 0) or 0)
    if n > 0:
        return n
    r = scene.render
    if getattr(r, "threads_mode", "AUTO") == "FIXED":
        return int(r.threads)
    return None


def sensor_report(stats):
    """One line of the sensor statistics (lux): over the pixels fully on a sensor, the partly
    covered ones (outlines, contact lines) counted as excluded."""
    excluded = int(stats.get("excluded", 0))
    if not stats.get("pixels"):
        if excluded:
            return f"Sensors: no pixel fully on a sensor ({excluded} partly covered px)"
        return "Sensors: no sensor surface in view"
    emin_std = stats.get("Emin_std", float("nan"))
    pm = f" ± {emin_std:.2g}" if math.isfinite(emin_std) else ""
    text = (f"Sensors: Em {stats['Em']:.4g} lx, Emin {stats['Emin']:.4g}{pm} lx, Emax {stats['Emax']:.4g} lx, "
            f"U0 {stats['U0']:.3f} ({stats['pixels']} px")
    return text + (f", {excluded} partly covered px excluded)" if excluded else ")")


def _render_sensors(engine, core_scene, layer, threads):
    """The measuring render of the sensor objects into the Illuminance pass; statistics into STATE."""
    from ..core import has_sensors, render_illuminance

    STATE.illuminance = None
    if not has_sensors(core_scene):
        engine.report({"WARNING"}, "Spectral GI: Sensors is on but no rendered object is an Illuminance Sensor "
                                   "(Object properties); the Illuminance pass is left black")
        return

    def progress(done, total_spp, rate):
        engine.update_progress(min(1.0, done / max(total_spp, 1)))
        engine.update_stats("Spectral GI", f"Illuminance: sample {done}/{total_spp}")

    res = render_illuminance(core_scene, threads=threads, progress=progress, should_cancel=engine.test_break,
                             status=lambda text: engine.update_stats("Spectral GI", f"Illuminance: {text}"))
    write_result_passes(layer, {"Illuminance": illuminance_pass(res.image.lux)})
    STATE.illuminance = res.stats.as_dict()
    engine.report({"INFO"}, "Spectral GI: " + sensor_report(STATE.illuminance))


def render_with_engine(engine, depsgraph):
    """Export the depsgraph's scene and render it into ``engine``'s render result, progressively.

    Partial results after each pass (throttled), ``test_break()`` cancels after the current
    pass and keeps what was rendered; errors are reported, never raised.
    """
    scene = depsgraph.scene
    view_layer = depsgraph.view_layer
    settings = getattr(scene, "spectral_gi", None)
    STATE.illuminance = None
    engine.update_stats("Spectral GI", "Exporting scene")
    try:
        exported = export_scene(depsgraph, scene, should_cancel=engine.test_break)
    except ExportCancelled:
        return
    except Exception as exc:  # the scene cannot be exported: say why
        traceback.print_exc()
        engine.report({"ERROR"}, f"Spectral GI: cannot export the scene: {exc}")
        return
    if exported.warning:
        engine.report({"WARNING"}, f"Spectral GI: {exported.warning}")
    core_scene = exported.scene
    cam = core_scene.camera
    width, height = int(engine.resolution_x), int(engine.resolution_y)
    if (width, height) != (cam.width, cam.height):
        # a border render asks for part of the frame: render the whole frame at the size asked for
        engine.report({"WARNING"}, "Spectral GI: render region (border) not supported; the whole frame is "
                                   f"rendered at {width} × {height} px")
        cam.width, cam.height = width, height
    total = int(core_scene.settings.spp)
    white_balance = None
    if settings is not None and getattr(settings, "white_balance", "NONE") == "LIGHT":
        from ..core import scene_white_xy

        white_balance = scene_white_xy(core_scene)
    names = [p[0] for p in enabled_passes(view_layer)]
    colour_space = core_scene.settings.colour_space

    result = engine.begin_result(0, 0, width, height, layer=view_layer.name)
    layer = result.layers[0]
    clock = {"last": -1e9, "interval": ENGINE_MIN_UPDATE, "shown": 0}

    def status(text):
        engine.update_stats("Spectral GI", str(text))

    def progress(done, total_spp, rate):
        engine.update_progress(min(1.0, done / max(total_spp, 1)))
        engine.update_stats("Spectral GI", f"Sample {done}/{total_spp} | {rate / 1e6:.2f} M samples/s")

    def on_pass(film):
        now = time.monotonic()
        if now - clock["last"] < clock["interval"] or film.spp >= total:
            return  # the last pass is written in full below
        t0 = time.perf_counter()
        arrays = pass_arrays(film.develop(white_balance=white_balance, colour_space=colour_space), [])
        write_result_passes(layer, arrays)
        engine.update_result(result)
        clock["shown"] = film.spp
        clock["last"] = time.monotonic()
        # developing a large film is not free: update less often than it takes, 4×
        clock["interval"] = max(ENGINE_MIN_UPDATE, 4.0 * (time.perf_counter() - t0))

    stats = None
    try:
        from ..core import render

        film, stats = render(core_scene, threads=engine_threads(scene), progress=progress,
                             should_cancel=engine.test_break, on_pass=on_pass, status=status)
        if film.spp > 0:
            developed = film.develop(white_balance=white_balance, colour_space=colour_space)
            write_result_passes(layer, colour_output_arrays(developed, pass_arrays(developed, names)))
            if sensors_enabled(scene) and not stats.cancelled:
                _render_sensors(engine, core_scene, layer, engine_threads(scene))
    except Exception as exc:  # a failure in the renderer: report it, keep Blender alive
        traceback.print_exc()
        engine.report({"ERROR"}, f"Spectral GI: render failed: {type(exc).__name__}: {exc}")
    finally:
        engine.end_result(result)
    if stats is not None:
        if stats.cancelled:
            text = f"Cancelled after {stats.spp} of {total} samples ({stats.seconds:.1f} s)"
        else:
            text = (f"{stats.spp} samples in {stats.seconds:.1f} s "
                    f"({stats.samples_per_second / 1e6:.2f} M samples/s)")
            reason = stats.stop_reason
            if reason in ("time_limit", "noise_target"):
                text += " — stopped at the " + ("time limit" if reason == "time_limit" else "noise target")
        engine.update_stats("Spectral GI", text)
        if STATE.illuminance is not None:
            text += " | " + sensor_report(STATE.illuminance)
        dropped = dropped_samples_warning(stats)
        if dropped:
            engine.report({"WARNING"}, f"Spectral GI: {dropped}")
            text += " | " + dropped
        STATE.message = text
        STATE.engine_stats = stats  # the last engine render's RenderStats (spectral-gi render-blend reports them)
