"""``spectral-gi render-blend``: render a .blend file without Blender's interface, as F12 would.

Opens the file with the ``bpy`` module (Blender as a Python module), registers this
checkout's add-on (nothing is installed) and renders the scene through the registered
Spectral GI render engine with ``bpy.ops.render.render(write_still=True)``: the same
export, the same passes (the view layer's *Spectral GI Passes*), compositor and output
settings as F12 in Blender, so a render farm gets what an artist sees. The only
settings changed (and only for this render) are the engine, ``--spp``, and the output:
``--out`` as a 32-bit multilayer OpenEXR. An sRGB PNG of the Combined pass is written
beside it; ``--compare-cycles`` then runs the code path of the "Compare with Cycles"
operator on that image.
"""
import contextlib
import io
import json
import math
import os
import sys
import time
from pathlib import Path

BLEND_MAGIC = (b"BLENDER", b"\x28\xb5\x2f\xfd", b"\x1f\x8b")  # plain, zstd- and gzip-compressed .blend
ENGINE = "SPECTRAL_GI"


class HeadlessError(Exception):
    """A problem the command reports in one line (missing file, not a .blend, no bpy, ...)."""


def one_line(text):
    return " ".join(str(text).split())


def check_blend_file(path):
    """Raise HeadlessError unless ``path`` is an existing .blend file (checked by its first bytes)."""
    p = Path(path)
    if not p.exists():
        raise HeadlessError(f"{p}: no such file")
    if not p.is_file():
        raise HeadlessError(f"{p}: not a file")
    with open(p, "rb") as f:
        head = f.read(8)
    if not head.startswith(BLEND_MAGIC):
        raise HeadlessError(f"{p}: not a .blend file")
    return p


def _import_bpy():
    try:
        import bpy
    except ImportError as exc:
        raise HeadlessError(f"the bpy module (Blender as a Python module, pip install bpy) is not available: "
                            f"{exc}") from None
    return bpy


def read_multilayer_exr(path):
    """{"Pass.Channel": (H, W) float64} of a Blender multilayer EXR (every part, view layer prefix dropped)."""
    import numpy as np
    import OpenEXR

    out = {}
    with OpenEXR.File(str(path), separate_channels=True) as f:
        for part in f.parts:
            for name, ch in part.channels.items():
                key = name.split(".", 1)[1] if name.count(".") >= 2 else name
                out[key] = np.array(ch.pixels, np.float64)
    return out


