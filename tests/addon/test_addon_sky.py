"""Sky Texture worlds: exported as the core's spectral daylight (a sky image and a sun light) and
rendered beside Cycles: a grey ground under the sky, mean luminance within 5 % of Cycles'."""
import math

import pytest

pytestmark = pytest.mark.blender


def sky_world(bpy, scene, sky_type="SINGLE_SCATTERING", elevation=15.0, rotation=30.0, strength=1.0, **props):
    world = bpy.data.worlds.new("Daylight")
    scene.world = world
    tree = world.node_tree
    bg = next(n for n in tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Strength"].default_value = strength
    tex = tree.nodes.new("ShaderNodeTexSky")
    tex.sky_type = sky_type
    tex.sun_elevation = math.radians(elevation)
    tex.sun_rotation = math.radians(rotation)
    for key, value in props.items():
        setattr(tex, key, value)
    tree.links.new(tex.outputs["Color"], bg.inputs["Color"])
    return tex


def ground_under_the_sky(b, bpy, **sky):
    b.plane("Ground", size=400.0, material=b.shader("Grey", "ShaderNodeBsdfDiffuse", Color=(0.5, 0.5, 0.5, 1.0)))
    cam = b.camera(location=(0.0, 0.0, 5.0), rotation=(0.0, 0.0, 0.0))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 4.0
    b.resolution(16, 16)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.seed = 64, 1, 1
    return sky_world(bpy, b.scene, **sky)


def test_sky_texture_exports_a_sky_image_and_a_sun_light(ext, bpy):
    b = ext.build
    ground_under_the_sky(b, bpy, elevation=30.0, rotation=0.0, strength=2.0)
    result = b.export(ext)
    world, lights = result.scene.world, result.scene.lights
    assert world.image is not None and world.image.shape[2] == 3 and world.image_scale == 2.0
    sun = [li for li in lights if li.kind == ext.core.constants.LIGHT_SUN]
    assert len(sun) == 1
    e = math.radians(30.0)
    # rotation 0: the Sun towards +Y, its light travelling towards −Y and down
    assert sun[0].direction == pytest.approx((0.0, -math.cos(e), -math.sin(e)), abs=1e-6)
    assert sun[0].angle == pytest.approx(bpy.data.worlds["Daylight"].node_tree.nodes["Sky Texture"].sun_size)
    assert sun[0].illuminance > 2.0 * 50e3  # lux × strength 2: a clear 30° sun gives ≈ 80 klx
    assert not result.warning or "Sky Texture" not in result.warning


def test_sky_texture_without_its_disc_has_no_sun(ext, bpy):
    b = ext.build
    ground_under_the_sky(b, bpy, sun_disc=False)
    result = b.export(ext)
    assert result.scene.world.image is not None
    assert not [li for li in result.scene.lights if li.kind == ext.core.constants.LIGHT_SUN]


def test_unsupported_sky_types_are_named_in_the_warning(ext, bpy):
    b = ext.build
    ground_under_the_sky(b, bpy, sky_type="HOSEK_WILKIE")
    result = b.export(ext)
    assert "Sky Texture types" in result.warning and "HOSEK_WILKIE" in result.warning
    ground_under_the_sky(b, bpy, sky_type="MULTIPLE_SCATTERING")
    assert "approximated" in b.export(ext).warning


def _ratio(bpy, b, tmp_path):
    s = b.scene.spectral_gi
    s.compare_output_dir = str(tmp_path)
    assert bpy.ops.spectral_gi.compare_cycles() == {"FINISHED"}
    assert s.compare_valid
    return s.compare_luminance_ratio


@pytest.mark.slow
@pytest.mark.parametrize("elevation", [15.0, 60.0])
def test_single_scattering_sky_matches_cycles(ext, bpy, tmp_path, elevation):
    b = ext.build
    ground_under_the_sky(b, bpy, elevation=elevation)
    ratio = _ratio(bpy, b, tmp_path)
    print(f"Single Scattering sky, sun {elevation:g}°: luminance ratio {ratio:.4f}")
    assert ratio == pytest.approx(1.0, abs=0.05)


def test_preetham_sky_exports_its_closed_form(ext, bpy):
    b = ext.build
    tex = ground_under_the_sky(b, bpy, sky_type="PREETHAM")
    tex.sun_direction = (0.3, 0.5, 0.6)
    tex.turbidity = 3.0
    result = b.export(ext)
    assert result.scene.world.image is not None
    assert not [li for li in result.scene.lights if li.kind == ext.core.constants.LIGHT_SUN]  # no sun disc
    assert not result.warning or "Sky Texture" not in result.warning


@pytest.mark.slow
def test_preetham_sky_matches_cycles(ext, bpy, tmp_path):
    b = ext.build
    tex = ground_under_the_sky(b, bpy, sky_type="PREETHAM")
    tex.sun_direction = (0.3, 0.5, 0.6)
    ratio = _ratio(bpy, b, tmp_path)
    print(f"Preetham sky: luminance ratio {ratio:.4f}")
    assert ratio == pytest.approx(1.0, abs=0.05)


@pytest.mark.slow
@pytest.mark.parametrize("elevation", [15.0, 60.0])
def test_multiple_scattering_sky_against_cycles(ext, bpy, tmp_path, elevation):
    """The higher orders are approximated (core/lights/sky.py), the Sun scaled to Cycles' normalisation
    of the model: within 5 %."""
    b = ext.build
    ground_under_the_sky(b, bpy, sky_type="MULTIPLE_SCATTERING", elevation=elevation)
    ratio = _ratio(bpy, b, tmp_path)
    print(f"Multiple Scattering sky, sun {elevation:g}°: luminance ratio {ratio:.4f}")
    assert ratio == pytest.approx(1.0, abs=0.05)


@pytest.mark.slow
def test_sky_seen_by_the_camera_matches_cycles(ext, bpy, tmp_path):
    """The sky itself, seen above a ground, looking away from the Sun: the world image's texels."""
    b = ext.build
    ground_under_the_sky(b, bpy, elevation=30.0, rotation=0.0)  # the Sun towards +Y
    cam = b.scene.camera
    cam.data.type = "PERSP"
    cam.location = (0.0, 0.0, 1.5)
    cam.rotation_euler = (math.radians(80.0), 0.0, math.radians(180.0))  # looking towards −Y, a little down
    ratio = _ratio(bpy, b, tmp_path)
    s = b.scene.spectral_gi
    print(f"sky seen by the camera: luminance ratio {ratio:.4f}, ΔE00 mean {s.compare_delta_e_mean:.2f}")
    assert ratio == pytest.approx(1.0, abs=0.05)
