"""Cornell box, 256×256: this renderer against Cycles (bpy), same samples and bounce limit.

    python benchmarks/cornell_vs_cycles.py [--spp 256] [--bounces 4] [--size 256] [--threads 2]

Both renderers get the same Blender scene (built by the add-on's *Add Cornell Box*),
the same resolution, samples per pixel and maximum bounces (Cycles' meaning: 0 is
direct light only). Cycles runs on the CPU with adaptive sampling, denoising and
clamping off, and its diffuse/glossy/transmission/total limits all set to the same
bounce count. Times are wall-clock for the render itself; this renderer's kernel
compilation is done (or loaded from its cache) before timing, Cycles' scene
synchronisation (its BVH build) is included in its time, as is this renderer's BVH
build and export. The script prints times, samples/s, their ratio, the efficiency
1/(T·σ²) of each, and the mean luminance ratio of the two images.
"""
import argparse
import os
import sys
import tempfile
import time

import results  # benchmarks/results.py: the JSON record of this run (benchmarks/ is on sys.path)

import numpy as np


def build_scene(size):
    import bpy

    from spectral_gi.addon import registration

    registration.register()
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.spectral_gi.add_cornell_box()
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    return scene


def render_cycles(scene, spp, bounces, threads, path):
    import bpy

    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = bounces
    c.transparent_max_bounces = max(8, bounces)
    c.caustics_reflective = c.caustics_refractive = True
    c.seed = 0
    scene.render.threads_mode = "FIXED"
    scene.render.threads = threads
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = path
    scene.view_settings.view_transform = "Standard"
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    return time.perf_counter() - t0


def read_rgb(path):
    from spectral_gi.core import read_exr

    ch, _ = read_exr(path)
    return np.stack([ch["R"], ch["G"], ch["B"]], axis=-1).astype(np.float64)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--bounces", type=int, default=4)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    args = ap.parse_args(argv)

    scene = build_scene(args.size)
    import bpy

    from spectral_gi import core
    from spectral_gi.addon.export import export_scene

    px = args.size * args.size
    tmp = tempfile.mkdtemp(prefix="sgi-bench-")

    # this renderer: compile (or load the cache) first, then time export + render
    t0 = time.perf_counter()
    warm = export_scene(bpy.context.evaluated_depsgraph_get()).scene
    warm.camera.width = warm.camera.height = 8
    warm.settings.spp = 1
    core.render(warm, threads=args.threads)
    t_warm = time.perf_counter() - t0

    t0 = time.perf_counter()
    sc = export_scene(bpy.context.evaluated_depsgraph_get()).scene
    sc.settings.spp = args.spp
    sc.settings.max_depth = args.bounces
    film, stats = core.render(sc, threads=args.threads)
    t_ours = time.perf_counter() - t0
    dev = film.develop()
    ours_rgb = dev.rgb

    t_cycles = render_cycles(scene, args.spp, args.bounces, args.threads, os.path.join(tmp, "cycles.exr"))
    cyc_rgb = read_rgb(os.path.join(tmp, "cycles.exr"))

    def lum(rgb):
        return rgb @ np.array([0.2126, 0.7152, 0.0722])

    var_ours = float(np.mean(dev.variance[np.isfinite(dev.variance)])) / (core.constants.K_M ** 2)
    samples = px * args.spp
    print(f"Cornell box {args.size}x{args.size}, {args.spp} spp, max bounces {args.bounces}, "
          f"{args.threads} threads")
    print(f"  spectral-gi : {t_ours:8.2f} s  {samples / t_ours / 1e6:6.3f} M samples/s  "
          f"(render {stats.seconds:.2f} s, BVH {stats.build_seconds:.2f} s; warm-up/compile {t_warm:.1f} s)")
    print(f"  Cycles      : {t_cycles:8.2f} s  {samples / t_cycles / 1e6:6.3f} M samples/s")
    print(f"  time ratio Cycles / spectral-gi: {t_cycles / t_ours:.2f}x")
    print(f"  efficiency 1/(T·σ²) of spectral-gi (σ² = mean per-pixel variance of Y): "
          f"{1.0 / (t_ours * var_ours):.4g}")
    ratio = lum(ours_rgb).mean() / lum(cyc_rgb).mean()
    print(f"  mean luminance spectral-gi / Cycles: {ratio:.4f}")
    results.write("cornell_vs_cycles", [results.table(
        f"Cornell box {args.size}², {args.spp} spp, max bounces {args.bounces}, {args.threads} threads",
        ["renderer", "time (s)", "M samples/s", "mean luminance / Cycles'"],
        [["spectral-gi (export + render)", round(t_ours, 2), round(samples / t_ours / 1e6, 3), round(float(ratio), 4)],
         ["Cycles", round(t_cycles, 2), round(samples / t_cycles / 1e6, 3), 1.0]])],
        conditions={"size": args.size, "spp": args.spp, "bounces": args.bounces, "threads": args.threads})
    return 0


if __name__ == "__main__":
    sys.exit(main())
