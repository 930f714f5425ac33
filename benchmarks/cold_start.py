"""Cold and warm start: the quick start's first Cornell render on an empty kernel cache, then again.

    python benchmarks/cold_start.py [--size 256] [--spp 64] [--profile]

Each run is a fresh Python process rendering the built-in Cornell box (256², 64 spp, as
``spectral-gi render`` does) with ``core.render``; the kernel cache is a temporary folder
(``SPECTRAL_GI_CACHE_DIR``), empty for the cold run and left as the cold run filled it for
the warm one. For each it prints the time from the process's start to: ``core`` imported,
the scene prepared (the BVH builder compiled on a cold start), the kernels compiled (or
loaded), the first pass on screen, and the last; and the render's own time. The cold run
uses the second compile process (core/warmup.py) as a first render does.

``--blender`` installs the Blender extension (built by ``tools/build_extension.py``) in
background bpy with an empty cache and times its background compile (``addon/background.py``,
started when the extension is enabled) and then an F12 render of the Cornell box.
``--profile`` adds a process, cold again and compiling in one process
(``SPECTRAL_GI_PARALLEL_COMPILE=0``), that listens to numba's compile events and prints
where the compile time goes: each function's own time (its callees' compiles taken out),
summed by module, and the largest functions. Installing the package (pip) is not timed:
its time is the network's.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import results  # benchmarks/results.py: the JSON record of this run (benchmarks/ is on sys.path)

_CHILD = r"""
import json, sys, time
t0 = time.perf_counter()
size, spp, profile = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3] == "1"
own = {}
if profile:
    from numba.core import event

    stack = []

    class Listener(event.Listener):
        def on_start(self, ev):
            f = ev.data["dispatcher"].py_func
            stack.append([f.__module__.split(".core.", 1)[-1] + "." + f.__qualname__, time.perf_counter(), 0.0])

        def on_end(self, ev):
            name, ts, child = stack.pop()
            dt = time.perf_counter() - ts
            own[name] = own.get(name, 0.0) + dt - child
            if stack:
                stack[-1][2] += dt

    event.register("numba:compile", Listener())
from spectral_gi import core
t_import = time.perf_counter() - t0
marks = {}

def status(text):
    if text == "Rendering":
        marks.setdefault("kernels", time.perf_counter() - t0)

def on_pass(film):
    marks.setdefault("first_pass", time.perf_counter() - t0)

film, st = core.render(core.cornell_box(size, size, spp=spp), status=status, on_pass=on_pass)
print(json.dumps({"import": t_import, "prepared": marks["kernels"] - st.compile_seconds, "kernels": marks["kernels"],
                  "first_pass": marks["first_pass"], "done": time.perf_counter() - t0, "build": st.build_seconds,
                  "compile": st.compile_seconds, "render": st.seconds, "spp": st.spp, "own": own}))
"""


_BLENDER = r"""
import importlib.util, json, os, sys, tempfile, time
t0 = time.perf_counter()
os.environ["BLENDER_USER_RESOURCES"] = tempfile.mkdtemp(prefix="sgi-blender-user-")
repo = sys.argv[1]
import bpy
spec = importlib.util.spec_from_file_location("build_extension", os.path.join(repo, "tools", "build_extension.py"))
tool = importlib.util.module_from_spec(spec)
spec.loader.exec_module(tool)
zip_path = tool.build(tempfile.mkdtemp(prefix="sgi-dist-"), quiet=True)
t_start = time.perf_counter()
assert bpy.ops.extensions.package_install_files(filepath=str(zip_path), repo="user_default",
                                                enable_on_install=True) == {"FINISHED"}
t_enabled = time.perf_counter() - t_start
bg = sys.modules["bl_ext.user_default.spectral_gi.addon.background"]
while bg.running():
    time.sleep(0.05)
t_ready = time.perf_counter() - t_start
status = bg.status_text()
bpy.ops.wm.read_homefile(use_empty=True)
bpy.ops.spectral_gi.add_cornell_box()
scene = bpy.context.scene
scene.render.engine = "SPECTRAL_GI"
scene.spectral_gi.samples = int(sys.argv[2])
t = time.perf_counter()
bpy.ops.render.render()
t_render = time.perf_counter() - t
job = sys.modules["bl_ext.user_default.spectral_gi.addon.render_job"]
print(json.dumps({"enabled": t_enabled, "ready": t_ready, "status": status, "f12": t_render,
                  "message": job.STATE.message, "size": scene.render.resolution_x}))
"""


def run_blender(cache, spp):
    """Install and enable the extension in background bpy with an empty kernel cache; the
    background compile's time, then F12 on the Cornell box."""
    env = dict(os.environ, SPECTRAL_GI_CACHE_DIR=cache)
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    out = subprocess.run([sys.executable, "-c", _BLENDER, repo, str(spp)], capture_output=True, text=True, env=env)
    if out.returncode != 0:
        raise SystemExit(out.stderr[-3000:])
    return json.loads(out.stdout.strip().splitlines()[-1])


