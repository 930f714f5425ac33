"""Compare with Cycles: matched settings, side by side, ΔE00 map, report; Cycles settings restored.

The interactive operator is a state machine (``ComparisonRun``): Spectral GI on a worker
thread, then Cycles as Blender's render job, stepped from a timer. Blender-as-a-module has
no event loop, so these tests step the machine directly, with Cycles rendered on the spot
(its end still seen through the render_complete / render_cancel handlers).
"""
import importlib
import json
import math
import time

import numpy as np
import pytest

pytestmark = pytest.mark.blender


def diffuse_scene(b, w=24, h=24, spp=64):
    grey = b.shader("Grey", "ShaderNodeBsdfDiffuse", Color=(0.6, 0.6, 0.6, 1.0))
    red = b.shader("Red", "ShaderNodeBsdfDiffuse", Color=(0.7, 0.2, 0.1, 1.0))
    b.plane("Floor", size=6.0, material=grey)
    wall = b.plane("Back", size=6.0, location=(0, 2, 3), material=red)
    wall.rotation_euler = (math.radians(90), 0, 0)
    b.light("Key", "AREA", location=(0, 0, 3), energy=300.0, size=1.0)
    b.camera(location=(0, -6, 2), rotation=(math.radians(75), 0, 0), lens=35.0)
    b.resolution(w, h)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.seed = spp, 8, 1


def test_compare_with_cycles_on_a_diffuse_scene(ext, bpy, tmp_path, monkeypatch):
    import tempfile

    temp = tmp_path / "temp"  # the system's temporary folder, for this test
    temp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(temp))
    b = ext.build
    diffuse_scene(b)
    scene = b.scene
    s = scene.spectral_gi
    s.compare_output_dir = str(tmp_path)
    before = (scene.render.engine, scene.cycles.samples, scene.cycles.use_denoising,
              scene.cycles.use_adaptive_sampling, scene.cycles.diffuse_bounces)
    # INVOKE (a button press) in background mode falls back to the blocking comparison
    assert bpy.ops.spectral_gi.compare_cycles("INVOKE_DEFAULT") == {"FINISHED"}
    # every setting the comparison changed is back
    assert (scene.render.engine, scene.cycles.samples, scene.cycles.use_denoising,
            scene.cycles.use_adaptive_sampling, scene.cycles.diffuse_bounces) == before

    # Both renderers read Blender's units alike (Cycles' area light: P/(πA) radiance; 683 lm per W),
    # so on a diffuse scene their mean luminances agree within the noise of 64 spp (~0.3 % here).
    assert s.compare_valid
    assert s.compare_luminance_ratio == pytest.approx(1.0, abs=0.02)
    assert 0.0 < s.compare_relative_rmse < 0.2
    assert 0.0 < s.compare_delta_e_mean <= s.compare_delta_e_p95 < 20.0

    report = json.loads(open(s.compare_report_path, encoding="utf-8").read())
    assert report["luminance_ratio"] == pytest.approx(s.compare_luminance_ratio, rel=1e-6)
    assert (report["samples"], report["max_bounces"], report["width"], report["height"]) == (64, 8, 24, 24)
    assert report["mean_luminance_reference"] > 0.0 and report["luminance_unit"] == "cd/m2"
    for key in ("side_by_side", "delta_e00"):
        assert (tmp_path / report["images"][key].split("/")[-1]).is_file()
    sbs = bpy.data.images["Spectral GI vs Cycles"]
    assert tuple(sbs.size) == (2 * 24 + 2, 24)
    de = bpy.data.images["Spectral GI ΔE00"]
    assert de.size[0] == 24 and de.size[1] > 24  # the map and its legend bar below
    px = np.empty(de.size[0] * de.size[1] * 4, np.float32)
    de.pixels.foreach_get(px)
    assert np.isfinite(px).all() and px.max() > 0.0
    assert not list(temp.iterdir())  # Cycles' EXR and its folder are removed once read back


