"""Radiosity against closed forms and the path tracer: the figures of the validation section
of docs/reference/radiosity.md.

    python benchmarks/radiosity_validation.py [--spp 16384] [--image 64]

* closed cubes (ρ = 0.5 and 0.95) whose ceiling emits: the area mean of the indirect
  illuminance against the power balance Φρ / (A(1 − ρ));
* an integrating sphere (faceted icosphere, ρ = 0.8, a point light at its centre): each
  patch's indirect illuminance against Φρ / (A(1 − ρ));
* a closed grey room (ρ = 0.5) under a rectangular light: illuminance at floor and wall
  points against ``core.point_illuminance``;
* the Cornell box: illuminance at points of the floor, walls and ceiling against the path
  tracer, for 0.1 m patches and the lighting analysis' default solve;
* the Cornell box's final-gather image (``core.render_radiosity``) against the path-traced
  image: mean luminance and the mean over the floor, ceiling and walls (``--image`` px a
  side; 0 skips it).

Prints every figure and writes benchmarks/results/radiosity_validation.json.
"""
import argparse
import math
import os
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "integrators", "radiosity"))

from spectral_gi import core  # noqa: E402
from spectral_gi.core import constants as C  # noqa: E402
from spectral_gi.core.integrators.radiosity import solve  # noqa: E402
from spectral_gi.core.scene import Light, Material, Mesh, Scene, SpectrumTable  # noqa: E402

import results  # noqa: E402
from helpers import flat_emission, flat_reflectance  # noqa: E402
from test_final_gather import cornell_regions  # noqa: E402
from test_solve import icosphere, room  # noqa: E402

CORNELL_POINTS = [  # (name, point, normal): clear of the blocks' footprints, 1 cm off the walls
    ("floor, front left", (-0.45, 0.10, 0.0), (0, 0, 1.0)),
    ("floor, back right", (-0.10, 0.45, 0.0), (0, 0, 1.0)),
    ("floor, front right", (-0.05, 0.05, 0.0), (0, 0, 1.0)),
    ("floor, behind the tall block", (-0.28, 0.52, 0.0), (0, 0, 1.0)),
    ("left wall", (-0.54, 0.30, 0.30), (1.0, 0, 0)),
    ("right wall", (-0.01, 0.30, 0.30), (-1.0, 0, 0)),
    ("back wall", (-0.28, 0.549, 0.40), (0, -1.0, 0)),
    ("ceiling", (-0.10, 0.10, 0.54), (0, 0, -1.0)),
]


def closed_cubes():
    rows = []
    for rho in (0.5, 0.95):
        lum = 100.0
        sol = core.radiosity(room(rho, ceiling_luminance=lum), max_edge=0.34, n_vis=2, tol=1e-7)
        a = sol.patches.area
        v = sol._ctx.v_band
        rho_eff = float(sol.reflectance[0] @ v / v.sum())
        want = math.pi * lum * rho_eff / (a.sum() * (1 - rho_eff))
        mean = float(np.sum(a * (sol.illuminance - sol.direct_illuminance)) / a.sum())
        rows.append([f"closed cube, ρ = {rho}", sol.patches.n, f"{100 * (mean / want - 1):+.3f} %", "–"])
    return rows


def sphere():
    rho = 0.8
    tri = icosphere(2)[:, ::-1]
    sp = SpectrumTable.empty()
    r = sp.add("grey", flat_reflectance(rho), C.SPECTRUM_BOUNDED)
    e = sp.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    pos = tri.reshape(-1, 3).astype(np.float32)
    mesh = Mesh("sphere", pos, np.arange(pos.shape[0], dtype=np.int32).reshape(-1, 3), np.zeros(len(tri), np.int32))
    light = Light("bulb", C.LIGHT_POINT, (0.0, 0.0, 0.0), (0, 0, 0), (0, 0, 0), e, 0.0, intensity=50.0)
    sc = Scene(meshes=[mesh], spectra=sp, materials=[Material("coat", reflectance=r)], lights=[light])
    sol = core.radiosity(sc, n_vis=2, n_light=1, tol=1e-7, sides="front")
    a = sol.patches.area
    v = sol._ctx.v_band
    rho_eff = float(sol.reflectance[0] @ v / v.sum())
    received = np.sum(a * sol.direct_illuminance)
    want = received * rho_eff / (a.sum() * (1 - rho_eff))
    ind = sol.illuminance - sol.direct_illuminance
    return [["integrating sphere, ρ = 0.8", sol.patches.n, f"{100 * (np.sum(a * ind) / a.sum() / want - 1):+.3f} %",
             f"{100 * np.max(np.abs(ind / want - 1)):.2f} %"]]


