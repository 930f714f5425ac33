"""The ``spectral-gi`` command line.

    spectral-gi render [SCENE] [--spp N] [--width W --height H] [--max-depth D]
                       [--seed S] [--threads T] [--out FILE.exr] [--exposure EV]
    spectral-gi render-blend SCENE.blend [--out FILE.exr] [--spp N] [--compare-cycles] [--json REPORT.json]
    spectral-gi lux [SCENE] --sensors POINTS.pts [--out lux.csv] [--spp N | --rel-error E]
                    [--max-depth D] [--seed S] [--threads T] [--method path|radiosity] [--max-edge M]
    spectral-gi save-default-scene OUT.json

Without SCENE it renders the built-in Cornell box. Bad input prints one line
``spectral-gi: error: ...`` and exits with status 2. Ctrl-C stops after the current
pass and writes what was rendered so far (exit status 130).
"""
from __future__ import annotations

import argparse
import os
import signal
import sys
import time
from pathlib import Path

EXIT_OK = 0
EXIT_ERROR = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130


class _Progress:
    """A one-line progress bar on stderr with samples per second."""

    def __init__(self, stream=sys.stderr, width=30):
        self.stream = stream
        self.width = width
        self.tty = stream.isatty()
        self.last = 0.0

    def status(self, text):
        self.stream.write(f"{text}\n")
        self.stream.flush()

    def __call__(self, done, total, rate):
        now = time.monotonic()
        if not self.tty and done < total and now - self.last < 2.0:
            return
        self.last = now
        frac = done / total if total else 1.0
        filled = int(round(frac * self.width))
        bar = "#" * filled + "-" * (self.width - filled)
        line = f"[{bar}] {done}/{total} spp  {rate / 1e6:6.2f} M samples/s"
        self.stream.write(("\r" if self.tty else "") + line + ("" if self.tty else "\n"))
        if self.tty and done >= total:
            self.stream.write("\n")
        self.stream.flush()


def _positive_int(text):
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {v}")
    return v


def _non_negative_int(text):
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if v < 0:
        raise argparse.ArgumentTypeError(f"expected zero or more, got {v}")
    return v


