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
import re
import socket
import subprocess
import sys
import time
import uuid
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


def missing_files(bpy):
    """[(what, path)] of the external files the open .blend renders with that are not on this
    machine: images used by something (neither packed nor generated) and linked libraries."""
    out = []
    for img in bpy.data.images:
        if img.users == 0 or img.packed_file is not None or img.source not in ("FILE", "SEQUENCE"):
            continue
        path = bpy.path.abspath(img.filepath, library=img.library)
        if path and not os.path.isfile(path):
            out.append((f"image {img.name!r}", os.path.normpath(path)))
    for lib in bpy.data.libraries:
        path = bpy.path.abspath(lib.filepath)
        if not os.path.isfile(path):
            out.append((f"library {lib.name!r}", os.path.normpath(path)))
    return out


def render_blend(blend, out, spp=None, compare_cycles=False, json_path=None, stream=None, frame=None,
                 require_files=False):
    """Render ``blend`` to ``out`` (.exr, with a .png beside it). Returns a dict summary (also the JSON report).
    frame: the frame to render (None: the file's current frame); require_files: fail, naming
    the file, when an image or library the file uses is missing (a render farm's machines
    must all see the same files)."""
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
    from . import background, registration

    background.AUTOSTART = False  # this render compiles what it needs; nothing to compile ahead
    registration.register()  # idempotent: classes already registered are skipped
    try:
        bpy.ops.wm.open_mainfile(filepath=str(blend.resolve()), load_ui=False)
    except RuntimeError as exc:
        raise HeadlessError(f"{blend}: Blender cannot open it ({one_line(exc)})") from None
    scene = bpy.context.scene
    if require_files:
        missing = missing_files(bpy)
        if missing:
            what, path = missing[0]
            more = f" (and {len(missing) - 1} more)" if len(missing) > 1 else ""
            raise HeadlessError(f"{blend}: {what}: {path} is missing on {socket.gethostname()}{more}")
    if frame is not None:
        scene.frame_set(int(frame))
    if scene.camera is None:
        raise HeadlessError(f"{blend}: scene {scene.name!r} has no active camera")

    import numpy as np

    from ..core import write_png
    from . import render_job
    from .export.detail import Overrides
    from .operators.compare import compare_with_cycles, write_json_atomic

    out.parent.mkdir(parents=True, exist_ok=True)
    ov = Overrides()
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
                   "engine_message": render_job.STATE.message, "sensors": sensor_summary(scene, render_job.STATE)}
        if not math.isfinite(mean_lum):
            raise HeadlessError(f"{out}: the image holds NaN or Inf")
        say(f"wrote {out} (passes {', '.join(passes)}) and {png}: {render_job.STATE.message or f'{samples} spp'}, "
            f"mean luminance {mean_lum:.4g} cd/m²")
        if compare_cycles:
            report = compare_with_cycles(scene, None, out_dir=str(out.parent),
                                         ours=(rgb, samples, summary["seconds"]),
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


def sensor_summary(scene, state):
    """The sensor statistics of the render as fields of the JSON report, or None when the
    scene's Sensors option is off: the sensor objects, and over the pixels fully on a sensor
    their count, the mean, minimum and maximum illuminance (lux), the uniformity U0 = Emin / Em
    and the standard error of the Emin pixel; the partly covered pixels left out are counted.
    A value that is not defined (no sensor pixel in view) is null."""
    from .imageio import sensors_enabled
    from .properties.scene import SENSOR_PROPERTY

    if not sensors_enabled(scene):
        return None
    objects = sorted(o.name for o in scene.objects if getattr(o, SENSOR_PROPERTY, False))
    stats = getattr(state, "illuminance", None) or {}

    def number(key, kind=float):
        v = stats.get(key)
        return kind(v) if v is not None and math.isfinite(float(v)) else None

    return {"objects": objects, "count": len(objects), "unit": "lx",
            "pixels": number("pixels", int) or 0, "excluded_pixels": number("excluded", int) or 0,
            "min_coverage": number("min_coverage"), "Em": number("Em"), "Emin": number("Emin"),
            "Emax": number("Emax"), "U0": number("U0"), "Emin_std": number("Emin_std")}


def _save_png_as_blender_shows_it(bpy, scene, png, ov):
    """Write the render's PNG through Blender's colour management (the scene's view
    transform, look, exposure and gamma), so it looks as F12 shows it. Returns the view's
    name, or None when Blender has no Render Result to save."""
    from ..core import atomic_path

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
def parse_frames(text):
    """The frames of ``text``: ``N``, ``A-B`` (inclusive) or a comma-separated list of both, in order
    and without repeats; HeadlessError naming the problem otherwise."""
    frames = []
    for part in str(text).replace(" ", "").split(","):
        m = re.fullmatch(r"(-?\d+)(?:-(-?\d+))?", part)
        if m is None:
            raise HeadlessError(f"--frames: expected N, A-B or a list of them, got {text!r}")
        a = int(m.group(1))
        b = int(m.group(2)) if m.group(2) is not None else a
        if b < a:
            raise HeadlessError(f"--frames: {part} ends before it starts")
        frames += [f for f in range(a, b + 1) if f not in frames]
    return frames


def frame_path(out, frame):
    """The EXR of ``frame``: the run of '#' in ``out``'s name replaced by the frame number,
    zero-padded to its length, or ``_NNNN`` added before the suffix when there is none."""
    out = Path(out)
    if out.suffix.lower() != ".exr":
        raise HeadlessError(f"--out: expected a .exr file name, got {out}")
    m = re.search(r"#+", out.name)
    if m is None:
        return out.with_name(f"{out.stem}_{frame:04d}{out.suffix}")
    return out.with_name(out.name[:m.start()] + f"{frame:0{len(m.group(0))}d}" + out.name[m.end():])


def render_frame(blend, frame, out, spp=None, stream=None):
    """Render one frame to ``out`` atomically: to a temporary name in the same folder, then
    moved into place (the PNG first, the EXR last), so an existing EXR is a whole frame.
    Missing images or libraries fail the frame, naming the file. Returns the summary."""
    out = Path(out).absolute()
    tmp = out.with_name(f".{out.stem}.{uuid.uuid4().hex[:8]}.partial.exr")
    try:
        summary = render_blend(blend, tmp, spp=spp, stream=stream, frame=frame, require_files=True)
        os.replace(tmp.with_suffix(".png"), out.with_suffix(".png"))
        os.replace(tmp, out)
    finally:
        for p in (tmp, tmp.with_suffix(".png")):
            p.unlink(missing_ok=True)
    summary.update(exr=str(out), png=str(out.with_suffix(".png")), frame=int(frame))
    return summary


def frame_main(argv):
    """A farm task's process: ``BLEND FRAME OUT [SPP]``; prints the summary as JSON, or one error line."""
    blend, frame, out = argv[0], int(argv[1]), argv[2]
    spp = int(argv[3]) if len(argv) > 3 and argv[3] else None
    try:
        summary = render_frame(blend, frame, out, spp=spp)
    except HeadlessError as e:
        sys.stderr.write(f"spectral-gi: error: {e}\n")
        return 1
    except RuntimeError as e:
        sys.stderr.write(f"spectral-gi: error: {one_line(e)}\n")
        return 1
    print(json.dumps(summary))
    return 0


def frame_task(blend, frame, out, spp):
    """Runs on a farm worker: one frame in its own Python process (Blender as a module runs in
    a process's main thread, one scene at a time); HeadlessError with its one-line error."""
    package = __name__.rsplit(".addon.", 1)[0]
    code = f"import sys; from {package}.addon.headless import frame_main; sys.exit(frame_main(sys.argv[1:]))"
    proc = subprocess.run([sys.executable, "-c", code, str(blend), str(frame), str(out), str(spp or "")],
                          capture_output=True, text=True)
    if proc.returncode != 0:
        lines = [ln for ln in proc.stderr.splitlines() if ln.startswith("spectral-gi: error:")]
        text = lines[-1].removeprefix("spectral-gi: error: ") if lines else \
            one_line(proc.stderr[-500:]) or f"exit status {proc.returncode}"
        raise HeadlessError(f"frame {frame} on {socket.gethostname()}: {text}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def render_frames(blend, out, frames, spp=None, scheduler=None, stream=None):
    """Render ``frames`` of ``blend`` to ``frame_path(out, frame)``, skipping the frames whose
    EXR exists (a rerun renders what is missing). scheduler: None (here, one after another),
    or a Dask scheduler address / ``local:N`` (one task per frame; every machine must see
    the .blend, its files and the output folder at the same paths). Returns the summaries of
    the frames rendered, in frame order."""
    stream = stream or sys.stderr

    def say(text):
        stream.write(f"{text}\n")
        stream.flush()

    blend = check_blend_file(blend).absolute()
    paths = {f: frame_path(Path(out).absolute(), f) for f in frames}
    todo = [f for f in frames if not paths[f].is_file()]
    if len(todo) < len(frames):
        say(f"{len(frames) - len(todo)} of {len(frames)} frames already written, skipped")
    if todo:
        paths[todo[0]].parent.mkdir(parents=True, exist_ok=True)
    if scheduler is None:
        done = []
        for f in todo:
            done.append(render_frame(blend, f, paths[f], spp=spp, stream=stream))
        return done
    from ..core import Farm, FarmError

    results = {}
    with Farm(scheduler) as farm:
        import distributed

        futures = {farm.client.submit(frame_task, str(blend), f, str(paths[f]), spp, pure=False,
                                      key=f"spectral-gi-frame-{f}-{uuid.uuid4().hex[:8]}"): f for f in todo}
        try:
            for fut in distributed.as_completed(futures):
                f = futures[fut]
                if fut.status == "error":
                    exc = fut.exception()
                    raise HeadlessError(one_line(exc)) if isinstance(exc, (HeadlessError, FarmError)) else \
                        HeadlessError(f"frame {f}: {type(exc).__name__}: {one_line(exc)}")
                results[f] = fut.result()
                say(f"frame {f}: wrote {paths[f]} ({len(results)} of {len(todo)})")
        finally:
            farm.client.cancel([fu for fu in futures if not fu.done()])
    return [results[f] for f in todo]


def main(args):
    """Entry point for core/cli.py's ``render-blend`` (args: blend, out, spp, compare_cycles, json,
    frames, scheduler)."""
    out = args.out or (Path(args.blend).with_suffix("").name + ".exr")
    frames = getattr(args, "frames", None)
    scheduler = getattr(args, "scheduler", None)
    if frames is not None or scheduler is not None:
        if args.compare_cycles:
            raise HeadlessError("--compare-cycles compares one still render: not with --frames or --scheduler")
        if frames is None:
            raise HeadlessError("--scheduler: render-blend spreads frames over a farm; give --frames")
        done = render_frames(args.blend, out, parse_frames(frames), spp=args.spp, scheduler=scheduler)
        if args.json:
            from .operators.compare import write_json_atomic

            write_json_atomic(str(args.json), {"frames": done})
        print(json.dumps({"frames": [{k: d[k] for k in ("frame", "exr", "samples")} for d in done]}))
        return 0
    summary = render_blend(args.blend, out, spp=args.spp, compare_cycles=args.compare_cycles, json_path=args.json)
    print(json.dumps({k: summary[k] for k in ("exr", "png", "samples")}))
    return 0
