"""Colour output, observer, Fourier order and spectrum files in the add-on (real bpy)."""
import importlib
import math

import numpy as np
import pytest

from helpers import floor_cube_scene, recording_layout

pytestmark = pytest.mark.blender

MODULE = "bl_ext.user_default.spectral_gi"


def read_multilayer(path):
    import OpenEXR

    out = {}
    with OpenEXR.File(str(path), separate_channels=True) as f:
        for part in f.parts:
            for name, ch in part.channels.items():
                out[name.split(".", 1)[1] if name.count(".") >= 2 else name] = np.array(ch.pixels, np.float64)
    return out


def render_still(bpy, path):
    r = bpy.context.scene.render
    r.image_settings.media_type = "MULTI_LAYER_IMAGE"
    r.image_settings.color_depth = "32"
    r.filepath = str(path)
    assert bpy.ops.render.render(write_still=True) == {"FINISHED"}


def write_reflectance(path, rho_blue=0.8, rho_red=0.05, percent=False):
    """A blue-ish reflectance: high below 500 nm, low above."""
    k = 100.0 if percent else 1.0
    lines = ["wavelength,reflectance"]
    for w in range(360, 835, 5):
        v = rho_blue if w < 500 else rho_red
        lines.append(f"{w},{k * v:g}")
    path.write_text("\n".join(lines) + "\n")
    return path


def test_scene_settings_reach_the_core_scene(ext, bpy):
    b = ext.build
    floor_cube_scene(b, w=12, h=10)
    s = b.scene.spectral_gi
    assert (s.colour_space, s.observer, s.fourier_order) == ("REC709", "CIE1931", 12)
    st = b.export(ext).scene.settings
    assert (st.colour_space, st.observer) == ("rec709", "1931")
    s.colour_space, s.observer = "ACESCG", "CIE1964"
    st = b.export(ext).scene.settings
    assert (st.colour_space, st.observer) == ("acescg", "1964")
    s.colour_space = "XYZ"
    assert b.export(ext).scene.settings.colour_space == "xyz"
    with pytest.raises(TypeError):
        s.fourier_order = "x"
    s.fourier_order = 99  # clamped by the property's range
    assert s.fourier_order == 16
    s.fourier_order = 1
    assert s.fourier_order == 3


@pytest.mark.parametrize("order", [3, 5, 12, 16])
def test_fourier_order_sets_the_width_of_every_spectrum(ext, bpy, order):
    b = ext.build
    key, red = floor_cube_scene(b, w=12, h=10)
    key.data.spectral_gi.spectrum, key.data.spectral_gi.temperature = "BLACKBODY", 3000.0
    patch = b.principled("Patch")
    patch.spectral_gi.model, patch.spectral_gi.spectrum = "LAMBERT", "PRESET"
    b.cube("Checker", size=0.5, location=(1.5, 0, 0.25), material=patch)
    b.scene.spectral_gi.fourier_order = order
    scene = b.export(ext).scene
    assert scene.spectra.coeffs.shape == (len(scene.spectra), order)
    assert len(scene.spectra) >= 4  # grey, red, the patch and the blackbody
    # the k-wide table is what the exporter fits at order k (the moments are a prefix of the 16-wide fit)
    full = ext.core.reflectance_preset(patch.spectral_gi.reflectance_preset, 16)
    row = scene.spectra.names.index(f"ColorChecker {patch.spectral_gi.reflectance_preset}")
    np.testing.assert_allclose(scene.spectra.coeffs[row], full[:order], rtol=1e-12, atol=1e-14)


@pytest.mark.slow
def test_acescg_output_is_a_pass_and_combined_stays_rec709(ext, bpy, tmp_path):
    b = ext.build
    floor_cube_scene(b, w=12, h=10)
    b.scene.spectral_gi.colour_space = "ACESCG"
    vl = bpy.context.view_layer
    vl.spectral_gi.use_pass_luminance = True
    render_still(bpy, tmp_path / "aces.exr")
    ch = read_multilayer(tmp_path / "aces.exr")
    assert {"Colour Output.R", "Colour Output.G", "Colour Output.B"} <= set(ch), sorted(ch)
    film, _ = ext.core.render(b.export(ext).scene)
    dev = film.develop(colour_space="acescg")
    out = np.stack([ch[f"Colour Output.{c}"] for c in "RGB"], -1)
    np.testing.assert_allclose(out, dev.output, rtol=1e-5, atol=1e-6)
    rgb = np.stack([ch[f"Combined.{c}"] for c in "RGB"], -1)
    np.testing.assert_allclose(rgb, dev.rgb, rtol=1e-5, atol=1e-6)
    # the two differ (AP1 is wider than Rec.709): the red cube is less saturated in ACEScg
    assert not np.allclose(out, rgb, rtol=1e-2)
    # Rec.709 output: no extra pass
    b.scene.spectral_gi.colour_space = "REC709"
    render_still(bpy, tmp_path / "rec.exr")
    assert not any(k.startswith("Colour Output") for k in read_multilayer(tmp_path / "rec.exr"))


