"""Restart latency of the interactive (viewport) render.

    python benchmarks/viewport_restart.py [--width 640] [--height 360] [--threads 0] [--reps 5]

Renders the core Cornell box with ``core.InteractiveRender`` (coarse passes at pixel size
4 and 2, then full resolution) and, while it refines, changes the camera, a material's
spectrum, and one mesh's position. For each kind of change it prints the time from
``update()`` to the first frame of the new generation (median and worst of ``reps``),
and whether the BVH was rebuilt. The add-on's own export (depsgraph → core scene) comes on
top of these figures; tests/addon/test_addon_viewport.py prints the whole latency in
Blender for a small scene.
"""
import argparse
import dataclasses
import statistics
import time

import numpy as np

import results  # benchmarks/results.py: the JSON record of this run

from spectral_gi.core import InteractiveRender, cornell_box


def changes(scene):
    """(label, kwargs of update()) for each kind of change, a new value at each call."""
    state = {"k": 0}

    def camera():
        state["k"] += 1
        to_world = np.array(scene.camera.to_world, dtype=np.float64)
        to_world[0, 3] += 0.001 * state["k"]
        return {"camera": dataclasses.replace(scene.camera, to_world=to_world)}

    def material():
        state["k"] += 1
        spectra = dataclasses.replace(scene.spectra, coeffs=scene.spectra.coeffs.copy())
        red = next(m for m in scene.materials if m.name == "red")
        spectra.coeffs[red.reflectance] *= 1.0 - 0.01 * (state["k"] % 10)
        return {"scene": dataclasses.replace(scene, spectra=spectra)}

    def geometry():
        state["k"] += 1
        meshes = list(scene.meshes)
        meshes[-1] = dataclasses.replace(meshes[-1], positions=meshes[-1].positions + np.float32(1e-3 * state["k"]))
        return {"scene": dataclasses.replace(scene, meshes=meshes)}

    return [("view (camera only)", camera), ("material (BVH kept)", material), ("geometry (BVH rebuilt)", geometry)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=360)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--reps", type=int, default=5)
    a = ap.parse_args()
    scene = cornell_box(width=a.width, height=a.height, spp=1 << 20, max_depth=8)
    s = InteractiveRender(threads=a.threads or None).start()
    rows = []
    try:
        gen = s.update(scene=scene)
        assert s.wait_frame(gen, spp=4, timeout=1800) is not None, s.error
        for label, make in changes(scene):
            times, builds = [], s.counters.bvh_builds
            for _ in range(a.reps):
                assert s.wait_frame(s.generation, spp=2, timeout=120) is not None, s.error  # refining again
                t0 = time.perf_counter()
                gen = s.update(**make())
                f = s.wait_frame(gen, timeout=120)
                assert f is not None, s.error
                times.append(f.restart_seconds)
                print(f"{label}: {time.perf_counter() - t0:.3f} s to the first frame (pixel size {f.pixel_size})")
            rows.append([label, round(statistics.median(times), 4), round(max(times), 4),
                         s.counters.bvh_builds - builds])
    finally:
        s.stop(wait=10)
    for r in rows:
        print(f"{r[0]:<24} median {r[1]:.3f} s, worst {r[2]:.3f} s, BVH builds {r[3]}")
    results.write("viewport_restart", [results.table(
        f"Interactive render restart, Cornell box {a.width}×{a.height}, update → first coarse frame",
        ["change", "median s", "worst s", "BVH builds"], rows)],
        conditions={"width": a.width, "height": a.height, "threads": a.threads or "all", "reps": a.reps})


if __name__ == "__main__":
    main()
