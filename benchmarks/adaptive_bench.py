"""Adaptive sampling under a noise target: samples saved, and the error at equal time, against
stopping the whole image.

    python benchmarks/adaptive_bench.py [--quick] [--target 0.1] [--product FILE] [--only cornell,product]

For each scene (the built-in Cornell box; the product shot of ``artist_scenes.py``, built in
Blender and exported, or read from ``--product``, a scene file that ``artist_scenes.py
--save-scenes`` wrote) it renders

* a reference: every pixel at ``--ref-spp`` samples, another seed;
* **adaptive**: ``noise_target`` = ``--target``, per-pixel allocation (the default);
* **whole image**: the same target, the whole image stopped at once when 95 % of its pixels
  are within it (``render(adaptive=False)``);
* **uniform, equal time**: every pixel sampled, for as long as the adaptive render took
  (settings.time_limit).

and prints, for each, the samples taken (and their share of spp × pixels), the seconds, the
relative RMSE of luminance against the reference, the share of pixels whose error exceeds
the target (against the reference), and records them in ``benchmarks/results/adaptive_bench.json``.
"""
import argparse
import os
import sys
import time

import results  # benchmarks/results.py: the JSON record of this run (benchmarks/ is on sys.path)

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def product_scene(width, height):
    """The product shot of artist_scenes.py, exported by the add-on (needs bpy)."""
    import bpy

    sys.path.insert(0, HERE)
    import artist_scenes
    from spectral_gi.addon.export import export_scene

    scene = artist_scenes.product_scene(bpy, width, height, 16)
    return export_scene(bpy.context.evaluated_depsgraph_get(), scene).scene


def scenes(args):
    from spectral_gi.core import cornell_box, load_scene

    out = {}
    if "cornell" in args.only:
        out["cornell"] = lambda: cornell_box(args.size, args.size, spp=16, max_depth=8, seed=1)
    if "product" in args.only:
        if args.product:
            out["product"] = lambda: load_scene(args.product)
        else:
            built = product_scene(2 * args.size, args.size * 9 // 8)
            out["product"] = lambda: built
    return out


def run(make, spp, seed, target=0.0, adaptive=True, time_limit=0.0):
    from spectral_gi.core import render

    sc = make()
    sc.settings.spp, sc.settings.seed = int(spp), int(seed)
    sc.settings.noise_target, sc.settings.time_limit = float(target), float(time_limit)
    t0 = time.perf_counter()
    film, stats = render(sc, threads=os.cpu_count(), adaptive=adaptive)
    seconds = time.perf_counter() - t0
    taken = film.spp * film.width * film.height - film.skipped_samples
    return film, stats, seconds, taken


def figures(film, ref_lum, target):
    lum = film.develop().luminance
    mean = float(ref_lum.mean())
    rel = float(np.sqrt(np.mean((lum - ref_lum) ** 2)) / mean)
    # a pixel's error against the reference, relative as the noise target's (dark pixels
    # against NOISE_DARK × the image's mean)
    from spectral_gi.core.integrators.render import NOISE_DARK

    err = np.abs(lum - ref_lum) / np.maximum(ref_lum, NOISE_DARK * mean)
    return rel, float(np.mean(err > 2.0 * target))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="48-pixel Cornell box, at most 256 spp, reference 256 spp")
    ap.add_argument("--target", type=float, default=0.1)
    ap.add_argument("--spp", type=int, default=None, help="the most samples a pixel may take (default 512)")
    ap.add_argument("--ref-spp", type=int, default=None)
    ap.add_argument("--size", type=int, default=None, help="the Cornell box's side (the product: 2× wide, 9/8 high)")
    ap.add_argument("--product", default=None, help="the product shot as a scene file (else built with bpy)")
    ap.add_argument("--only", default="cornell,product")
    args = ap.parse_args(argv)
    args.size = args.size or (48 if args.quick else 96)
    args.spp = args.spp or (256 if args.quick else 512)
    args.ref_spp = args.ref_spp or (256 if args.quick else 1024)
    rows = []
    for name, make in scenes(args).items():
        from spectral_gi.core import render

        render(make(), threads=1)  # the kernels this scene needs, compiled or loaded before any timing
        ref, _, t_ref, _ = run(make, args.ref_spp, 99)
        ref_lum = ref.develop().luminance
        pixels = ref.width * ref.height
        ad, st_ad, t_ad, n_ad = run(make, args.spp, 1, args.target, True)
        wh, st_wh, t_wh, n_wh = run(make, args.spp, 1, args.target, False)
        un, st_un, t_un, n_un = run(make, args.spp, 1, 0.0, True, time_limit=t_ad)
        for label, film, st, t, n in (("adaptive", ad, st_ad, t_ad, n_ad), ("whole image", wh, st_wh, t_wh, n_wh),
                                      ("uniform, adaptive's time", un, st_un, t_un, n_un)):
            rel, over = figures(film, ref_lum, args.target)
            rows.append([name, label, st.spp, n, round(n / (st.spp * pixels), 3), round(t, 2), round(rel, 4),
                         round(over, 4)])
            print(f"{name:8s} {label:26s} {st.spp:5d} spp (max)  {n:10d} samples ({n / (st.spp * pixels):5.1%} of "
                  f"spp × pixels)  {t:6.2f} s  rel. RMSE {rel:.4f}  pixels off by > 2× target {over:.2%}", flush=True)
        print(f"{name:8s} reference {args.ref_spp} spp: {t_ref:.1f} s; adaptive saves "
              f"{1 - n_ad / (st_ad.spp * pixels):.1%} of its spp × pixels; {n_ad / max(n_wh, 1):.2f}× the samples of "
              f"whole-image stopping", flush=True)
    results.write("adaptive_bench", [results.table(
        f"Adaptive sampling at noise target {args.target} (at most {args.spp} spp) against stopping the whole image "
        f"and against uniform sampling for the same time; relative RMSE of luminance against {args.ref_spp} spp",
        ["scene", "sampling", "spp (max)", "samples", "share of spp × pixels", "seconds", "relative RMSE",
         "pixels off by > 2× target"], rows)],
        conditions={"target": args.target, "spp": args.spp, "ref_spp": args.ref_spp, "size": args.size,
                    "threads": os.cpu_count()})
    return 0


if __name__ == "__main__":
    sys.exit(main())
