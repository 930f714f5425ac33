"""The speed race: this renderer against Cycles and Mitsuba 3 on the Cornell box.

    python benchmarks/race.py [--spp 256] [--bounces 4] [--size 256] [--threads 2] [--rounds 2]
                              [--seconds 10] [--rmse-size 128] [--skip speed,rmse,overhead]

Three measurements, each printed with its figures and ratios:

1. **Speed**: Cornell box (the add-on's *Add Cornell Box*, Lambertian walls), 256×256,
   256 spp, max bounces 4 (Cycles' default diffuse limit): wall time and samples/s of
   this renderer (export + BVH + render, kernels already compiled), Cycles (CPU, no
   denoising, adaptive sampling or clamping; its scene sync included) and Mitsuba 3
   ``llvm_ad_spectral`` from PyPI (benchmarks/peers.py; max_depth = bounces + 2, which
   facts.md measured to be the same path length; the warm render is timed, its first
   render including Dr.Jit's compilation is printed too). Mitsuba renders the core's
   own Cornell box (same published geometry and spectra). Targets: ≥ Mitsuba's
   samples/s and ≥ 2× Cycles'. This renderer and Cycles run ``--rounds`` times each in
   alternating order (ours, Cycles, Cycles, ours, ...), so a drift of the machine's
   speed during the race strikes both alike; every run is printed and the ratio uses
   each renderer's fastest run (on a shared machine the fastest run is the one least
   disturbed by other work).
2. **Equal-time quality**: each renderer renders for ``--seconds`` (time limit) at
   ``--rmse-size``²; the relative RMSE of luminance, sqrt(mean((Y − Y_ref)²)) / mean(Y_ref),
   is taken against that renderer's own converged reference (8× the samples reached in
   the timed run; its residual noise inflates both figures by about 6 %). Each is
   compared with its own reference because spectral and RGB rendering legitimately
   differ a little on coloured interreflections. Target: lower than Cycles'.
3. **Spectral overhead**: the core's Cornell box with all reflectances uplifted colours
   vs all grey (the same mean reflectance). Target: colours add ≤ 30 % to the time.
"""
import argparse
import os
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import cornell_vs_cycles as cvc  # noqa: E402
import peers  # noqa: E402

REC709_Y = np.array([0.2126, 0.7152, 0.0722])
SAMPLER = None  # --sampler: this renderer's sampler (None: the exported scene's, the add-on's default stratified)


def _ours(scene_bpy, spp, bounces, threads, size, time_limit=0.0):
    import bpy

    from spectral_gi import core
    from spectral_gi.addon.export import export_scene

    scene_bpy.render.resolution_x = scene_bpy.render.resolution_y = size
    t0 = time.perf_counter()
    sc = export_scene(bpy.context.evaluated_depsgraph_get()).scene
    sc.settings.spp = spp
    sc.settings.max_depth = bounces
    sc.settings.time_limit = float(time_limit)
    if SAMPLER is not None:
        sc.settings.sampler = SAMPLER
    film, stats = core.render(sc, threads=threads)
    return time.perf_counter() - t0, film, stats


def _cycles(scene_bpy, spp, bounces, threads, size, path):
    scene_bpy.render.resolution_x = scene_bpy.render.resolution_y = size
    t = cvc.render_cycles(scene_bpy, spp, bounces, threads, path)
    return t, cvc.read_rgb(path)


def speed(args, scene_bpy, tmp):
    from spectral_gi import core

    px = args.size * args.size
    samples = px * args.spp
    runs_ours, runs_cyc = [], []
    for r in range(max(1, args.rounds)):
        for who in (("ours", "cycles") if r % 2 == 0 else ("cycles", "ours")):
            if who == "ours":
                runs_ours.append(_ours(scene_bpy, args.spp, args.bounces, args.threads, args.size))
            else:
                runs_cyc.append(_cycles(scene_bpy, args.spp, args.bounces, args.threads, args.size,
                                        os.path.join(tmp, "c.exr")))
    t_ours, film, stats = min(runs_ours, key=lambda run: run[0])
    t_cyc, cyc = min(runs_cyc, key=lambda run: run[0])
    ours_rgb = film.develop().rgb
    print(f"[speed] Cornell box {args.size}x{args.size}, {args.spp} spp, max bounces {args.bounces}, "
          f"{args.threads} threads")
    print(f"  spectral-gi        : {t_ours:8.2f} s  {samples / t_ours / 1e6:6.3f} M samples/s "
          f"(render {stats.seconds:.2f} s = {stats.samples_per_second / 1e6:.3f} M/s, BVH {stats.build_seconds:.2f} s)")
    print(f"  Cycles             : {t_cyc:8.2f} s  {samples / t_cyc / 1e6:6.3f} M samples/s")
    if len(runs_ours) > 1:
        print("  every run (s), in the order run: spectral-gi " + ", ".join(f"{run[0]:.2f}" for run in runs_ours)
              + "; Cycles " + ", ".join(f"{run[0]:.2f}" for run in runs_cyc))
    print(f"  ratio spectral-gi/Cycles samples/s: {t_cyc / t_ours:.2f}x (target >= 2)")
    print(f"  mean luminance spectral-gi / Cycles: "
          f"{(ours_rgb @ REC709_Y).mean() / (cyc @ REC709_Y).mean():.4f}")
    try:
        ref = core.cornell_box(args.size, args.size)
        times, mimg = peers.render_mitsuba(ref, args.spp, args.bounces + 2, threads=args.threads)
        t_m = times["warm"]
        print(f"  Mitsuba {times['variant']}: {t_m:8.2f} s  {samples / t_m / 1e6:6.3f} M samples/s "
              f"(first render with JIT {times['first']:.2f} s, scene load {times['load']:.2f} s)")
        print(f"  ratio spectral-gi/Mitsuba samples/s: {t_m / t_ours:.2f}x (target >= 1)")
        ref.settings.spp = args.spp
        ref.settings.max_depth = args.bounces
        f2, _ = core.render(ref, threads=args.threads)
        print(f"  mean luminance spectral-gi / Mitsuba (core Cornell box): "
              f"{(f2.develop().rgb @ REC709_Y).mean() / (mimg @ REC709_Y).mean():.4f}")
    except Exception as e:  # a missing peer is reported, not fatal
        print(f"  Mitsuba: not run ({e})")


