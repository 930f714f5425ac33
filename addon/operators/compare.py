"""Compare with Cycles: render the scene with Spectral GI and with Cycles at matched settings.

Matched: resolution, samples, max bounces (every Cycles bounce limit set to it, as a
converging renderer has no separate diffuse/glossy limits), pixel filter and width,
seed; Cycles' adaptive sampling, denoising, clamping, glossy filtering and film
exposure are switched off (Cycles 5.0's defaults: adaptive, denoised, indirect clamp 10). Both images are compared in
scene-linear Rec.709 (core.compare_images: mean luminance ratio, relative RMSE of
luminance, mean and 95th-percentile ΔE00). The side-by-side image and the false-colour
ΔE00 map (with its legend) become Blender images and EXR files; the report is written
as JSON, atomically, and shown in the Spectral GI panel.

Two ways to run the same steps:

* ``ComparisonRun`` — the interactive operator's state machine: Spectral GI renders on a
  worker thread (as ``render_job.RenderJob``), then Cycles renders as Blender's own
  render job (``bpy.ops.render.render('INVOKE_DEFAULT')``, its end seen through the
  ``render_complete`` / ``render_cancel`` handlers), so the UI never freezes; the
  operator calls ``step()`` from a timer. Esc cancels either part; nothing is written
  unless both renders completed, so the previous comparison stays as it was.
* ``compare_with_cycles`` — blocking, for background mode, scripts and
  ``spectral-gi render-blend --compare-cycles``.

Both end in ``finish_comparison`` (numbers, images, JSON, panel values).
"""
import json
import os
import shutil
import tempfile
import time

import bpy

from .. import render_job
from ..export.detail import Overrides, render_detail
from ..jobs import ModalJobOperator, redraw

SIDE_BY_SIDE_IMAGE = "Spectral GI vs Cycles"
DELTA_E_IMAGE = "Spectral GI ΔE00"
CYCLES_FILTERS = {"BOX": "BOX", "BLACKMAN_HARRIS": "BLACKMAN_HARRIS", "GAUSSIAN": "GAUSSIAN"}
JOB_START_GRACE = 2.0  # seconds a Cycles render job may take to show up as running

RUNNING, FINISHED, CANCELLED, FAILED = "RUNNING", "FINISHED", "CANCELLED", "FAILED"


def cycles_settings(scene, samples, max_bounces, pixel_filter, filter_width, seed):
    """The (owner, attribute, value) list that matches Cycles to a Spectral GI render."""
    c = scene.cycles
    r = scene.render
    out = [(r, "engine", "CYCLES"), (c, "device", "CPU"), (c, "samples", int(samples)),
           (c, "use_adaptive_sampling", False), (c, "use_denoising", False),
           (c, "sample_clamp_direct", 0.0), (c, "sample_clamp_indirect", 0.0), (c, "blur_glossy", 0.0),
           (c, "caustics_reflective", True), (c, "caustics_refractive", True),
           (c, "max_bounces", int(max_bounces)), (c, "diffuse_bounces", int(max_bounces)),
           (c, "glossy_bounces", int(max_bounces)), (c, "transmission_bounces", int(max_bounces)),
           (c, "volume_bounces", int(max_bounces)), (c, "transparent_max_bounces", max(8, int(max_bounces))),
           (c, "pixel_filter_type", CYCLES_FILTERS.get(pixel_filter, "BLACKMAN_HARRIS")),
           (c, "filter_width", float(filter_width)), (c, "seed", int(seed)), (c, "use_animated_seed", False),
           (c, "film_exposure", 1.0), (c, "use_auto_tile", False), (r, "film_transparent", False),
           (r, "use_border", False), (r, "use_compositing", False), (r, "use_sequencer", False)]
    return out


def matched_settings(scene, core_settings=None, spp=None):
    """What Cycles is matched to: {samples, max_bounces, pixel_filter, filter_width, seed}.

    From the exported scene's settings when given, else from ``scene.spectral_gi``;
    ``spp`` (the samples actually rendered) overrides the sample count.
    """
    s = getattr(scene, "spectral_gi", None)
    if core_settings is not None:
        samples, max_bounces, seed = core_settings.spp, core_settings.max_depth, core_settings.seed
    else:
        samples = getattr(s, "samples", 64)
        max_bounces = getattr(s, "max_bounces", 16)
        seed = getattr(s, "seed", 0)
    return {"samples": int(spp or samples), "max_bounces": int(max_bounces),
            "pixel_filter": getattr(s, "pixel_filter", "BLACKMAN_HARRIS"),
            "filter_width": float(getattr(s, "filter_width", 1.5)), "seed": int(seed)}


