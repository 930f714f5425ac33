"""The Render GI operator, the render job, cancel, errors, and the Cornell box."""
import importlib
import math
import time

import numpy as np
import pytest

pytestmark = pytest.mark.blender

RESULT = "Spectral GI Result"


def small_scene(b, bpy, w=32, h=24, spp=4):
    floor = b.principled("Floor", (0.7, 0.7, 0.7))
    b.plane("Floor", size=6.0, material=floor)
    b.cube("Cube", size=1.0, location=(0, 0, 0.5), material=b.principled("Red", (0.7, 0.1, 0.1)))
    glow = b.principled("Glow", (0.5, 0.5, 0.5), emission=(1.0, 1.0, 1.0), strength=2.0)
    panel = b.plane("Glow", size=1.0, location=(1.5, 1.5, 1.0), material=glow)
    panel.rotation_euler = (math.radians(90), 0, 0)
    b.light("Key", "AREA", location=(0, 0, 3), energy=200.0, size=1.0)
    b.camera(location=(0, -6, 2), rotation=(math.radians(75), 0, 0), lens=30.0)
    b.resolution(w, h)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.seed = spp, 8, 1


def check_image(b, bpy, w, h):
    assert RESULT in bpy.data.images
    img = bpy.data.images[RESULT]
    assert tuple(img.size) == (w, h)
    assert img.is_float
    px = b.image_array()
    rgb = px[..., :3]
    assert np.all(np.isfinite(rgb))
    assert rgb.mean() > 0.0 and rgb.max() < 1e4
    return rgb


def test_render_operator(ext, bpy):
    b = ext.build
    small_scene(b, bpy)
    t0 = time.perf_counter()
    assert bpy.ops.spectral_gi.render() == {"FINISHED"}
    print(f"first render (includes kernel compilation unless cached): {time.perf_counter() - t0:.1f} s")
    check_image(b, bpy, 32, 24)
    job = ext.render_job.current_job()
    assert job.error is None and job.stats.spp == 4 and not job.cancelled
    assert not ext.render_job.busy() and not ext.render_job.STATE.running
    assert "Rendered 4 samples" in ext.render_job.STATE.message
    # A second render at another size reuses and resizes the same image. Invoked as from the
    # button: without an event loop (background mode) the operator renders synchronously.
    b.resolution(20, 10)
    assert bpy.ops.spectral_gi.render("INVOKE_DEFAULT") == {"FINISHED"}
    check_image(b, bpy, 20, 10)
    assert len([i for i in bpy.data.images if i.name.startswith(RESULT)]) == 1


def test_render_job_on_a_worker_thread(ext, bpy):
    """The interactive path: the worker renders, the main thread polls (as the modal timer does)."""
    b = ext.build
    small_scene(b, bpy, spp=8)
    res = b.export(ext)
    job = ext.render_job.RenderJob(res.scene, threads=0)
    job.start()
    assert job.thread is not None and ext.render_job.busy()
    deadline = time.monotonic() + 120
    lines = set()
    while not job.poll():
        lines.add(ext.render_job.status_line())
        assert time.monotonic() < deadline, "the worker did not finish"
        time.sleep(0.05)
    assert job.error is None, job.traceback
    assert not job.thread.is_alive() and not ext.render_job.busy()
    assert job.stats.spp == 8
    assert all(line.startswith("Spectral GI:") for line in lines)
    check_image(b, bpy, 32, 24)


def test_cancel_after_first_pass_keeps_a_partial_image(ext, bpy, monkeypatch):
    b = ext.build
    small_scene(b, bpy, spp=64)
    monkeypatch.setattr(ext.render_job.RenderJob, "should_cancel", lambda self: self.passes >= 1)
    assert bpy.ops.spectral_gi.render() == {"FINISHED"}  # no error
    job = ext.render_job.current_job()
    assert job.error is None and job.cancelled
    assert 1 <= job.stats.spp < 64
    assert "Cancelled" in ext.render_job.STATE.message
    check_image(b, bpy, 32, 24)


def test_errors_are_reported_not_raised_inside_blender(ext, bpy):
    b = ext.build
    b.plane("Floor")  # no camera
    with pytest.raises(RuntimeError, match="no active camera"):
        bpy.ops.spectral_gi.render()  # an ERROR report surfaces as RuntimeError in a script
    assert RESULT not in bpy.data.images
    assert not ext.render_job.busy()


