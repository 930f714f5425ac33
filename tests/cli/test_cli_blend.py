"""``spectral-gi render-blend``: failures in one line, and a real .blend rendered headlessly."""
import json
from pathlib import Path
import subprocess
import sys

import numpy as np
import pytest

from helpers import make_floor_blend
from spectral_gi.cli import main


def test_missing_file(tmp_path, capsys):
    assert main(["render-blend", str(tmp_path / "nope.blend")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nope.blend: no such file" in err


def test_not_a_blend_file(tmp_path, capsys):
    p = tmp_path / "scene.blend"
    p.write_text("not a blend file")
    assert main(["render-blend", str(p)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not a .blend file" in err


def test_bpy_missing(tmp_path):
    p = tmp_path / "fake.blend"
    p.write_bytes(b"BLENDER-v500" + bytes(64))  # passes the header check; bpy is then needed
    code = ("import sys; sys.modules['bpy'] = None; from spectral_gi.cli import main; "
            f"sys.exit(main(['render-blend', {str(p)!r}]))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 1
    assert proc.stderr.count("\n") == 1 and "bpy module" in proc.stderr, proc.stderr


BLEND_EXTRA = """
if "--bad-light" in sys.argv:  # lux is a sun's unit: the exporter refuses it for an area light
    light.spectral_gi.unit = "LUX"
if "--sensors" in sys.argv:  # the floor measures the light of a 100 cd point 3 m above it
    bpy.data.objects["Floor"].spectral_gi_sensor = True
    scene.spectral_gi.use_sensors = True
    light.type = "POINT"
    light.shadow_soft_size = 0.0
    light.spectral_gi.unit = "CANDELA"
    light.spectral_gi.value = 100.0
scene.render.engine = "CYCLES"  # render-blend renders with Spectral GI whatever the file says
scene.view_layers[0].spectral_gi.use_pass_xyz = True  # besides Luminance, on by default
scene.view_layers[0].spectral_gi.use_pass_depth = True
"""


def _make_blend(path, *flags):
    return make_floor_blend(path, BLEND_EXTRA, *flags)


def _cli(*args, timeout=1200):
    return subprocess.run([sys.executable, "-m", "spectral_gi.cli", "render-blend", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout)


@pytest.mark.slow
@pytest.mark.blender
def test_render_blend_end_to_end(tmp_path):
    """The file is rendered by the registered engine (F12's path): its passes, its units, --spp honoured."""
    pytest.importorskip("bpy")
    blend = _make_blend(tmp_path / "scene.blend")
    out, report = tmp_path / "out" / "render.exr", tmp_path / "report.json"
    proc = _cli(blend, "--out", out, "--spp", "4", "--compare-cycles", "--json", report, "--mkdir")
    assert proc.returncode == 0, proc.stderr[-3000:]
    import OpenEXR

    chans = {}
    with OpenEXR.File(str(out), separate_channels=True) as f:  # a multilayer EXR: one part per pass
        for part in f.parts:
            for name, ch in part.channels.items():
                chans[name] = np.array(ch.pixels, np.float64)
    for name in ("Combined.R", "Combined.G", "Combined.B", "Combined.A", "Luminance.Y", "XYZ.X", "XYZ.Y", "XYZ.Z",
                 "Depth.Z"):
        assert f"ViewLayer.{name}" in chans, (name, sorted(chans))
    lum = chans["ViewLayer.Luminance.Y"]
    assert lum.shape == (8, 12) and lum.mean() > 0.0 and np.all(np.isfinite(lum))
    # the engine's passes are consistent: luminance is K_m·Y of the XYZ pass, and Y of the Rec.709 RGB
    np.testing.assert_allclose(lum, 683.0 * chans["ViewLayer.XYZ.Y"], rtol=1e-5)
    rgb = np.stack([chans[f"ViewLayer.Combined.{c}"] for c in "RGB"], -1)
    np.testing.assert_allclose(lum, 683.0 * rgb @ np.array([0.2126, 0.7152, 0.0722]), rtol=2e-3, atol=1e-3)
    # the camera looks down at the floor from 3 m: the depth pass holds metres, not 1e10, at the bottom rows
    assert 2.0 < chans["ViewLayer.Depth.Z"][-1].mean() < 8.0
    assert out.with_suffix(".png").is_file()
    assert proc.stderr.count("spectral-gi: error") == 0
    doc = json.loads(report.read_text())
    assert doc["engine"] == "SPECTRAL_GI" and {"Combined", "Luminance", "XYZ", "Depth"} <= set(doc["passes"])
    assert doc["samples"] == 4 and (doc["width"], doc["height"]) == (12, 8)  # --spp overrides the file's 2
    assert doc["mean_luminance"] == pytest.approx(float(lum.mean()), rel=1e-6)
    cmp = doc["comparison"]
    assert cmp["samples"] == 4 and np.isfinite(cmp["luminance_ratio"]) and cmp["luminance_ratio"] > 0.5
    assert json.loads(proc.stdout.strip().splitlines()[-1])["samples"] == 4
    # the reported times are the renders' own, not the hand-over of a finished image
    assert cmp["seconds_spectral_gi"] >= doc["seconds"] > 1e-3
    # the PNG went through Blender's colour management (the file's AgX view), not a plain sRGB encode
    from helpers import read_png_rgb8
    from spectral_gi.core.io.png import to_srgb8

    assert doc["png_view_transform"].startswith("AgX")
    png = read_png_rgb8(out.with_suffix(".png")).astype(int)
    plain = to_srgb8(rgb).astype(int)
    assert png.shape == plain.shape and np.abs(png - plain).mean() > 2.0
    # the comparison images come as PNG too; report files are readable like the images
    for key in ("side_by_side_png", "delta_e00_png"):
        assert Path(cmp["images"][key]).is_file()
    assert report.stat().st_mode & 0o044 == out.with_suffix(".png").stat().st_mode & 0o044


def _one_line_error(proc, *needles):
    assert proc.returncode == 1, (proc.returncode, proc.stderr[-2000:])
    errors = [ln for ln in proc.stderr.splitlines() if ln.startswith("spectral-gi: error:")]
    assert len(errors) == 1 and "Traceback" not in proc.stderr, proc.stderr[-2000:]
    for needle in needles:
        assert needle in errors[0], errors[0]


@pytest.mark.slow
@pytest.mark.blender
def test_render_blend_failures_are_one_line(tmp_path):
    pytest.importorskip("bpy")
    blend = _make_blend(tmp_path / "scene.blend")
    # bad arguments: not an EXR name
    _one_line_error(_cli(blend, "--out", tmp_path / "render.png"), "--out", ".exr")
    # a damaged .blend: the header is right, the rest cut off
    broken = tmp_path / "broken.blend"
    broken.write_bytes(blend.read_bytes()[:3000])
    _one_line_error(_cli(broken, "--out", tmp_path / "b.exr"), "broken.blend", "cannot open")
    assert not (tmp_path / "b.exr").exists()
    # a scene the exporter refuses: the engine's error, in one line, and no output file
    bad = _make_blend(tmp_path / "bad_light.blend", "--bad-light")
    proc = _cli(bad, "--out", tmp_path / "bad.exr", "--spp", "1")
    _one_line_error(proc, "bad_light.blend", "Key")
    assert not (tmp_path / "bad.exr").exists()


@pytest.mark.slow
@pytest.mark.blender
def test_render_blend_json_holds_the_sensor_statistics(tmp_path):
    """With Sensors on, the JSON report gives the sensor statistics as fields: the sensor
    objects and, over the pixels fully on a sensor, Em, Emin, Emax (lux) and U0. The floor is
    lit by a 100 cd point light 3 m above it and nothing else (a plane does not light itself),
    so no point of it gets more than I / h² = 11.1 lx, and the pixel nearest the foot of the
    light close to that; without the option the field is null."""
    pytest.importorskip("bpy")
    blend = _make_blend(tmp_path / "sensors.blend", "--sensors")
    out, report = tmp_path / "render.exr", tmp_path / "report.json"
    proc = _cli(blend, "--out", out, "--json", report)
    assert proc.returncode == 0, proc.stderr[-3000:]
    doc = json.loads(report.read_text())
    sensors = doc["sensors"]
    assert sensors["objects"] == ["Floor"] and sensors["count"] == 1 and sensors["unit"] == "lx"
    assert 0 < sensors["pixels"] <= 12 * 8
    peak = 100.0 / 3.0 ** 2
    assert 0.8 * peak < sensors["Emax"] <= peak * (1 + 1e-6)
    assert 0.0 < sensors["Emin"] <= sensors["Em"] <= sensors["Emax"]
    assert sensors["U0"] == pytest.approx(sensors["Emin"] / sensors["Em"], rel=1e-9)
    assert f"Em {sensors['Em']:.4g} lx" in doc["engine_message"]  # the same figures as the text line
    plain = _make_blend(tmp_path / "plain.blend")
    proc = _cli(plain, "--out", tmp_path / "plain.exr", "--json", tmp_path / "plain.json")
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert json.loads((tmp_path / "plain.json").read_text())["sensors"] is None
