"""A furnished office by radiosity and by the path tracer: the false-colour illuminance of
every visible surface (radiosity's per-vertex values, as the viewport's lux overlay shows
them) beside the path tracer's at the same points, and the illuminance on the work plane
both ways, on one colour scale with its legend.

    python benchmarks/radiosity_interior.py [--res 120] [--spp 256] [--plane-spp 2048]

The office (built here from the core scene types): 6 × 4 × 2.8 m, Lambertian floor
(ρ = 0.2), walls (0.5) and ceiling (0.7); a window of 2.4 × 1.4 m in the wall x = 0, a
diffuse pane of 1500 cd/m² (an overcast sky seen through it, an emitting surface of the
radiosity mesh); four ceiling panels of 0.6 × 0.6 m (analytic rectangle lights of
2500 cd/m², about 2800 lm each); four desks (top 1.6 × 0.8 m at 0.72 m on two panel
legs, ρ = 0.45), a cabinet of 0.8 × 0.4 × 1.2 m against the back wall (ρ = 0.35) and a
bookcase of 1.0 × 0.35 × 1.8 m (ρ = 0.3). The work plane is 0.75 m above the floor with a
0.5 m band at the walls, a grid of 0.25 m.

The radiosity solve is the lighting analysis' default (``solve.LUX_DEFAULTS``, patch size
``solve.default_max_edge``); the work-plane points take ``core.radiosity_illuminance``
(direct light gathered at the point, the solution's reflected light), the path tracer
``core.point_illuminance``. Writes docs/images/radiosity_office_lux.png and
benchmarks/results/radiosity_interior.json, and prints the agreement: the median and 90th
percentile of |radiosity / path − 1| over the pixels whose path estimate has a relative
standard error below 3 %, and over the work-plane points, and the work plane's mean
illuminance both ways.
"""
import argparse
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from spectral_gi import core
from spectral_gi.core import constants as C
from spectral_gi.core.integrators.radiosity import solve
from spectral_gi.core.lux import falsecolour as fc
from spectral_gi.core.scene import Camera, Light, Material, Mesh, RenderSettings, Scene, SpectrumTable

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import results  # noqa: E402
from radiosity_figure import camera_rays, path_at_hits, radiosity_at_hits  # noqa: E402

OUT = Path(__file__).resolve().parents[1] / "docs" / "images" / "radiosity_office_lux.png"
ROOM = (6.0, 4.0, 2.8)
WINDOW = ((0.0, 0.8, 0.9), (0.0, 3.2, 2.3))  # the pane in the wall x = 0: (x, y0, z0), (x, y1, z1)
WINDOW_LUMINANCE = 1500.0  # cd/m²
PANELS = ((1.5, 1.0), (4.5, 1.0), (1.5, 3.0), (4.5, 3.0))  # plan positions, m
PANEL_HALF = 0.3  # m
PANEL_LUMINANCE = 2500.0  # cd/m²
DESKS = ((1.0, 0.6), (3.6, 0.6), (1.0, 2.6), (3.6, 2.6))  # the corner (x, y) of each 1.6 × 0.8 m desk
WORK_PLANE = 0.75  # m
BAND = 0.5  # m
GRID = 0.25  # m


def _grey(sp, name, rho):
    return sp.add(name, core.reflectance_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX], [rho, rho]),
                  C.SPECTRUM_BOUNDED)


def _quads(name, quads, material, inward=False):
    """A mesh of quads (Q, 4, 3), counter-clockwise seen from their front (reversed if inward)."""
    q = np.asarray(quads, np.float64)
    if inward:
        q = q[:, ::-1]
    k = np.arange(len(q))[:, None] * 4
    tris = np.concatenate([k + [0, 1, 2], k + [0, 2, 3]]).astype(np.int32)
    return Mesh(name, q.reshape(-1, 3).astype(np.float32), tris, np.full(len(tris), material, np.int32))


