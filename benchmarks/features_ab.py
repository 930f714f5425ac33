"""Scenes that use none of the optional features are not slower: paired A/B renders in one process.

    python benchmarks/features_ab.py --base DIR [--pairs 9] [--cold]

The optional features are those a scene compiles only when it uses them: shader programs,
image textures, hair, visibility flags and linking, adaptive sampling. The base is a
checkout without them (or with fewer); the figure shows what they cost a scene that has
none of them.

DIR holds another checkout of the package (for instance ``git archive <commit>`` unpacked
there) as a folder of any name that is a Python identifier; it is imported under that name
beside this checkout's ``spectral_gi``. Each pair renders the same scene with both, in an
order that alternates, after one render each to compile and warm up; the figure is the
median of the ratios of their render times in CPU seconds on one thread (base / this, so
≥ 1 is faster; on a shared machine CPU time is far steadier than wall time). Scenes: the
built-in Cornell box, the ColorChecker and an interior (a 5 × 4 × 2.6 m room lit by the sun
and the sky through a window, with a rough plastic floor, a table and a shelf), none of
which uses an optional feature (the path kernel takes their records as None). With --cold
it also times the first render of the Cornell box in fresh processes with an empty numba
cache (compile_bench.py's measure), alternating base and this checkout, in wall and in CPU
seconds (the process and its second compile process).
"""
import argparse
import importlib
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import results  # benchmarks/results.py (benchmarks/ is on sys.path)

_COLD = r"""
import importlib, json, sys, time
t0 = time.perf_counter()
core = importlib.import_module(sys.argv[1] + ".core")
film, st = core.render(core.cornell_box(16, 16, spp=1, max_depth=4), threads=1)
print(json.dumps({"total": time.perf_counter() - t0, "compile": st.compile_seconds}))
"""


def _scenes(core, size, spp):
    builtin = importlib.import_module(core.__name__ + ".scene.builtin")
    return {"Cornell box": core.cornell_box(size, size, spp=spp, max_depth=8),
            "ColorChecker": builtin.colorchecker(width=size, height=size, spp=spp),
            "Interior": interior(core, size, spp)}