def test_render_failure_in_core_is_reported(ext, bpy, monkeypatch):
    b = ext.build
    small_scene(b, bpy)

    def broken(self, on_pass):
        try:
            raise ValueError("kernel exploded")
        except ValueError as exc:
            self.error = f"{type(exc).__name__}: {exc}"
        finally:
            self.finished = True

    monkeypatch.setattr(ext.render_job.RenderJob, "_run", broken)
    with pytest.raises(RuntimeError, match="kernel exploded"):
        bpy.ops.spectral_gi.render()
    assert not ext.render_job.busy()


def test_cornell_box(ext, bpy):
    b = ext.build
    assert bpy.ops.spectral_gi.add_cornell_box() == {"FINISHED"}
    scene = b.scene
    assert scene.camera is not None and scene.camera.data.lens == pytest.approx(35.0)
    assert (scene.camera.data.sensor_width, scene.camera.data.sensor_fit) == (pytest.approx(25.0), "AUTO")
    assert (scene.render.resolution_x, scene.render.resolution_y) == (256, 256)

    # The exported box matches core's own Cornell box (geometry in metres, camera).
    ref = ext.core.cornell_box(256, 256)
    exported = b.export(ext).scene
    assert exported.n_triangles == ref.n_triangles
    np.testing.assert_allclose(exported.camera.to_world, ref.camera.to_world, atol=1e-6)
    lo = np.min([m.positions.min(axis=0) for m in exported.meshes], axis=0)
    hi = np.max([m.positions.max(axis=0) for m in exported.meshes], axis=0)
    ref_lo = np.min([m.positions.min(axis=0) for m in ref.meshes], axis=0)
    ref_hi = np.max([m.positions.max(axis=0) for m in ref.meshes], axis=0)
    np.testing.assert_allclose(lo, ref_lo, atol=1e-6)
    np.testing.assert_allclose(hi, ref_hi, atol=1e-6)
    red = next(n for n in bpy.data.materials["Cornell red"].node_tree.nodes if n.type == "BSDF_DIFFUSE")
    red_ref = next(m for m in ref.materials if m.name == "red")
    # the walls are Lambertian, as published (exported as the Lambert model, not a coated plastic)
    assert all(m.model == ext.core.constants.MAT_LAMBERT for m in exported.materials if m.emission < 0)
    np.testing.assert_allclose(red.inputs["Color"].default_value[:3],
                               ext.core.reflectance_to_rgb(ref.spectra.coeffs[red_ref.reflectance]), atol=1e-6)
    light = next(m for m in exported.materials if m.emission >= 0)
    assert light.emission_luminance == pytest.approx(ref.materials[-1].emission_luminance, rel=1e-4)

    b.resolution(64, 64)
    scene.spectral_gi.samples = 16
    assert bpy.ops.spectral_gi.render() == {"FINISHED"}
    rgb = check_image(b, bpy, 64, 64).astype(np.float64)
    left, right = rgb[:, :21], rgb[:, -21:]
    # Red wall on the left, green wall on the right. The published light is warm (orange), so the
    # right third as a whole is still reddish: compare the walls themselves (outer eighth, middle rows)
    # and the balance of the thirds.
    assert left[..., 0].mean() > left[..., 1].mean()
    wall_right = rgb[16:48, -8:]
    assert wall_right[..., 1].mean() > wall_right[..., 0].mean()
    assert right[..., 1].mean() / right[..., 0].mean() > 2 * left[..., 1].mean() / left[..., 0].mean()


def _render_modal(ext):
    """A stand-in for the Render GI operator: its own methods, its reports recorded (Blender in the
    background sends no events and an operator instance cannot be made outside a call)."""
    ops = importlib.import_module(ext.module.__name__ + ".addon.operators.render")
    cls = ops.SPECTRALGI_OT_render

    class Modal(ops.ModalJobOperator):
        _prepare, _conclude = cls._prepare, cls._conclude

        def __init__(self, job=None):
            self._job, self._timer, self.reports = job, None, []

        def report(self, kind, text):
            self.reports.append((set(kind), text))

    return Modal


def _drive(bpy, op, event):
    for _ in range(60000):
        r = op.modal(bpy.context, event)
        if r != {"PASS_THROUGH"}:
            return r
        time.sleep(0.01)
    raise AssertionError("the render did not finish")


