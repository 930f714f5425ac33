"""The Cornell box seen through its camera, every pixel the illuminance (lux) of the surface
it sees: by radiosity (the lighting analysis' default solve, per-vertex values interpolated
across each patch, as the viewport's lux overlay shows them) next to the path tracer's
estimate at the same points, in the lux false colours of core/lux/falsecolour.py.

    python benchmarks/radiosity_figure.py [--res 96] [--spp 256]

Writes docs/images/radiosity_cornell_lux.png and prints the agreement (median and
90th percentile of |radiosity / path − 1| over the pixels whose path estimate has a
relative standard error below 3 %); the numbers go into docs/reference/radiosity.md.
"""
import argparse
import time
from pathlib import Path

import numpy as np

from spectral_gi import core
from spectral_gi.core.geometry.bvh import trace_closest_batch
from spectral_gi.core.integrators.radiosity import solve
from spectral_gi.core.lux import falsecolour as fc

OUT = Path(__file__).resolve().parents[1] / "docs" / "images" / "radiosity_cornell_lux.png"


def camera_rays(cam, width, height=None):
    """(origins, unit directions) through the pixel centres of a width × height view (square
    when height is None; row 0 at the top), the sensor fitted to the image's width."""
    height = width if height is None else height
    half = 0.5 * cam.sensor_width_mm / cam.lens_mm
    sx = ((np.arange(width) + 0.5) / width * 2 - 1) * half
    sy = -((np.arange(height) + 0.5) / height * 2 - 1) * half * height / width
    gx, gy = np.meshgrid(sx, sy)
    m = np.asarray(cam.to_world, np.float64)
    d = m[:3, 0] * gx[..., None] + m[:3, 1] * gy[..., None] - m[:3, 2]
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    return np.broadcast_to(m[:3, 3], d.shape).reshape(-1, 3).copy(), d.reshape(-1, 3)


def path_at_hits(sc, x, nrm, ok, spp):
    """The path tracer's illuminance (and standard error) at the hit points ``x[ok]``, a hair in
    front of the surface; NaN where ``ok`` is False. Returns (lux, standard error, seconds)."""
    t0 = time.perf_counter()
    pt = np.full(len(x), np.nan)
    se = np.full(len(x), np.nan)
    p, s, _ = core.point_illuminance(sc, x[ok] + 1e-5 * nrm[ok], nrm[ok], spp=spp, seed=7)
    pt[ok], se[ok] = p, s
    return pt, se, time.perf_counter() - t0


def radiosity_at_hits(sol, orig, dirs):
    """The first patch each ray meets and the solution's per-vertex illuminance interpolated
    at the hit point (barycentric over the patch). Returns (points, normals facing the
    ray, lux; NaN where the ray leaves)."""
    pat = sol._ctx.pat
    t, prim = trace_closest_batch(np.ascontiguousarray(orig), np.ascontiguousarray(dirs), np.full(len(orig), np.inf),
                                  pat.nodes, pat.tris)
    ok = prim >= 0
    side = np.where(np.sum(dirs * pat.tri_nrm[np.maximum(prim, 0)], axis=1) < 0, 0, 1)
    patch = np.where(ok, pat.tri_patch[np.maximum(prim, 0), side], -1)
    ok &= patch >= 0
    x = orig + np.where(ok, t, 0.0)[:, None] * dirs
    c = sol.patches.corners[np.maximum(patch, 0)]
    e1, e2, w = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0], x - c[:, 0]
    d11, d12, d22 = np.sum(e1 * e1, 1), np.sum(e1 * e2, 1), np.sum(e2 * e2, 1)
    w1, w2 = np.sum(w * e1, 1), np.sum(w * e2, 1)
    den = d11 * d22 - d12 * d12
    u = (d22 * w1 - d12 * w2) / den
    v = (d11 * w2 - d12 * w1) / den
    vert = sol.vertex_illuminance[sol.mesh.faces[np.maximum(patch, 0)]]
    lux = (1 - u - v) * vert[:, 0] + u * vert[:, 1] + v * vert[:, 2]
    nrm = sol.patches.normal[np.maximum(patch, 0)]
    return x, nrm, np.where(ok, lux, np.nan), ok


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--res", type=int, default=96)
    ap.add_argument("--spp", type=int, default=256)
    a = ap.parse_args()
    sc = core.cornell_box()
    t0 = time.perf_counter()
    opts = dict(solve.LUX_DEFAULTS, max_edge=solve.default_max_edge(sc))
    sol = core.radiosity(sc, **opts)
    t_rad = time.perf_counter() - t0
    orig, dirs = camera_rays(sc.camera, a.res)
    x, nrm, rad, ok = radiosity_at_hits(sol, orig, dirs)
    pt, se, t_pt = path_at_hits(sc, x, nrm, ok, a.spp)
    good = ok & (pt > 0) & (se < 0.03 * pt)
    dev = np.abs(rad[good] / pt[good] - 1)
    med, p90 = float(np.median(dev)), float(np.percentile(dev, 90))
    print(f"radiosity: {sol.patches.n} patches in {t_rad:.1f} s; path tracer: {ok.sum()} points at {a.spp} spp in "
          f"{t_pt:.1f} s; |radiosity / path - 1| over {good.sum()} pixels: median {med:.3%}, 90th percentile "
          f"{p90:.3%}")
    vmax = float(np.nanpercentile(pt, 99))
    fig = fc.new_figure(10.0, 4.6)
    for k, (img, title) in enumerate(((rad, f"radiosity ({sol.patches.n} patches)"),
                                      (pt, f"path tracer ({a.spp} samples a point)"))):
        ax = fig.add_axes((0.02 + 0.44 * k, 0.05, 0.42, 0.84))
        ax.imshow(fc.false_colour(img.reshape(a.res, a.res), 0.0, vmax), interpolation="nearest")
        ax.set_axis_off()
        ax.set_title(title, fontsize=10)
    cax = fig.add_axes((0.91, 0.05, 0.025, 0.84))
    fc.draw_legend(fig, cax, 0.0, vmax)
    fig.suptitle(f"Cornell box, illuminance of the visible surfaces: median |radiosity / path - 1| {med:.1%}, "
                 f"90th percentile {p90:.1%}", fontsize=10)
    fc.save_figure(fig, OUT)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
