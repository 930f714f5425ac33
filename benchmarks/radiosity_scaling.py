"""Radiosity cost against the number of patches (compendium items 58, 61, 62).

    python benchmarks/radiosity_scaling.py [--dense 1000 10000] [--progressive 1000 10000]
                                           [--stochastic 1000 10000 50000]
                                           [--threads N] [--n-vis 1] [--n-points 1]

The scene: a closed grey room (ρ = 0.6, 4 × 3 × 2.5 m) with a table-sized box in it
(occluders) and a rectangular ceiling light, meshed to about N patches (the room's
insides; the outsides see nothing and are dropped). For each N it prints the seconds of
the direct light, the form factors and the solve, the peak memory NumPy allocated during
the run (tracemalloc) and, between sizes, the growth exponent d log T / d log N:

* dense (Gauss–Seidel on the stored n × n float32 form-factor matrix, to a residual of
  1e-5): form factors grow as N² (every pair, shadow rays included), memory as 4 N² bytes;
* progressive (Southwell shooting in batches, rows computed as patches first shoot, to an
  unshot power of 1 % of the power leaving the patches): the rows are the same N² pairs,
  the solve a few shots per patch;
* stochastic (matrix-free shooting, 16 rays per patch per iteration): about N log N
  (each ray a BVH query), memory linear in N.

Writes benchmarks/results/radiosity_scaling.json (benchmarks/results.py).
"""
import argparse
import math
import os
import sys
import time
import tracemalloc

import numpy as np

import results  # benchmarks/results.py: the JSON record of this run

from spectral_gi import core
from spectral_gi.core import constants as C
from spectral_gi.core.scene import Light, Material, Scene, SpectrumTable

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from helpers import box_mesh, flat_emission, flat_reflectance  # noqa: E402  (the test suite's scene builders)

SIZE = (4.0, 3.0, 2.5)


def scene():
    sp = SpectrumTable.empty()
    r = sp.add("grey", flat_reflectance(0.6), C.SPECTRUM_BOUNDED)
    e = sp.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    room = box_mesh("room", (0, 0, 0), SIZE, 0)
    room.indices = np.ascontiguousarray(room.indices[:, ::-1])
    table = box_mesh("table", (1.5, 1.0, 0.0), (2.5, 2.0, 0.75), 0)
    light = Light("panel", C.LIGHT_RECT, (2.0, 1.5, 2.49), (0.3, 0, 0), (0, -0.3, 0), e, 3000.0)
    return Scene(meshes=[room, table], spectra=sp, materials=[Material("grey", reflectance=r)], lights=[light])


def inside_area():
    a, b, c = SIZE
    return 2 * (a * b + b * c + a * c) + (1.0 * 1.0 + 4 * 1.0 * 0.75) + 1.0 * 1.0


def edge_for(n):
    """The max_edge giving about n patches: a face's two right triangles are cut into pieces
    of hypotenuse h and area h²/4, on both sides of the table's faces (its inside sees
    itself, so those sides stay); 2.4 is the ratio measured for this scene with ⌈ℓ/h⌉
    rounding. The tables print the patches actually solved."""
    return math.sqrt(2.0 * 2.4 * inside_area() / n)


TOL = {"stochastic": 1e-3, "southwell": 1e-2, "gauss-seidel": 1e-5}


def run(n, method, threads, n_vis, n_points):
    sc = scene()
    tracemalloc.start()
    t0 = time.perf_counter()
    sol = core.radiosity(sc, max_edge=edge_for(n), method=method, n_vis=n_vis, n_points=n_points, n_light=16,
                         rays=16 * n, tol=TOL[method], threads=threads)
    wall = time.perf_counter() - t0
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    s = sol.seconds
    return dict(n=sol.patches.n, direct=s.get("direct", 0.0), ff=s.get("form factors", 0.0), solve=s.get("solve", 0.0),
                total=wall, peak_mb=peak / 2 ** 20, iters=sum(st.iterations for st in sol.stats),
                residual=max(st.residual for st in sol.stats),
                mean_lux=float(np.sum(sol.patches.area * sol.illuminance) / sol.patches.area.sum()))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dense", type=int, nargs="*", default=[1000, 10000])
    ap.add_argument("--progressive", type=int, nargs="*", default=[1000, 10000])
    ap.add_argument("--stochastic", type=int, nargs="*", default=[1000, 10000, 50000])
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--n-vis", type=int, default=1)
    ap.add_argument("--n-points", type=int, default=1)
    a = ap.parse_args()
    run(200, "gauss-seidel", a.threads, a.n_vis, a.n_points)  # compiles the kernel (first run only)
    run(200, "southwell", a.threads, a.n_vis, a.n_points)
    run(200, "stochastic", a.threads, a.n_vis, a.n_points)
    tables = []
    for method, sizes in (("gauss-seidel", a.dense), ("southwell", a.progressive), ("stochastic", a.stochastic)):
        rows = []
        prev = None
        for n in sizes:
            r = run(n, method, a.threads, a.n_vis, a.n_points)
            growth = "" if prev is None else \
                f"{math.log(r['total'] / prev['total']) / math.log(r['n'] / prev['n']):.2f}"
            rows.append([r["n"], round(r["direct"], 2), round(r["ff"], 2), round(r["solve"], 2), round(r["total"], 2),
                         round(r["peak_mb"], 1), r["iters"], float(f"{r['residual']:.3g}"), round(r["mean_lux"], 2),
                         growth])
            print(f"{method:13s} n={r['n']:7d}  direct {r['direct']:8.2f} s  form factors {r['ff']:8.2f} s  "
                  f"solve {r['solve']:8.2f} s  total {r['total']:8.2f} s  peak {r['peak_mb']:9.1f} MiB  "
                  f"iterations {r['iters']:5d}  residual {r['residual']:.3g}  mean {r['mean_lux']:.2f} lx  "
                  f"growth {growth}", flush=True)
            prev = r
        tables.append(results.table(f"radiosity, {method}", ["patches", "direct s", "form factors s", "solve s",
                                                             "total s", "peak MiB", "iterations", "residual",
                                                             "mean lux",
                                                             "growth d log T / d log N"], rows))
    results.write("radiosity_scaling", tables, conditions={"threads": a.threads, "n_vis": a.n_vis,
                                                           "n_points": a.n_points, "dense": a.dense,
                                                           "progressive": a.progressive,
                                                           "stochastic": a.stochastic})


if __name__ == "__main__":
    main()