def _box(lo, hi):
    """(positions (8, 3), triangles (12, 3)) of an axis-aligned box, faces outwards."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    p = np.array([[x, y, z] for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)], np.float32)
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    t = [(a, b, c) for a, b, c, d in quads] + [(a, c, d) for a, b, c, d in quads]
    return p, np.array(t, np.int32)


def _quad(*corners):
    return np.array(corners, np.float32), np.array([[0, 1, 2], [0, 2, 3]], np.int32)


def interior(core, size, spp):
    """A room of 5 × 4 × 2.6 m with a 2 × 1.4 m window in its south wall (y = 0): the sun
    (60 000 lx, 40° up) and a sky rectangle (4000 cd/m²) in the opening; white walls and
    ceiling, a rough plastic floor, a table and a shelf (plastic, Cycles' layering). It
    uses the core API that every checkout has, so both sides render the same scene."""
    C = importlib.import_module(core.__name__ + ".constants")
    params = importlib.import_module(core.__name__ + ".bsdfs.params")
    uplift = importlib.import_module(core.__name__ + ".spectra.uplift")
    spectra = core.SpectrumTable.empty(C.N_COEFFS_DEFAULT)

    def grey(name, rho):
        return spectra.add(name, uplift.reflectance_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX], [rho, rho],
                                                                 C.N_COEFFS_DEFAULT), C.SPECTRUM_BOUNDED)
    wood = spectra.add("wood", uplift.reflectance_from_samples([400.0, 500.0, 600.0, 700.0], [0.08, 0.15, 0.35, 0.45],
                                                               C.N_COEFFS_DEFAULT), C.SPECTRUM_BOUNDED)
    daylight = spectra.add("daylight", uplift.emission_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX], [1.0, 1.0],
                                                                    C.N_COEFFS_DEFAULT), C.SPECTRUM_UNBOUNDED)
    rough = params.plastic_params(0.3 ** 2, layering="cycles")
    materials = [core.Material(name="wall", reflectance=grey("wall", 0.8)),
                 core.Material(name="floor", model=C.MAT_PLASTIC, reflectance=wood, params=list(rough)),
                 core.Material(name="furniture", model=C.MAT_PLASTIC, reflectance=grey("furniture", 0.5),
                               params=list(params.plastic_params(0.5 ** 2, layering="cycles")))]
    w, d, h = 5.0, 4.0, 2.6
    wx0, wx1, wz0, wz1 = 1.5, 3.5, 0.9, 2.3
    parts = [("floor", 1, _quad((0, 0, 0), (w, 0, 0), (w, d, 0), (0, d, 0))),
             ("ceiling", 0, _quad((0, 0, h), (0, d, h), (w, d, h), (w, 0, h))),
             ("north", 0, _quad((0, d, 0), (w, d, 0), (w, d, h), (0, d, h))),
             ("west", 0, _quad((0, 0, 0), (0, d, 0), (0, d, h), (0, 0, h))),
             ("east", 0, _quad((w, 0, 0), (w, 0, h), (w, d, h), (w, d, 0))),
             ("south below", 0, _quad((0, 0, 0), (0, 0, wz0), (w, 0, wz0), (w, 0, 0))),
             ("south above", 0, _quad((0, 0, wz1), (0, 0, h), (w, 0, h), (w, 0, wz1))),
             ("south left", 0, _quad((0, 0, wz0), (0, 0, wz1), (wx0, 0, wz1), (wx0, 0, wz0))),
             ("south right", 0, _quad((wx1, 0, wz0), (wx1, 0, wz1), (w, 0, wz1), (w, 0, wz0))),
             ("table", 2, _box((1.8, 1.6, 0.7), (3.4, 2.6, 0.75))),
             ("table leg", 2, _box((1.85, 1.65, 0.0), (1.95, 1.75, 0.7))),
             ("table leg 2", 2, _box((3.25, 2.45, 0.0), (3.35, 2.55, 0.7))),
             ("shelf", 2, _box((0.2, 3.6, 0.0), (1.6, 3.95, 1.8)))]
    meshes = [core.Mesh(name=n, positions=p, indices=t, material=np.full(t.shape[0], m, np.int32))
              for n, m, (p, t) in parts]
    e = math.radians(40.0)
    lights = [core.Light(name="sun", kind=C.LIGHT_SUN, position=(0.0, 0.0, 0.0), axis_u=(0.0, 0.0, 0.0),
                         axis_v=(0.0, 0.0, 0.0), spectrum=daylight, luminance=0.0, illuminance=60000.0,
                         direction=(0.3 * math.cos(e), math.cos(e), -math.sin(e)), angle=math.radians(0.53)),
              core.Light(name="sky", kind=C.LIGHT_RECT, position=((wx0 + wx1) / 2, -0.01, (wz0 + wz1) / 2),
                         axis_u=(0.0, 0.0, (wz1 - wz0) / 2), axis_v=((wx1 - wx0) / 2, 0.0, 0.0),
                         spectrum=daylight, luminance=4000.0)]
    to_world = np.eye(4)
    fwd = np.array([-0.35, 1.0, -0.25])
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    to_world[:3, 0], to_world[:3, 1], to_world[:3, 2] = right, np.cross(right, fwd), -fwd
    to_world[:3, 3] = (4.4, 0.4, 1.6)
    camera = core.Camera(to_world=to_world, width=int(size), height=int(size), lens_mm=20.0, sensor_width_mm=36.0)
    return core.Scene(meshes=meshes, spectra=spectra, materials=materials, lights=lights, camera=camera,
                      settings=core.RenderSettings(spp=int(spp), max_depth=8, seed=0), metadata={"name": "Interior"})


def _time(core, scene):
    """CPU seconds of one render on one thread: on a shared machine far steadier than its
    wall time, which the other jobs stretch."""
    t0 = time.process_time()
    core.render(scene, threads=1)
    return time.process_time() - t0


def cold(pkg, path):
    """The first render in a fresh process with an empty cache: its wall seconds and the CPU
    seconds of the process and its second compile process."""
    with tempfile.TemporaryDirectory(prefix="sgi-ab-") as cache:
        env = dict(os.environ, SPECTRAL_GI_CACHE_DIR=cache, PYTHONPATH=path)
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        out = subprocess.run([sys.executable, "-c", _COLD, pkg], capture_output=True, text=True, env=env, check=True)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    res = json.loads(out.stdout.strip().splitlines()[-1])
    res["cpu"] = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", required=True, help="folder holding the base checkout as a package")
    ap.add_argument("--pairs", type=int, default=9)
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--cold", action="store_true", help="also time cold first renders (compile)")
    ap.add_argument("--cold-runs", type=int, default=2, help="fresh processes per checkout")
    ap.add_argument("--base-label", help="what the base is, for the record (e.g. its commit)")
    a = ap.parse_args()
    base_dir = os.path.abspath(a.base)
    base_name = os.path.basename(base_dir.rstrip("/"))
    sys.path.insert(0, os.path.dirname(base_dir))
    rows = []
    medians = {}
    for this_first in (False, True):
        # the package imported first runs faster by a few per cent (two copies of one commit:
        # 0.94 in 21 pairs on a shared machine; where its code lands in memory), so each
        # order is measured and the figure is the geometric mean of the two
        base, this = _import_both(base_name, this_first)
        _pairs(a, base, this, this_first, rows, medians)
    for name, (m0, m1) in medians.items():
        g = math.sqrt(m0 * m1)
        print(f"{name}: geometric mean of the two orders {g:.3f}")
        rows.append([name, "geometric mean of both orders", round(g, 3), "", "", ""])
    tables = [results.table("Scenes without optional features: render time of the base over this checkout",
                            ["scene", "imported first", "median ratio", "min", "max", "pairs"], rows)]
    _cold_table(a, base_dir, base_name, this, tables)
    results.write("features_ab", tables=tables,
                  conditions={"size": a.size, "spp": a.spp, "pairs": a.pairs, "threads": 1,
                              "base": a.base_label or base_name, "time": "CPU seconds (process_time) per render"})


def _import_both(base_name, this_first):
    """(base core, this core), imported in a fresh state in the given order."""
    for mod in [m for m in sys.modules if m.split(".")[0] in (base_name, "spectral_gi")]:
        del sys.modules[mod]
    order = ["spectral_gi", base_name] if this_first else [base_name, "spectral_gi"]
    cores = {n: importlib.import_module(n + ".core") for n in order}
    return cores[base_name], cores["spectral_gi"]


def _pairs(a, base, this, this_first, rows, medians):
    for name in _scenes(this, a.size, a.spp):
        sb = _scenes(base, a.size, a.spp)[name]
        st = _scenes(this, a.size, a.spp)[name]
        _time(base, sb)
        _time(this, st)
        ratios = []
        for k in range(a.pairs):
            if k % 2:
                tt, tb = _time(this, st), _time(base, sb)
            else:
                tb, tt = _time(base, sb), _time(this, st)
            ratios.append(tb / tt)
        med = statistics.median(ratios)
        first = "this" if this_first else "base"
        print(f"{name} ({first} imported first): median speed ratio (base time / this time) {med:.3f} over "
              f"{a.pairs} pairs (min {min(ratios):.3f}, max {max(ratios):.3f})")
        rows.append([name, first, round(med, 3), round(min(ratios), 3), round(max(ratios), 3), a.pairs])
        medians.setdefault(name, []).append(med)


def _cold_table(a, base_dir, base_name, this, tables):
    if a.cold:
        this_parent = os.path.dirname(os.path.dirname(os.path.abspath(this.__file__)))
        cold_rows = []
        tb, tt = [], []
        for k in range(a.cold_runs):
            order = ((base_name, os.path.dirname(base_dir), tb), ("spectral_gi", this_parent, tt))
            for pkg, path, out in (order if k % 2 == 0 else order[::-1]):
                out.append(cold(pkg, path))
        for key, what in (("total", "wall"), ("cpu", "CPU")):
            mb = statistics.median(r[key] for r in tb)
            mt = statistics.median(r[key] for r in tt)
            print(f"cold first render (Cornell box 16x16, 1 spp), {what} s: base {mb:.1f}, this {mt:.1f}, "
                  f"ratio {mt / mb:.3f}")
            cold_rows.append([f"Cornell box, 16×16, 1 spp ({what} s)", round(mb, 1), round(mt, 1), round(mt / mb, 3)])
        tables.append(results.table(f"Cold first render (compile included), median of {a.cold_runs} fresh processes "
                                    "each", ["measure", "base", "this", "this / base"], cold_rows))


if __name__ == "__main__":
    main()
