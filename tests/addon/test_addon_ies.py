"""Photometric profiles in the add-on: a point or spot light with an IES / EULUMDAT profile
(a file or a shipped sample) exports it into Scene.profiles with the light object's frame
(nadir local −Z, C0 towards local −Y) and the chosen brightness; a missing or malformed file
is reported in the export warning, and the light renders without it."""
import importlib
import math

import numpy as np
import pytest

pytestmark = pytest.mark.blender

K_M = 683.0
MODULE = "bl_ext.user_default.spectral_gi"


def _only_light(res):
    assert len(res.scene.lights) == 1
    return res.scene.lights[0]


def test_profile_items_list_the_shipped_samples(ext, bpy):
    props = importlib.import_module(MODULE + ".addon.properties.light")
    ids = [item[0] for item in props.PROFILE_ITEMS]
    assert ids[:2] == ["NONE", "FILE"]
    assert "PRESET_wallwasher" in ids and "PRESET_cosine_downlight" in ids
    assert len(ids) == 2 + len(ext.core.photometric_presets())


def test_point_light_with_a_profile_file_exports_it(ext, bpy):
    b = ext.build
    b.camera()
    obj = b.light("Lum", "POINT", location=(1.0, 2.0, 3.0), energy=10.0)
    obj.rotation_euler = (0.0, 0.0, math.radians(90.0))  # local +X → world +Y, local −Y → world +X
    s = obj.data.spectral_gi
    s.profile = "FILE"
    src = ext.core.photometric_presets()["wallwasher"]
    s.profile_path = str(src)
    res = b.export(ext)
    L = _only_light(res)
    assert res.warning is None or "profile" not in res.warning
    assert L.profile == 0 and L.profile_mode == "file"
    pr = res.scene.profiles[0]
    np.testing.assert_allclose(pr.candela, ext.core.read_profile(src).candela)
    np.testing.assert_allclose(L.direction, (0, 0, -1), atol=1e-6)
    np.testing.assert_allclose(L.axis_u, (0, 1, 0), atol=1e-6)
    # the renderer's frame: C0 (the light's local −Y) is world +X after the 90° turn about Z
    renderer = importlib.import_module(MODULE + ".core.integrators.render")
    lights = importlib.import_module(MODULE + ".core.lights.kernel")
    prep = renderer.prepare(res.scene)
    g = prep.emitters.light_geo[0]
    np.testing.assert_allclose(g[lights.LG_U:lights.LG_U + 3], (0, 1, 0), atol=1e-6)
    np.testing.assert_allclose(g[lights.LG_V:lights.LG_V + 3], (-1, 0, 0), atol=1e-6)  # local +Y
    # light selection: the file's absolute candela, flux π · 1000 lm (bilinear)
    assert prep.emitters.emit_prob.tolist() == [1.0]


def test_preset_profile_and_brightness_from_the_lights_unit(ext, bpy):
    b = ext.build
    b.camera()
    obj = b.light("Spot", "SPOT", location=(0, 0, 3), energy=50.0, spot_size=math.radians(90.0), spot_blend=0.1)
    s = obj.data.spectral_gi
    s.profile = "PRESET_quadrant"
    s.profile_brightness = "UNIT"
    L = _only_light(b.export(ext))
    # Blender power: the same flux as the spot without the profile, I · Ω(cone)
    inten = K_M * 50.0 / (4 * math.pi)
    assert L.profile_mode == "flux"
    assert L.flux == pytest.approx(inten * ext.core.spot_solid_angle(math.radians(90.0), 0.1), rel=1e-6)
    s.unit = "LUMEN"
    s.value = 1200.0
    L = _only_light(b.export(ext))
    assert (L.profile_mode, L.flux) == ("flux", pytest.approx(1200.0))
    s.unit = "CANDELA"
    s.value = 321.0
    L = _only_light(b.export(ext))
    assert (L.profile_mode, L.intensity) == ("peak", pytest.approx(321.0))
    s.profile_brightness = "FILE"
    assert _only_light(b.export(ext)).profile_mode == "file"
    s.profile = "NONE"
    res = b.export(ext)
    assert _only_light(res).profile == -1 and res.scene.profiles == []


