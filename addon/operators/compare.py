"""Compare with Cycles: render the scene with Spectral GI and with Cycles at matched settings.

Matched: resolution, samples, max bounces (every Cycles bounce limit set to it, as a
converging renderer has no separate diffuse/glossy limits), pixel filter and width,
seed; Cycles' adaptive sampling, denoising, clamping, glossy filtering and film
exposure are switched off (see shared/design/facts.md). Both images are compared in
scene-linear Rec.709 (core.compare_images: mean luminance ratio, relative RMSE of
luminance, mean and 95th-percentile ΔE00). The side-by-side image and the false-colour
ΔE00 map (with its legend) become Blender images and EXR files; the report is written
as JSON, atomically, and shown in the Spectral GI panel.

The same code path serves ``spectral-gi render-blend --compare-cycles``.
"""
import json
import os
import tempfile
import time

import bpy

from .. import render_job

SIDE_BY_SIDE_IMAGE = "Spectral GI vs Cycles"
DELTA_E_IMAGE = "Spectral GI ΔE00"
CYCLES_FILTERS = {"BOX": "BOX", "BLACKMAN_HARRIS": "BLACKMAN_HARRIS", "GAUSSIAN": "GAUSSIAN"}


class _Overrides:
    """Set attributes and put every one back afterwards (also on errors)."""

    def __init__(self):
        self._saved = []

    def set(self, owner, attr, value):
        if owner is None or not hasattr(owner, attr):
            return False
        self._saved.append((owner, attr, getattr(owner, attr)))
        try:
            setattr(owner, attr, value)
        except (TypeError, ValueError, AttributeError):
            self._saved.pop()
            return False
        return True

    def restore(self):
        for owner, attr, value in reversed(self._saved):
            try:
                setattr(owner, attr, value)
            except (TypeError, ValueError, AttributeError, ReferenceError):
                pass
        self._saved.clear()


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