def run(cache, size, spp, profile=False, parallel=True):
    env = dict(os.environ, SPECTRAL_GI_CACHE_DIR=cache, SPECTRAL_GI_PARALLEL_COMPILE="1" if parallel else "0")
    t = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", _CHILD, str(size), str(spp), "1" if profile else "0"],
                         capture_output=True, text=True, env=env)
    if out.returncode != 0:
        raise SystemExit(out.stderr[-3000:])
    r = json.loads(out.stdout.strip().splitlines()[-1])
    r["process"] = time.perf_counter() - t
    return r


def module_of(name):
    parts = name.split(".")
    return ".".join(parts[:-1]) if len(parts) > 1 else name


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--profile", action="store_true", help="also profile a one-process cold compile")
    ap.add_argument("--blender", action="store_true",
                    help="also install the extension in background bpy on an empty cache and time its background "
                         "compile and the first F12")
    a = ap.parse_args()
    print(f"cores: {os.cpu_count()}, load average before: {os.getloadavg()[0]:.2f}")
    runs = {}
    with tempfile.TemporaryDirectory(prefix="sgi-cold-") as cache:
        runs["cold"] = run(cache, a.size, a.spp)
        runs["warm"] = run(cache, a.size, a.spp)
    for label, r in runs.items():
        print(f"{label}: import {r['import']:.1f} s, scene prepared {r['prepared']:.1f} s (BVH {r['build']:.1f} s), "
              f"kernels {'compiled' if label == 'cold' else 'loaded'} {r['kernels']:.1f} s ({r['compile']:.1f} s of "
              f"it), first pass {r['first_pass']:.1f} s, done {r['done']:.1f} s after the start (process "
              f"{r['process']:.1f} s); the render itself {r['render']:.1f} s for {r['spp']} spp")
    tables = [results.table(
        f"First Cornell render ({a.size}², {a.spp} spp) in a fresh process, seconds from the process's start",
        ["cache", "core imported", "scene prepared (BVH builder compiled)", "kernels ready",
         "of which compiling / loading", "first pass", "done", "render itself"],
        [[label, round(r["import"], 1), round(r["prepared"], 1), round(r["kernels"], 1), round(r["compile"], 1),
          round(r["first_pass"], 1), round(r["done"], 1), round(r["render"], 1)]
         for label, r in (("empty (cold)", runs["cold"]), ("filled (warm)", runs["warm"]))])]
    if a.blender:
        with tempfile.TemporaryDirectory(prefix="sgi-blender-") as cache:
            b = run_blender(cache, a.spp)
        print(f"Blender: extension installed and enabled {b['enabled']:.1f} s, background compile done "
              f"{b['ready']:.1f} s after the install started ({b['status']}); then F12 on the Cornell box "
              f"({b['size']}², {a.spp} spp) {b['f12']:.1f} s: {b['message']}")
        tables.append(results.table(
            "The extension installed in Blender (background bpy) on an empty kernel cache, seconds from the install",
            ["installed and enabled", "background compile done", "status",
             f"then F12, Cornell {b['size']}², {a.spp} spp"],
            [[round(b["enabled"], 1), round(b["ready"], 1), b["status"], round(b["f12"], 1)]]))
    if a.profile:
        with tempfile.TemporaryDirectory(prefix="sgi-profile-") as cache:
            p = run(cache, 16, 1, profile=True, parallel=False)
        own = p["own"]
        total = sum(own.values())
        by_module = {}
        for name, t in own.items():
            by_module[module_of(name)] = by_module.get(module_of(name), 0.0) + t
        print(f"one-process cold compile: kernels ready {p['kernels']:.1f} s after the start; numba compile "
              f"events {total:.1f} s over {len(own)} functions")
        mods = sorted(by_module.items(), key=lambda kv: -kv[1])
        for m, t in mods:
            n = sum(1 for k in own if module_of(k) == m)
            print(f"  {t:6.1f} s  {100 * t / total:4.1f} %  {m} ({n} functions)")
        top = sorted(own.items(), key=lambda kv: -kv[1])[:15]
        print("largest functions:")
        for k, t in top:
            print(f"  {t:6.1f} s  {k}")
        tables.append(results.table(
            "Where a one-process cold compile goes (Cornell box; each function's own compile time, its callees' "
            "taken out), by module under core",
            ["module", "functions", "seconds", "share"],
            [[m, sum(1 for k in own if module_of(k) == m), round(t, 1), f"{100 * t / total:.0f} %"]
             for m, t in mods] + [["all", len(own), round(total, 1), "100 %"]]))
        tables.append(results.table("The fifteen largest functions of that compile", ["function", "seconds"],
                                    [[k, round(t, 1)] for k, t in top]))
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    results.write("cold_start", tables, conditions={"size": a.size, "spp": a.spp, "profile": a.profile,
                                                    "blender": a.blender})


if __name__ == "__main__":
    main()