# an EULUMDAT file whose cd/klm × lamp flux (1e300 lm) overflows: refused, never infinite candela
OVERFLOWING_LDT = "\n".join(
    ["c", "1", "1", "4", "90", "2", "90", "r", "l", "n", "f.ldt", "d", "100", "100", "50", "80", "80", "0", "0", "0",
     "0", "100", "100", "1", "0", "1", "1", "lamp", "1e300", "3000 K", "1B", "10"]
    + ["0.5"] * 10 + ["0", "90", "180", "270", "0", "90", "1e10", "5e9"]) + "\n"


@pytest.mark.parametrize("content, problem, name", [
    (None, "no such file", "broken.ies"),
    ("IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 3", "truncated", "broken.ies"),
    ("IESNA:LM-63-2002\nTILT=INCLUDE\n", "TILT=INCLUDE", "broken.ies"),
    (OVERFLOWING_LDT, "broken.ldt: ", "broken.ldt"),
])
def test_bad_profile_file_is_reported_not_fatal(ext, bpy, tmp_path, content, problem, name):
    b = ext.build
    b.camera()
    obj = b.light("Broken", "POINT", location=(0, 0, 2), energy=10.0)
    path = tmp_path / name
    if content is not None:
        path.write_text(content)
    obj.data.spectral_gi.profile = "FILE"
    obj.data.spectral_gi.profile_path = str(path)
    res = b.export(ext)
    assert res.warning is not None and "Broken" in res.warning and problem in res.warning
    assert name in res.warning
    L = _only_light(res)
    assert L.profile == -1  # rendered as a plain point light
    assert L.intensity == pytest.approx(K_M * 10.0 / (4 * math.pi), rel=1e-6)
    # no file at all
    obj.data.spectral_gi.profile_path = ""
    res = b.export(ext)
    assert "no file set" in res.warning


@pytest.mark.slow
def test_cycles_ies_texture_node_renders_at_cycles_brightness(ext, bpy):
    """A point light lit for Cycles: its node tree's IES Texture node (a Lambertian downlight,
    1000 cd cos θ) drives the Emission strength. Exported as the light's profile at Cycles'
    scale (candela × 683 P / 177.83, the IES node's 4π/177.83 per candela: 76 815 cd at the peak
    for 20 W), the mean luminance of a grey floor under it is the closed form ρ/π · I(θ) cos θ / d²
    averaged over the view (296.0 cd/m²; a Cycles render of the same scene from a plain bpy
    session gives 296.1)."""
    b = ext.build
    floor = b.shader("Grey", "ShaderNodeBsdfDiffuse", Color=(0.5, 0.5, 0.5, 1.0))
    b.plane("Floor", size=12.0, material=floor)
    obj = b.light("Lum", "POINT", location=(0.3, 0.0, 2.0), energy=20.0, shadow_soft_size=0.05)
    data = obj.data
    data.use_nodes = True
    tree = data.node_tree
    emission = next(n for n in tree.nodes if n.type == "EMISSION")
    ies = tree.nodes.new("ShaderNodeTexIES")
    ies.mode = "EXTERNAL"
    ies.filepath = str(ext.core.photometric_presets()["cosine_downlight"])
    tree.links.new(ies.outputs["Fac"], emission.inputs["Strength"])
    b.camera(location=(0.0, 0.0, 6.0), rotation=(0.0, 0.0, 0.0), lens=20.0)
    b.resolution(16, 16)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.seed = 16, 1, 1
    res = b.export(ext)
    L = _only_light(res)
    assert L.profile == 0 and L.profile_mode == "peak"
    assert L.intensity == pytest.approx(K_M * 20.0 * 1000.0 / 177.83, rel=1e-6)
    assert res.warning is None or "light node trees" not in res.warning
    film, _ = ext.core.render(res.scene, threads=2)
    ours = float(film.develop().luminance.mean())
    n, t = 160, 18.0 / 20.0  # the closed form over the view (the filter barely changes this smooth mean)
    u = ((np.arange(n) + 0.5) / n * 2 - 1) * t * 6.0
    x, y = np.meshgrid(u, u)
    d2 = (x - 0.3) ** 2 + y ** 2 + 4.0
    cos = 2.0 / np.sqrt(d2)
    closed = float((0.5 / math.pi * L.intensity * cos * cos / d2).mean())
    assert closed == pytest.approx(296.0, abs=0.1)
    assert ours == pytest.approx(closed, rel=0.02)