def test_rotated_environment_matches_cycles(ext, bpy, tmp_path):
    """An equirectangular map with distinct regions, turned by a Mapping node, seen directly and lit
    onto a floor: the orientation and the rotation's sign must match Cycles'. (With the rotation's
    sign flipped the luminance ratio is 0.97 and the mean ΔE00 14; matched: 1.00 and 2.5.)"""
    b = ext.build
    w, h = 64, 32
    img = bpy.data.images.new("HDRI", width=w, height=h, float_buffer=True)
    u = (np.arange(w) + 0.5) / w
    v = (np.arange(h) + 0.5) / h
    px = np.zeros((h, w, 4), np.float32)
    px[..., 0] = 0.2 + 2.0 * ((u > 0.6) & (u < 0.8))[None, :]
    px[..., 1] = 0.2 + 1.5 * v[:, None]
    px[..., 2] = 0.3 + 1.0 * (u < 0.3)[None, :]
    px[..., 3] = 1.0
    img.pixels.foreach_set(px.reshape(-1))
    world = bpy.data.worlds.new("Sky")
    b.scene.world = world
    tree = world.node_tree
    bg = next(n for n in tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Strength"].default_value = 1.5
    env = tree.nodes.new("ShaderNodeTexEnvironment")
    env.image = img
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, 0.5)
    coords = tree.nodes.new("ShaderNodeTexCoord")
    tree.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    tree.links.new(env.outputs["Color"], bg.inputs["Color"])
    b.plane("Floor", size=4.0, material=b.shader("Grey", "ShaderNodeBsdfDiffuse", Color=(0.6, 0.6, 0.6, 1.0)))
    cam = b.camera(location=(0, -5, 1.5), rotation=(math.radians(85), 0, math.radians(-20)), lens=12.0)
    assert cam is not None
    b.resolution(32, 16)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.compare_output_dir = 64, 4, str(tmp_path)
    assert bpy.ops.spectral_gi.compare_cycles() == {"FINISHED"}
    assert s.compare_luminance_ratio == pytest.approx(1.0, abs=0.015)
    assert s.compare_delta_e_mean < 6.0


@pytest.mark.parametrize("kind", ["EQUIRECTANGULAR", "FISHEYE_EQUISOLID"])
def test_panoramic_camera_matches_cycles(ext, bpy, tmp_path, kind):
    """An equirectangular (or equisolid fisheye) camera inside a lit room with a grey sky: the
    whole sphere (or the fisheye's circle, black outside in both) in the same layout as Cycles'."""
    b = ext.build
    diffuse_scene(b, w=48, h=24 if kind == "EQUIRECTANGULAR" else 48, spp=64)
    world = bpy.data.worlds.new("Grey sky")
    b.scene.world = world
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (0.3, 0.35, 0.4, 1.0)
    cam = b.scene.camera
    cam.location = (0.5, -1.0, 1.2)
    cam.data.type, cam.data.panorama_type = "PANO", kind
    cam.data.fisheye_lens, cam.data.fisheye_fov = 6.0, math.radians(220.0)
    s = b.scene.spectral_gi
    s.compare_output_dir = str(tmp_path)
    assert bpy.ops.spectral_gi.compare_cycles() == {"FINISHED"}
    assert s.compare_valid
    assert s.compare_luminance_ratio == pytest.approx(1.0, abs=0.02)
    assert s.compare_delta_e_mean < 6.0