def _parser():
    p = argparse.ArgumentParser(prog="spectral-gi", description="Spectral path tracer with photometric output.")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("render", help="render a scene file (default: the Cornell box) to OpenEXR + PNG")
    r.add_argument("scene", nargs="?", help="scene file (.json with its .npz beside it) or scene folder")
    r.add_argument("--builtin", choices=("cornell", "colorchecker"),
                   help="render a built-in scene instead of a file (default: cornell)")
    r.add_argument("--light", help="emission spectrum of the built-in scene's light: blackbody:<K> or a CIE "
                                   "illuminant name (D65, A, F11, LED-B3, ...)")
    r.add_argument("--white-balance", default="none",
                   help="white balance of the RGB/PNG output: none (default), light (the scene's brightest "
                        "light), or x,y chromaticity; XYZ, Lab and Luv are never adapted")
    r.add_argument("--spp", type=_positive_int, help="samples per pixel (default: the scene's, 64 for the Cornell box)")
    r.add_argument("--width", type=_positive_int, help="image width in pixels")
    r.add_argument("--height", type=_positive_int, help="image height in pixels")
    r.add_argument("--max-depth", type=_non_negative_int,
                   help="maximum number of bounces, as Cycles' Max Bounces (0: direct light only; default 64)")
    r.add_argument("--seed", type=_non_negative_int, help="random seed")
    r.add_argument("--sampler", choices=("independent", "halton", "hammersley", "stratified"),
                   help="sample generator: independent random numbers; Owen-scrambled Halton or Hammersley "
                        "points per pixel; or stratified: Sobol (0, 2) pixel positions with a per-pixel digital "
                        "shift and Owen-scrambled Sobol pairs for the other dimensions (default: the scene's, "
                        "stratified)")
    r.add_argument("--time-limit", type=float, help="stop after this many seconds of rendering (default: the scene's; "
                                                    "0: none)")
    r.add_argument("--noise-target", type=float,
                   help="stop once the relative standard error of the image's mean luminance is at most this "
                        "(e.g. 0.002; default: the scene's; 0: none)")
    r.add_argument("--colour-space", "--color-space", dest="colour_space", choices=("rec709", "acescg", "xyz"),
                   help="colour space of the EXR's R, G, B channels: linear Rec.709, ACEScg (AP1) or CIE XYZ "
                        "(default: the scene's, rec709); the PNG preview is always sRGB")
    r.add_argument("--observer", choices=("1931", "1964"),
                   help="CIE standard observer of the film's XYZ: 1931 (2 degree) or 1964 (10 degree) "
                        "(default: the scene's, 1931); luminance always uses V(lambda)")
    r.add_argument("--threads", type=_non_negative_int, default=0, help="worker threads (0: all cores)")
    r.add_argument("--out", help="output OpenEXR file (default: cornell.exr or <scene>.exr); "
                                 "the sRGB PNG preview is written beside it")
    r.add_argument("--spectral-bins", type=_non_negative_int, default=0,
                   help="also write the spectral radiance in this many bins of 360-830 nm as "
                        "S0.<wavelength>nm channels (Fichet et al. 2021 layout; default 0: off)")
    r.add_argument("--exposure", type=float, default=0.0, help="exposure of the PNG preview in stops (default 0)")
    b = sub.add_parser("render-blend", help="render a .blend file with the bpy module (no Blender window) to "
                                            "OpenEXR + PNG, optionally compared with Cycles")
    b.add_argument("blend", help="the .blend file")
    b.add_argument("--out", help="output OpenEXR file (default: <blend name>.exr); the PNG is written beside it")
    b.add_argument("--spp", type=_positive_int, help="samples per pixel (default: the scene's Spectral GI setting)")
    b.add_argument("--compare-cycles", action="store_true",
                   help="also render with Cycles at matched settings and report luminance ratio, relative RMSE "
                        "and ΔE00 (images and report beside --out)")
    b.add_argument("--json", help="write a JSON report of the render (and the comparison) to this file")
    lx = sub.add_parser("lux", help="illuminance (lux) at sensor points, as Radiance's rtrace -I: a .pts file in, "
                                    "a CSV of lux and standard errors out")
    lx.add_argument("scene", nargs="?", help="scene file (.json with its .npz beside it) or scene folder")
    lx.add_argument("--builtin", choices=("cornell", "colorchecker"), help="a built-in scene instead of a file")
    lx.add_argument("--sensors",
                    help="points file: one point a line, 'x y z nx ny nz' in metres ('#' comments allowed); "
                         "without it, every calculation surface of the scene")
    lx.add_argument("--out", help="with --sensors: the results CSV (x,y,z,nx,ny,nz,lux,std_error; default: "
                                  "<points file>.csv); else the folder for each surface's CSV, JSON summary "
                                  "and report page (default: <scene>_lux)")
    stop = lx.add_mutually_exclusive_group()
    stop.add_argument("--spp", type=_positive_int, default=256, help="samples per point (default 256)")
    stop.add_argument("--rel-error", type=float,
                      help="stop each point at this relative standard error (at most 4096 samples a point)")
    lx.add_argument("--max-depth", type=_non_negative_int,
                    help="bounces after the first (default: unlimited, Russian roulette ends paths without bias)")
    lx.add_argument("--seed", type=_non_negative_int, help="random seed (default: the scene's)")
    lx.add_argument("--threads", type=_non_negative_int, default=0, help="worker threads (0: all cores)")
    lx.add_argument("--method", choices=("path", "radiosity"), default="path",
                    help="path: the path tracer (default); radiosity: a radiosity solution of the scene (diffuse "
                         "materials; others replaced by their albedo), direct light gathered at each point")
    lx.add_argument("--max-edge", type=float,
                    help="radiosity: patch size in m (default: 1/16 of the scene's largest extent)")
    s = sub.add_parser("save-default-scene", help="write the built-in Cornell box as a scene file")
    s.add_argument("out", help="output scene file (.json; the .npz is written beside it)")
    return p


