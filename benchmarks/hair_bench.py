"""What a groom costs as tessellated curves (core/geometry/curves.py): triangles, tessellation
time, BVH build time and the memory the BVH keeps.

    python benchmarks/hair_bench.py [--strands 10000] [--segments 16] [--sides 4 6 8]

Strands of ``segments`` straight-ish segments (a gentle random bend per key) on a 1 m patch,
tessellated round at each number of sides and as ribbons, then built into the BVH
(core.geometry.accel.build); the last row first follows the Catmull-Rom spline through the
keys as the exporter does (``catmull_rom_refine``: more segments where strands bend). The
first build of a run also compiles or loads the BVH kernels, so one small build runs first and
is not counted.
"""
import argparse
import time

import numpy as np

import results  # benchmarks/results.py: the JSON record of this run

from spectral_gi.core.geometry import accel
from spectral_gi.core.geometry import curves as G


def groom(n_strands, segments, length=0.2, radius=0.0005, seed=0):
    rng = np.random.default_rng(seed)
    keys = segments + 1
    root = np.concatenate([rng.uniform(-0.5, 0.5, (n_strands, 2)), np.zeros((n_strands, 1))], 1)
    step = np.tile([0.0, 0.0, length / segments], (n_strands, keys - 1, 1))
    step[:, :, :2] += rng.normal(0.0, 0.1 * length / segments, (n_strands, keys - 1, 2))
    pts = np.concatenate([root[:, None], root[:, None] + np.cumsum(step, axis=1)], axis=1)
    radii = np.tile(np.linspace(radius, 0.0, keys), n_strands)
    return pts.reshape(-1, 3), radii, np.full(n_strands, keys)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--strands", type=int, default=10000)
    ap.add_argument("--segments", type=int, default=16)
    ap.add_argument("--sides", type=int, nargs="+", default=[4, 6, 8])
    args = ap.parse_args()
    p, r, c = groom(args.strands, args.segments)
    warm = G.tessellate(*groom(10, 2), shape=G.ROUND)
    accel.build(*(warm[0][warm[1][:, k]].astype(np.float64) for k in range(3)))
    rows = []
    cases = [(G.ROUND, s) for s in args.sides] + [(G.RIBBON, G.DEFAULT_COLUMNS), ("spline", G.DEFAULT_SIDES)]
    for shape, n in cases:
        t0 = time.perf_counter()
        if shape == "spline":
            rp, rr, rc = G.catmull_rom_refine(p, r, c)
            pos, tri, nrm, _ = G.tessellate(rp, rr, rc, shape=G.ROUND, sides=n)
        elif shape == G.ROUND:
            pos, tri, nrm, _ = G.tessellate(p, r, c, shape=shape, sides=n)
        else:
            pos, tri, nrm, _ = G.tessellate(p, r, c, shape=shape, columns=n, eye=(0.0, -3.0, 1.0))
        t1 = time.perf_counter()
        bvh = accel.build(*(pos[tri[:, k]].astype(np.float64) for k in range(3)))
        t2 = time.perf_counter()
        mesh_mb = (pos.nbytes + tri.nbytes + nrm.nbytes) / 1e6
        label = {G.ROUND: f"round, {n} sides", G.RIBBON: f"ribbon, {n} columns"}.get(shape, f"spline, {n} sides")
        rows.append([label, int(tri.shape[0]), round(t1 - t0, 2), round(t2 - t1, 2), round(mesh_mb, 1),
                     round(bvh.nbytes / 1e6, 1)])
        print(f"{label:>18}: {tri.shape[0]:>9} triangles, tessellate {t1 - t0:6.2f} s, BVH build "
              f"{t2 - t1:6.2f} s, mesh {mesh_mb:6.1f} MB, BVH {bvh.nbytes / 1e6:6.1f} MB")
    results.write("hair_bench", tables=[results.table(
        f"A groom of {args.strands} strands × {args.segments} segments as triangles",
        ["shape", "triangles", "tessellate (s)", "BVH build (s)", "mesh (MB)", "BVH (MB)"], rows)],
        conditions={"strands": args.strands, "segments": args.segments})


if __name__ == "__main__":
    main()
