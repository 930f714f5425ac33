"""BVH at scale: build time, memory and ray throughput for millions of triangles.

    python benchmarks/scale_bench.py [--sizes 1,4,16] [--rays 1000000] [--threads 2]

The scene is a fixed world whose tessellation grows with the triangle count, so a ray
meets the same surfaces at every size and only the tree gets deeper: 256 displaced
spheres (cube-spheres, each face an n×n grid of quads, radius perturbed by four random
waves) in 8 Gaussian clusters, standing on a tessellated ground plane that holds ~1/8 of
the triangles. ``n`` is chosen so the total is close to the requested number of millions.

For each size it prints

* the build time of ``accel.build`` (float32 corners in) and the time per million triangles,
* the bytes per triangle the renderer keeps (``BVH.nbytes``: node records, leaf-order
  triangles for traversal and shading, ``prims``) and the peak extra resident memory of the build (VmHWM reset
  through /proc/self/clear_refs just before it; the corner arrays already exist),
* tree statistics (nodes, depth, mean leaf size, SAH cost),
* closest-hit rays/s: ``--rays`` rays from 16 camera positions on a ring around the scene,
  each in a random direction within a 60° cone aimed at the scene centre,
* occlusion rays/s: shadow segments from the hit points of those rays to 4 jittered
  points of an area light above the scene,

both with the batch kernels (``trace_closest_batch``, ``trace_occluded_batch``) under
``--threads`` threads, as wall-clock rates and per CPU second (the machine is shared:
wall-clock rates drop when others run, rays per CPU second much less), and the ratio of
each per-CPU-second rate to the smallest size's next to log2(N0)/log2(N): a throughput
that falls only logarithmically keeps the ratio at or above that column. All trees are
built first; then each of ``--reps`` rounds times every size in turn and the best pass
of each is kept, so load from other jobs strikes every size alike. Compile time is
excluded (kernels are warmed on a small scene first). No thresholds: the figures are
for reading.

With ``--one-ray`` it also times the path kernel's own traversal, one ray at a time
(``trace_closest`` / ``trace_occluded`` in a serial loop on one thread, over the first
300,000 rays): each kind on its own, and in path order, each closest hit's shadow ray
traced right after it, as the path kernel traces a vertex. The batch kernels keep 12
rays in flight per thread to overlap their memory waits, which a path tracer following
one path cannot do.
"""
import argparse
import math
import re
import time

import results  # benchmarks/results.py: the JSON record of this run (benchmarks/ is on sys.path)

import numpy as np

N_SPHERES = 256
GROUND_FRACTION = 1.0 / 8.0


def _cube_sphere(n):
    """Unit-sphere vertex directions and faces of a normalized cube, each face n×n quads.

    Returns (dirs (6 (n+1)², 3), faces (12 n², 3)); faces are counter-clockwise seen
    from outside. Vertices on the cube's edges are duplicated (the mesh is not welded).
    """
    s = np.linspace(-1.0, 1.0, n + 1)
    a, b = np.meshgrid(s, s, indexing="ij")
    a = a.ravel()
    b = b.ravel()
    one = np.ones_like(a)
    faces_pts = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            p = np.empty((a.size, 3))
            p[:, axis] = sign * one
            u, v = (axis + 1) % 3, (axis + 2) % 3
            if sign > 0:
                p[:, u] = a
                p[:, v] = b
            else:
                p[:, u] = b
                p[:, v] = a
            faces_pts.append(p)
    dirs = np.concatenate(faces_pts)
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    q00 = (i * (n + 1) + j).ravel()
    q10 = q00 + (n + 1)
    q01 = q00 + 1
    q11 = q10 + 1
    quad = np.concatenate([np.stack([q00, q10, q11], 1), np.stack([q00, q11, q01], 1)])
    faces = np.concatenate([quad + f * (n + 1) ** 2 for f in range(6)])
    return dirs, faces