def _white_balance(text, scene):
    """None, or the xy chromaticity the RGB output is balanced from."""
    from .core.scene import SceneError
    from .core.spectra.fit import emission_XYZ

    t = (text or "none").strip().lower()
    if t == "none":
        return None
    if t == "light":
        emitters = [(li.luminance, li.spectrum) for li in scene.lights]
        emitters += [(m.emission_luminance, m.emission) for m in scene.materials if m.emission >= 0]
        if not emitters:
            raise SceneError("--white-balance light: the scene has no light")
        _, s = max(emitters)
        XYZ = emission_XYZ(scene.spectra.coeffs[s])
        return (XYZ[0] / XYZ.sum(), XYZ[1] / XYZ.sum())
    try:
        x, y = (float(v) for v in t.split(","))
    except ValueError:
        raise SceneError(f"--white-balance: expected none, light or x,y; got {text!r}") from None
    if not (0 < x < 1 and 0 < y < 1 and x + y < 1):
        raise SceneError(f"--white-balance: ({x}, {y}) is not a chromaticity")
    return (x, y)


def _fail(msg, code=EXIT_USAGE):
    sys.stderr.write(f"spectral-gi: error: {msg}\n")
    return code


def _render(args):
    from .core import constants as C
    from .core.io.exr import write_render
    from .core.io.png import write_png
    from .core.integrators.render import render
    from .core.scene import SceneError, load, validate

    from .core.scene.builtin import BUILTIN_SCENES

    if args.scene and args.builtin:
        raise SceneError("give either a scene file or --builtin, not both")
    if args.scene:
        if args.light:
            raise SceneError("--light applies to built-in scenes only")
        scene = load(args.scene)
        default_out = Path(args.scene).with_suffix("").name + ".exr" if Path(args.scene).suffix else \
            Path(args.scene).name + ".exr"
    else:
        name = args.builtin or "cornell"
        if args.light and name == "cornell":
            raise SceneError("--light: the Cornell box keeps its measured light")
        scene = BUILTIN_SCENES[name](light=args.light) if args.light else BUILTIN_SCENES[name]()
        default_out = f"{name}.exr"
    white_balance = _white_balance(args.white_balance, scene)
    cam = scene.camera
    if args.width or args.height:
        if args.width and args.height:
            cam.width, cam.height = args.width, args.height
        elif args.width:  # keep the aspect ratio
            cam.height = max(1, round(cam.height * args.width / cam.width))
            cam.width = args.width
        else:
            cam.width = max(1, round(cam.width * args.height / cam.height))
            cam.height = args.height
    st = scene.settings
    if args.spp:
        st.spp = args.spp
    if args.max_depth is not None:
        st.max_depth = args.max_depth
    if args.seed is not None:
        st.seed = args.seed
    if args.sampler:
        st.sampler = {"independent": C.SAMPLER_INDEPENDENT, "halton": C.SAMPLER_HALTON,
                      "hammersley": C.SAMPLER_HAMMERSLEY,
                      "stratified": C.SAMPLER_STRATIFIED}[args.sampler]
    if args.time_limit is not None:
        st.time_limit = args.time_limit
    if args.noise_target is not None:
        st.noise_target = args.noise_target
    if getattr(args, "colour_space", None):
        st.colour_space = args.colour_space
    if getattr(args, "observer", None):
        st.observer = args.observer
    validate(scene)
    out = Path(args.out or default_out)
    if out.suffix.lower() != ".exr":
        raise SceneError(f"--out: expected a .exr file name, got {out}")
    png = out.with_suffix(".png")

    stop = {"requested": False}

    def on_sigint(signum, frame):
        if stop["requested"]:  # second Ctrl-C: leave at once
            os._exit(EXIT_INTERRUPTED)
        stop["requested"] = True
        sys.stderr.write("\nInterrupted: finishing the current pass and writing what was rendered "
                         "(Ctrl-C again to quit at once)\n")

    old = signal.signal(signal.SIGINT, on_sigint)
    bar = _Progress()
    try:
        bar.status(f"Rendering {scene.metadata.get('name', args.scene or 'scene')}: {cam.width}x{cam.height}, "
                   f"{st.spp} spp, max depth {st.max_depth}, {scene.n_triangles} triangles")
        film, stats = render(scene, threads=args.threads or None, progress=bar, status=bar.status,
                             should_cancel=lambda: stop["requested"], spectral_bins=args.spectral_bins)
    finally:
        signal.signal(signal.SIGINT, old)
    dev = film.develop(white_balance=white_balance, colour_space=st.colour_space)
    attrs = {"spectralgi.spp": str(stats.spp), "spectralgi.seed": str(st.seed),
             "spectralgi.maxDepth": str(st.max_depth)}
    spectral = (film.bin_centres(), film.spectral_radiance()) if film.spectral_bins else None
    write_render(out, dev, attrs, spectral=spectral)
    write_png(png, dev.rgb, args.exposure)
    sys.stderr.write(f"{stats.spp} spp in {stats.seconds:.2f} s ({stats.samples_per_second / 1e6:.2f} M samples/s"
                     f"; BVH {stats.build_seconds:.2f} s"
                     + (f", kernel compile {stats.compile_seconds:.1f} s" if stats.compile_seconds > 0.5 else "")
                     + f"); mean luminance {float(dev.luminance.mean()):.4g} cd/m²\n")
    print(f"wrote {out} and {png}")
    if stats.stop_reason in ("time_limit", "noise_target"):
        sys.stderr.write(f"stopped at {stats.spp} of {st.spp} spp: {stats.stop_reason.replace('_', ' ')} reached "
                         f"(relative error {stats.relative_error:.3g})\n")
    if stats.cancelled:
        sys.stderr.write(f"stopped early at {stats.spp} of {st.spp} spp\n")
        return EXIT_INTERRUPTED
    return EXIT_OK