@pytest.mark.slow
def test_observer_keeps_the_luminance_pass(ext, bpy, tmp_path):
    b = ext.build
    floor_cube_scene(b, w=12, h=10)
    bpy.context.view_layer.spectral_gi.use_pass_luminance = True
    bpy.context.view_layer.spectral_gi.use_pass_xyz = True
    got = {}
    for obs in ("CIE1931", "CIE1964"):
        b.scene.spectral_gi.observer = obs
        render_still(bpy, tmp_path / f"{obs}.exr")
        got[obs] = read_multilayer(tmp_path / f"{obs}.exr")
    np.testing.assert_allclose(got["CIE1964"]["Luminance.Y"], got["CIE1931"]["Luminance.Y"], rtol=1e-6, atol=1e-9)
    assert not np.allclose(got["CIE1964"]["XYZ.X"], got["CIE1931"]["XYZ.X"], rtol=1e-3)


def test_material_spectrum_file(ext, bpy, tmp_path):
    b = ext.build
    floor_cube_scene(b, w=12, h=10)
    mat = b.principled("Measured", rgb=(0.2, 0.9, 0.2))
    s = mat.spectral_gi
    s.model, s.spectrum = "LAMBERT", "FILE"
    s.spectrum_file = str(write_reflectance(tmp_path / "blue.csv", percent=True))
    b.cube("Sample", size=0.5, location=(1.5, 0, 0.25), material=mat)
    res = b.export(ext)
    sp = res.scene.spectra
    row = sp.names.index("blue.csv")
    values = ext.core.tabulate_reflectance(sp.coeffs[row])
    grid = ext.core.wavelength_grid()
    assert values[(grid > 420) & (grid < 480)].mean() == pytest.approx(0.8, abs=0.05)  # percent read as %
    assert values[(grid > 560) & (grid < 700)].mean() == pytest.approx(0.05, abs=0.05)
    m = next(m for m in res.scene.materials if m.name.startswith("Measured"))
    assert m.reflectance == row
    # a bad file: reported with the material's name and the file's line, the node colour stands in
    (tmp_path / "bad.csv").write_text("380,0.5\n500,oops\n780,0.4\n")
    s.spectrum_file = str(tmp_path / "bad.csv")
    res = b.export(ext)
    assert "Measured" in res.warning and "line 2" in res.warning and "bad.csv" in res.warning
    m = next(m for m in res.scene.materials if m.name.startswith("Measured"))
    green = ext.core.reflectance_to_rgb(res.scene.spectra.coeffs[m.reflectance])
    assert green[1] > 2 * green[0]  # the node's green
    s.spectrum_file = ""
    assert "no file chosen" in b.export(ext).warning


def test_light_spectrum_file(ext, bpy, tmp_path):
    b = ext.build
    key, _ = floor_cube_scene(b, w=12, h=10)
    path = tmp_path / "led.txt"
    path.write_text("# a narrow blue LED\n" + "".join(
        f"{w} {math.exp(-0.5 * ((w - 450) / 12) ** 2):.6f}\n" for w in range(360, 831, 2)))
    s = key.data.spectral_gi
    s.unit, s.value, s.spectrum, s.spectrum_file = "LUMEN", 500.0, "FILE", str(path)
    res = b.export(ext)
    light = res.scene.lights[0]
    from spectral_gi.core.spectra.fit import emission_XYZ

    XYZ = emission_XYZ(res.scene.spectra.coeffs[light.spectrum])
    x, y = XYZ[:2] / XYZ.sum()
    assert x < 0.2 and y < 0.1  # deep blue
    assert res.scene.spectra.names[light.spectrum] == "led.txt"
    # unreadable: reported with the light's name, the RGB colour is used, nothing crashes
    s.spectrum_file = str(tmp_path / "missing.txt")
    res = b.export(ext)
    assert "Key" in res.warning and "missing.txt" in res.warning
    assert res.scene.lights[0].spectrum >= 0


def test_panels_draw_the_new_settings(ext, bpy):
    from unittest import mock

    b = ext.build
    key, red = floor_cube_scene(b, w=12, h=10)
    drawn = []

    def layout():
        return recording_layout(drawn)

    b.scene.spectral_gi.colour_space = "XYZ"
    bpy.types.SPECTRALGI_PT_film.draw(mock.MagicMock(layout=layout()), bpy.context)
    assert {"colour_space", "observer", "fourier_order"} <= set(drawn)
    key.data.spectral_gi.spectrum = "FILE"
    drawn.clear()
    bpy.types.SPECTRALGI_PT_light.draw(mock.MagicMock(layout=layout()), mock.MagicMock(light=key.data))
    assert "spectrum_file" in drawn
    panel_mod = importlib.import_module(MODULE + ".addon.ui.material_panel")
    red.spectral_gi.model, red.spectral_gi.spectrum = "WARD", "FILE"
    drawn.clear()
    panel_mod.draw_settings(layout(), red.spectral_gi)
    assert "spectrum_file" in drawn
