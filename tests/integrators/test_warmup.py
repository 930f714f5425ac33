"""The two-process cold compile (core/warmup.py): the recorded plan must be what the path
kernel's type inference asks for, or the second process compiles helpers nobody uses."""
import os
import subprocess
import sys
import time

import numpy as np
import pytest

from spectral_gi import core
from spectral_gi.core.integrators import warmup
from spectral_gi.core.integrators.compile_plan import PLAN


@pytest.fixture(scope="module")
def rendered():
    core.render(core.cornell_box(8, 8, spp=1, max_depth=3), threads=1)


@pytest.mark.slow
def test_plan_matches_the_kernels_type_inference(rendered):
    """Every helper the kernel calls, with the argument types it calls it with, is recorded,
    and nothing else (re-record with `python benchmarks/compile_bench.py --record`)."""
    assert [tuple(e) for e in PLAN] == warmup.record()


def test_groups_split_the_plan():
    names = {name for _, name, _ in PLAN}
    assert warmup.HELPER_GROUP <= names, "a helper group name is not in the plan"
    assert names - warmup.HELPER_GROUP, "this process would compile nothing ahead"


@pytest.mark.slow
def test_second_process_imports_the_package_under_blenders_name(rendered, tmp_path):
    """Blender imports the extension as bl_ext.<repository>.spectral_gi: the second process
    imports it under the same dotted name without running the add-on's __init__ (which
    imports bpy), and compiles its whole group.

    In a cache folder of its own: numba's cache index names the kernel records' classes by
    their module, so a process that imports these files under another package name than
    the one that wrote the index cannot read it (in Blender both processes use one name)."""
    root = warmup._ROOT  # the package root (the folder holding core/)
    env = dict(os.environ, PYTHONPATH="", SPECTRAL_GI_CACHE_DIR=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", warmup._BOOT, "bl_ext.user_default.spectral_gi", root],
                         capture_output=True, text=True, env=env, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "bpy" not in out.stderr
    assert int(out.stdout.strip().splitlines()[-1]) == len(warmup.HELPER_GROUP)


def test_no_second_process_when_the_kernel_is_ready(rendered):
    assert core.kernels_compiled()
    assert warmup.start() is None
    warmup.finish(None)  # nothing to stop


def test_only_a_python_executable_is_started(monkeypatch):
    """An interpreter whose executable is not Python (an old Blender binary) starts nothing;
    a Python one gets this process's module search path (Blender adds the extension's
    wheels to sys.path at run time)."""
    monkeypatch.setattr(sys, "executable", "/opt/blender/blender")
    assert warmup.command() is None
    monkeypatch.undo()
    argv, env = warmup.command()
    assert argv[0] == sys.executable and argv[1] == "-c"
    numba_dir = os.path.dirname(os.path.dirname(os.path.abspath(__import__("numba").__file__)))
    assert numba_dir in env["PYTHONPATH"].split(os.pathsep)


def test_switch_off(monkeypatch):
    monkeypatch.setenv("SPECTRAL_GI_PARALLEL_COMPILE", "0")
    assert warmup.start() is None


def test_finish_waits_for_the_second_process_but_not_forever():
    """Before the kernel's compile, ``finish`` lets the second process end its group, but
    never waits longer than its grace: a stuck process is stopped."""
    warmup.finish(None, 5.0)  # nothing to wait for
    quick = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(0.5)"])
    t = time.perf_counter()
    warmup.finish(quick, 30.0)
    assert quick.returncode == 0 and 0.3 < time.perf_counter() - t < 20.0  # ended on its own
    stuck = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    t = time.perf_counter()
    warmup.finish(stuck, 0.5)
    assert stuck.returncode not in (None, 0) and 0.4 < time.perf_counter() - t < 15.0  # stopped


@pytest.mark.parametrize("on_disk, message", [(True, "Loading compiled kernels"),
                                              (False, "Compiling kernels (first run only)")])
def test_status_says_compiling_only_when_the_cache_lacks_the_kernels(rendered, monkeypatch, on_disk, message):
    """A process whose kernels are not loaded yet says "Compiling" only when numba's cache
    on disk does not hold them; otherwise it is loading them."""
    from spectral_gi.core.integrators import render as render_module

    monkeypatch.setattr(render_module, "kernels_compiled", lambda: False)
    monkeypatch.setattr(warmup, "start", lambda: None)
    monkeypatch.setattr(warmup, "kernel_cached", lambda: on_disk)
    said = []
    core.render(core.cornell_box(4, 4, spp=1), threads=1, status=said.append)
    assert message in said
    other = {"Loading compiled kernels", "Compiling kernels (first run only)"} - {message}
    assert not other & set(said)


_CACHE_PROBE = """
import json, sys
from spectral_gi import core
from spectral_gi.core import jit
from spectral_gi.core.integrators import warmup
from spectral_gi.core.integrators.path import render_rows
cached = warmup.kernel_cached()
film, st = core.render(core.cornell_box(6, 6, spp=1, max_depth=2), threads=1)
print(json.dumps({"file": core.__file__, "cache": str(jit.CACHE_DIR), "cached_before": cached,
                  "hits": sum(render_rows.stats.cache_hits.values()),
                  "misses": sum(render_rows.stats.cache_misses.values()), "sum": float(film.sums.sum())}))
"""


def test_a_copy_of_the_package_elsewhere_loads_the_kernels_this_one_compiled(rendered, tmp_path):
    """The command line and every install of the extension (each a copy of the package in
    another folder) use one cache: what this checkout compiled (the ``rendered`` fixture),
    a copy with the same sources in another folder loads, and renders the same image."""
    import json
    import shutil
    from pathlib import Path

    from spectral_gi.core import jit
    from spectral_gi.core.integrators.path import render_rows

    root = Path(core.__file__).resolve().parents[1]
    copy = tmp_path / "elsewhere" / "spectral_gi"
    shutil.copytree(root / "core", copy / "core", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(root / "presets", copy / "presets", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(root / "__init__.py", copy / "__init__.py")
    here = core.render(core.cornell_box(6, 6, spp=1, max_depth=2), threads=1)[0]
    assert render_rows.signatures
    env = dict(os.environ, PYTHONPATH=str(copy.parent), SPECTRAL_GI_PARALLEL_COMPILE="0")
    out = subprocess.run([sys.executable, "-c", _CACHE_PROBE], env=env, capture_output=True, text=True,
                         timeout=900, cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-2000:]
    there = json.loads(out.stdout.strip().splitlines()[-1])
    assert Path(there["file"]).resolve().is_relative_to(copy.resolve())
    assert there["cache"] == str(jit.CACHE_DIR)
    assert there["cached_before"] and there["hits"] == 1 and there["misses"] == 0
    assert there["sum"] == float(here.sums.sum())


def _holding_the_compile_lock(release_after=None):
    """A thread that holds jit.COMPILE_LOCK (as a compile in progress does) until the returned
    event is set, or for ``release_after`` seconds."""
    import threading

    from spectral_gi.core import jit

    held, done = threading.Event(), threading.Event()

    def hold():
        with jit.COMPILE_LOCK:
            held.set()
            done.wait(release_after)

    t = threading.Thread(target=hold, daemon=True)
    t.start()
    assert held.wait(10)
    return done, t


def test_a_cold_render_waits_for_another_threads_compile_and_can_be_cancelled(rendered, monkeypatch):
    """A render that finds the kernels not loaded while another thread compiles them (the
    add-on's background compile) says so and waits; cancelled meanwhile, it returns at once
    with no samples and compiles nothing."""
    from spectral_gi.core.integrators import render as render_module

    monkeypatch.setattr(render_module, "kernels_compiled", lambda: False)
    monkeypatch.setattr(warmup, "start", lambda: pytest.fail("a second compile process was started"))
    done, t = _holding_the_compile_lock()
    said, asked = [], []
    t0 = time.perf_counter()
    try:
        film, st = core.render(core.cornell_box(4, 4, spp=2), threads=1, status=said.append,
                               should_cancel=lambda: asked.append(1) or len(asked) > 3)
    finally:
        done.set()
        t.join(10)
    assert said == [warmup.WAIT_MESSAGE]
    assert st.cancelled and st.spp == 0 and film.spp == 0 and float(film.sums.sum()) == 0.0
    assert time.perf_counter() - t0 < 5.0  # four polls, 0.1 s apart


def test_a_cold_render_goes_on_when_the_other_compile_ends(rendered, monkeypatch):
    """Once the compiling thread lets go, the waiting render takes the kernels it loaded and
    renders the same image as one that never waited."""
    from spectral_gi.core.integrators import render as render_module

    scene = core.cornell_box(4, 4, spp=2)
    want = core.render(scene, threads=1)[0]
    compiled = iter([False, True])  # cold when it starts; loaded once the lock is free
    monkeypatch.setattr(render_module, "kernels_compiled", lambda: next(compiled, True))
    done, t = _holding_the_compile_lock(release_after=0.5)
    said = []
    t0 = time.perf_counter()
    film, st = core.render(scene, threads=1, status=said.append)
    t.join(10)
    assert time.perf_counter() - t0 >= 0.45
    assert said[0] == warmup.WAIT_MESSAGE and "Compiling kernels (first run only)" not in said
    assert st.spp == 2 and not st.cancelled
    assert np.array_equal(film.sums, want.sums)
    assert jit_lock_free()


def jit_lock_free():
    from spectral_gi.core import jit

    if jit.COMPILE_LOCK.acquire(blocking=False):
        jit.COMPILE_LOCK.release()
        return True
    return False


def test_warm_up_loads_the_cornell_box_kernels_once(rendered):
    """core.warm_up (the add-on's background compile) has nothing to do once the kernels are
    loaded, and a render after it compiles nothing more."""
    from spectral_gi.core.integrators.path import render_rows

    assert core.warm_up() is False
    n = len(render_rows.signatures)
    core.render(core.cornell_box(5, 3, spp=1), threads=1)
    assert len(render_rows.signatures) == n
    assert jit_lock_free()