def against_path(sc, sol, pts, nrm, spp, seed=3):
    rad = core.radiosity_illuminance(sol, pts, nrm)
    pt, se, _ = core.point_illuminance(sc, pts, nrm, spp=spp, seed=seed)
    return rad, pt, se


def grey_room(spp):
    light = Light("panel", C.LIGHT_RECT, (1.0, 0.75, 1.19), (0.3, 0, 0), (0, -0.2, 0), 0, 2000.0)
    sc = room(0.5, size=(2.0, 1.5, 1.2), lights=[light])
    sol = core.radiosity(sc, max_edge=0.1, n_vis=4, n_light=256)
    pts = np.array([[0.3, 0.3, 0.0], [1.0, 0.75, 0.0], [1.7, 1.2, 0.0], [0.2, 0.75, 0.6]])
    nrm = np.array([[0, 0, 1.0], [0, 0, 1.0], [0, 0, 1.0], [1.0, 0, 0]])
    rad, pt, se = against_path(sc, sol, pts, nrm, spp)
    names = ["floor (0.3, 0.3)", "floor (1.0, 0.75)", "floor (1.7, 1.2)", "wall (0.2, 0.75, 0.6)"]
    return [[f"grey room ρ = 0.5: {n}", sol.patches.n, f"{100 * (r / p - 1):+.2f} %", f"{100 * s / p:.2f} %"]
            for n, r, p, s in zip(names, rad, pt, se)]


def cornell(spp):
    sc = core.cornell_box()
    pts = np.array([p for _, p, _ in CORNELL_POINTS])
    nrm = np.array([n for _, _, n in CORNELL_POINTS])
    rows = []
    pt, se, _ = core.point_illuminance(sc, pts, nrm, spp=spp, seed=3)
    for label, opts in (("0.1 m patches", dict(solve.LUX_DEFAULTS, max_edge=0.1)),
                        ("default solve", dict(solve.LUX_DEFAULTS, max_edge=solve.default_max_edge(sc)))):
        sol = core.radiosity(sc, **opts)
        rad = core.radiosity_illuminance(sol, pts, nrm)
        for (name, _, _), r, p, s in zip(CORNELL_POINTS, rad, pt, se):
            rows.append([f"Cornell box, {label}: {name}", sol.patches.n, f"{100 * (r / p - 1):+.2f} %",
                         f"{100 * s / p:.2f} %"])
    return rows


def cornell_image(res, spp_path=512, spp_fg=16, gather=64):
    t0 = time.perf_counter()
    pt_film, _ = core.render(core.cornell_box(width=res, height=res, spp=spp_path))
    t_pt = time.perf_counter() - t0
    pt = pt_film.develop().luminance
    t0 = time.perf_counter()
    fg_film, stats, sol = core.render_radiosity(core.cornell_box(width=res, height=res, spp=spp_fg), gather=gather)
    t_fg = time.perf_counter() - t0
    fg = fg_film.develop().luminance
    rows = [[f"final gather {res}², {spp_fg} spp × {gather} gather rays vs path {spp_path} spp: mean luminance",
             sol.patches.n, f"{100 * (fg.mean() / pt.mean() - 1):+.2f} %", "–"]]
    for name, (a, b) in cornell_regions(res, res).items():
        rows.append([f"final gather: {name}", sol.patches.n, f"{100 * (fg[a, b].mean() / pt[a, b].mean() - 1):+.2f} %",
                     "–"])
    print(f"path tracer {t_pt:.1f} s; radiosity {t_fg:.1f} s (solve {stats.build_seconds:.1f} s, final gather "
          f"{stats.seconds:.1f} s)")
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--spp", type=int, default=16384, help="path-tracer samples a point")
    ap.add_argument("--image", type=int, default=64, help="final-gather image size (0: skip)")
    a = ap.parse_args()
    warnings.simplefilter("ignore")
    rows = closed_cubes() + sphere() + grey_room(a.spp) + cornell(a.spp)
    if a.image:
        rows += cornell_image(a.image)
    cols = ["case", "patches", "radiosity / reference − 1", "reference's relative std. error (max |·| for the sphere)"]
    for r in rows:
        print(" | ".join(str(c) for c in r))
    results.write("radiosity_validation", tables=[results.table("Radiosity against closed forms and the path tracer",
                                                                cols, rows)],
                  conditions={"spp": a.spp, "image": a.image})


if __name__ == "__main__":
    main()