class CyclesRender:
    """One Cycles render of ``scene`` at matched settings: ``start``, ``poll`` until done, ``collect``.

    ``start(use_job=True)`` runs Cycles as Blender's render job (the UI stays live, Esc
    stops it as it stops F12); ``use_job=False`` renders on the spot (background mode).
    Either way the end is seen through the ``render_complete`` / ``render_cancel``
    handlers, which only set flags (Blender calls them on its render thread). Every
    setting changed is restored by ``collect`` or ``abort``.
    """

    def __init__(self, scene, samples, max_bounces, pixel_filter="BLACKMAN_HARRIS", filter_width=1.5, seed=0,
                 workdir=None):
        if not hasattr(scene, "cycles"):
            raise RuntimeError("Cycles is not available in this Blender")
        self.scene = scene
        self.args = (samples, max_bounces, pixel_filter, filter_width, seed)
        self.workdir = workdir
        self.completed = False
        self.cancelled = False
        self.started = False
        self.use_job = False
        self.seconds = 0.0
        self._t0 = 0.0
        self._ov = Overrides()
        self._hooked = False

    # handlers: called on Blender's render thread, so they only set flags
    def _on_complete(self, *_args):
        self.completed = True

    def _on_cancel(self, *_args):
        self.cancelled = True

    def _hook(self):
        bpy.app.handlers.render_complete.append(self._on_complete)
        bpy.app.handlers.render_cancel.append(self._on_cancel)
        self._hooked = True

    def _unhook(self):
        if not self._hooked:
            return
        for handlers, fn in ((bpy.app.handlers.render_complete, self._on_complete),
                             (bpy.app.handlers.render_cancel, self._on_cancel)):
            while fn in handlers:
                handlers.remove(fn)
        self._hooked = False

    def _launch(self):
        """Start the render; False if Blender refused to start it."""
        if self.use_job:
            result = bpy.ops.render.render("INVOKE_DEFAULT", write_still=False, scene=self.scene.name)
            return "RUNNING_MODAL" in result or "FINISHED" in result
        return "FINISHED" in bpy.ops.render.render(write_still=False, scene=self.scene.name)

    def start(self, use_job=False):
        scene = self.scene
        self.use_job = bool(use_job)
        for owner, attr, value in cycles_settings(scene, *self.args):
            self._ov.set(owner, attr, value)
        for vl in scene.view_layers:
            self._ov.set(vl, "samples", 0)  # no per-layer sample override
        settings = scene.render.image_settings
        self._ov.set(settings, "media_type", "IMAGE")  # Blender 5: a multilayer output cannot be OPEN_EXR
        self._ov.set(settings, "file_format", "OPEN_EXR")
        self._ov.set(settings, "color_depth", "32")
        self._ov.set(settings, "color_mode", "RGBA")
        self._hook()
        self._t0 = time.perf_counter()
        try:
            ok = self._launch()
        except BaseException:
            self.abort()
            raise
        if not ok:
            self.abort()
            raise RuntimeError("Blender did not start the Cycles render (is another render running?)")
        self.started = True

    def job_running(self):
        return bool(self.use_job and bpy.app.is_job_running("RENDER"))

    def poll(self):
        """RUNNING, FINISHED (a result to collect) or CANCELLED (stopped, failed, or ended without a result)."""
        if self.job_running():
            return RUNNING
        if self.cancelled:
            return CANCELLED
        if not self.completed:
            if self.use_job and time.perf_counter() - self._t0 < JOB_START_GRACE:
                return RUNNING  # the job may not have been scheduled yet
            return CANCELLED
        return FINISHED

    def collect(self):
        """The finished render's scene-linear RGB as (H, W, 3), rows top-down; restores the settings."""
        from ...core import read_exr

        import numpy as np

        self.seconds = time.perf_counter() - self._t0
        own = self.workdir is None  # a folder of its own, removed once the EXR is read back
        workdir = tempfile.mkdtemp(prefix="spectral-gi-cycles-") if own else self.workdir
        path = os.path.join(workdir, "cycles.exr")
        try:
            try:
                img = bpy.data.images.get("Render Result")
                if img is None:
                    raise RuntimeError("Cycles left no render result")
                img.save_render(filepath=path, scene=self.scene)  # with the overridden EXR settings
            finally:
                self.abort()
            chans, _header = read_exr(path)
        finally:
            if own:
                shutil.rmtree(workdir, ignore_errors=True)
        try:
            rgb = np.stack([chans[k] for k in ("R", "G", "B")], axis=-1)
        except KeyError:
            raise RuntimeError(f"Cycles' EXR has no R, G, B channels (it has {sorted(chans)})") from None
        return np.asarray(rgb, dtype=np.float64)

    def abort(self):
        """Restore every setting and remove the handlers (idempotent)."""
        self._unhook()
        self._ov.restore()


