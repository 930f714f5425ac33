"""Cold-start compile time of the first render (target: under 60 s, with a visible message).

    python benchmarks/compile_bench.py [--serial] [--record]

Each run is a fresh Python process with an empty numba cache folder (a temporary
SPECTRAL_GI_CACHE_DIR) rendering the built-in Cornell box at 16x16, 1 spp, as the quick
start's first render does. It prints the wall time from process start to the end of the
first render, the time spent compiling (RenderStats.compile_seconds, after the scene is
prepared), the status messages with their times, and the ratio to the 60 s target:
first with the second compile process (core/warmup.py), then, with --serial, without it
(SPECTRAL_GI_PARALLEL_COMPILE=0) and the speed-up. The machine has to be otherwise idle
for the figures to mean anything: the two processes need two free cores.

--record re-records core/compile_plan.py (the helpers' argument types) first.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import results  # benchmarks/results.py: the JSON record of this run (benchmarks/ is on sys.path)

TARGET = 60.0

_CHILD = r"""
import json, time
t0 = time.perf_counter()
from spectral_gi import core
msgs = []
film, st = core.render(core.cornell_box(16, 16, spp=1, max_depth=4), threads=1,
                       status=lambda m: msgs.append((round(time.perf_counter() - t0, 1), m)))
print(json.dumps({"total": time.perf_counter() - t0, "compile": st.compile_seconds, "messages": msgs}))
"""


def cold_run(parallel):
    with tempfile.TemporaryDirectory(prefix="sgi-compile-") as cache:
        env = dict(os.environ, SPECTRAL_GI_CACHE_DIR=cache, SPECTRAL_GI_PARALLEL_COMPILE="1" if parallel else "0")
        out = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True, env=env, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--serial", action="store_true", help="also time the compile in one process")
    ap.add_argument("--record", action="store_true", help="re-record core/compile_plan.py first")
    a = ap.parse_args()
    if a.record:
        from spectral_gi import core
        from spectral_gi.core.integrators import warmup

        core.render(core.cornell_box(8, 8, spp=1, max_depth=4), threads=1)
        entries = warmup.record()
        warmup.write_plan(entries)
        print(f"recorded {len(entries)} helpers in core/compile_plan.py")
    print(f"cores: {os.cpu_count()}, load average before: {os.getloadavg()[0]:.2f}")
    runs = [("two processes", True)] + ([("one process", False)] if a.serial else [])
    res = {}
    for label, parallel in runs:
        r = cold_run(parallel)
        res[label] = r
        print(f"{label:14s}: first render done {r['total']:6.1f} s after start (compiling {r['compile']:5.1f} s "
              f"after the scene was prepared); target {TARGET:.0f} s: ratio {r['total'] / TARGET:.2f}"
              f" -> {'met' if r['total'] < TARGET else 'NOT met'}")
        print("                " + "; ".join(f"{t:.1f} s {m}" for t, m in r["messages"]))
    if a.serial:
        print(f"speed-up of the second process: {res['one process']['total'] / res['two processes']['total']:.2f}x")
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    results.write("compile_bench", [results.table(
        "First render on a cold cache (the Cornell box, 16², 1 spp, in a fresh process with an empty cache folder)",
        ["compile", "done after (s)", "of which compiling after the scene is prepared (s)", "target (s)"],
        [[label, round(r["total"], 1), round(r["compile"], 1), TARGET] for label, r in res.items()])],
        conditions={"cores": os.cpu_count()})


if __name__ == "__main__":
    main()