def make_scene(n_target, seed=1):
    """(v0, v1, v2) float32 (T, 3) triangle corners of the benchmark world, T ≈ n_target."""
    rng = np.random.default_rng(seed)
    n_sphere_tris = n_target * (1.0 - GROUND_FRACTION)
    n = max(2, int(round(math.sqrt(n_sphere_tris / (12.0 * N_SPHERES)))))
    dirs, faces = _cube_sphere(n)
    clusters = rng.uniform([-12, -12, 1], [12, 12, 6], (8, 3))
    centre = clusters[rng.integers(0, 8, N_SPHERES)] + rng.normal(0, 2.5, (N_SPHERES, 3))
    centre[:, 2] = np.abs(centre[:, 2])
    radius = np.exp(rng.uniform(np.log(0.3), np.log(1.6), N_SPHERES))
    n_tri = N_SPHERES * faces.shape[0]
    g = max(1, int(round(math.sqrt(n_target * GROUND_FRACTION / 2.0))))
    total = n_tri + 2 * g * g
    out = [np.empty((total, 3), np.float32) for _ in range(3)]
    f = faces.shape[0]
    for k in range(N_SPHERES):
        w = rng.normal(size=(4, 3))
        w /= np.linalg.norm(w, axis=1)[:, None]
        freq = rng.uniform(2.0, 9.0, 4)
        amp = rng.uniform(0.02, 0.12, 4)
        phase = rng.uniform(0, 2 * np.pi, 4)
        r = 1.0 + np.sin((dirs @ w.T) * freq + phase) @ amp
        pts = (centre[k] + radius[k] * r[:, None] * dirs).astype(np.float32)
        for c in range(3):
            out[c][k * f:(k + 1) * f] = pts[faces[:, c]]
    # ground: a g×g grid of quads over [-20, 20]², gently rolling
    s = np.linspace(-20.0, 20.0, g + 1)
    x, y = np.meshgrid(s, s, indexing="ij")
    z = 0.15 * np.sin(0.7 * x) * np.cos(0.5 * y) - 1.0
    grid = np.stack([x, y, z], -1).reshape(-1, 3).astype(np.float32)
    i, j = np.meshgrid(np.arange(g), np.arange(g), indexing="ij")
    q00 = (i * (g + 1) + j).ravel()
    q10 = q00 + (g + 1)
    tri = np.concatenate([np.stack([q00, q10, q10 + 1], 1), np.stack([q00, q10 + 1, q00 + 1], 1)])
    for c in range(3):
        out[c][n_tri:] = grid[tri[:, c]]
    return out


