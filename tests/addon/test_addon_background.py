"""The background compile started when the add-on is enabled (addon/background.py, addon/preferences.py)."""
import importlib
import math
import threading
import time
from unittest import mock

import pytest

pytestmark = pytest.mark.blender

MODULE = "bl_ext.user_default.spectral_gi"


def modules():
    return (importlib.import_module(MODULE + ".addon.background"),
            importlib.import_module(MODULE + ".addon.preferences"))


def wait_until(cond, timeout):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(0.02)
    return cond()


def blocking_warm_up(gate, said="Compiling kernels (first run only)", calls=None):
    def warm_up(status, should_cancel):
        if calls is not None:
            calls.append(should_cancel)
        status(said)
        assert gate.wait(60)
        return True
    return warm_up


def test_disabling_the_add_on_during_the_sessions_compile(ext, bpy):
    """The session's first test: the extension was enabled a moment ago, so its background
    compile runs (compiling, or loading from the user's cache). Disabling the add-on meanwhile
    and enabling it again neither crashes nor starts a second compile; it ends ready."""
    import addon_utils

    bg, _ = modules()
    state = bg.STATE
    assert state.phase in (bg.COMPILING, bg.READY), bg.status_text()
    thread = state.thread
    assert thread is not None
    if bg.running():
        addon_utils.disable(MODULE, default_set=True)
        assert state.abandoned
        addon_utils.enable(MODULE, default_set=True)
        assert state.thread is thread and not state.abandoned  # the same compile, wanted again
    assert hasattr(bpy.types, "SPECTRALGI_PT_render")
    assert wait_until(lambda: not bg.running(), 1500), "the background compile did not end"
    assert state.phase == bg.READY, bg.status_text()
    assert bg.status_text().startswith("Kernels ready")


def test_a_render_after_it_finds_the_kernels_loaded(ext, bpy):
    """After the background compile, an exported scene renders without compiling or loading
    anything (the add-on compiles what a Cornell box needs, and an exported scene needs the same)."""
    bg, _ = modules()
    assert wait_until(lambda: not bg.running(), 1500)
    path = importlib.import_module(MODULE + ".core.integrators.path")
    n = len(path.render_rows.signatures)
    assert ext.core.kernels_compiled() and n >= 1
    b = ext.build
    grey = b.principled("Grey", (0.6, 0.6, 0.6))
    b.plane("Floor", size=6.0, material=grey)
    b.cube("Cube", location=(0, 0, 0.5), material=b.principled("Red", (0.7, 0.1, 0.1)))
    b.light("Key", "AREA", location=(0, 0, 3), energy=200.0, size=1.0)
    b.camera(location=(0, -6, 2), rotation=(math.radians(75), 0, 0))
    b.resolution(8, 8)
    said = []
    film, st = ext.core.render(b.export(ext).scene, threads=1, status=said.append)
    assert st.spp > 0 and film.sums[..., 3].min() > 0
    assert len(path.render_rows.signatures) == n
    assert not [m for m in said if m.startswith(("Compiling", "Loading", "Waiting"))], said


def test_state_machine(ext):
    """idle → compiling (one at a time) → ready, or → failed with the reason; the status line follows."""
    bg, _ = modules()
    state = bg.CompileState()
    assert bg.status_text(state) == "Kernels not compiled yet"
    gate = threading.Event()
    assert bg.start(state, blocking_warm_up(gate))
    assert state.phase == bg.COMPILING and bg.running(state)
    assert wait_until(lambda: state.detail, 10)
    assert bg.status_text(state) == "Compiling kernels…" and bg.status_icon(state) == "TIME"
    assert not bg.start(state, blocking_warm_up(gate))  # one at a time
    gate.set()
    state.thread.join(10)
    assert state.phase == bg.READY and bg.status_text(state).startswith("Kernels ready (")
    assert not bg.start(state, blocking_warm_up(gate))  # done: nothing more to do
    bg.switched_off(state)
    assert state.phase == bg.READY  # switching the preference off keeps what was compiled

    loading = bg.CompileState()
    gate2 = threading.Event()
    bg.start(loading, blocking_warm_up(gate2, said="Loading compiled kernels"))
    assert wait_until(lambda: loading.detail, 10)
    assert bg.status_text(loading) == "Loading compiled kernels…"
    gate2.set()
    loading.thread.join(10)

    def broken(status, should_cancel):
        raise RuntimeError("LLVM ran out of\nmemory")

    failed = bg.CompileState()
    bg.start(failed, broken)
    failed.thread.join(10)
    assert failed.phase == bg.FAILED and bg.status_icon(failed) == "ERROR"
    assert bg.status_text(failed) == "Kernel compile failed: RuntimeError: LLVM ran out of memory"
    bg.switched_off(failed)
    assert bg.status_text(failed).startswith("Background compile off")
    assert bg.start(failed, lambda status, should_cancel: False)  # switched on again: retried
    failed.thread.join(10)
    assert failed.phase == bg.READY and bg.status_text(failed) == "Kernels ready"  # nothing had to be compiled


