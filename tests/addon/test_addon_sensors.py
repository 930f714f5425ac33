"""Illuminance sensors, holdout and transparent film through the add-on (real bpy, F12)."""

import numpy as np
import pytest


def _engine_tests():
    """tests/addon/test_addon_engine.py, for its EXR reader and F12 helper."""
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location("spectral_gi_test_addon_engine",
                                                  Path(__file__).with_name("test_addon_engine.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


read_multilayer = _engine_tests().read_multilayer
render_still = _engine_tests().render_still

pytestmark = pytest.mark.blender


def top_view(b, size=4.0, res=16):
    """An orthographic camera 5 m up looking straight down over ``size`` m."""
    cam = b.camera(location=(0, 0, 5), rotation=(0, 0, 0))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = size
    b.resolution(res, res)
    return cam


def sensor_scene(b, ext, intensity_cd=100.0, height=2.0, spp=8):
    grey = b.shader("Grey", "ShaderNodeBsdfDiffuse", Color=(0.3, 0.3, 0.3, 1.0))
    floor = b.plane("Floor", size=3.0, material=grey)
    floor.spectral_gi_sensor = True
    light = b.light("Bulb", "POINT", location=(0, 0, height), energy=10.0)
    light.data.shadow_soft_size = 0.0
    light.data.spectral_gi.unit = "CANDELA"
    light.data.spectral_gi.value = intensity_cd  # the add-on's photometric intensity (cd)
    top_view(b)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.seed = spp, 4, 1
    s.use_sensors = True
    b.scene.render.engine = "SPECTRAL_GI"
    return floor, light


def test_sensor_plane_gives_the_analytic_illuminance(ext, bpy, tmp_path):
    b = ext.build
    floor, light = sensor_scene(b, ext)
    scene = b.export(ext).scene
    assert [m.sensor for m in scene.meshes] == [True]
    li = scene.lights[0]
    I = li.intensity
    assert I == pytest.approx(100.0, rel=1e-6)
    render_still(bpy, tmp_path / "lux.exr")
    ch = read_multilayer(tmp_path / "lux.exr")
    assert "Illuminance.X" in ch, sorted(ch)
    lux = ch["Illuminance.X"]
    # the four pixels around the foot of the light: E = I h / (h² + r²)^(3/2) averaged over them
    px = 4.0 / 16
    s = (np.arange(32) + 0.5) / 32 * px
    r2 = s[:, None] ** 2 + s[None, :] ** 2
    want = float(np.mean(I * 2.0 / (4.0 + r2) ** 1.5))
    centre = lux[7:9, 7:9]
    assert np.mean(centre) == pytest.approx(want, rel=0.03), (centre, want)
    assert want == pytest.approx(I / 4.0, rel=0.02)  # ≈ I / h² = 25 lx
    # off the 3 m sensor plane (4 m view): 0 in the pass
    assert np.all(lux[:, 0] == 0.0) and np.all(lux[0, :] == 0.0)
    # the statistics reach the panel's state and the status line
    stats = ext.render_job.STATE.illuminance
    assert stats["pixels"] == 12 * 12
    assert stats["excluded"] == 0 and stats["min_coverage"] == 1.0  # the plane's outline is on pixel edges
    assert stats["Emax"] == pytest.approx(lux.max(), rel=1e-5)
    assert stats["U0"] == pytest.approx(stats["Emin"] / stats["Em"])
    assert "Em" in ext.render_job.STATE.message
    # the panel draws with the report
    from unittest import mock
    panel = bpy.types.SPECTRALGI_PT_sensors
    assert panel.poll(bpy.context)
    layout = mock.MagicMock()
    panel.draw(mock.Mock(layout=layout), bpy.context)
    labels = " ".join(str(c) for c in layout.mock_calls)
    assert "Em (mean)" in labels and "U0" in labels


def test_sensor_report_counts_partly_covered_pixels(ext):
    report = ext.render_job.sensor_report
    st = {"Em": 450.0, "Emin": 28.5, "Emax": 950.0, "U0": 28.5 / 450.0, "pixels": 700, "excluded": 250,
          "min_coverage": 1.0, "Emin_std": 3.2}
    line = report(st)
    assert "Emin 28.5 ± 3.2 lx" in line and "U0 0.063" in line and "(700 px, 250 partly covered px excluded)" in line
    assert report(dict(st, excluded=0, Emin_std=float("nan"))).endswith("U0 0.063 (700 px)")
    nan = float("nan")
    assert "no pixel fully on a sensor (12 partly" in report(dict(st, Em=nan, Emin=nan, Emax=nan, U0=nan, pixels=0,
                                                                    excluded=12))
    assert report({"pixels": 0}) == "Sensors: no sensor surface in view"


def test_no_illuminance_pass_without_sensors_option(ext, bpy, tmp_path):
    b = ext.build
    sensor_scene(b, ext, spp=2)
    b.scene.spectral_gi.use_sensors = False
    render_still(bpy, tmp_path / "plain.exr")
    ch = read_multilayer(tmp_path / "plain.exr")
    assert not any(k.startswith("Illuminance") for k in ch)
    assert ext.render_job.STATE.illuminance is None


def test_holdout_object_and_shader_give_alpha_zero(ext, bpy, tmp_path):
    b = ext.build
    grey = b.shader("Grey", "ShaderNodeBsdfDiffuse", Color=(0.5, 0.5, 0.5, 1.0))
    hold = b.shader("Hold", "ShaderNodeHoldout")
    b.plane("Floor", size=4.0, material=grey)  # fills the 4 m view
    obj_hold = b.plane("ObjectHoldout", size=1.0, location=(-1.0, 0, 0.5), material=grey)
    obj_hold.is_holdout = True
    b.plane("ShaderHoldout", size=1.0, location=(1.0, 0, 0.5), material=hold)
    b.light("Sun", "SUN", location=(0, 0, 5), energy=3.0)
    top_view(b)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.pixel_filter, s.filter_width = 4, 2, "BOX", 1.0
    b.scene.render.engine = "SPECTRAL_GI"
    scene = b.export(ext).scene
    by_name = {m.name: m for m in scene.meshes}
    assert by_name["ObjectHoldout"].holdout and not by_name["Floor"].holdout
    assert scene.materials[by_name["ShaderHoldout"].material[0]].holdout
    render_still(bpy, tmp_path / "holdout.exr")
    ch = read_multilayer(tmp_path / "holdout.exr")
    a = ch["Combined.A"]
    # pixel (row, col) centres: x = -2 + (col + 0.5) / 4, y = 2 - (row + 0.5) / 4; the holdout
    # squares cover x in [-1.5, -0.5] and [0.5, 1.5], y in [-0.5, 0.5]: rows 6-9, cols 2-5 and 10-13
    for cols in (slice(2, 6), slice(10, 14)):
        assert np.all(a[6:10, cols] == 0.0)
        assert np.all(ch["Combined.R"][6:10, cols] == 0.0)
    others = np.ones_like(a, bool)
    others[6:10, 2:6] = others[6:10, 10:14] = False
    assert np.all(a[others] == 1.0)
    assert np.all(ch["Combined.G"][others] > 0.0)


def test_film_transparent_alpha_over_a_lit_world(ext, bpy, tmp_path):
    b = ext.build
    grey = b.shader("Grey", "ShaderNodeBsdfDiffuse", Color=(0.5, 0.5, 0.5, 1.0))
    b.plane("Floor", size=2.0, material=grey)  # half of the 4 m view
    world = bpy.data.worlds.new("Sky")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.2, 0.2, 0.2, 1.0)
    b.scene.world = world
    top_view(b)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.pixel_filter, s.filter_width = 4, 2, "BOX", 1.0
    b.scene.render.engine = "SPECTRAL_GI"
    b.scene.render.film_transparent = True
    assert b.export(ext).scene.settings.film_transparent
    render_still(bpy, tmp_path / "clear.exr")
    ch = read_multilayer(tmp_path / "clear.exr")
    a = ch["Combined.A"]
    assert np.all(a[4:12, 4:12] == 1.0)  # the floor (±1 m: pixels 4-11)
    miss = np.ones_like(a, bool)
    miss[4:12, 4:12] = False
    assert np.all(a[miss] == 0.0) and np.all(ch["Combined.R"][miss] == 0.0)
    # the world still lights the floor: a grey Lambert under a uniform sky of RGB 0.2 reflects 0.5 · 0.2
    assert np.mean(ch["Combined.G"][4:12, 4:12]) == pytest.approx(0.1, rel=0.05)


def test_sensor_and_holdout_flags_of_curves_and_instances(ext, bpy):
    b = ext.build
    curve = bpy.data.curves.new("Text", "FONT")
    curve.body = "A"
    curve.extrude = 0.05
    text = b.link(bpy.data.objects.new("Text", curve))
    text.spectral_gi_sensor = True
    text.is_holdout = True
    plain = b.plane("Plain", size=1.0, location=(3, 0, 0))
    b.camera()
    scene = b.export(ext).scene
    flags = {m.name: (m.sensor, m.holdout) for m in scene.meshes}
    assert flags[plain.name] == (False, False)
    text_flags = [v for k, v in flags.items() if k.startswith("Text")]
    assert text_flags == [(True, True)], flags