def test_coarse_environment_is_filtered_as_cycles_filters_it(ext, bpy, tmp_path):
    """A 4 × 2 HDRI seen directly through an equirectangular camera looking along +X (Blender's
    rotation (90°, 0, −90°)): bilinear lookups against Cycles' Linear interpolation, pixel by pixel.
    Cycles' lookup is periodic in v too (within half a texel of the zenith the top row blends with
    the bottom one): clamping there instead gave a mean ΔE00 of 1.85 and a 95th percentile of 7.6.
    The grey texels keep the luminance simple: RGB 1 = 683 cd/m² on both sides."""
    b = ext.build
    vals = np.array([[0.3, 1.2, 0.5, 0.9], [0.8, 0.2, 1.5, 0.4]], np.float32)
    img = bpy.data.images.new("Coarse", width=4, height=2, float_buffer=True)
    px = np.ones((2, 4, 4), np.float32)
    px[..., :3] = vals[::-1, :, None]  # Blender's rows run bottom to top
    img.pixels.foreach_set(px.reshape(-1))
    world = bpy.data.worlds.new("Coarse sky")
    b.scene.world = world
    tree = world.node_tree
    bg = next(n for n in tree.nodes if n.type == "BACKGROUND")
    env = tree.nodes.new("ShaderNodeTexEnvironment")
    env.image = img
    tree.links.new(env.outputs["Color"], bg.inputs["Color"])
    cam = b.camera(location=(0, 0, 0), rotation=(math.radians(90), 0, math.radians(-90)))
    cam.data.type, cam.data.panorama_type = "PANO", "EQUIRECTANGULAR"
    b.resolution(64, 32)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.compare_output_dir = 64, 1, str(tmp_path)
    assert bpy.ops.spectral_gi.compare_cycles() == {"FINISHED"}
    # measured: ratio 1.00001, ΔE00 mean 0.38, 95th percentile 0.83
    assert s.compare_luminance_ratio == pytest.approx(1.0, abs=0.02)
    assert s.compare_delta_e_mean < 1.0 and s.compare_delta_e_p95 < 2.0


@pytest.mark.parametrize("kind", ["POINT", "SPOT", "SUN"])
def test_point_spot_and_sun_units_match_cycles(ext, bpy, tmp_path, kind):
    """End to end, Blender's units as Cycles reads them: P/(4π) W/sr for point and spot lights, a
    sun's strength as irradiance, 683 lm per W on both sides. Measured at 48x48, 256 spp: ratios
    1.0003 (point), 0.9983 (spot), 0.9990 (sun)."""
    b = ext.build
    diffuse_scene(b, spp=64)
    bpy.data.objects.remove(bpy.data.objects["Key"])
    props = {"POINT": dict(shadow_soft_size=0.1), "SPOT": dict(shadow_soft_size=0.1, spot_size=1.0, spot_blend=0.3),
             "SUN": dict(angle=0.05)}[kind]
    light = b.light("Lamp", kind, location=(0, 0, 3), energy=3.0 if kind == "SUN" else 300.0,
                    color=(1.0, 0.9, 0.7), **props)
    light.rotation_euler = (0.3, 0.2, 0.0)
    b.scene.spectral_gi.compare_output_dir = str(tmp_path)
    assert bpy.ops.spectral_gi.compare_cycles() == {"FINISHED"}
    assert b.scene.spectral_gi.compare_luminance_ratio == pytest.approx(1.0, abs=0.02)


def _compare_module(ext):
    return importlib.import_module(ext.module.__name__ + ".addon.operators.compare")


def _step_until_done(run, timeout=600.0):
    t0 = time.monotonic()
    while True:
        state = run.step()
        if state != "RUNNING":
            return state
        assert time.monotonic() - t0 < timeout, f"comparison still running in phase {run.phase}"
        time.sleep(0.05)


def _cycles_snapshot(scene):
    c = scene.cycles
    return (scene.render.engine, c.samples, c.use_denoising, c.use_adaptive_sampling, c.diffuse_bounces,
            c.max_bounces, scene.render.image_settings.file_format)