def camera_rays(n_rays, seed=2):
    """Origins on a ring around the scene and directions in a 60° cone towards its centre."""
    rng = np.random.default_rng(seed)
    ang = np.arange(16) * (2 * np.pi / 16)
    cams = np.stack([30 * np.cos(ang), 30 * np.sin(ang), 8 + 4 * np.sin(3 * ang)], 1)
    k = rng.integers(0, 16, n_rays)
    o = cams[k]
    axis = np.array([0.0, 0.0, 2.0]) - o
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    # uniform directions in the cone of half-angle 30° about each axis
    cos_max = math.cos(math.radians(30.0))
    cz = rng.uniform(cos_max, 1.0, n_rays)
    phi = rng.uniform(0, 2 * np.pi, n_rays)
    sz = np.sqrt(1.0 - cz * cz)
    helper = np.where(np.abs(axis[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])
    t1 = np.cross(axis, helper)
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    t2 = np.cross(axis, t1)
    d = axis * cz[:, None] + t1 * (sz * np.cos(phi))[:, None] + t2 * (sz * np.sin(phi))[:, None]
    return np.ascontiguousarray(o), np.ascontiguousarray(d)


def shadow_rays(o, d, t, seed=3):
    """Segments from the hit points (nudged back along the ray) to an area light above."""
    rng = np.random.default_rng(seed)
    hit = np.isfinite(t)
    p = o[hit] + (t[hit] * (1.0 - 1e-5))[:, None] * d[hit]
    light = np.array([[-6.0, 4.0, 25.0], [5.0, -3.0, 25.0], [0.0, 0.0, 25.0], [8.0, 8.0, 25.0]])
    q = light[rng.integers(0, 4, p.shape[0])] + rng.uniform(-2, 2, (p.shape[0], 3)) * [1, 1, 0]
    w = q - p
    dist = np.linalg.norm(w, axis=1)
    return np.ascontiguousarray(p), np.ascontiguousarray(w / dist[:, None]), dist


def _status(key):
    with open("/proc/self/status") as f:
        return int(re.search(key + r":\s+(\d+)", f.read()).group(1)) * 1024


def _reset_peak():
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def tree_stats(bvh):
    """(depth, mean leaf size, SAH cost with unit record-visit and intersection costs)."""
    from spectral_gi.core.geometry.accel import tree_depth

    def area(box):
        ext = (box[:, 3:6] - box[:, 0:3]).astype(np.float64)
        return 2 * (ext[:, 0] * ext[:, 1] + ext[:, 1] * ext[:, 2] + ext[:, 2] * ext[:, 0])

    lk = bvh.links
    live = lk[0, 24:28] >= 0
    root_boxes = np.stack([bvh.child_boxes(c)[0] for c in range(4)])[live]
    root = area(np.concatenate([root_boxes[:, :3].min(0), root_boxes[:, 3:].max(0)])[None])[0]
    inner = 0.0
    for c in range(4):  # every record child, i.e. every record but the root's
        sel = (lk[:, 28 + c] == 0) & (lk[:, 24 + c] >= 0)
        inner += area(bvh.child_boxes(c)[sel]).sum()
    _, counts, _, boxes = bvh.leaves()
    cost = (root + inner + (area(boxes) * counts).sum()) / root
    return tree_depth(bvh), counts.mean(), cost


def build(size_m, n_rays):
    """Scene, tree, statistics and rays of one size (timing comes later, interleaved)."""
    from spectral_gi.core.geometry import accel
    from spectral_gi.core.geometry import bvh as K

    v0, v1, v2 = make_scene(int(size_m * 1_000_000))
    n = v0.shape[0]
    # warm the compiled kernels on a small scene so compile time is not counted
    w0, w1, w2 = make_scene(20_000)
    wb = accel.build(w0, w1, w2)
    wo, wd = camera_rays(1000)
    accel.closest(wb, wo, wd)
    accel.occluded(wb, wo, wd, np.full(1000, 10.0))
    del wb

    ok = _reset_peak()
    base = _status("VmRSS")
    t0 = time.perf_counter()
    c0 = time.thread_time()
    bvh = accel.build(v0, v1, v2)  # serial kernel on this thread
    cpu_build = time.thread_time() - c0
    t_build = time.perf_counter() - t0
    peak = _status("VmHWM") - base if ok else float("nan")
    del v0, v1, v2
    depth, leaf, cost = tree_stats(bvh)

    o, d = camera_rays(n_rays)
    tm = np.full(n_rays, np.inf)
    t, p = K.trace_closest_batch(o, d, tm, bvh.nodes, bvh.tris)
    so, sd, sdist = shadow_rays(o, d, t)
    return dict(n=n, build=t_build, build_cpu=cpu_build, kept=bvh.nbytes / n, peak=peak / n,
                nodes=bvh.n_nodes, depth=depth, leaf=leaf, cost=cost, hit=np.isfinite(t).mean(),
                bvh=bvh, rays=(o, d, tm), shadow=(so, sd, sdist), closest=0.0, occluded=0.0,
                closest_cpu=0.0, occluded_cpu=0.0)


_ONE_RAY = {}


def _one_ray_loops():
    """The serial one-ray loops, compiled once under the project's jit policy."""
    if not _ONE_RAY:
        from spectral_gi.core.jit import kernel
        from spectral_gi.core.geometry import bvh as K

        @kernel
        def closest_loop(o, d, nodes, tris):
            stack = np.empty(K.STACK_SIZE, np.int32)
            hits = 0
            for i in range(o.shape[0]):
                t = K.trace_closest(o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2], 0.0, np.inf,
                                    nodes, tris, stack)[0]
                if t < np.inf:
                    hits += 1
            return hits

        @kernel
        def occluded_loop(o, d, tmax, nodes, tris):
            stack = np.empty(K.STACK_SIZE, np.int32)
            hits = 0
            for i in range(o.shape[0]):
                if K.trace_occluded(o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2], 0.0, tmax[i],
                                    nodes, tris, stack):
                    hits += 1
            return hits

        @kernel
        def path_loop(o, d, so, sd, sdist, nodes, tris):
            """Each camera ray's closest hit, then at once the shadow ray from that hit, as
            the path kernel traces a vertex: rays traced (closest and shadow)."""
            stack = np.empty(K.STACK_SIZE, np.int32)
            k = 0
            for i in range(o.shape[0]):
                t = K.trace_closest(o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2], 0.0, np.inf,
                                    nodes, tris, stack)[0]
                if t < np.inf and k < so.shape[0]:
                    K.trace_occluded(so[k, 0], so[k, 1], so[k, 2], sd[k, 0], sd[k, 1], sd[k, 2], 0.0, sdist[k],
                                     nodes, tris, stack)
                    k += 1
            return o.shape[0] + k

        _ONE_RAY["closest"] = closest_loop
        _ONE_RAY["occluded"] = occluded_loop
        _ONE_RAY["path"] = path_loop
    return _ONE_RAY["closest"], _ONE_RAY["occluded"], _ONE_RAY["path"]