def render_cycles_rgb(scene, samples, max_bounces, pixel_filter="BLACKMAN_HARRIS", filter_width=1.5, seed=0,
                      workdir=None):
    """Render ``scene`` with Cycles at matched settings, blocking; its scene-linear RGB as (H, W, 3), rows top-down."""
    cycles = CyclesRender(scene, samples, max_bounces, pixel_filter, filter_width, seed, workdir)
    cycles.start(use_job=False)
    if cycles.poll() != FINISHED:
        cycles.abort()
        raise RuntimeError("the Cycles render was cancelled or failed")
    return cycles.collect()


def render_ours(scene, depsgraph, spp=None, progress=None, status=None, should_cancel=None):
    """Export and render with Spectral GI on the calling thread: (core scene, film, stats, export warning)."""
    from ...core import render
    from ..export import export_scene

    exported = export_scene(depsgraph, scene, should_cancel=should_cancel)
    core_scene = exported.scene
    if spp:
        core_scene.settings.spp = int(spp)
    film, stats = render(core_scene, threads=render_job.engine_threads(scene), progress=progress,
                         status=status, should_cancel=should_cancel)
    return core_scene, film, stats, exported.warning


def output_dir(scene):
    """Where the comparison's files go: the scene's folder setting, beside the .blend, or a temporary folder."""
    s = getattr(scene, "spectral_gi", None)
    d = bpy.path.abspath(s.compare_output_dir) if s is not None and s.compare_output_dir else ""
    if not d:
        d = os.path.dirname(bpy.data.filepath) if bpy.data.filepath else tempfile.gettempdir()
    os.makedirs(d, exist_ok=True)
    return d


def write_json_atomic(path, doc):
    """Write ``doc`` as JSON to ``path``: a temporary file in the same folder, then an atomic rename."""
    folder = os.path.dirname(os.path.abspath(path)) or "."
    from ...core import write_text_atomic

    os.makedirs(folder, exist_ok=True)
    write_text_atomic(path, json.dumps(doc, indent=1))  # readable by the group, as the images are
    return path


def _save_image_exr(img, path):
    img.filepath_raw = path
    img.file_format = "OPEN_EXR"
    img.save()