def test_modal_state_machine_runs_both_renders(ext, bpy, tmp_path):
    """The operator's steps: worker thread, then Cycles seen finishing through the render handlers."""
    cmp = _compare_module(ext)
    b = ext.build
    diffuse_scene(b)
    scene = b.scene
    before = _cycles_snapshot(scene)
    n_handlers = (len(bpy.app.handlers.render_complete), len(bpy.app.handlers.render_cancel))
    run = cmp.ComparisonRun(scene, bpy.context.evaluated_depsgraph_get(), out_dir=str(tmp_path), use_job=False)
    run.begin()
    assert run.phase == "spectral" and run.job.thread is not None
    t0 = time.monotonic()
    while run.phase == "spectral":
        assert run.step() == "RUNNING", run.error
        assert time.monotonic() - t0 < 600.0
        time.sleep(0.05)
    # Cycles' turn: the worker is done, yet Render GI and another comparison stay disabled
    assert run.phase == "cycles" and not run.job.thread and ext.render_job.busy()
    assert _step_until_done(run) == "FINISHED", run.error
    assert not ext.render_job.busy() and not ext.render_job.STATE.running
    assert _cycles_snapshot(scene) == before
    assert (len(bpy.app.handlers.render_complete), len(bpy.app.handlers.render_cancel)) == n_handlers
    s = scene.spectral_gi
    assert s.compare_valid and s.compare_luminance_ratio == pytest.approx(1.0, abs=0.02)
    report = json.loads(open(s.compare_report_path, encoding="utf-8").read())
    assert report["samples"] == 64 and report["luminance_ratio"] == pytest.approx(s.compare_luminance_ratio)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["Scene_cycles_comparison.json", "Scene_cycles_delta_e00.exr", "Scene_cycles_side_by_side.exr",
         "Scene_cycles_delta_e00.png", "Scene_cycles_side_by_side.png"])


def _previous_result(bpy, s, tmp_path):
    """A comparison shown before: panel values, an image and a report file that a cancel must keep."""
    s.compare_valid, s.compare_luminance_ratio, s.compare_delta_e_mean = True, 0.987, 1.5
    s.compare_report_path = str(tmp_path / "old.json")
    (tmp_path / "old.json").write_text('{"luminance_ratio": 0.987}')
    img = bpy.data.images.new("Spectral GI vs Cycles", 4, 2, float_buffer=True)
    img.pixels.foreach_set(np.full(32, 0.25, np.float32))
    return img


def _assert_previous_result_kept(bpy, s, tmp_path):
    assert (s.compare_valid, s.compare_luminance_ratio, s.compare_delta_e_mean) == (True, pytest.approx(0.987), 1.5)
    assert s.compare_report_path == str(tmp_path / "old.json")
    assert [p.name for p in tmp_path.iterdir()] == ["old.json"]  # no partial images or report
    img = bpy.data.images["Spectral GI vs Cycles"]
    px = np.empty(32, np.float32)
    img.pixels.foreach_get(px)
    assert tuple(img.size) == (4, 2) and np.all(px == 0.25)
    assert "Spectral GI ΔE00" not in bpy.data.images


def test_cancel_during_the_spectral_render_stops_the_worker_and_writes_nothing(ext, bpy, tmp_path):
    cmp = _compare_module(ext)
    b = ext.build
    diffuse_scene(b, spp=100000)  # far more than it can finish before the cancel
    scene = b.scene
    s = scene.spectral_gi
    _previous_result(bpy, s, tmp_path)
    before = _cycles_snapshot(scene)
    run = cmp.ComparisonRun(scene, bpy.context.evaluated_depsgraph_get(), out_dir=str(tmp_path), use_job=False)
    started = []
    run_cycles = cmp.CyclesRender.start
    cmp.CyclesRender.start = lambda self, use_job=False: started.append(1)  # must never be reached
    try:
        run.begin()
        thread = run.job.thread
        time.sleep(0.5)
        assert thread.is_alive() and run.step() == "RUNNING"
        run.request_cancel()  # what Esc does in the modal operator
        assert _step_until_done(run, timeout=900.0) == "CANCELLED"
    finally:
        cmp.CyclesRender.start = run_cycles
    assert not thread.is_alive() and run.job.finished and not started
    assert run.job.stats is not None and run.job.stats.cancelled and run.job.stats.spp < 100000
    assert not ext.render_job.busy() and "cancelled" in ext.render_job.STATE.message
    assert _cycles_snapshot(scene) == before
    _assert_previous_result_kept(bpy, s, tmp_path)


