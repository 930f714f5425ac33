"""The SPECTRAL_GI RenderEngine: F12 renders with passes, cancel, animation, errors, panels."""
import importlib

import numpy as np
import pytest

from helpers import floor_cube_scene, recording_layout

pytestmark = pytest.mark.blender

MODULE = "bl_ext.user_default.spectral_gi"
ALL_PASSES = ("use_pass_xyz", "use_pass_luminance", "use_pass_lab", "use_pass_variance", "use_pass_albedo",
              "use_pass_normal", "use_pass_depth")


def read_multilayer(path):
    """{'Pass.Channel': (H, W) array} of a Blender multilayer EXR (one part per pass), rows top-down."""
    import OpenEXR

    out = {}
    with OpenEXR.File(str(path), separate_channels=True) as f:
        for part in f.parts:
            for name, ch in part.channels.items():
                out[name.split(".", 1)[1] if name.count(".") >= 2 else name] = np.array(ch.pixels, np.float64)
    return out


def render_still(bpy, path, multilayer=True):
    r = bpy.context.scene.render
    if multilayer:
        r.image_settings.media_type = "MULTI_LAYER_IMAGE"
    else:
        r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.filepath = str(path)
    assert bpy.ops.render.render(write_still=True) == {"FINISHED"}


def test_engine_is_registered_with_its_panels(ext, bpy):
    cls = bpy.types.RenderEngine.bl_rna  # noqa: F841 (the RNA exists)
    engine = importlib.import_module(MODULE + ".addon.engine").SpectralGIRenderEngine
    assert (engine.bl_idname, engine.bl_label, engine.bl_use_preview) == ("SPECTRAL_GI", "Spectral GI", False)
    scene = bpy.context.scene
    scene.render.engine = "SPECTRAL_GI"
    assert scene.render.engine == "SPECTRAL_GI"
    for name in ("SPECTRALGI_PT_sampling", "SPECTRALGI_PT_film", "SPECTRALGI_PT_passes", "SPECTRALGI_PT_light"):
        panel = getattr(bpy.types, name)
        assert panel.COMPAT_ENGINES == {"SPECTRAL_GI"}
    assert "SPECTRAL_GI" in bpy.types.RENDER_PT_format.COMPAT_ENGINES  # Blender's output panels follow
    assert "SPECTRAL_GI" in bpy.types.DATA_PT_camera_dof.COMPAT_ENGINES  # settings the exporter reads
    assert "SPECTRAL_GI" in bpy.types.EEVEE_WORLD_PT_surface.COMPAT_ENGINES
    assert "SPECTRAL_GI" not in bpy.types.DATA_PT_light.COMPAT_ENGINES  # our light panel replaces it
    assert bpy.types.SPECTRALGI_PT_sampling.poll(bpy.context)
    scene.render.engine = "CYCLES"
    assert not bpy.types.SPECTRALGI_PT_sampling.poll(bpy.context)