def _box_quads(lo, hi):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    c = np.array([[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
                  [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]])
    return c[[(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (2, 3, 7, 6), (1, 2, 6, 5), (0, 4, 7, 3)]]


def office(width=120, height=80):
    """The office of the module text, with a camera in the front-right corner looking at the
    window wall and the desks."""
    w, d, h = ROOM
    sp = SpectrumTable.empty()
    white = sp.add("D65-ish flat", core.emission_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX], [1.0, 1.0]),
                   C.SPECTRUM_UNBOUNDED)
    mats = [Material("floor", reflectance=_grey(sp, "floor", 0.2)),
            Material("walls", reflectance=_grey(sp, "walls", 0.5)),
            Material("ceiling", reflectance=_grey(sp, "ceiling", 0.7)),
            Material("desk", reflectance=_grey(sp, "desk", 0.45)),
            Material("cabinet", reflectance=_grey(sp, "cabinet", 0.35)),
            Material("books", reflectance=_grey(sp, "books", 0.3)),
            Material("window", reflectance=_grey(sp, "glass", 0.08), emission=white,
                     emission_luminance=WINDOW_LUMINANCE, two_sided=False)]
    room = _box_quads((0, 0, 0), (w, d, h))
    meshes = [_quads("floor", room[:1], 0, inward=True), _quads("ceiling", room[1:2], 2, inward=True),
              _quads("walls", room[2:], 1, inward=True)]
    (x, y0, z0), (_, y1, z1) = WINDOW
    x = 0.001  # 1 mm in front of the wall, facing into the room
    meshes.append(_quads("window", [[(x, y0, z0), (x, y1, z0), (x, y1, z1), (x, y0, z1)]], 6))
    desks = []
    for dx, dy in DESKS:
        desks.append(_box_quads((dx, dy, 0.69), (dx + 1.6, dy + 0.8, 0.72)))
        for lx in (dx + 0.05, dx + 1.52):
            desks.append(_box_quads((lx, dy + 0.05, 0.0), (lx + 0.03, dy + 0.75, 0.69)))
    meshes.append(_quads("desks", np.concatenate(desks), 3))
    meshes.append(_quads("cabinet", _box_quads((2.6, d - 0.4, 0.0), (3.4, d - 0.001, 1.2)), 4))
    meshes.append(_quads("bookcase", _box_quads((w - 0.35, 1.5, 0.0), (w - 0.001, 2.5, 1.8)), 5))
    z = h - 0.001
    lights = [Light(f"panel {k + 1}", C.LIGHT_RECT, (px, py, z), (PANEL_HALF, 0, 0), (0, -PANEL_HALF, 0), white,
                    PANEL_LUMINANCE) for k, (px, py) in enumerate(PANELS)]
    eye = np.array([w - 0.3, d - 0.3, 1.7])
    target = np.array([1.2, 1.2, 0.8])
    f = target - eye
    f /= np.linalg.norm(f)
    r = np.cross(f, (0, 0, 1.0))
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = r, u, -f, eye
    cam = Camera(to_world=m, width=width, height=height, lens_mm=16.0, sensor_width_mm=36.0, sensor_height_mm=24.0)
    return Scene(meshes=meshes, spectra=sp, materials=mats, lights=lights, camera=cam,
                 settings=RenderSettings(spp=64, seed=0), metadata={"name": "office (radiosity figure)"})


def work_plane():
    """The work-plane grid: (points (N, 3), plan shape (ny, nx))."""
    w, d, _ = ROOM
    xs = np.arange(BAND + GRID / 2, w - BAND, GRID)
    ys = np.arange(BAND + GRID / 2, d - BAND, GRID)
    gx, gy = np.meshgrid(xs, ys)
    return np.stack([gx.ravel(), gy.ravel(), np.full(gx.size, WORK_PLANE)], 1), gx.shape


def _agreement(rad, pt):
    dev = np.abs(rad / pt - 1)
    return float(np.median(dev)), float(np.percentile(dev, 90))