def finish_comparison(scene, ours_rgb, ref_rgb, matched, seconds_ours, seconds_cycles, out_dir=None,
                      json_path=None, log=None):
    """Numbers, side-by-side and ΔE00 images (Blender images + EXR), JSON report and panel values.

    Called only once both renders are complete, so a cancelled comparison leaves the last one intact.
    """
    from ...core import compare_images, delta_e_image, side_by_side, write_png
    from ..imageio import write_rgb

    say = log or (lambda text: None)
    out_dir = out_dir or output_dir(scene)
    report, de = compare_images(ours_rgb, ref_rgb)
    report.update({
        "samples": int(matched["samples"]), "max_bounces": int(matched["max_bounces"]),
        "pixel_filter": matched["pixel_filter"], "filter_width": float(matched["filter_width"]),
        "seed": int(matched["seed"]), "seconds_spectral_gi": float(seconds_ours),
        "seconds_cycles": float(seconds_cycles), "blend_file": bpy.data.filepath, "scene": scene.name,
        "cycles_settings": "adaptive sampling off, denoising off, clamping 0, blur glossy 0, every bounce "
                           "limit = max bounces, film exposure 1, device CPU",
        "images": {},
    })
    sbs = write_rgb(side_by_side(ours_rgb, ref_rgb), SIDE_BY_SIDE_IMAGE)
    dimg = write_rgb(delta_e_image(de), DELTA_E_IMAGE)
    stem = bpy.path.clean_name(scene.name) or "scene"
    for img, rgb, suffix in ((sbs, side_by_side(ours_rgb, ref_rgb), "side_by_side"),
                             (dimg, delta_e_image(de), "delta_e00")):
        path = os.path.join(out_dir, f"{stem}_cycles_{suffix}.exr")
        try:
            _save_image_exr(img, path)
            report["images"][suffix] = path
        except RuntimeError as exc:
            say(f"could not save {path}: {exc}")
        png = os.path.join(out_dir, f"{stem}_cycles_{suffix}.png")  # sRGB, for viewers without EXR
        try:
            write_png(png, rgb)
            report["images"][suffix + "_png"] = png
        except OSError as exc:
            say(f"could not save {png}: {exc}")
    json_path = json_path or os.path.join(out_dir, f"{stem}_cycles_comparison.json")
    write_json_atomic(json_path, report)
    report["report_path"] = json_path
    s = getattr(scene, "spectral_gi", None)
    if s is not None:
        s.compare_valid = True
        s.compare_luminance_ratio = report["luminance_ratio"]
        s.compare_relative_rmse = report["relative_rmse"]
        s.compare_delta_e_mean = report["delta_e00_mean"]
        s.compare_delta_e_p95 = report["delta_e00_p95"]
        s.compare_report_path = json_path
    return report


def report_text(report):
    return (f"luminance ratio {report['luminance_ratio']:.4f}, relative RMSE {report['relative_rmse']:.4f}, "
            f"ΔE00 mean {report['delta_e00_mean']:.2f} / p95 {report['delta_e00_p95']:.2f}")


def compare_with_cycles(scene, depsgraph, out_dir=None, json_path=None, spp=None, ours=None, log=None):
    """Run the comparison, blocking; returns the report dict (also stored on ``scene.spectral_gi`` and as JSON).

    ``ours``: an already rendered image to compare instead of rendering again: a
    (core scene, film) pair, or (linear Rec.709 (H, W, 3) array, samples rendered, and
    optionally the seconds that render took).
    """
    import numpy as np

    say = log or (lambda text: None)
    t0 = time.perf_counter()
    if ours is None:
        say("Rendering with Spectral GI")
        core_scene, film, _stats, _warning = render_ours(scene, depsgraph, spp)
        ours_rgb, matched = film.develop().rgb, matched_settings(scene, core_scene.settings, film.spp)
    elif isinstance(ours[0], np.ndarray):
        ours_rgb, matched = ours[0], matched_settings(scene, spp=ours[1])
        if len(ours) > 2:  # the render's own time, not the time to hand its image over
            t0 -= float(ours[2])
    else:
        core_scene, film = ours
        ours_rgb, matched = film.develop().rgb, matched_settings(scene, core_scene.settings, film.spp)
    t_ours = time.perf_counter() - t0
    say(f"Rendering with Cycles ({matched['samples']} samples, max bounces {matched['max_bounces']})")
    t1 = time.perf_counter()
    out_dir = out_dir or output_dir(scene)
    ref_rgb = render_cycles_rgb(scene, matched["samples"], matched["max_bounces"], matched["pixel_filter"],
                                matched["filter_width"], matched["seed"])
    return finish_comparison(scene, ours_rgb, ref_rgb, matched, t_ours, time.perf_counter() - t1, out_dir,
                             json_path, log)


class _SpectralJob(render_job.RenderJob):
    """The Spectral GI half of a comparison: no image is touched; the film stays in memory."""

    def _on_pass(self, film):
        pass

    def _show(self, film):
        return None

    def _status(self, text):
        render_job.STATE.phase = f"Compare 1/2, Spectral GI: {text}"