def _lux(args):
    """``lux``: illuminance at the points of a ``.pts`` file, written as a CSV in input order."""
    import numpy as np

    from .core.integrators.illuminance import illuminance
    from .core.lux import calculate_pts_file
    from .core.scene import SceneError, load
    from .core.scene.builtin import BUILTIN_SCENES

    if args.scene and args.builtin:
        raise SceneError("give either a scene file or --builtin, not both")
    if not args.scene and not args.builtin:
        raise SceneError("give a scene file or --builtin")
    scene = load(args.scene) if args.scene else BUILTIN_SCENES[args.builtin]()
    if args.rel_error is not None and not 0.0 < args.rel_error < 1.0:
        raise SceneError(f"--rel-error must be in (0, 1), got {args.rel_error}")
    bar = _Progress()
    done = {"spp": 0}
    t0 = time.perf_counter()

    def progress(samples, total):
        bar(samples, total, samples / max(time.perf_counter() - t0, 1e-9))

    def estimate(sc, points, normals):
        lux, se, spp = illuminance(sc, points, normals, spp=4096 if args.rel_error else args.spp,
                                   rel_error=args.rel_error, max_depth=args.max_depth, seed=args.seed,
                                   threads=args.threads or None, progress=progress)
        done["spp"] = int(np.sum(spp))
        return lux, se

    if args.method == "radiosity":
        from .core.integrators.radiosity import lux_integrator

        if args.max_edge is not None and not args.max_edge > 0:
            raise SceneError(f"--max-edge must be a positive length in m, got {args.max_edge}")
        estimate = lux_integrator(max_edge=args.max_edge, seed=args.seed or 0, threads=args.threads or None)

    if args.sensors is None:
        stem = Path(args.scene).with_suffix("").name if args.scene else args.builtin
        return _lux_surfaces(scene, estimate, done, Path(args.out or f"{stem}_lux"), stem, t0)
    out = Path(args.out) if args.out else Path(args.sensors).with_suffix(".csv")
    lux, se = calculate_pts_file(estimate, scene, args.sensors, out)
    rel = np.where(lux > 0, se / np.where(lux > 0, lux, 1.0), 0.0)
    sys.stderr.write(f"{lux.size} points, {done['spp']} samples in {time.perf_counter() - t0:.1f} s; "
                     f"largest relative standard error {rel.max():.3g}; wrote {out}\n")
    return EXIT_OK


