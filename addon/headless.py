"""``spectral-gi render-blend``: render a .blend file without Blender's interface.

Opens the file with the ``bpy`` module (Blender as a Python module), registers this
checkout's add-on (nothing is installed), exports the scene from the evaluated
depsgraph, renders it and writes OpenEXR + PNG, optionally with the Cycles comparison
(the code path of the "Compare with Cycles" operator).
"""
import json
import sys
import time
from pathlib import Path

BLEND_MAGIC = (b"BLENDER", b"\x28\xb5\x2f\xfd", b"\x1f\x8b")  # plain, zstd- and gzip-compressed .blend


class HeadlessError(Exception):
    """A problem the command reports in one line (missing file, not a .blend, no bpy, ...)."""


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


def render_blend(blend, out, spp=None, compare_cycles=False, json_path=None, stream=None):
    """Render ``blend`` to ``out`` (.exr, with a .png beside it). Returns a dict summary (also the JSON report)."""
    stream = stream or sys.stderr

    def say(text):
        stream.write(f"{text}\n")
        stream.flush()

    blend = check_blend_file(blend)
    out = Path(out)
    if out.suffix.lower() != ".exr":
        raise HeadlessError(f"--out: expected a .exr file name, got {out}")
    bpy = _import_bpy()
    from . import registration

    registration.register()  # idempotent: classes already registered are skipped
    try:
        bpy.ops.wm.open_mainfile(filepath=str(blend.resolve()), load_ui=False)
    except RuntimeError as exc:
        raise HeadlessError(f"{blend}: Blender cannot open it ({str(exc).strip()})") from None
    scene = bpy.context.scene
    depsgraph = bpy.context.evaluated_depsgraph_get()

    from ..core import write_exr, write_png
    from .export import ExportError
    from .operators.compare import compare_with_cycles, render_ours, write_json_atomic

    last = {"t": 0.0}

    def progress(done, total, rate):
        now = time.monotonic()
        if done >= total or now - last["t"] > 2.0:
            last["t"] = now
            say(f"{done}/{total} spp  {rate / 1e6:.2f} M samples/s")

    try:
        core_scene, film, stats, warning = render_ours(scene, depsgraph, spp, progress=progress, status=say)
    except ExportError as exc:
        raise HeadlessError(f"{blend}: {exc}") from None
    if warning:
        say(f"warning: {warning}")
    st = core_scene.settings
    dev = film.develop(colour_space=getattr(st, "colour_space", "rec709"))
    attrs = {"spectralgi.spp": str(stats.spp), "spectralgi.seed": str(st.seed),
             "spectralgi.maxDepth": str(st.max_depth), "spectralgi.blendFile": str(blend)}
    write_exr(out, dev, attrs)
    png = out.with_suffix(".png")
    write_png(png, dev.rgb)
    summary = {"blend_file": str(blend), "scene": scene.name, "exr": str(out), "png": str(png),
               "width": int(film.width), "height": int(film.height), "samples": int(stats.spp),
               "seconds": float(stats.seconds), "samples_per_second": float(stats.samples_per_second),
               "mean_luminance": float(dev.luminance.mean()), "luminance_unit": "cd/m2",
               "export_warning": warning}
    say(f"wrote {out} and {png}: {stats.spp} spp in {stats.seconds:.2f} s, "
        f"mean luminance {summary['mean_luminance']:.4g} cd/m²")
    if compare_cycles:
        report = compare_with_cycles(scene, depsgraph, out_dir=str(out.parent), ours=(core_scene, film),
                                     json_path=str(json_path) if json_path else None, log=say)
        summary["comparison"] = report
        say(f"Cycles comparison: luminance ratio {report['luminance_ratio']:.4f}, relative RMSE "
            f"{report['relative_rmse']:.4f}, ΔE00 mean {report['delta_e00_mean']:.2f}, "
            f"p95 {report['delta_e00_p95']:.2f} ({report['report_path']})")
        if json_path:  # the JSON holds the render summary too
            write_json_atomic(str(json_path), summary)
    elif json_path:
        write_json_atomic(str(json_path), summary)
    return summary


def main(args):
    """Entry point for core/cli.py's ``render-blend`` (args: blend, out, spp, compare_cycles, json)."""
    out = args.out or (Path(args.blend).with_suffix("").name + ".exr")
    summary = render_blend(args.blend, out, spp=args.spp, compare_cycles=args.compare_cycles, json_path=args.json)
    print(json.dumps({k: summary[k] for k in ("exr", "png", "samples")}))
    return 0
