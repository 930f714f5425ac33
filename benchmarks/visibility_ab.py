"""Scenes without visibility flags are not slower: paired A/B renders in one process.

    python benchmarks/visibility_ab.py --base DIR [--pairs 9] [--cold]

DIR holds another checkout of the package (for instance ``git archive <commit>`` unpacked
there) as a folder of any name that is a Python identifier; it is imported under that name
beside this checkout's ``spectral_gi``. Each pair renders the same scene with both, in an
order that alternates, after one render each to compile and warm up; the figure is the
median of the ratios of their render times (base / this, so ≥ 1 is faster). Scenes: the
built-in Cornell box and ColorChecker, which use no visibility flag (the path kernel takes
its visibility record as None). With --cold it also times the first render of the Cornell
box in fresh processes with an empty numba cache (compile_bench.py's measure), alternating
base and this checkout.
"""
import argparse
import importlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

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
            "ColorChecker": builtin.colorchecker(width=size, height=size, spp=spp)}


def _time(core, scene):
    t0 = time.perf_counter()
    core.render(scene, threads=1)
    return time.perf_counter() - t0


def cold(pkg, path):
    with tempfile.TemporaryDirectory(prefix="sgi-ab-") as cache:
        env = dict(os.environ, SPECTRAL_GI_CACHE_DIR=cache, PYTHONPATH=path)
        out = subprocess.run([sys.executable, "-c", _COLD, pkg], capture_output=True, text=True, env=env, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", required=True, help="folder holding the base checkout as a package")
    ap.add_argument("--pairs", type=int, default=9)
    ap.add_argument("--size", type=int, default=48)
    ap.add_argument("--spp", type=int, default=8)
    ap.add_argument("--cold", action="store_true", help="also time cold first renders (compile)")
    a = ap.parse_args()
    base_dir = os.path.abspath(a.base)
    base_name = os.path.basename(base_dir.rstrip("/"))
    sys.path.insert(0, os.path.dirname(base_dir))
    base = importlib.import_module(base_name + ".core")
    this = importlib.import_module("spectral_gi.core")
    rows = []
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
        print(f"{name}: median speed ratio (base time / this time) {med:.3f} over {a.pairs} pairs "
              f"(min {min(ratios):.3f}, max {max(ratios):.3f})")
        rows.append([name, round(med, 3), round(min(ratios), 3), round(max(ratios), 3), a.pairs])
    tables = [results.table("Scenes without visibility flags: render time of the base over this checkout",
                            ["scene", "median ratio", "min", "max", "pairs"], rows)]
    if a.cold:
        this_parent = os.path.dirname(os.path.dirname(os.path.abspath(this.__file__)))
        cold_rows = []
        tb, tt = [], []
        for k in range(2):
            order = ((base_name, os.path.dirname(base_dir), tb), ("spectral_gi", this_parent, tt))
            for pkg, path, out in (order if k % 2 == 0 else order[::-1]):
                out.append(cold(pkg, path)["total"])
        mb, mt = statistics.median(tb), statistics.median(tt)
        print(f"cold first render (Cornell box 16x16, 1 spp): base {mb:.1f} s, this {mt:.1f} s, "
              f"ratio {mt / mb:.3f}")
        cold_rows.append(["Cornell box, 16×16, 1 spp", round(mb, 1), round(mt, 1), round(mt / mb, 3)])
        tables.append(results.table("Cold first render (compile included), median of 2 fresh processes each",
                                    ["scene", "base s", "this s", "this / base"], cold_rows))
    results.write("visibility_ab", tables=tables,
                  conditions={"size": a.size, "spp": a.spp, "pairs": a.pairs, "threads": 1, "base": base_name})


if __name__ == "__main__":
    main()