def time_one_ray(r, n_max=300_000):
    """One pass of the one-ray loops over size ``r``; keeps the best rates per CPU second."""
    closest_loop, occluded_loop, path_loop = _one_ray_loops()
    bvh = r["bvh"]
    o, d, _ = r["rays"]
    so, sd, sdist = r["shadow"]
    o, d, so, sd, sdist = o[:n_max], d[:n_max], so[:n_max], sd[:n_max], sdist[:n_max]
    # the shadow rays belong to the hits in ray order, so the path loop's k-th hit is the
    # origin of shadow ray k
    c0 = time.thread_time()
    n = path_loop(o, d, so, sd, sdist, bvh.nodes, bvh.tris)
    r["one_path"] = max(r.get("one_path", 0.0), n / (time.thread_time() - c0))
    c0 = time.thread_time()
    closest_loop(o, d, bvh.nodes, bvh.tris)
    r["one_closest"] = max(r.get("one_closest", 0.0), o.shape[0] / (time.thread_time() - c0))
    c0 = time.thread_time()
    occluded_loop(so, sd, sdist, bvh.nodes, bvh.tris)
    r["one_occluded"] = max(r.get("one_occluded", 0.0), so.shape[0] / (time.thread_time() - c0))


def time_round(r):
    """One timed pass of each query over size ``r``; keeps the best rates seen."""
    from spectral_gi.core.geometry import bvh as K

    bvh = r["bvh"]
    o, d, tm = r["rays"]
    so, sd, sdist = r["shadow"]
    t0 = time.perf_counter()
    c0 = time.process_time()
    K.trace_closest_batch(o, d, tm, bvh.nodes, bvh.tris)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    r["closest"] = max(r["closest"], o.shape[0] / wall)
    r["closest_cpu"] = max(r["closest_cpu"], o.shape[0] / cpu)
    t0 = time.perf_counter()
    c0 = time.process_time()
    occ = K.trace_occluded_batch(so, sd, sdist, bvh.nodes, bvh.tris)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    r["occluded"] = max(r["occluded"], so.shape[0] / wall)
    r["occluded_cpu"] = max(r["occluded_cpu"], so.shape[0] / cpu)
    r["occ"] = occ.mean()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", default="1,4,16", help="comma-separated millions of triangles")
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--reps", type=int, default=3, help="timing rounds (best kept)")
    ap.add_argument("--one-ray", action="store_true",
                    help="also time the path kernel's one-ray traversal (serial loop, one thread)")
    args = ap.parse_args()
    from spectral_gi.core.jit import set_threads

    threads = set_threads(args.threads)
    sizes = [float(s) for s in args.sizes.split(",") if s.strip()]
    rows = [build(s, args.rays) for s in sizes]
    if args.one_ray:  # compile the one-ray loops first, so compile time is not counted
        time_one_ray(rows[0], n_max=1000)
        rows[0].pop("one_closest")
        rows[0].pop("one_occluded")
        rows[0].pop("one_path")
    # every round times every size, so a burst of load from other jobs hits all sizes alike
    for _ in range(args.reps):
        for r in rows:
            time_round(r)
            if args.one_ray:
                time_one_ray(r)
    for r in rows:
        print(f"{r['n']:>10,d} tris: build {r['build']:6.2f} s ({r['build'] / r['n'] * 1e6:5.2f} s/M, "
              f"CPU {r['build_cpu']:.2f} s), "
              f"kept {r['kept']:5.1f} B/tri, peak build {r['peak']:5.1f} B/tri, {r['nodes']:,d} nodes, "
              f"depth {r['depth']}, leaf {r['leaf']:.2f}, SAH {r['cost']:.1f}; "
              f"closest {r['closest'] / 1e6:5.2f} Mrays/s (hit {r['hit']:.2f}), "
              f"occlusion {r['occluded'] / 1e6:5.2f} Mrays/s (blocked {r['occ']:.2f}); per CPU second: "
              f"closest {r['closest_cpu'] / 1e6:.2f} M, occlusion {r['occluded_cpu'] / 1e6:.2f} M", flush=True)
    print(f"\n{threads} threads, {args.rays:,d} camera rays per pass (best of {args.reps} rounds, each over all "
          "sizes in turn); rates are wall-clock, "
          "'/CPU-s' ones per CPU second of all threads (steadier on a shared machine); ratios use the latter")
    print("| triangles | build s (CPU s) | s per M | kept B/tri | peak build B/tri | depth | closest Mrays/s "
          "| occlusion Mrays/s | closest M/CPU-s | occlusion M/CPU-s | closest ratio | occlusion ratio "
          "| log2(N0)/log2(N) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    r0 = rows[0]
    for r in rows:
        print(f"| {r['n']:,d} | {r['build']:.2f} ({r['build_cpu']:.2f}) | {r['build'] / r['n'] * 1e6:.2f} "
              f"| {r['kept']:.1f} | {r['peak']:.1f} | {r['depth']} | {r['closest'] / 1e6:.2f} "
              f"| {r['occluded'] / 1e6:.2f} | {r['closest_cpu'] / 1e6:.2f} | {r['occluded_cpu'] / 1e6:.2f} "
              f"| {r['closest_cpu'] / r0['closest_cpu']:.3f} | {r['occluded_cpu'] / r0['occluded_cpu']:.3f} "
              f"| {math.log2(r0['n']) / math.log2(r['n']):.3f} |")
    if args.one_ray:
        print("\none-ray traversal (the path kernel's trace_closest / trace_occluded, serial, 1 thread, "
              "first 300,000 rays), per CPU second; 'path order' traces each closest hit's shadow ray "
              "right after it, as the path kernel does (rays of both kinds per CPU second):")
        print("| triangles | closest M/CPU-s | occlusion M/CPU-s | path order M/CPU-s | closest ratio "
              "| occlusion ratio | path order ratio | log2(N0)/log2(N) |")
        print("|---|---|---|---|---|---|---|---|")
        for r in rows:
            print(f"| {r['n']:,d} | {r['one_closest'] / 1e6:.2f} | {r['one_occluded'] / 1e6:.2f} "
                  f"| {r['one_path'] / 1e6:.2f} "
                  f"| {r['one_closest'] / r0['one_closest']:.3f} | {r['one_occluded'] / r0['one_occluded']:.3f} "
                  f"| {r['one_path'] / r0['one_path']:.3f} | {math.log2(r0['n']) / math.log2(r['n']):.3f} |")
    tables = [results.table(
        f"BVH build and batch traversal, {threads} threads, {args.rays:,d} camera rays and their shadow rays, "
        f"best of {args.reps} rounds; rays per CPU second",
        ["triangles", "build s (CPU s)", "kept B/tri", "peak build B/tri", "depth", "closest M/CPU-s",
         "occlusion M/CPU-s", "closest ratio", "occlusion ratio", "log2(N0)/log2(N)"],
        [[r["n"], f"{r['build']:.2f} ({r['build_cpu']:.2f})", round(r["kept"], 1), round(r["peak"], 1), r["depth"],
          round(r["closest_cpu"] / 1e6, 2), round(r["occluded_cpu"] / 1e6, 2),
          round(r["closest_cpu"] / r0["closest_cpu"], 3), round(r["occluded_cpu"] / r0["occluded_cpu"], 3),
          round(math.log2(r0["n"]) / math.log2(r["n"]), 3)] for r in rows])]
    if args.one_ray:
        tables.append(results.table(
            "The path kernel's one-ray traversal (serial, 1 thread, first 300,000 rays), rays per CPU second",
            ["triangles", "closest M/CPU-s", "occlusion M/CPU-s", "path order M/CPU-s", "closest ratio",
             "occlusion ratio", "path order ratio", "log2(N0)/log2(N)"],
            [[r["n"], round(r["one_closest"] / 1e6, 2), round(r["one_occluded"] / 1e6, 2),
              round(r["one_path"] / 1e6, 2), round(r["one_closest"] / r0["one_closest"], 3),
              round(r["one_occluded"] / r0["one_occluded"], 3), round(r["one_path"] / r0["one_path"], 3),
              round(math.log2(r0["n"]) / math.log2(r["n"]), 3)] for r in rows]))
    results.write("scale_bench", tables, conditions={"sizes": args.sizes, "rays": args.rays, "threads": threads,
                                                     "reps": args.reps, "one_ray": args.one_ray})


if __name__ == "__main__":
    main()