def _lux_surfaces(scene, estimate, done, out_dir, project, t0):
    """Every calculation surface of ``scene``: its CSV, JSON summary and (with matplotlib) report page."""
    import datetime

    from .core.lux import calculate_surface, render_report, statistics, write_summary_json, write_surface_csv
    from .core.lux.schedule import luminaire_schedule
    from .core.scene import SceneError

    if not scene.calculation_surfaces:
        raise SceneError("calculation_surfaces: the scene has none; give --sensors POINTS.pts")
    out_dir.mkdir(parents=True, exist_ok=True)
    schedule = luminaire_schedule(scene)
    date = datetime.date.today().isoformat()
    for s in scene.calculation_surfaces:
        lux, se = calculate_surface(estimate, scene, s)
        samples = max(1, done["spp"] // s.n_points)
        base = out_dir / s.name
        write_surface_csv(base.with_suffix(".csv"), s, lux, se)
        write_summary_json(base.with_suffix(".json"), s, lux, se, samples, schedule, project, date)
        st = statistics(s, lux, se, samples)
        page = ""
        try:
            render_report(s, lux, se, samples, schedule, project=project, date=date,
                          png_path=base.with_suffix(".png"), pdf_path=base.with_suffix(".pdf"))
            page = ", report page .png/.pdf"
        except ImportError as e:  # matplotlib (the analysis extra) is not installed
            page = f" (no report page: {e})"
        sys.stderr.write(f"{s.name}: {s.n_points} points, Ē {st.mean:.1f} lx, Emin {st.minimum:.1f} lx, "
                         f"Emax {st.maximum:.1f} lx, U0 {st.u0 if st.u0 is None else round(st.u0, 3)}; "
                         f"wrote {base}.csv, .json{page}\n")
    sys.stderr.write(f"{len(scene.calculation_surfaces)} surfaces in {time.perf_counter() - t0:.1f} s\n")
    return EXIT_OK


def _render_blend(args):
    """``render-blend``: handled by the add-on's headless driver (it needs bpy, which core never
    imports), imported only when the command runs."""
    from .addon import headless

    try:
        return headless.main(args)
    except headless.HeadlessError as e:
        return _fail(str(e), EXIT_ERROR)
    except RuntimeError as e:  # from Blender (e.g. a failed Cycles render)
        return _fail(" ".join(str(e).split()), EXIT_ERROR)


def main(argv=None):
    args = _parser().parse_args(argv)
    from .core.scene import SceneError

    try:
        if args.command == "render":
            return _render(args)
        if args.command == "render-blend":
            return _render_blend(args)
        if args.command == "lux":
            return _lux(args)
        if args.command == "save-default-scene":
            from .core.scene import save
            from .core.scene.builtin import cornell_box
            path = save(cornell_box(), args.out)
            print(f"wrote {path} and {path.with_suffix('.npz')}")
            return EXIT_OK
    except SceneError as e:
        return _fail(str(e))
    except (OSError, ValueError) as e:
        return _fail(str(e), EXIT_ERROR if isinstance(e, OSError) else EXIT_USAGE)
    return EXIT_USAGE


if __name__ == "__main__":
    sys.exit(main())
