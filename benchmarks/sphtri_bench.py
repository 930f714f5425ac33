"""Emissive triangles sampled by area vs by solid angle (compendium item 22).

    python benchmarks/sphtri_bench.py [--res 64] [--spp 16] [--ref-spp 2048] [--sweep]

For each scene, renders with emissive triangles sampled

* by area only (RenderSettings.tri_solid_angle_min > max), and
* by the default rule (uniform in the solid angle Ω, Arvo's spherical triangle, when Ω is in
  [tri_solid_angle_min, tri_solid_angle_max]; by area otherwise),

and prints the relative RMSE of luminance (RMSE over the pixels / mean luminance of the
reference) against a converged reference (the mean of both strategies at ``ref-spp``: they
estimate the same image), at equal samples per pixel and at equal CPU time (the
solid-angle render gets the samples per pixel that fit in the area render's CPU time, from
the CPU time per sample of the equal-spp runs), plus the efficiency ratio 1/(T σ²)
(item 29). One thread, CPU time (process_time), so other jobs on the machine matter less.
The independent sampler unless ``--sampler 3``: the default stratified sampler's error does
not fall smoothly with non-power-of-two sample counts (the Cornell lamp's edge pixels), which
blurs the equal-time comparison; the same seed for every strategy (common random numbers).

Scenes:

* ``cornell``: the core Cornell box (a small ceiling lamp, Ω ≲ 0.1 sr from most points):
  the two strategies should be about equally good.
* ``panel``: a floor with two boxes under a large one-sided emissive panel (2 triangles,
  2 × 2 m) 0.35 m above it, the camera looking down at an angle: a large, near emitter,
  where area sampling suffers from 1/r² and the emitter's cosine.
* ``panel8``: the same panel tessellated into 8 × 8 quads (128 triangles): each triangle
  is smaller, so the gain shrinks.

``--sweep`` also renders the panel and Cornell scenes at equal spp for several
(min, max) thresholds of the rule and prints their RMSE and CPU time.
"""
import argparse
import os
import sys
import time

import numpy as np

import results  # benchmarks/results.py: the JSON record of this run

from spectral_gi import core
from spectral_gi.core import constants as C
from spectral_gi.core.scene import (
    TRI_SOLID_ANGLE_MAX, TRI_SOLID_ANGLE_MIN, Camera, Material, Mesh, RenderSettings, Scene, SpectrumTable)
from spectral_gi.core.spectra import uplift

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from helpers import box_mesh, look_at  # noqa: E402  (the test suite's scene builders)

AREA_ONLY = (1.0, 0.0)
DEFAULT = (TRI_SOLID_ANGLE_MIN, TRI_SOLID_ANGLE_MAX)


def _grid(name, x0, x1, y0, y1, z, n, material, down):
    """An n × n grid of quads on the plane z (normal -z when ``down``)."""
    xs = np.linspace(x0, x1, n + 1)
    ys = np.linspace(y0, y1, n + 1)
    pos = np.array([[x, y, z] for y in ys for x in xs], np.float32)
    tris = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 2, a + n + 1
            tris += [(a, c, b), (a, d, c)] if down else [(a, b, c), (a, c, d)]
    tris = np.array(tris, np.int32)
    return Mesh(name, pos, tris, np.full(len(tris), material, np.int32))


