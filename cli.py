"""The ``spectral-gi`` command line.

    spectral-gi render [SCENE] [--spp N] [--width W --height H] [--max-depth D]
                       [--seed S] [--threads T] [--out FILE.exr] [--exposure EV]
                       [--method path|radiosity] [--max-edge M] [--gather G]
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
import warnings
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


# Bounds of the numeric options (the scene's validation bounds what they set, these keep the
# option itself readable): whole numbers, plain decimal or scientific reals, no ``1_0``, ``nan``.
MAX_OPTION_INT = 1 << 32
MAX_THREADS = 4096
MAX_EXPOSURE = 64.0  # stops


def _bounded(parser, lo, hi, expected, what, show):
    """An argparse type: text read by ``core.io.strict.<parser>``, then checked to lie in [lo, hi]."""
    def parse(text):
        from .core.io import strict

        try:
            v = getattr(strict, parser)(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {expected}, got {text!r}") from None
        if not lo <= v <= hi:
            raise argparse.ArgumentTypeError(f"expected {what} in [{show(lo)}, {show(hi)}], got {show(v)}")
        return v

    return parse


def _int_in(lo, hi, what):
    return _bounded("parse_int", lo, hi, "a whole number", what, str)


def _float_in(lo, hi):
    return _bounded("parse_float", lo, hi, "a finite number", "a number", "{:g}".format)


_positive_int = _int_in(1, MAX_OPTION_INT, "a positive number")
_non_negative_int = _int_in(0, MAX_OPTION_INT, "zero or more")


def _spectral_bins(text):
    from .core.film import MAX_SPECTRAL_BINS

    return _int_in(0, MAX_SPECTRAL_BINS, "a number of bins (at most one per nanometre of 360-830 nm)")(text)


class _Parser(argparse.ArgumentParser):
    """argparse with one line for a usage error: ``spectral-gi render: error: ...`` (status 2)."""

    def error(self, message):
        self.exit(EXIT_USAGE, f"spectral-gi: error: {' '.join(message.split())} (see {self.prog} --help)\n")


MKDIR_HELP = "create the output's folder if it does not exist (without it, a missing folder is an error)"


def _version():
    """The installed distribution's version, else the extension manifest's (a checkout or Blender)."""
    from importlib import metadata

    try:
        return metadata.version("spectral-gi")
    except metadata.PackageNotFoundError:
        import tomllib

        manifest = Path(__file__).resolve().parent / "blender_manifest.toml"
        with open(manifest, "rb") as f:
            return tomllib.load(f)["version"]


def _out_folder(path, mkdir, option="--out"):
    """Check, before any work, that the folder ``path`` is written into exists (or make it
    with ``--mkdir``), so that a long render does not end in a missing folder."""
    from .core.scene import SceneError

    folder = Path(path).absolute().parent
    if folder.is_dir():
        return
    if folder.exists():
        raise SceneError(f"{option}: {folder} is not a folder")
    if not mkdir:
        raise SceneError(f"{option}: the folder {folder} does not exist (give --mkdir to create it)")
    folder.mkdir(parents=True, exist_ok=True)
SCHEDULER_HELP = ("render on a Dask farm: tcp://host:8786 (a running scheduler) or local:N (N worker processes "
                  "started here); the image is the same as a local render's. Needs pip install "
                  "\"spectral-gi[farm]\"")


def _parser():
    p = _Parser(prog="spectral-gi", description="Spectral path tracer with photometric output.")
    p.add_argument("--version", action="version", version=f"spectral-gi {_version()}")
    sub = p.add_subparsers(dest="command", parser_class=_Parser)
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
    r.add_argument("--time-limit", type=_float_in(0.0, 1e9),
                   help="stop after this many seconds of rendering (default: the scene's; 0: none)")
    r.add_argument("--noise-target", type=_float_in(0.0, 1e6),
                   help="adaptive sampling: after Cycles' minimum samples, a pixel stops receiving samples once "
                        "its relative standard error of luminance, and its neighbours', is at most this (e.g. "
                        "0.05; default: the scene's; 0: none)")
    r.add_argument("--colour-space", "--color-space", dest="colour_space", choices=("rec709", "acescg", "xyz"),
                   help="colour space of the EXR's R, G, B channels: linear Rec.709, ACEScg (AP1) or CIE XYZ "
                        "(default: the scene's, rec709); the PNG preview is always sRGB")
    r.add_argument("--observer", choices=("1931", "1964"),
                   help="CIE standard observer of the film's XYZ: 1931 (2 degree) or 1964 (10 degree) "
                        "(default: the scene's, 1931); luminance always uses V(lambda)")
    r.add_argument("--threads", type=_int_in(0, MAX_THREADS, "a thread count"), default=0,
                   help="worker threads (0: all cores)")
    r.add_argument("--resume", metavar="FILM.npz",
                   help="continue from a film checkpoint (one a failed write kept) of the same scene and options, "
                        "up to the scene's spp, and write its image")
    r.add_argument("--out", help="output OpenEXR file (default: cornell.exr or <scene>.exr); "
                                 "the sRGB PNG preview is written beside it")
    r.add_argument("--mkdir", action="store_true", help=MKDIR_HELP)
    r.add_argument("--spectral-bins", type=_spectral_bins, default=0,
                   help="also write the spectral radiance in this many bins of 360-830 nm as "
                        "S0.<wavelength>nm channels (Fichet et al. 2021 layout; default 0: off)")
    r.add_argument("--exposure", type=_float_in(-MAX_EXPOSURE, MAX_EXPOSURE), default=0.0,
                   help="exposure of the PNG preview in stops (default 0)")
    r.add_argument("--scheduler", metavar="ADDRESS", help=SCHEDULER_HELP)
    r.add_argument("--batch-spp", type=_positive_int,
                   help="with --scheduler: samples per farm task, a multiple of 16 (default 16)")
    r.add_argument("--checkpoint", metavar="FILE.npz",
                   help="save the film to this file as it renders (after each farm batch; locally every 10 s) "
                        "and resume from it when it exists")
    r.add_argument("--denoise", action="store_true",
                   help="denoise the colour image (R, G, B and the PNG) with OpenImageDenoise, guided by the film's "
                        "albedo and normals (needs the pyoidn package); XYZ, Luminance, xyY, Lab and Luv stay the "
                        "renderer's unbiased estimates")
    r.add_argument("--method", choices=("path", "radiosity"), default="path",
                   help="path: the path tracer (default); radiosity: a radiosity solution of the scene (diffuse "
                        "materials; others replaced by their albedo) rendered by final gather: the path tracer's "
                        "first bounce, exact direct light and gather rays reading the solution")
    r.add_argument("--max-edge", type=_float_in(1e-6, 1e9),
                   help="radiosity: patch size in m (default: the size that cuts the scene into about 2500 "
                        "patches)")
    r.add_argument("--gather", type=_positive_int, default=64,
                   help="radiosity: gather rays per camera sample (default 64)")
    b = sub.add_parser("render-blend", help="render a .blend file with the bpy module (no Blender window) to "
                                            "OpenEXR + PNG, optionally compared with Cycles")
    b.add_argument("blend", help="the .blend file")
    b.add_argument("--out", help="output OpenEXR file (default: <blend name>.exr); the PNG is written beside it")
    b.add_argument("--mkdir", action="store_true", help=MKDIR_HELP)
    b.add_argument("--spp", type=_positive_int, help="samples per pixel (default: the scene's Spectral GI setting)")
    b.add_argument("--compare-cycles", action="store_true",
                   help="also render with Cycles at matched settings and report luminance ratio, relative RMSE "
                        "and ΔE00 (images and report beside --out)")
    b.add_argument("--json", help="write a JSON report of the render (and the comparison) to this file")
    b.add_argument("--frames", help="render these frames (N, A-B or a list, e.g. 1-24): --out's run of '#' (or "
                                    "_NNNN before .exr) takes the frame number; frames already written are skipped")
    b.add_argument("--scheduler", metavar="ADDRESS", help=SCHEDULER_HELP + " (with --frames: one task per frame)")
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
    lx.add_argument("--mkdir", action="store_true", help=MKDIR_HELP)
    stop = lx.add_mutually_exclusive_group()
    stop.add_argument("--spp", type=_positive_int, default=256, help="samples per point (default 256)")
    stop.add_argument("--rel-error", type=_float_in(0.0, 1.0),
                      help="stop each point at this relative standard error (at most 4096 samples a point)")
    lx.add_argument("--max-depth", type=_non_negative_int,
                    help="bounces after the first (default: unlimited, Russian roulette ends paths without bias)")
    lx.add_argument("--seed", type=_non_negative_int, help="random seed (default: the scene's)")
    lx.add_argument("--threads", type=_int_in(0, MAX_THREADS, "a thread count"), default=0,
                    help="worker threads (0: all cores)")
    lx.add_argument("--scheduler", metavar="ADDRESS", help=SCHEDULER_HELP + " (the points split across workers)")
    lx.add_argument("--method", choices=("path", "radiosity"), default="path",
                    help="path: the path tracer (default); radiosity: a radiosity solution of the scene (diffuse "
                         "materials; others replaced by their albedo), direct light gathered at each point")
    lx.add_argument("--max-edge", type=float,
                    help="radiosity: patch size in m (default: the size that cuts the scene into about 2500 "
                         "patches)")
    s = sub.add_parser("save-default-scene", help="write the built-in Cornell box as a scene file")
    s.add_argument("out", help="output scene file (.json; the .npz is written beside it)")
    s.add_argument("--mkdir", action="store_true", help=MKDIR_HELP)
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


class _Stop:
    """Ctrl-C (SIGINT) and SIGTERM. Before a render starts (start-up, reading the scene) and in
    the other commands they interrupt at once (nothing is written, temporary files are
    removed). While rendering (compiling included), the first stops the render after the
    current pass and what was rendered is written; a second one quits at once. While the
    output is written, signals wait for the write to finish (so a finished render is never
    thrown away and no temporary file is left behind)."""

    def __init__(self):
        self.requested = False
        self.mode = "raise"  # "raise", "cancel" (rendering) or "write"
        self.old = {}

    def install(self):
        for sig in (signal.SIGINT, signal.SIGTERM):
            try:
                self.old[sig] = signal.signal(sig, self)
            except (ValueError, OSError):  # not the main thread, or no such signal here
                pass
        return self

    def restore(self):
        for sig, handler in self.old.items():
            signal.signal(sig, handler)
        self.old = {}

    def __call__(self, signum, frame):
        if self.mode == "raise":
            raise KeyboardInterrupt
        if self.mode == "write":
            sys.stderr.write("\nInterrupted: the output is being written and will be complete\n")
            self.requested = True
            return
        if self.requested:  # a second signal: leave at once
            os._exit(EXIT_INTERRUPTED)
        self.requested = True
        sys.stderr.write("\nInterrupted: finishing the current pass and writing what was rendered "
                         "(Ctrl-C again to quit at once)\n")


def _keep_film(film, out):
    """Save ``film`` as a checkpoint beside ``out``, else in a new folder of the temporary
    folder; its path, or None when neither can be written."""
    import tempfile

    try:
        return film.save(out.with_name(out.stem + ".film.npz"))
    except Exception:
        pass
    try:
        return film.save(Path(tempfile.mkdtemp(prefix="spectral-gi-")) / (out.stem + ".film.npz"))
    except Exception:
        return None


def _resume_hint(args, out, kept):
    scene = args.scene if args.scene else f"--builtin {args.builtin or 'cornell'}"
    return f"spectral-gi render {scene} --resume {kept} --out {out} (with the same options)"


def _render(args, stop):
    from .core import constants as C
    from .core.film import Film
    from .core.io.atomic import atomic_paths
    from .core.io.exr import write_render
    from .core.io.png import write_png
    from .core.integrators.render import check_render_inputs, render
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
    if args.denoise:
        from .core import denoise_available
        from .core.film.denoise import PACKAGE

        if not denoise_available():
            raise SceneError(f"--denoise needs Intel Open Image Denoise's Python binding: pip install {PACKAGE}")
    out = Path(args.out or default_out)
    if out.suffix.lower() != ".exr":
        raise SceneError(f"--out: expected a .exr file name, got {out}")
    _out_folder(out, args.mkdir)
    png = out.with_suffix(".png")
    resume = None
    bins = args.spectral_bins

    def load_film(path, option, what):
        try:
            film = Film.load(path)
        except ValueError as e:
            raise SceneError(f"{option}: {e}") from None
        if bins and bins != film.spectral_bins:
            raise SceneError(f"--spectral-bins {bins}: {what} has {film.spectral_bins} spectral bins")
        return film

    if args.resume:
        resume, bins = load_film(args.resume, "--resume", "the film to resume"), 0
    if resume is None and args.checkpoint and Path(args.checkpoint).is_file():
        resume, bins = load_film(args.checkpoint, "--checkpoint", "the checkpoint"), 0
    if args.method == "radiosity":
        for flag, given in (("--resume", args.resume), ("--checkpoint", args.checkpoint),
                            ("--scheduler", args.scheduler), ("--spectral-bins", bins), ("--denoise", args.denoise),
                            ("--time-limit", args.time_limit), ("--noise-target", args.noise_target)):
            if given:
                raise SceneError(f"{flag}: not available with --method radiosity")
        return _render_radiosity(args, stop, scene, out, png, white_balance)
    if args.max_edge is not None:
        raise SceneError("--max-edge applies to --method radiosity")
    check_render_inputs(scene, bins, resume)  # before anything is printed: one line if it fails
    bar = _Progress()
    title = scene.metadata.get("name", args.scene or "scene")
    title = title if isinstance(title, str) else str(args.scene or "scene")
    bar.status(f"Rendering {title[:200]}: {cam.width}x{cam.height}, "
               f"{st.spp} spp, max depth {st.max_depth}, {scene.n_triangles} triangles"
               + (f", resuming at {resume.spp} spp" if resume is not None else ""))
    stop.mode = "cancel"
    film, stats = render(scene, threads=args.threads or None, progress=bar, status=bar.status,
                         should_cancel=lambda: stop.requested, spectral_bins=bins, resume=resume,
                         client=args.scheduler, batch_spp=args.batch_spp, checkpoint=args.checkpoint)
    stop.mode = "write"  # from here on, a signal no longer cuts the write short
    if stats.spp == 0:
        sys.stderr.write("spectral-gi: interrupted before any sample was rendered; nothing written\n")
        return EXIT_INTERRUPTED
    try:
        dev = film.develop(white_balance=white_balance, colour_space=st.colour_space)
        attrs = {"spectralgi.spp": str(stats.spp), "spectralgi.seed": str(st.seed),
                 "spectralgi.maxDepth": str(st.max_depth)}
        if args.denoise and stats.spp > 0:
            dev = _denoised(dev, attrs)
        spectral = (film.bin_centres(), film.spectral_radiance()) if film.spectral_bins else None
        with atomic_paths([out, png]) as (tmp_exr, tmp_png):  # both files or neither
            write_render(tmp_exr, dev, attrs, spectral=spectral)
            write_png(tmp_png, dev.rgb, args.exposure)
    except Exception as e:
        kept = _keep_film(film, out)
        why = _one_line(e)
        if kept is None:
            return _fail(f"cannot write {out} and {png.name} ({why}); the render could not be kept either",
                         EXIT_ERROR)
        return _fail(f"cannot write {out} and {png.name} ({why}); the rendered film ({stats.spp} spp) is kept "
                     f"in {kept}: write it with {_resume_hint(args, out, kept)}", EXIT_ERROR)
    sys.stderr.write(f"{stats.spp} spp in {stats.seconds:.2f} s ({stats.samples_per_second / 1e6:.2f} M samples/s"
                     f"; BVH {stats.build_seconds:.2f} s"
                     + (f", kernel compile {stats.compile_seconds:.1f} s" if stats.compile_seconds > 0.5 else "")
                     + f"); mean luminance {float(dev.luminance.mean()):.4g} cd/m²\n")
    print(f"wrote {out} and {png}")
    import numpy as np

    bad = int(np.count_nonzero(~np.isfinite(dev.luminance)))
    if bad:  # validation bounds every input so that this cannot happen; if it does, it is not silent
        sys.stderr.write(f"spectral-gi: warning: {bad} pixels are not finite (NaN or Inf) in {out}\n")
    if stats.dropped_samples:  # as above: left out of their pixels' means, and said
        sys.stderr.write(f"spectral-gi: warning: {stats.dropped_samples} samples were not finite (NaN or Inf) "
                         "and were left out of their pixels\n")
    if stats.stop_reason in ("time_limit", "noise_target"):
        sys.stderr.write(f"stopped at {stats.spp} of {st.spp} spp: {stats.stop_reason.replace('_', ' ')} reached "
                         f"(relative error {stats.relative_error:.3g})\n")
    if stats.skipped_samples:
        total = stats.spp * film.width * film.height
        sys.stderr.write(f"adaptive sampling: {stats.skipped_samples / total:.0%} of the {total} samples were not "
                         "needed (converged pixels)\n")
    if stats.cancelled:
        sys.stderr.write(f"stopped early at {stats.spp} of {st.spp} spp\n")
        return EXIT_INTERRUPTED
    if stop.requested:
        sys.stderr.write("interrupted while writing; the output is complete\n")
        return EXIT_INTERRUPTED
    return EXIT_OK


def _render_radiosity(args, stop, scene, out, png, white_balance):
    """``render --method radiosity``: solve, final gather, and the same EXR and PNG outputs."""
    from .core.integrators.radiosity import render_radiosity
    from .core.io.atomic import atomic_paths
    from .core.io.exr import write_render
    from .core.io.png import write_png

    st = scene.settings
    bar = _Progress()
    bar.status(f"Rendering by radiosity and final gather: {scene.camera.width}x{scene.camera.height}, {st.spp} spp, "
               f"{args.gather} gather rays a sample, {scene.n_triangles} triangles")
    stop.mode = "cancel"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        film, stats, sol = render_radiosity(scene, max_edge=args.max_edge, gather=args.gather,
                                            threads=args.threads or None, progress=bar, status=bar.status,
                                            should_cancel=lambda: stop.requested)
    for w in caught:
        sys.stderr.write(f"spectral-gi: warning: {w.message}\n")
    stop.mode = "write"
    if stats.cancelled or film.spp == 0:
        sys.stderr.write("spectral-gi: interrupted; nothing written\n")
        return EXIT_INTERRUPTED
    try:
        dev = film.develop(white_balance=white_balance, colour_space=st.colour_space)
        attrs = {"spectralgi.spp": str(stats.spp), "spectralgi.seed": str(st.seed),
                 "spectralgi.method": "radiosity", "spectralgi.patches": str(sol.patches.n),
                 "spectralgi.gather": str(args.gather)}
        with atomic_paths([out, png]) as (tmp_exr, tmp_png):  # both files or neither
            write_render(tmp_exr, dev, attrs)
            write_png(tmp_png, dev.rgb, args.exposure)
    except Exception as e:
        return _fail(f"cannot write {out} and {png.name} ({_one_line(e)})", EXIT_ERROR)
    sys.stderr.write(f"radiosity: {sol.patches.n} patches in {stats.build_seconds:.2f} s; final gather {stats.spp} "
                     f"spp in {stats.seconds:.2f} s; mean luminance {float(dev.luminance.mean()):.4g} cd/m²\n")
    print(f"wrote {out} and {png}")
    if stop.requested:
        sys.stderr.write("interrupted while writing; the output is complete\n")
        return EXIT_INTERRUPTED
    return EXIT_OK


def _one_line(e):
    text = " ".join(str(e).split()) or type(e).__name__
    if isinstance(e, OSError) and e.strerror:
        text = e.strerror + (f": {e.filename}" if e.filename else "")
    return text[:500]


def _denoised(dev, attrs):
    """``dev`` with its colour image (rgb, and output unless it is XYZ) denoised; the measurements untouched."""
    import dataclasses

    from .core import denoise

    rgb = denoise(dev.rgb, dev.albedo, dev.normal)
    output = rgb if dev.output is dev.rgb else dev.output
    if dev.colour_space == "acescg":
        output = denoise(dev.output, dev.albedo, dev.normal)
    attrs["spectralgi.denoised"] = ("R,G,B" if dev.colour_space != "xyz" else "PNG only") + \
        " (OpenImageDenoise, albedo and normal guides)"
    return dataclasses.replace(dev, rgb=rgb, output=output)


def _lux(args):
    """``lux``: illuminance at the points of a ``.pts`` file, written as a CSV in input order."""
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
    farm = None
    if args.scheduler:  # one farm for every surface's points
        from .core.farm import Farm

        farm = Farm(args.scheduler)
    try:
        return _lux_run(args, scene, bar, done, t0, farm)
    finally:
        if farm is not None:
            farm.close()


def _lux_run(args, scene, bar, done, t0, farm):
    import numpy as np

    from .core.integrators.illuminance import illuminance
    from .core.integrators.unlit import unlit_points
    from .core.lux import calculate_pts_file, read_pts

    def progress(samples, total):
        bar(samples, total, samples / max(time.perf_counter() - t0, 1e-9))

    def estimate(sc, points, normals):
        import warnings

        from .core.integrators.illuminance import NonFiniteSamples

        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always", NonFiniteSamples)
            lux, se, spp = illuminance(sc, points, normals, spp=4096 if args.rel_error else args.spp,
                                       rel_error=args.rel_error, max_depth=args.max_depth, seed=args.seed,
                                       threads=args.threads or None, progress=progress, client=farm)
        for w in said:  # one line each (validated input cannot produce them)
            if issubclass(w.category, NonFiniteSamples):
                sys.stderr.write(f"spectral-gi: warning: {w.message}\n")
            else:
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        done["spp"] = int(np.sum(spp))
        return lux, se

    if args.method == "radiosity":
        import math

        from .core.integrators.radiosity import lux_integrator
        from .core.scene import SceneError

        if farm is not None:
            raise SceneError("--scheduler: the radiosity method runs on this machine; leave out --scheduler")
        if args.max_edge is not None and not (args.max_edge > 0 and math.isfinite(args.max_edge)):
            raise SceneError(f"--max-edge must be a positive length in m, got {args.max_edge}")
        estimate = lux_integrator(max_edge=args.max_edge, seed=args.seed or 0, threads=args.threads or None,
                                  progress=_RadiosityProgress(t0))

    if args.sensors is None:
        stem = Path(args.scene).with_suffix("").name if args.scene else args.builtin
        out_dir = Path(args.out or f"{stem}_lux")
        _out_folder(out_dir, args.mkdir)
        return _lux_surfaces(scene, estimate, done, out_dir, stem, t0)
    out = Path(args.out) if args.out else Path(args.sensors).with_suffix(".csv")
    _out_folder(out, args.mkdir)
    lux, se = calculate_pts_file(estimate, scene, args.sensors, out)
    rel = np.where(lux > 0, se / np.where(lux > 0, lux, 1.0), 0.0)
    sys.stderr.write(f"{lux.size} points, {done['spp']} samples in {time.perf_counter() - t0:.1f} s; "
                     f"largest relative standard error {rel.max():.3g}; wrote {out}\n")
    points, normals = read_pts(args.sensors)
    _warn_unlit(unlit_points(scene, points, normals, lux, se), "points (0-based, in file order)")
    return EXIT_OK


UNLIT_SHOWN = 10  # point indices named in the warning line


def _warn_unlit(unlit, what):
    """One warning line on stderr naming the points outside the lit geometry, if any."""
    line = unlit.warning(UNLIT_SHOWN, what)
    if line:
        sys.stderr.write(f"warning: {line}\n")


class _RadiosityProgress:
    """``lux --method radiosity``: the stages of the solve on stderr, one line each (on a
    terminal the running stage rewrites its line; otherwise at most one line every two
    seconds per stage, and its last)."""

    def __init__(self, t0, stream=sys.stderr):
        self.t0 = t0
        self.stream = stream
        self.tty = stream.isatty()
        self.stage = None
        self.last = 0.0

    def __call__(self, stage, a, b):
        now = time.monotonic()
        t = time.perf_counter() - self.t0
        if stage == "patches":
            text, final = f"radiosity: {a} patches" + (f" (max edge {b:.3g} m)" if b else ""), True
        elif stage == "direct":
            text, final = f"radiosity: direct light at {a} patches", True
        elif stage == "form factors":
            text, final = f"radiosity: form factors, {a}/{b} rows", a >= b
        elif stage == "solve":
            text, final = f"radiosity: solve, iteration {a}, residual {b:.3g}", False
        else:
            text, final = f"radiosity: {stage} at {a} points", True
        new = stage != self.stage
        if not (self.tty or new or final or now - self.last >= 2.0):
            return
        if self.tty and not new and self.stage is not None:
            self.stream.write("\r")
        elif self.tty and self.stage is not None:
            self.stream.write("\n")
        self.stream.write(f"{text}  [{t:.1f} s]" + ("" if self.tty else "\n"))
        self.stream.flush()
        self.stage = stage
        self.last = now
        if self.tty and stage == "gather":
            self.stream.write("\n")
            self.stage = None


def _lux_surfaces(scene, estimate, done, out_dir, project, t0):
    """Every calculation surface of ``scene``: its CSV, JSON summary and (with matplotlib) report page."""
    import datetime

    from .core.integrators.unlit import unlit_points
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
        unlit = unlit_points(scene, s.points, s.normals, lux, se)
        write_summary_json(base.with_suffix(".json"), s, lux, se, samples, schedule, project, date,
                           unlit=unlit.to_dict())
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
        _warn_unlit(unlit, f"points of {s.name} (0-based, in its CSV's order)")
    sys.stderr.write(f"{len(scene.calculation_surfaces)} surfaces in {time.perf_counter() - t0:.1f} s\n")
    return EXIT_OK


def _render_blend(args):
    """``render-blend``: handled by the add-on's headless driver (it needs bpy, which core never
    imports), imported only when the command runs."""
    from .addon import headless

    if args.out:
        _out_folder(args.out, args.mkdir)
    try:
        return headless.main(args)
    except headless.HeadlessError as e:
        return _fail(str(e), EXIT_ERROR)
    except RuntimeError as e:  # from Blender (e.g. a failed Cycles render)
        return _fail(" ".join(str(e).split()), EXIT_ERROR)


def main(argv=None):
    """Run the command line; every failure ends in one line on stderr and an exit status
    (2 bad input, 1 a failed write or an internal error, 130 interrupted)."""
    stop = _Stop().install()
    try:
        return _main(argv, stop)
    except KeyboardInterrupt:
        sys.stderr.write("spectral-gi: interrupted (no file is left half-written)\n")
        return EXIT_INTERRUPTED
    finally:
        stop.restore()


def _main(argv, stop):
    parser = _parser()
    args = parser.parse_args(argv)
    from .core.farm import FarmError
    from .core.scene import SceneError

    if args.command is None:  # bare ``spectral-gi``: what it can do
        parser.print_help()
        return EXIT_OK
    try:
        if args.command == "render":
            return _render(args, stop)
        if args.command == "render-blend":
            return _render_blend(args)
        if args.command == "lux":
            return _lux(args)
        if args.command == "save-default-scene":
            from .core.scene import save
            from .core.scene.builtin import cornell_box
            _out_folder(args.out, args.mkdir, "OUT")
            path = save(cornell_box(), args.out)
            print(f"wrote {path} and {path.with_suffix('.npz')}")
            return EXIT_OK
    except SceneError as e:
        return _fail(_one_line(e))
    except FarmError as e:
        return _fail(" ".join(str(e).split()), EXIT_ERROR)
    except MemoryError:
        return _fail("not enough memory for this render (try a smaller resolution or fewer spectral bins)",
                     EXIT_ERROR)
    except RecursionError:
        return _fail("the input nests too deeply", EXIT_USAGE)
    except (OSError, ValueError) as e:
        return _fail(_one_line(e), EXIT_ERROR if isinstance(e, OSError) else EXIT_USAGE)
    except Exception as e:  # an internal error: one line, the traceback only on request
        if os.environ.get("SPECTRAL_GI_DEBUG"):
            raise
        return _fail(f"internal error ({type(e).__name__}: {_one_line(e)}); set SPECTRAL_GI_DEBUG=1 for the "
                     "traceback", EXIT_ERROR)
    return EXIT_USAGE


if __name__ == "__main__":
    sys.exit(main())