class ComparisonRun:
    """The interactive comparison as a state machine, stepped from the main thread.

    ``begin()`` exports the scene and starts the Spectral GI worker thread; each
    ``step()`` returns RUNNING until the run ends in FINISHED, CANCELLED or FAILED
    (``error`` then says why). Phases: "spectral" (worker thread), "cycles" (Blender's
    render job, or a blocking render with ``use_job=False``), "done".
    ``request_cancel()`` stops the worker after its current pass; during the Cycles
    phase Esc reaches Blender's render job itself, which ends with ``render_cancel``.
    No file, image or panel value is written unless both renders complete.
    """

    def __init__(self, scene, depsgraph, out_dir=None, json_path=None, spp=None, use_job=True, log=None):
        self.scene = scene
        self.depsgraph = depsgraph
        self.out_dir = out_dir
        self.json_path = json_path
        self.spp = spp
        self.use_job = use_job
        self.log = log or (lambda text: None)
        self.phase = "idle"
        self.state = RUNNING
        self.error = None
        self.warning = None
        self.report = None
        self.job = None
        self.cycles = None
        self.cancel_requested = False
        self._t0 = 0.0
        self._seconds_ours = 0.0
        self._ours_rgb = None
        self._matched = None

    # ------------------------------------------------------------------ steps

    def begin(self):
        """Export (main thread) and start the Spectral GI worker. Raises ExportError/ExportCancelled on failure."""
        from ..export import export_scene

        if render_job.busy():
            raise RuntimeError("a Spectral GI render is running")
        self.out_dir = self.out_dir or output_dir(self.scene)
        render_job.STATE.phase = "Compare 1/2, Spectral GI: exporting scene"
        exported = export_scene(self.depsgraph, self.scene, should_cancel=lambda: self.cancel_requested)
        self.warning = exported.warning
        core_scene = exported.scene
        if self.spp:
            core_scene.settings.spp = int(self.spp)
        self._t0 = time.perf_counter()
        self.job = _SpectralJob(core_scene, threads=render_job.engine_threads(self.scene) or 0)
        self.job.start()
        self.phase = "spectral"
        return self

    def request_cancel(self):
        self.cancel_requested = True
        render_job.STATE.cancelling = True
        if self.job is not None and self.phase == "spectral":
            self.job.request_cancel()

    def poll(self):
        """One step (:meth:`step`) from the operator's timer: True once the run has ended."""
        return self.step() != RUNNING

    def status_line(self):
        return render_job.status_line()

    def step(self):
        """Advance the run by one non-blocking step; returns RUNNING, FINISHED, CANCELLED or FAILED."""
        if self.state != RUNNING:
            return self.state
        try:
            if self.phase == "spectral":
                return self._step_spectral()
            if self.phase == "cycles":
                return self._step_cycles()
        except Exception as exc:  # never raise into Blender's event loop
            import traceback

            traceback.print_exc()
            return self._end(FAILED, f"{type(exc).__name__}: {exc}")
        return self.state

    def _step_spectral(self):
        job = self.job
        if not job.finished:
            return RUNNING
        if job.thread is not None:
            job.thread.join(timeout=1.0)
            job.thread = None  # render_job.busy() now follows STATE.running, kept on until the end
        if job.error is not None:
            return self._end(FAILED, f"Spectral GI render failed: {job.error}")
        if self.cancel_requested or job.cancelled or job.film is None or job.film.spp <= 0:
            return self._end(CANCELLED, "comparison cancelled during the Spectral GI render")
        self._seconds_ours = time.perf_counter() - self._t0
        self._ours_rgb = job.film.develop().rgb
        self._matched = matched_settings(self.scene, job.scene.settings, job.film.spp)
        m = self._matched
        self.phase = "cycles"
        st = render_job.STATE
        st.phase, st.done, st.total, st.rate = "Compare 2/2: rendering with Cycles", 0, 0, 0.0
        self.log(f"Rendering with Cycles ({m['samples']} samples, max bounces {m['max_bounces']})")
        self.cycles = CyclesRender(self.scene, m["samples"], m["max_bounces"], m["pixel_filter"],
                                   m["filter_width"], m["seed"])
        self.cycles.start(use_job=self.use_job)
        return RUNNING

    def _step_cycles(self):
        state = self.cycles.poll()
        if state == RUNNING:
            return RUNNING
        if state == CANCELLED or self.cancel_requested:
            self.cycles.abort()
            return self._end(CANCELLED, "comparison cancelled during the Cycles render")
        ref_rgb = self.cycles.collect()
        self.report = finish_comparison(self.scene, self._ours_rgb, ref_rgb, self._matched, self._seconds_ours,
                                        self.cycles.seconds, self.out_dir, self.json_path, self.log)
        return self._end(FINISHED, None)

    def abort(self):
        """Stop everything now (the operator was cancelled by Blender): cancel the worker, restore Cycles."""
        if self.state != RUNNING:
            return
        self.request_cancel()
        if self.cycles is not None:
            self.cycles.abort()
        self._end(CANCELLED, "comparison cancelled")

    def _end(self, state, error):
        self.state = state
        self.error = error
        self.phase = "done"
        job = self.job
        if job is not None:
            if state != RUNNING and job.thread is not None and not job.finished:
                job.request_cancel()
            job.conclude()  # no image: _SpectralJob shows nothing; STATE.running off
        st = render_job.STATE
        st.running = False
        st.cancelling = False
        if state == FINISHED:
            st.phase, st.message = "Finished", "Cycles comparison: " + report_text(self.report)
        elif state == CANCELLED:
            st.phase, st.message = "Cancelled", "Cycles comparison cancelled; the last comparison is kept"
        else:
            st.phase, st.message = "Failed", f"Cycles comparison failed: {error}"
        return state