def panel_scene(res=64, spp=16, n_panel=1, height=0.35, max_depth=3, seed=0):
    """A grey floor and two boxes under a large, near, one-sided emissive panel."""
    spectra = SpectrumTable.empty()
    grey = spectra.add("grey", uplift.reflectance_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX], [0.6, 0.6]),
                       C.SPECTRUM_BOUNDED)
    flat = spectra.add("flat", uplift.emission_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX], [1.0, 1.0]),
                       C.SPECTRUM_UNBOUNDED)
    mats = [Material("floor", reflectance=grey),
            Material("panel", reflectance=grey, emission=flat, emission_luminance=100.0, two_sided=False)]
    meshes = [_grid("floor", -2.0, 2.0, -2.0, 2.0, 0.0, 1, 0, False),
              _grid("panel", -1.0, 1.0, -1.0, 1.0, height, n_panel, 1, True),
              box_mesh("box1", (-0.5, -0.3, 0.0), (-0.2, 0.0, 0.15), 0),
              box_mesh("box2", (0.2, 0.1, 0.0), (0.6, 0.5, 0.1), 0)]
    cam = Camera(look_at((0.0, -1.9, 0.3), (0.0, 0.0, 0.05)), width=res, height=res, lens_mm=24.0)
    return Scene(meshes=meshes, spectra=spectra, materials=mats, camera=cam,
                 settings=RenderSettings(spp=spp, max_depth=max_depth, seed=seed, filter=C.FILTER_BOX))


def cornell_scene(res=64, spp=16, seed=0):
    sc = core.cornellbox_mesh(res, res, spp=spp, max_depth=3, seed=seed)
    sc.settings.filter = C.FILTER_BOX
    return sc


SCENES = {"cornell": cornell_scene, "panel": panel_scene,
          "panel-direct": lambda res, spp, seed=0: panel_scene(res, spp, max_depth=0, seed=seed),
          "panel8": lambda res, spp, seed=0: panel_scene(res, spp, n_panel=8, seed=seed)}
SWEEP = [AREA_ONLY, (1e-6, 6.22), (0.01, 6.22), (0.03, 6.22), (0.1, 6.22), (0.3, 6.22), (1.0, 6.22), (0.1, 2.0),
         (0.1, 4.0), (0.1, 2 * np.pi)]


SAMPLER = [C.SAMPLER_INDEPENDENT]


def render(make, res, spp, rule, seed, sampler=None):
    sampler = SAMPLER[0] if sampler is None else sampler
    sc = make(res, spp, seed=seed)
    sc.settings.sampler = sampler
    sc.settings.tri_solid_angle_min, sc.settings.tri_solid_angle_max = rule
    c0 = time.process_time()
    film, _ = core.render(sc, threads=1)
    return film.develop().luminance, time.process_time() - c0


def rel_rmse(img, ref):
    return float(np.sqrt(np.mean((img - ref) ** 2)) / ref.mean())


