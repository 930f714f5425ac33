"""Scenes without visibility flags are not slower: paired A/B renders in one process.

    python benchmarks/visibility_ab.py --base DIR [--pairs 9] [--cold]

DIR holds another checkout of the package (for instance ``git archive <commit>`` unpacked
there) as a folder of any name that is a Python identifier; it is imported under that name
beside this checkout's ``spectral_gi``. Each pair renders the same scene with both, in an
order that alternates, after one render each to compile and warm up; the figure is the
median of the ratios of their render times in CPU seconds on one thread (base / this, so
≥ 1 is faster; on a shared machine CPU time is far steadier than wall time). Scenes: the
built-in Cornell box and ColorChecker, which use no visibility flag (the path kernel takes
its visibility record as None). With --cold it also times the first render of the Cornell
box in fresh processes with an empty numba cache (compile_bench.py's measure), alternating
base and this checkout, in wall and in CPU seconds (the process and its second compile
process).
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
    tables = [results.table("Scenes without visibility flags: render time of the base over this checkout",
                            ["scene", "imported first", "median ratio", "min", "max", "pairs"], rows)]
    _cold_table(a, base_dir, base_name, this, tables)
    results.write("visibility_ab", tables=tables,
                  conditions={"size": a.size, "spp": a.spp, "pairs": a.pairs, "threads": 1, "base": base_name,
                              "time": "CPU seconds (process_time) per render"})


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