class SPECTRALGI_OT_compare_cycles(ModalJobOperator, bpy.types.Operator):
    """Render the scene with Spectral GI and with Cycles at matched settings; show a side-by-side image, a ΔE00 map and the numbers"""  # noqa: E501  (the tooltip)

    bl_idname = "spectral_gi.compare_cycles"
    bl_label = "Compare with Cycles"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        return context.scene is not None and not render_job.busy() and hasattr(context.scene, "cycles")

    def _say(self, text):
        self.report({"INFO"}, f"Spectral GI: {text}")

    def _show_result(self, context, report):
        from ..imageio import show_in_image_editors

        img = bpy.data.images.get(SIDE_BY_SIDE_IMAGE)
        if img is not None:
            show_in_image_editors(img, context.window_manager)
        self.report({"INFO"}, f"Spectral GI vs Cycles: {report_text(report)} ({report['report_path']})")

    # ------------------------------------------------------------------ blocking (background mode, scripts)

    def execute(self, context):
        from ..export import ExportCancelled

        scene = context.scene
        wm = context.window_manager
        render_job.STATE.phase = "Comparing with Cycles"
        try:
            wm.progress_begin(0, 100)
        except (AttributeError, RuntimeError):
            pass
        try:
            # the export sees what F12 renders (the viewport settings it changes do not reach Cycles' render)
            with render_detail(scene, context.view_layer):
                report = compare_with_cycles(scene, context.evaluated_depsgraph_get(), log=self._say)
        except ExportCancelled:
            self.report({"INFO"}, "Spectral GI: comparison cancelled")
            return {"CANCELLED"}
        except Exception as exc:  # report, never raise into Blender
            import traceback

            traceback.print_exc()
            self.report({"ERROR"}, f"Spectral GI: comparison failed: {type(exc).__name__}: {exc}")
            return {"CANCELLED"}
        finally:
            try:
                wm.progress_end()
            except (AttributeError, RuntimeError):
                pass
            render_job.STATE.phase = ""
        render_job.STATE.message = "Cycles comparison: " + report_text(report)
        self._show_result(context, report)
        return {"FINISHED"}

    # ------------------------------------------------------------------ interactive (modal, nothing blocks)

    def _start(self, context):
        """The run, begun (its Spectral GI worker started); None after reporting why it could not begin."""
        from ..export import ExportCancelled

        try:
            with render_detail(context.scene, context.view_layer):  # the export sees what F12 renders
                run = ComparisonRun(context.scene, context.evaluated_depsgraph_get(), use_job=True, log=self._say)
                run.begin()
        except ExportCancelled:
            self.report({"INFO"}, "Spectral GI: comparison cancelled")
            return None
        except Exception as exc:
            render_job.STATE.phase = ""
            self.report({"ERROR"}, f"Spectral GI: comparison failed: {type(exc).__name__}: {exc}")
            return None
        return run

    def _conclude(self, context, run):
        redraw(context.window_manager)
        if run.state == FINISHED:
            self._show_result(context, run.report)
            return {"FINISHED"}
        if run.state == CANCELLED:
            self.report({"INFO"}, f"Spectral GI: {run.error}; the last comparison is kept")
        else:
            self.report({"ERROR"}, f"Spectral GI: comparison failed: {run.error}")
        return {"CANCELLED"}

    def _abandon(self, run):
        # Blender ends the modal operator (new file, quit): stop the worker, restore Cycles' settings.
        run.abort()