def rel_rmse(y, ref):
    return float(np.sqrt(np.mean((y - ref) ** 2)) / np.mean(ref))


def equal_time(args, scene_bpy, tmp):
    size, secs = args.rmse_size, args.seconds
    big = 1 << 20
    t_o, film, st = _ours(scene_bpy, big, args.bounces, args.threads, size, time_limit=secs)
    y_o = film.develop().rgb @ REC709_Y
    spp_o = st.spp
    _, film_r, _ = _ours(scene_bpy, 8 * spp_o, args.bounces, args.threads, size)
    y_or = film_r.develop().rgb @ REC709_Y

    # Cycles: its time limit does not report the samples reached, so calibrate its rate with a
    # short render and give it the sample count that fills the same time.
    t_cal, _ = _cycles(scene_bpy, 16, args.bounces, args.threads, size, os.path.join(tmp, "cal.exr"))
    spp_c = max(1, int(round(16 * secs / t_cal)))
    t_c, cyc = _cycles(scene_bpy, spp_c, args.bounces, args.threads, size, os.path.join(tmp, "ct.exr"))
    _, cyc_r = _cycles(scene_bpy, 8 * spp_c, args.bounces, args.threads, size, os.path.join(tmp, "cr.exr"))
    e_o = rel_rmse(y_o, y_or)
    e_c = rel_rmse(cyc @ REC709_Y, cyc_r @ REC709_Y)
    print(f"[equal time] {size}x{size}, {secs:g} s each, max bounces {args.bounces}")
    print(f"  spectral-gi: {spp_o} spp in {st.seconds:.1f} s render ({t_o:.1f} s with export)  "
          f"relative RMSE {e_o:.4f}")
    print(f"  Cycles     : {spp_c} spp in {t_c:.1f} s (sample count calibrated to the time)  relative RMSE {e_c:.4f}")
    print(f"  RMSE ratio Cycles/spectral-gi: {e_c / e_o:.2f}x (target > 1)")


def overhead(args):
    from spectral_gi import core
    from spectral_gi.core import constants as C
    from spectral_gi.core.spectra import uplift

    def run(scene):
        scene.settings.spp = args.overhead_spp
        scene.settings.max_depth = args.bounces
        film, st = core.render(scene, threads=args.threads)
        return st.seconds, film

    colour = core.cornell_box(args.size, args.size)
    grey = core.cornell_box(args.size, args.size)
    from spectral_gi.core.spectra import moments

    tab = moments.tabulate(colour.spectra.coeffs, colour.spectra.kind)
    for i, k in enumerate(colour.spectra.kind):
        if k == C.SPECTRUM_BOUNDED:
            mean = float(np.clip(tab[i].mean(), 0.0, 1.0))
            grey.spectra.coeffs[i] = uplift.reflectance_from_samples(
                [C.LAMBDA_MIN, C.LAMBDA_MAX], [mean, mean], colour.spectra.coeffs.shape[1])
    run(grey)  # warm-up
    t_g, _ = run(grey)
    t_c, _ = run(colour)
    print(f"[spectral overhead] core Cornell box {args.size}x{args.size}, {args.overhead_spp} spp")
    print(f"  grey reflectances: {t_g:.2f} s   uplifted colours: {t_c:.2f} s   "
          f"overhead {100 * (t_c / t_g - 1):+.1f} % (target <= 30 %)")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--bounces", type=int, default=4)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--rounds", type=int, default=2,
                    help="runs of this renderer and of Cycles each, in alternating order (speed)")
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--rmse-size", type=int, default=128)
    ap.add_argument("--overhead-spp", type=int, default=32)
    ap.add_argument("--skip", default="", help="comma-separated: speed, rmse, overhead")
    ap.add_argument("--sampler", choices=("independent", "halton", "hammersley", "stratified"), default=None,
                    help="this renderer's sampler (default: the exported scene's)")
    args = ap.parse_args(argv)
    global SAMPLER
    if args.sampler:
        from spectral_gi.core import constants as C
        SAMPLER = {"independent": C.SAMPLER_INDEPENDENT, "halton": C.SAMPLER_HALTON,
                   "hammersley": C.SAMPLER_HAMMERSLEY, "stratified": C.SAMPLER_STRATIFIED}[args.sampler]
    skip = {s.strip() for s in args.skip.split(",") if s.strip()}

    scene_bpy = cvc.build_scene(args.size)
    from spectral_gi import core

    # compile (or load the cache) before anything is timed
    warm = core.cornell_box(8, 8)
    warm.settings.spp = 1
    t0 = time.perf_counter()
    core.render(warm, threads=args.threads)
    print(f"kernel compile/load: {time.perf_counter() - t0:.1f} s")
    tmp = tempfile.mkdtemp(prefix="sgi-race-")
    if "speed" not in skip:
        speed(args, scene_bpy, tmp)
    if "rmse" not in skip:
        equal_time(args, scene_bpy, tmp)
    if "overhead" not in skip:
        overhead(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