def _figure(rad_img, pt_img, rad_wp, pt_wp, shape, vmax, n_patches, spp, plane_spp, stats):
    fig = fc.new_figure(11.0, 8.2)
    (cm, cp), (wm, wp) = stats["camera"], stats["plane"]
    panels = [(rad_img, f"radiosity ({n_patches} patches)", (0.02, 0.50, 0.43, 0.40)),
              (pt_img, f"path tracer ({spp} samples a point)", (0.47, 0.50, 0.43, 0.40)),
              (rad_wp, f"work plane {WORK_PLANE} m, radiosity: mean {stats['mean'][0]:.0f} lx",
               (0.02, 0.05, 0.43, 0.36)),
              (pt_wp, f"work plane, path tracer ({plane_spp} spp): mean {stats['mean'][1]:.0f} lx",
               (0.47, 0.05, 0.43, 0.36))]
    for img, title, box in panels:
        ax = fig.add_axes(box)
        origin = "lower" if img.shape == shape else "upper"
        ax.imshow(fc.false_colour(img, 0.0, vmax), interpolation="nearest", origin=origin)
        ax.set_axis_off()
        ax.set_title(title, fontsize=9)
    cax = fig.add_axes((0.92, 0.05, 0.022, 0.85))
    fc.draw_legend(fig, cax, 0.0, vmax)
    fig.suptitle(f"Office, illuminance of the visible surfaces: median |radiosity / path - 1| {cm:.1%}, 90th "
                 f"percentile {cp:.1%}; work plane: median {wm:.1%}, 90th percentile {wp:.1%}", fontsize=10)
    fc.save_figure(fig, OUT)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--res", type=int, default=120, help="image width (the height is 2/3 of it)")
    ap.add_argument("--spp", type=int, default=256, help="path-tracer samples a pixel's point")
    ap.add_argument("--plane-spp", type=int, default=2048, help="path-tracer samples a work-plane point")
    a = ap.parse_args()
    warnings.simplefilter("ignore")
    sc = office(a.res, a.res * 2 // 3)
    t0 = time.perf_counter()
    max_edge = solve.default_max_edge(sc)
    sol = core.radiosity(sc, **dict(solve.LUX_DEFAULTS, max_edge=max_edge))
    t_rad = time.perf_counter() - t0
    orig, dirs = camera_rays(sc.camera, sc.camera.width, sc.camera.height)
    x, nrm, rad, ok = radiosity_at_hits(sol, orig, dirs)
    pt, se, t_pt = path_at_hits(sc, x, nrm, ok, a.spp)
    good = ok & (pt > 0) & (se < 0.03 * pt)
    cam_stats = _agreement(rad[good], pt[good])
    wp_pts, shape = work_plane()
    up = np.tile([0.0, 0.0, 1.0], (len(wp_pts), 1))
    t0 = time.perf_counter()
    rad_wp = core.radiosity_illuminance(sol, wp_pts, up)
    t_gather = time.perf_counter() - t0
    t0 = time.perf_counter()
    pt_wp, se_wp, _ = core.point_illuminance(sc, wp_pts, up, spp=a.plane_spp, seed=11)
    t_wp = time.perf_counter() - t0
    wp_stats = _agreement(rad_wp, pt_wp)
    means = (float(rad_wp.mean()), float(pt_wp.mean()))
    se_mean = float(np.sqrt(np.sum(se_wp ** 2)) / len(se_wp))
    vmax = float(np.nanpercentile(np.concatenate([pt[ok], pt_wp]), 99))
    stats = {"camera": cam_stats, "plane": wp_stats, "mean": means}
    print(f"radiosity: {sol.patches.n} patches of at most {max_edge:.3f} m in {t_rad:.1f} s "
          f"({', '.join(f'{k} {v:.1f} s' for k, v in sol.seconds.items())}); work-plane gather {t_gather:.1f} s")
    print(f"path tracer: {ok.sum()} pixel points at {a.spp} spp in {t_pt:.1f} s; {len(wp_pts)} work-plane points at "
          f"{a.plane_spp} spp in {t_wp:.1f} s")
    print(f"pixels ({good.sum()}): median |rad/path - 1| {cam_stats[0]:.2%}, p90 {cam_stats[1]:.2%}")
    print(f"work plane ({len(wp_pts)} points): median {wp_stats[0]:.2%}, p90 {wp_stats[1]:.2%}; mean "
          f"{means[0]:.1f} lx radiosity, {means[1]:.1f} ± {se_mean:.1f} lx path "
          f"({100 * (means[0] / means[1] - 1):+.2f} %)")
    _figure(rad.reshape(sc.camera.height, sc.camera.width), pt.reshape(sc.camera.height, sc.camera.width),
            rad_wp.reshape(shape), pt_wp.reshape(shape), shape, vmax, sol.patches.n, a.spp, a.plane_spp, stats)
    print(f"wrote {OUT}")
    cols = ["figure", "value"]
    rows = [["patches", sol.patches.n], ["patch size, m", round(max_edge, 4)],
            ["radiosity solve, s", round(t_rad, 1)],
            ["pixels compared (path rel. std. error < 3 %)", int(good.sum())],
            ["pixels: median |radiosity / path - 1|", f"{100 * cam_stats[0]:.2f} %"],
            ["pixels: 90th percentile |radiosity / path - 1|", f"{100 * cam_stats[1]:.2f} %"],
            ["work-plane points", len(wp_pts)],
            ["work plane: median |radiosity / path - 1|", f"{100 * wp_stats[0]:.2f} %"],
            ["work plane: 90th percentile |radiosity / path - 1|", f"{100 * wp_stats[1]:.2f} %"],
            ["work plane: mean illuminance by radiosity, lx", round(means[0], 1)],
            ["work plane: mean illuminance by the path tracer, lx", round(means[1], 1)],
            ["work plane: std. error of the path tracer's mean, lx", round(se_mean, 2)],
            ["work plane: min / max by radiosity, lx", f"{rad_wp.min():.0f} / {rad_wp.max():.0f}"],
            ["work plane: min / max by the path tracer, lx", f"{pt_wp.min():.0f} / {pt_wp.max():.0f}"]]
    results.write("radiosity_interior", tables=[results.table("Office: radiosity against the path tracer", cols,
                                                              rows)],
                  conditions={"res": a.res, "spp": a.spp, "plane_spp": a.plane_spp,
                              "solve": {k: v for k, v in solve.LUX_DEFAULTS.items()}})


if __name__ == "__main__":
    main()