def render_cycles_rgb(scene, samples, max_bounces, pixel_filter="BLACKMAN_HARRIS", filter_width=1.5, seed=0,
                      workdir=None):
    """Render ``scene`` with Cycles at matched settings; its scene-linear RGB as (H, W, 3), rows top-down."""
    from ...core import read_exr

    import numpy as np

    if not hasattr(scene, "cycles"):
        raise RuntimeError("Cycles is not available in this Blender")
    ov = _Overrides()
    workdir = workdir or tempfile.mkdtemp(prefix="spectral-gi-cycles-")
    path = os.path.join(workdir, "cycles.exr")
    try:
        for owner, attr, value in cycles_settings(scene, samples, max_bounces, pixel_filter, filter_width, seed):
            ov.set(owner, attr, value)
        for vl in scene.view_layers:
            ov.set(vl, "samples", 0)  # no per-layer sample override
        settings = scene.render.image_settings
        ov.set(settings, "file_format", "OPEN_EXR")
        ov.set(settings, "color_depth", "32")
        ov.set(settings, "color_mode", "RGBA")
        bpy.ops.render.render(write_still=False, scene=scene.name)
        img = bpy.data.images.get("Render Result")
        if img is None:
            raise RuntimeError("Cycles left no render result")
        img.save_render(filepath=path, scene=scene)
    finally:
        ov.restore()
    chans, _header = read_exr(path)
    try:
        rgb = np.stack([chans[k] for k in ("R", "G", "B")], axis=-1)
    except KeyError:
        raise RuntimeError(f"Cycles' EXR has no R, G, B channels (it has {sorted(chans)})") from None
    return np.asarray(rgb, dtype=np.float64)


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
    fd, tmp = tempfile.mkstemp(prefix=".spectral-gi-", suffix=".json.tmp", dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump(doc, f, indent=1)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    return path


def _save_image_exr(img, path):
    img.filepath_raw = path
    img.file_format = "OPEN_EXR"
    img.save()


def compare_with_cycles(scene, depsgraph, out_dir=None, json_path=None, spp=None, ours=None, log=None):
    """Run the comparison; returns the report dict (also stored on ``scene.spectral_gi`` and written as JSON).

    ``ours``: an already rendered (core scene, film) to compare instead of rendering again.
    """
    from ...core import compare_images, delta_e_image, side_by_side
    from ..imageio import write_rgb

    say = log or (lambda text: None)
    t0 = time.perf_counter()
    if ours is None:
        say("Rendering with Spectral GI")
        core_scene, film, _stats, _warning = render_ours(scene, depsgraph, spp)
    else:
        core_scene, film = ours
    st = core_scene.settings
    ours_rgb = film.develop().rgb
    t_ours = time.perf_counter() - t0
    s = getattr(scene, "spectral_gi", None)
    pixel_filter = getattr(s, "pixel_filter", "BLACKMAN_HARRIS")
    filter_width = float(getattr(s, "filter_width", 1.5))
    say(f"Rendering with Cycles ({film.spp} samples, max bounces {st.max_depth})")
    t1 = time.perf_counter()
    out_dir = out_dir or output_dir(scene)
    ref_rgb = render_cycles_rgb(scene, film.spp, st.max_depth, pixel_filter, filter_width, st.seed,
                                workdir=tempfile.mkdtemp(prefix="spectral-gi-cycles-"))
    t_cycles = time.perf_counter() - t1
    report, de = compare_images(ours_rgb, ref_rgb)
    report.update({
        "samples": int(film.spp), "max_bounces": int(st.max_depth), "pixel_filter": pixel_filter,
        "filter_width": filter_width, "seed": int(st.seed), "seconds_spectral_gi": t_ours,
        "seconds_cycles": t_cycles, "blend_file": bpy.data.filepath, "scene": scene.name,
        "cycles_settings": "adaptive sampling off, denoising off, clamping 0, blur glossy 0, every bounce "
                           "limit = max bounces, film exposure 1, device CPU",
        "images": {},
    })
    sbs = write_rgb(side_by_side(ours_rgb, ref_rgb), SIDE_BY_SIDE_IMAGE)
    dimg = write_rgb(delta_e_image(de), DELTA_E_IMAGE)
    stem = bpy.path.clean_name(scene.name) or "scene"
    for img, suffix in ((sbs, "side_by_side"), (dimg, "delta_e00")):
        path = os.path.join(out_dir, f"{stem}_cycles_{suffix}.exr")
        try:
            _save_image_exr(img, path)
            report["images"][suffix] = path
        except RuntimeError as exc:
            say(f"could not save {path}: {exc}")
    json_path = json_path or os.path.join(out_dir, f"{stem}_cycles_comparison.json")
    write_json_atomic(json_path, report)
    report["report_path"] = json_path
    if s is not None:
        s.compare_valid = True
        s.compare_luminance_ratio = report["luminance_ratio"]
        s.compare_relative_rmse = report["relative_rmse"]
        s.compare_delta_e_mean = report["delta_e00_mean"]
        s.compare_delta_e_p95 = report["delta_e00_p95"]
        s.compare_report_path = json_path
    return report


class SPECTRALGI_OT_compare_cycles(bpy.types.Operator):
    """Render the scene with Spectral GI and with Cycles at matched settings; show a side-by-side image, a ΔE00 map and the numbers"""

    bl_idname = "spectral_gi.compare_cycles"
    bl_label = "Compare with Cycles"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        return context.scene is not None and not render_job.busy() and hasattr(context.scene, "cycles")

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
            report = compare_with_cycles(scene, context.evaluated_depsgraph_get(),
                                         log=lambda text: self.report({"INFO"}, f"Spectral GI: {text}"))
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
        from ..imageio import show_in_image_editors

        img = bpy.data.images.get(SIDE_BY_SIDE_IMAGE)
        if img is not None:
            show_in_image_editors(img, wm)
        text = (f"luminance ratio {report['luminance_ratio']:.4f}, relative RMSE {report['relative_rmse']:.4f}, "
                f"ΔE00 mean {report['delta_e00_mean']:.2f} / p95 {report['delta_e00_p95']:.2f}")
        render_job.STATE.message = "Cycles comparison: " + text
        self.report({"INFO"}, f"Spectral GI vs Cycles: {text} ({report['report_path']})")
        return {"FINISHED"}