def test_enabling_starts_it_unless_the_preference_is_off(ext, bpy, monkeypatch):
    """Registering (what enabling the add-on runs) starts the compile; with the preference off
    it does not, and the status says so; switching the preference on starts it. Disabling the
    add-on while it runs leaves the thread to finish on its own; nothing touches Blender."""
    import addon_utils

    bg, prefs = modules()
    state = bg.CompileState()
    monkeypatch.setattr(bg, "STATE", state)
    gate, calls = threading.Event(), []
    monkeypatch.setattr(bg, "_core_warm_up", blocking_warm_up(gate, calls=calls))
    try:
        ext.module.unregister()
        ext.module.register()
        assert state.phase == bg.COMPILING and len(calls) == 1, bg.status_text(state)
        p = prefs.preferences()
        assert p is not None and p.background_compile
        # the preferences and the render panel show the status
        labels = []
        layout = mock.MagicMock()
        for name in ("row", "column", "box"):
            getattr(layout, name).return_value = layout
        layout.label.side_effect = lambda text="", **kw: labels.append(text)
        prefs.SpectralGIPreferences.draw(mock.MagicMock(layout=layout), bpy.context)
        bpy.types.SPECTRALGI_PT_render.draw(mock.MagicMock(layout=layout), bpy.context)
        assert labels.count("Compiling kernels…") == 2, labels
        # disabled during the compile: no crash, the thread is asked to stop waiting and ends by itself
        addon_utils.disable(MODULE, default_set=True)
        assert not hasattr(bpy.types, "SPECTRALGI_PT_render") and calls[0]() is True
        gate.set()
        state.thread.join(10)
        assert state.phase == bg.READY
        addon_utils.enable(MODULE, default_set=True)
        bg, prefs = modules()
        # the preference off: enabling does not start it
        off = bg.CompileState()
        monkeypatch.setattr(bg, "STATE", off)
        prefs.preferences().background_compile = False
        ext.module.unregister()
        ext.module.register()
        assert off.phase == bg.OFF and not bg.running(off) and len(calls) == 1
        assert bg.status_text(off).startswith("Background compile off")
        gate.clear()
        prefs.preferences().background_compile = True  # switched on: starts
        assert off.phase == bg.COMPILING and len(calls) == 2
        gate.set()
        off.thread.join(10)
        assert off.phase == bg.READY
    finally:
        gate.set()
        if not hasattr(bpy.types, "SPECTRALGI_PT_render"):
            addon_utils.enable(MODULE, default_set=True)
        p = modules()[1].preferences()
        if p is not None:
            monkeypatch.setattr(bg, "start", lambda *a, **k: False)
            p.background_compile = True


def test_f12_during_a_compile_waits_and_stays_cancellable(ext, bpy, monkeypatch, tmp_path):
    """F12 while another thread compiles the kernels: the engine's status says it waits, and
    Esc (test_break) cancels it at once, with nothing rendered."""
    bg, _ = modules()
    assert wait_until(lambda: not bg.running(), 1500)
    render_module = importlib.import_module(MODULE + ".core.integrators.render")
    warmup = importlib.import_module(MODULE + ".core.integrators.warmup")
    jit = importlib.import_module(MODULE + ".core.jit")
    b = ext.build
    b.plane("Floor", size=6.0, material=b.principled("Grey"))
    b.light("Key", "AREA", location=(0, 0, 3), energy=200.0, size=1.0)
    b.camera(location=(0, -6, 2), rotation=(math.radians(75), 0, 0))
    b.resolution(8, 8)
    b.scene.render.engine = "SPECTRAL_GI"
    monkeypatch.setattr(render_module, "kernels_compiled", lambda: False)  # as before the compile ends
    said = []
    real_render = ext.core.render

    def render(scene, **kw):
        status, test_break = kw["status"], kw["should_cancel"]

        def saying(text):
            said.append(text)
            status(text)

        kw["status"] = saying
        kw["should_cancel"] = lambda: warmup.WAIT_MESSAGE in said or test_break()  # Esc once it waits
        return real_render(scene, **kw)

    monkeypatch.setattr(ext.core, "render", render)
    held, done = threading.Event(), threading.Event()

    def compiling():
        with jit.COMPILE_LOCK:
            held.set()
            done.wait(60)

    t = threading.Thread(target=compiling, daemon=True)
    t.start()
    assert held.wait(10)
    t0 = time.monotonic()
    try:
        assert bpy.ops.render.render() == {"FINISHED"}
    finally:
        done.set()
        t.join(10)
    assert time.monotonic() - t0 < 10.0
    assert said[0] == warmup.WAIT_MESSAGE
    message = ext.render_job.STATE.message
    assert message.startswith("Cancelled after 0 of"), message