def test_f12_render_gives_every_pass_with_the_core_values(ext, bpy, tmp_path):
    b = ext.build
    floor_cube_scene(b)
    vl = bpy.context.view_layer
    for prop in ALL_PASSES:
        setattr(vl.spectral_gi, prop, True)
    render_still(bpy, tmp_path / "f12.exr")
    ch = read_multilayer(tmp_path / "f12.exr")
    for name in ("Combined.R", "Combined.G", "Combined.B", "Combined.A", "XYZ.X", "XYZ.Y", "XYZ.Z", "Luminance.Y",
                 "Lab.L", "Lab.A", "Lab.B", "Variance.V", "Albedo.R", "Albedo.G", "Albedo.B", "Normal.X",
                 "Normal.Y", "Normal.Z", "Depth.Z"):
        assert name in ch, (name, sorted(ch))
        assert ch[name].shape == (16, 16)

    # The same scene rendered by core directly (same seed and samples; films are identical
    # whatever the thread count): every pass equals its development, rows in the right order.
    scene = b.export(ext).scene
    film, stats = ext.core.render(scene)
    dev = film.develop()
    assert stats.spp == 4
    np.testing.assert_allclose(ch["Luminance.Y"], dev.luminance, rtol=1e-5, atol=1e-6)
    rgb = np.stack([ch[f"Combined.{c}"] for c in "RGB"], axis=-1)
    np.testing.assert_allclose(rgb, dev.rgb, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(np.stack([ch[f"XYZ.{c}"] for c in "XYZ"], -1), dev.XYZ, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(np.stack([ch[f"Lab.{c}"] for c in "LAB"], -1), dev.Lab, rtol=1e-4, atol=1e-4)
    assert np.all(ch["Combined.A"] == 1.0)
    # physics of the passes: luminance is K_m · Y of the XYZ pass; the variance is finite at 4 spp
    np.testing.assert_allclose(ch["Luminance.Y"], 683.0 * ch["XYZ.Y"], rtol=1e-5)
    assert np.all(np.isfinite(ch["Variance.V"])) and ch["Variance.V"].max() > 0.0
    # no world: the sky at the top of the image is black; the lit floor and cube are not
    assert np.all(ch["Luminance.Y"][0] == 0.0) and ch["Luminance.Y"][8:].mean() > 1.0
    for aov, chans in (("albedo", "RGB"), ("normal", "XYZ"), ("depth", "Z")):
        data = getattr(dev, aov, None)
        got = np.stack([ch[f"{aov.title()}.{c}"] for c in chans], -1).squeeze()
        if data is None:  # this core does not produce the AOV yet: the pass is black
            assert np.all(got == 0.0)
        else:
            want = np.asarray(data, np.float64).squeeze()
            if aov == "depth":
                want = np.where(np.isfinite(want), want, 1e10)
            np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-5)


def test_cancel_mid_render_keeps_the_partial_result(ext, bpy, tmp_path, monkeypatch):
    b = ext.build
    floor_cube_scene(b, spp=512)
    seen = {"passes": 0}
    real_render = ext.core.render

    def render(scene, **kw):
        progress, test_break = kw["progress"], kw["should_cancel"]
        assert "test_break" in repr(test_break)  # the engine's own test_break() is the cancel check

        def counting(done, total, rate):
            seen["passes"] += 1
            progress(done, total, rate)

        # Esc in Blender makes test_break() return True; here it does after the first pass
        kw["progress"] = counting
        kw["should_cancel"] = lambda: seen["passes"] >= 1 or test_break()
        return real_render(scene, **kw)

    monkeypatch.setattr(ext.core, "render", render)
    render_still(bpy, tmp_path / "partial.exr")
    message = ext.render_job.STATE.message
    assert message.startswith("Cancelled after"), message
    done = int(message.split()[2])
    assert 1 <= done < 512
    ch = read_multilayer(tmp_path / "partial.exr")
    assert ch["Luminance.Y"].mean() > 0.0 and np.all(np.isfinite(ch["Combined.R"]))


def test_animation_renders_every_frame(ext, bpy, tmp_path):
    """Two frames with the light's power keyframed 100 W → 400 W: with the same seed the paths are
    the same, and the transport is linear in the emitted power, so frame 2 is exactly 4× frame 1."""
    b = ext.build
    key, _ = floor_cube_scene(b, spp=2)
    scene = b.scene
    key.data.energy = 100.0
    key.data.keyframe_insert("energy", frame=1)
    key.data.energy = 400.0
    key.data.keyframe_insert("energy", frame=2)
    scene.frame_start, scene.frame_end = 1, 2
    r = scene.render
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.filepath = str(tmp_path / "frame_")
    assert bpy.ops.render.render(animation=True) == {"FINISHED"}
    frames = sorted(tmp_path.glob("frame_*.exr"))
    assert [f.name for f in frames] == ["frame_0001.exr", "frame_0002.exr"]
    means = []
    for f in frames:
        chans, _ = ext.core.read_exr(f)
        means.append(np.mean([chans[c] for c in "RGB"]))
    assert means[0] > 0.0
    assert means[1] / means[0] == pytest.approx(4.0, rel=1e-5)


def test_export_errors_are_reported_not_raised(ext, bpy, tmp_path):
    b = ext.build
    b.plane("Floor")
    b.resolution(8, 8)
    b.scene.render.engine = "SPECTRAL_GI"
    b.scene.camera = None
    engine = importlib.import_module(MODULE + ".addon.engine").SpectralGIRenderEngine
    reports = []

    class Fake:
        resolution_x = resolution_y = 8

        def report(self, kind, text):
            reports.append((kind, text))

        def update_stats(self, *a):
            pass

        def test_break(self):
            return False

    # Blender refuses F12 without a camera before calling the engine; the engine's own guard:
    engine.render(Fake(), bpy.context.evaluated_depsgraph_get())
    assert reports and reports[0][0] == {"ERROR"} and "no active camera" in reports[0][1]


def test_transparent_film(ext, bpy, tmp_path):
    b = ext.build
    floor_cube_scene(b, spp=2)
    b.scene.render.film_transparent = True
    render_still(bpy, tmp_path / "alpha.exr")
    ch = read_multilayer(tmp_path / "alpha.exr")
    dev = ext.core.render(b.export(ext).scene)[0].develop()
    if getattr(dev, "depth", None) is None:
        pytest.skip("this core has no depth AOV (alpha stays 1)")
    hit = np.isfinite(dev.depth)
    assert hit.any() and (~hit).any()
    assert np.all(ch["Combined.A"][~hit] == 0.0) and np.all(ch["Combined.A"][hit] > 0.0)  # sky rows: alpha 0
    # the core's alpha (the fraction of samples that hit something: partial on edges)
    np.testing.assert_allclose(ch["Combined.A"], dev.alpha, rtol=1e-6)
    assert np.all(ch["Combined.R"][~hit] == 0.0)  # premultiplied: no colour where nothing was hit


def test_panels_draw_for_every_light_type(ext, bpy):
    """The engine's panels draw without errors and name only properties that exist."""
    from unittest import mock

    b = ext.build
    floor_cube_scene(b)
    ctx = bpy.context
    drawn = []

    def layout():
        return recording_layout(drawn)

    for name in ("SPECTRALGI_PT_sampling", "SPECTRALGI_PT_film", "SPECTRALGI_PT_passes"):
        panel = getattr(bpy.types, name)
        assert panel.poll(ctx)
        panel.draw(mock.MagicMock(layout=layout()), ctx)
    assert {"samples", "sampler", "pixel_filter", "use_pass_albedo", "use_pass_depth"} <= set(drawn)
    light_panel = bpy.types.SPECTRALGI_PT_light
    for kind in ("POINT", "SPOT", "SUN", "AREA"):
        data = bpy.data.lights.new(kind, kind)
        for unit, spectrum in (("BLENDER", "RGB"), ("LUMEN", "BLACKBODY"), ("LUX", "ILLUMINANT"), ("NIT", "LED")):
            data.spectral_gi.unit, data.spectral_gi.spectrum = unit, spectrum
            drawn.clear()
            light_panel.draw(mock.MagicMock(layout=layout()), mock.MagicMock(light=data))
            assert "unit" in drawn and "spectrum" in drawn


def test_white_balance_to_the_light(ext, bpy, tmp_path):
    """A grey floor under a 2700 K blackbody: orange without white balance, neutral with it."""
    b = ext.build
    key, _ = floor_cube_scene(b, spp=16)
    s = key.data.spectral_gi
    s.spectrum, s.temperature = "BLACKBODY", 2700.0
    means = {}
    for wb in ("NONE", "LIGHT"):
        b.scene.spectral_gi.white_balance = wb
        render_still(bpy, tmp_path / f"wb_{wb}.exr")
        ch = read_multilayer(tmp_path / f"wb_{wb}.exr")
        floor = ch["Luminance.Y"] > 0.0
        floor[:, :] &= np.abs(np.arange(16) - 7.5)[None, :] > 5  # the grey floor beside the red cube
        means[wb] = [ch[f"Combined.{c}"][floor].mean() for c in "RGB"]
    r, g, bl = means["NONE"]
    assert r > 1.5 * bl  # 2700 K is orange
    r, g, bl = means["LIGHT"]
    assert r / g == pytest.approx(1.0, abs=0.03) and bl / g == pytest.approx(1.0, abs=0.03)


def test_time_limit_stops_the_engine_early(ext, bpy, tmp_path):
    if "stop_reason" not in getattr(ext.core.RenderStats, "__dataclass_fields__", {}):
        pytest.skip("this core does not stop at settings.time_limit")
    b = ext.build
    floor_cube_scene(b, spp=1 << 20)
    b.scene.spectral_gi.time_limit = 1.0
    render_still(bpy, tmp_path / "timed.exr")
    message = ext.render_job.STATE.message
    done = int(message.split()[0])
    assert 1 <= done < 1 << 20 and "time limit" in message, message
    assert read_multilayer(tmp_path / "timed.exr")["Luminance.Y"].mean() > 0.0