def test_cancel_during_the_cycles_render_restores_cycles_and_writes_nothing(ext, bpy, tmp_path):
    """Esc during Cycles stops Blender's render job, which calls render_cancel: the run ends CANCELLED."""
    cmp = _compare_module(ext)
    b = ext.build
    diffuse_scene(b, w=8, h=8, spp=4)
    scene = b.scene
    s = scene.spectral_gi
    _previous_result(bpy, s, tmp_path)
    before = _cycles_snapshot(scene)
    seen = {}

    def cancelled_render(self):
        seen["engine"], seen["samples"] = scene.render.engine, scene.cycles.samples
        for handler in list(bpy.app.handlers.render_cancel):  # as Blender's render pipeline does
            if getattr(handler, "__self__", None) is self:
                handler(scene, None)
                seen["handler"] = True
        return True

    launch = cmp.CyclesRender._launch
    cmp.CyclesRender._launch = cancelled_render
    try:
        run = cmp.ComparisonRun(scene, bpy.context.evaluated_depsgraph_get(), out_dir=str(tmp_path),
                                use_job=False)
        run.begin()
        assert _step_until_done(run) == "CANCELLED"
    finally:
        cmp.CyclesRender._launch = launch
    assert seen == {"engine": "CYCLES", "samples": 4, "handler": True}  # Cycles was set up to match, then put back
    assert run.phase == "done" and "Cycles" in run.error
    assert _cycles_snapshot(scene) == before
    assert not any(getattr(h, "__self__", None) is run.cycles for h in bpy.app.handlers.render_cancel)
    assert not ext.render_job.busy()
    _assert_previous_result_kept(bpy, s, tmp_path)


def test_the_modal_operator_steps_the_run_and_esc_cancels(ext, bpy, tmp_path):
    """The operator's modal steps (timer events, Esc) on a run, driven by hand, with Cycles on the spot."""
    from types import SimpleNamespace

    cmp = _compare_module(ext)
    cls = cmp.SPECTRALGI_OT_compare_cycles

    class Modal(cmp.ModalJobOperator):  # the operator's own methods on a stand-in instance
        _conclude, _show_result, _abandon = cls._conclude, cls._show_result, cls._abandon

        def __init__(self, run):
            self._job, self._timer, self.reports = run, None, []

        def report(self, kind, text):
            self.reports.append((set(kind), text))

    timer = SimpleNamespace(type="TIMER", value="NOTHING")
    esc = SimpleNamespace(type="ESC", value="PRESS")

    def drive(op):
        t0 = time.monotonic()
        while (r := op.modal(bpy.context, timer)) == {"PASS_THROUGH"}:
            assert time.monotonic() - t0 < 600.0, f"comparison still running in phase {op._job.phase}"
            time.sleep(0.05)
        return r

    b = ext.build
    diffuse_scene(b, w=8, h=8, spp=4)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    op = Modal(cmp.ComparisonRun(b.scene, depsgraph, out_dir=str(tmp_path / "done"), use_job=False).begin())
    assert drive(op) == {"FINISHED"}
    kinds, text = op.reports[-1]
    assert kinds == {"INFO"} and text.startswith("Spectral GI vs Cycles: luminance ratio")
    assert text.endswith(f"({b.scene.spectral_gi.compare_report_path})")

    for name in (cmp.SIDE_BY_SIDE_IMAGE, cmp.DELTA_E_IMAGE):  # a comparison shown before, as below
        bpy.data.images.remove(bpy.data.images[name])
    s = b.scene.spectral_gi
    s.samples = 100000  # far more than it can finish before Esc
    (tmp_path / "kept").mkdir()
    _previous_result(bpy, s, tmp_path / "kept")
    op = Modal(cmp.ComparisonRun(b.scene, depsgraph, out_dir=str(tmp_path / "kept"), use_job=False).begin())
    assert op.modal(bpy.context, esc) == {"RUNNING_MODAL"} and op._job.cancel_requested
    assert drive(op) == {"CANCELLED"}
    assert op.reports == [({"INFO"}, "Spectral GI: comparison cancelled during the Spectral GI render; the last "
                                     "comparison is kept")]
    assert not ext.render_job.busy()
    _assert_previous_result_kept(bpy, s, tmp_path / "kept")