def render_blend(blend, out, spp=None, compare_cycles=False, json_path=None, stream=None):
    """Render ``blend`` to ``out`` (.exr, with a .png beside it). Returns a dict summary (also the JSON report)."""
    stream = stream or sys.stderr

    def say(text):
        stream.write(f"{text}\n")
        stream.flush()

    blend = check_blend_file(blend)
    out = Path(out).absolute()
    if out.suffix.lower() != ".exr":
        raise HeadlessError(f"--out: expected a .exr file name, got {out}")
    if "#" in out.name:
        raise HeadlessError(f"--out: '#' in {out.name} would be replaced by the frame number")
    bpy = _import_bpy()
    from . import registration

    registration.register()  # idempotent: classes already registered are skipped
    try:
        bpy.ops.wm.open_mainfile(filepath=str(blend.resolve()), load_ui=False)
    except RuntimeError as exc:
        raise HeadlessError(f"{blend}: Blender cannot open it ({one_line(exc)})") from None
    scene = bpy.context.scene
    if scene.camera is None:
        raise HeadlessError(f"{blend}: scene {scene.name!r} has no active camera")

    import numpy as np

    from ..core import write_png
    from . import render_job
    from .operators.compare import _Overrides, compare_with_cycles, write_json_atomic

    out.parent.mkdir(parents=True, exist_ok=True)
    ov = _Overrides()
    try:
        r = scene.render
        ov.set(r, "engine", ENGINE)
        if spp:
            ov.set(scene.spectral_gi, "samples", int(spp))
        ov.set(r, "filepath", str(out))
        ov.set(r, "use_file_extension", True)
        settings = r.image_settings
        ov.set(settings, "media_type", "MULTI_LAYER_IMAGE")  # Blender 5: one part per pass
        ov.set(settings, "file_format", "OPEN_EXR_MULTILAYER")
        ov.set(settings, "color_depth", "32")
        render_job.STATE.message = ""
        render_job.STATE.engine_stats = None  # set by the engine's render loop
        say(f"rendering {blend.name}, scene {scene.name!r}: {r.resolution_x * r.resolution_percentage // 100} × "
            f"{r.resolution_y * r.resolution_percentage // 100} px, {scene.spectral_gi.samples} spp")
        t0 = time.perf_counter()
        # The engine prints a traceback beside each error it reports (for Blender's console); here
        # the report itself becomes the one-line error, the traceback is shown only with SPECTRAL_GI_DEBUG.
        captured = io.StringIO()
        try:
            with contextlib.redirect_stderr(captured):
                bpy.ops.render.render(write_still=True, scene=scene.name)
        except RuntimeError as exc:  # Blender's or the engine's error reports
            if os.environ.get("SPECTRAL_GI_DEBUG"):
                stream.write(captured.getvalue())
            raise HeadlessError(f"{blend}: {one_line(exc).removeprefix('Error: ')}") from None
        if captured.getvalue():
            stream.write(captured.getvalue())
        seconds = time.perf_counter() - t0
        if not out.is_file():
            raise HeadlessError(f"{blend}: the render wrote no {out.name} "
                                f"({one_line(render_job.STATE.message) or 'no message from the engine'})")
        chans = read_multilayer_exr(out)
        try:
            rgb = np.stack([chans[f"Combined.{c}"] for c in "RGB"], axis=-1)
        except KeyError:
            raise HeadlessError(f"{out}: no Combined pass (channels: {', '.join(sorted(chans))})") from None
        png = out.with_suffix(".png")
        view = _save_png_as_blender_shows_it(bpy, scene, png, ov)
        if view is None:  # no Render Result to save: the plain sRGB preview
            write_png(png, rgb)
            view = "sRGB (Standard)"
        stats = getattr(render_job.STATE, "engine_stats", None)
        samples = int(stats.spp) if stats is not None else int(scene.spectral_gi.samples)
        lum = chans.get("Luminance.Y")
        mean_lum = float(lum.mean()) if lum is not None else \
            float(683.0 * (rgb @ np.array([0.2126, 0.7152, 0.0722])).mean())
        passes = sorted({k.split(".")[0] for k in chans})
        summary = {"blend_file": str(blend), "scene": scene.name, "engine": ENGINE, "exr": str(out),
                   "png": str(png), "passes": passes, "width": int(rgb.shape[1]), "height": int(rgb.shape[0]),
                   "samples": samples, "seconds": float(stats.seconds) if stats is not None else seconds,
                   "samples_per_second": float(stats.samples_per_second) if stats is not None else
                   samples * rgb.shape[0] * rgb.shape[1] / max(seconds, 1e-9),
                   "mean_luminance": mean_lum, "luminance_unit": "cd/m2", "png_view_transform": view,
                   "engine_message": render_job.STATE.message}
        if not math.isfinite(mean_lum):
            raise HeadlessError(f"{out}: the image holds NaN or Inf")
        say(f"wrote {out} (passes {', '.join(passes)}) and {png}: {render_job.STATE.message or f'{samples} spp'}, "
            f"mean luminance {mean_lum:.4g} cd/m²")
        if compare_cycles:
            report = compare_with_cycles(scene, None, out_dir=str(out.parent), ours=(rgb, samples, summary["seconds"]),
                                         json_path=str(json_path) if json_path else None, log=say)
            summary["comparison"] = report
            say(f"Cycles comparison: luminance ratio {report['luminance_ratio']:.4f}, relative RMSE "
                f"{report['relative_rmse']:.4f}, ΔE00 mean {report['delta_e00_mean']:.2f}, "
                f"p95 {report['delta_e00_p95']:.2f} ({report['report_path']})")
    finally:
        ov.restore()
    if json_path:  # the JSON holds the render summary (and the comparison)
        write_json_atomic(str(json_path), summary)
    return summary


def _save_png_as_blender_shows_it(bpy, scene, png, ov):
    """Write the render's PNG through Blender's colour management (the scene's view
    transform, look, exposure and gamma), so it looks as F12 shows it. Returns the view's
    name, or None when Blender has no Render Result to save."""
    from ..core.io.atomic import atomic_path

    img = bpy.data.images.get("Render Result")
    if img is None:
        return None
    settings = scene.render.image_settings
    ov.set(settings, "media_type", "IMAGE")
    ov.set(settings, "file_format", "PNG")
    ov.set(settings, "color_depth", "8")
    ov.set(settings, "color_mode", "RGB")
    with atomic_path(png) as tmp:
        img.save_render(filepath=str(tmp), scene=scene)
    vs = scene.view_settings
    return vs.view_transform + (f", look {vs.look}" if vs.look not in ("", "None") else "")


def main(args):
    """Entry point for core/cli.py's ``render-blend`` (args: blend, out, spp, compare_cycles, json)."""
    out = args.out or (Path(args.blend).with_suffix("").name + ".exr")
    summary = render_blend(args.blend, out, spp=args.spp, compare_cycles=args.compare_cycles, json_path=args.json)
    print(json.dumps({k: summary[k] for k in ("exr", "png", "samples")}))
    return 0