def test_the_modal_operator_polls_the_worker_and_esc_cancels(ext, bpy):
    """The operator's modal steps (timer events while the worker renders, Esc), driven by hand."""
    from types import SimpleNamespace

    b = ext.build
    small_scene(b, bpy, spp=8)
    modal = _render_modal(ext)
    timer = SimpleNamespace(type="TIMER", value="NOTHING")
    esc = SimpleNamespace(type="ESC", value="PRESS")
    mouse = SimpleNamespace(type="MOUSEMOVE", value="NOTHING")

    op = modal(ext.render_job.RenderJob(b.export(ext).scene))
    op._job.start()
    assert ext.render_job.busy() and not bpy.ops.spectral_gi.render.poll()
    assert op.modal(bpy.context, mouse) == {"PASS_THROUGH"}  # other events go on to Blender
    assert _drive(bpy, op, timer) == {"FINISHED"}
    assert not ext.render_job.busy() and op._job.stats.spp == 8
    assert op.reports == [({"INFO"}, f"Spectral GI: {op._job.summary()}")]
    assert op.reports[0][1].startswith("Spectral GI: Rendered 8 samples")
    check_image(b, bpy, 32, 24)

    # Esc: the worker stops after its current pass, the partial render is the result, no error
    small_scene(b, bpy, spp=1 << 20)
    op = modal(ext.render_job.RenderJob(b.export(ext).scene))
    op._job.start()
    assert op.modal(bpy.context, esc) == {"RUNNING_MODAL"} and op._job.cancel_requested
    assert "Cancelling…" in ext.render_job.status_line()
    assert _drive(bpy, op, timer) == {"FINISHED"}
    job = op._job
    assert job.cancelled and job.error is None and job.stats.spp < 1 << 20
    assert ext.render_job.STATE.phase == "Finished" and not ext.render_job.STATE.running
    assert op.reports[-1][1].startswith("Spectral GI: Cancelled after")


def test_samples_that_are_not_finite_are_reported(ext, bpy, monkeypatch, tmp_path):
    """A render whose statistics count dropped samples (validated input cannot make one, so core's
    statistics are given the count) says so: Render GI and F12 warn, the panel's message tells."""
    import dataclasses

    real_render = ext.core.render
    say = ext.render_job.dropped_samples_warning
    assert say(ext.core.RenderStats(4, 1.0, 1.0, False, 0.0, 0.0)) is None
    one = say(ext.core.RenderStats(4, 1.0, 1.0, False, 0.0, 0.0, dropped_samples=1))
    assert one == "1 sample was not finite (NaN or Inf) and was left out of their pixels"

    def render(scene, **kw):
        film, stats = real_render(scene, **kw)
        return film, dataclasses.replace(stats, dropped_samples=3)

    monkeypatch.setattr(ext.core, "render", render)
    b = ext.build
    small_scene(b, bpy)
    warning = "3 samples were not finite (NaN or Inf) and were left out of their pixels"

    op = _render_modal(ext)()
    assert op.execute(bpy.context) == {"FINISHED"}
    assert ({"WARNING"}, f"Spectral GI: {warning}") in op.reports
    assert op._job is None and ext.render_job.current_job().dropped_warning == warning
    assert ext.render_job.STATE.message.endswith(" | " + warning)
    check_image(b, bpy, 32, 24)

    # F12: the engine's reports, seen through a stand-in that hands everything else to the engine
    engine_mod = importlib.import_module(ext.module.__name__ + ".addon.engine")
    real_loop, reports = engine_mod.render_with_engine, []

    class Engine:
        def __init__(self, engine):
            self._engine = engine

        def __getattr__(self, name):
            return getattr(self._engine, name)

        def report(self, kind, text):
            reports.append((set(kind), text))
            self._engine.report(kind, text)

    monkeypatch.setattr(engine_mod, "render_with_engine", lambda engine, depsgraph: real_loop(Engine(engine),
                                                                                            depsgraph))
    b.scene.render.engine = "SPECTRAL_GI"
    b.scene.render.filepath = str(tmp_path / "f12.png")
    assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
    assert ({"WARNING"}, f"Spectral GI: {warning}") in reports
    assert ext.render_job.STATE.engine_stats.dropped_samples == 3
    assert ext.render_job.STATE.message.endswith(" | " + warning)