def cornell_cost(reps=3):
    """What the rule costs on an ordinary scene (pbench-style): the core Cornell box 128², 16
    spp, max bounces 4, default sampler, 1 thread, best CPU time of ``reps`` interleaved runs."""
    rules = [("area only", AREA_ONLY), ("default rule", DEFAULT), ("solid angle always", (1e-6, 6.22))]
    best = {name: 1e9 for name, _ in rules}
    for _ in range(reps):
        for name, rule in rules:
            sc = core.cornellbox_mesh(128, 128, spp=16, max_depth=4)
            sc.settings.tri_solid_angle_min, sc.settings.tri_solid_angle_max = rule
            c0 = time.process_time()
            core.render(sc, threads=1)
            best[name] = min(best[name], time.process_time() - c0)
    print("\nCornell box 128², 16 spp, 4 bounces, 1 thread (best of %d):" % reps)
    for name, _ in rules:
        print(f"  {name:20s} CPU {best[name]:5.2f} s  {128 * 128 * 16 / best[name] / 1e6:.3f} M samples/s"
              f"  ({best[name] / best['area only']:.3f}x area's time)")
    return results.table(f"Cost on the Cornell box, 128², 16 spp, 4 bounces, 1 thread, best CPU time of {reps}",
                         ["rule", "CPU s", "M samples/s", "time / area only's"],
                         [[name, round(best[name], 2), round(128 * 128 * 16 / best[name] / 1e6, 3),
                           round(best[name] / best["area only"], 3)] for name, _ in rules])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=2048)
    ap.add_argument("--scenes", default="cornell,panel,panel-direct,panel8")
    ap.add_argument("--sweep", action="store_true")
    ap.add_argument("--no-cost", action="store_true")
    ap.add_argument("--sampler", type=int, default=C.SAMPLER_INDEPENDENT,
                    help="0 independent (default here), 3 stratified (the renderer's default)")
    a = ap.parse_args()
    SAMPLER[0] = a.sampler
    render(cornell_scene, 8, 1, DEFAULT, 0)  # compile
    print(f"rule: solid angle in [{DEFAULT[0]:g}, {DEFAULT[1]:g}] sr; {a.res}² px, sampler {a.sampler}, 1 thread, "
          "CPU time")
    rows = []
    for name in a.scenes.split(","):
        make = SCENES[name]
        ra, _ = render(make, a.res, a.ref_spp // 2, AREA_ONLY, 101)
        rs, _ = render(make, a.res, a.ref_spp // 2, DEFAULT, 102)
        ref = 0.5 * (ra + rs)
        # the two references agree (same expectation) to within their noise
        ref_gap = float(np.abs(ra.mean() - rs.mean()) / ref.mean())
        ia, ta = render(make, a.res, a.spp, AREA_ONLY, 1)
        isp, ts = render(make, a.res, a.spp, DEFAULT, 1)
        spp_eq = max(1, int(round(a.spp * ta / ts)))
        ie, te = render(make, a.res, spp_eq, DEFAULT, 1)
        ea, es = rel_rmse(ia, ref), rel_rmse(isp, ref)
        ee = rel_rmse(ie, ref)
        eff = (ta * ea * ea) / (ts * es * es)
        print(f"\n{name}: reference {a.ref_spp} spp (area and solid-angle means differ by {100 * ref_gap:.2f} %)")
        print(f"  area only      {a.spp:5d} spp  CPU {ta:6.2f} s  rel. RMSE {ea:.4f}")
        print(f"  solid angle    {a.spp:5d} spp  CPU {ts:6.2f} s  rel. RMSE {es:.4f}  (x{es / ea:.3f} at equal spp)")
        print(f"  solid angle    {spp_eq:5d} spp  CPU {te:6.2f} s  rel. RMSE {ee:.4f}  (x{ee / ea:.3f} at equal time)")
        print(f"  efficiency 1/(T σ²) ratio solid angle / area: {eff:.2f}")
        rows.append([name, round(ea, 4), round(es, 4), round(es / ea, 3), spp_eq, round(ee, 4), round(ee / ea, 3),
                     round(eff, 2)])
        if a.sweep:
            print(f"  sweep at {a.spp} spp: (min, max) sr   rel. RMSE   CPU s   efficiency / area's")
            for rule in SWEEP:
                img, t = render(make, a.res, a.spp, rule, 1)
                e = rel_rmse(img, ref)
                print(f"  ({rule[0]:g}, {rule[1]:.4g}){'':12s}{e:9.4f}  {t:6.2f}   {ta * ea * ea / (t * e * e):5.2f}")
    tables = [results.table(
        f"Relative RMSE of luminance against a {a.ref_spp}-spp reference, {a.res}² px, sampler {a.sampler}, "
        f"1 thread: area sampling only against the default rule (solid angle for Ω in [{DEFAULT[0]:g}, "
        f"{DEFAULT[1]:g}] sr)",
        ["scene", f"area only, {a.spp} spp", f"solid angle, {a.spp} spp", "ratio", "equal-time spp",
         "solid angle, equal time", "ratio", "efficiency ratio"], rows)]
    if not a.no_cost:
        tables.append(cornell_cost())
    results.write("sphtri_bench", tables, conditions={"res": a.res, "spp": a.spp, "ref_spp": a.ref_spp,
                                                      "sampler": a.sampler, "threads": 1})


if __name__ == "__main__":
    main()
