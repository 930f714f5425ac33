"""Light and camera export: every Blender light type with Cycles' unit conventions, photometric units,
spectrum sources; orthographic and thin-lens cameras. Values are checked against hand-computed numbers."""
import importlib
import math

import numpy as np
import pytest

pytestmark = pytest.mark.blender

K_M = 683.0  # lm per Blender watt (core/units.py)
REC709_Y = (0.2126390, 0.7151687, 0.0721923)
MODULE = "bl_ext.user_default.spectral_gi"


def y_of(rgb):
    return sum(w * c for w, c in zip(REC709_Y, rgb))


def export_one(ext, bpy, obj, scale_length=1.0):
    """The core Light of ``obj`` (export_light on its evaluated object), plus the export context."""
    light_mod = importlib.import_module(MODULE + ".addon.export.light")
    context_mod = importlib.import_module(MODULE + ".addon.export.context")
    convert = importlib.import_module(MODULE + ".addon.export.convert")
    dg = bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(dg)
    ctx = context_mod.ExportContext(scale_length)
    return light_mod.export_light(ctx, ev, convert.matrix_to_array(ev.matrix_world), obj.name), ctx


def chromaticity(ctx, index):
    from spectral_gi.core.spectra.fit import emission_XYZ

    XYZ = emission_XYZ(ctx.spectra.coeffs[index])
    return XYZ[:2] / XYZ.sum()


def test_point_light_intensity_follows_cycles(ext, bpy):
    b = ext.build
    rgb = (1.0, 0.5, 0.25)
    obj = b.light("Bulb", "POINT", location=(1.0, 2.0, 3.0), energy=100.0, color=rgb, shadow_soft_size=0.1)
    L, _ = export_one(ext, bpy, obj)
    C = ext.core.constants
    assert L.kind == C.LIGHT_POINT
    # Cycles: P/(4π) W/sr; 683 lm per Blender W; colour weight Y(rgb)
    I = K_M * 100.0 / (4 * math.pi) * y_of(rgb)
    assert L.intensity == pytest.approx(I, rel=1e-5)
    assert L.radius == pytest.approx(0.1)
    assert L.luminance == pytest.approx(I / (math.pi * 0.01), rel=1e-5)  # a sphere of radius r: L = I/(πr²)
    np.testing.assert_allclose(L.position, (1, 2, 3), atol=1e-6)
    obj.data.exposure = 1.0  # Cycles: power · 2^exposure
    assert export_one(ext, bpy, obj)[0].intensity == pytest.approx(2 * I, rel=1e-5)


def test_spot_light(ext, bpy):
    b = ext.build
    obj = b.light("Spot", "SPOT", location=(0, 0, 4), energy=50.0, spot_size=math.radians(60.0), spot_blend=0.2)
    obj.rotation_euler = (math.radians(30.0), 0.0, 0.0)
    L, _ = export_one(ext, bpy, obj)
    assert L.kind == ext.core.constants.LIGHT_SPOT
    # same intensity convention as a point light (the cone does not concentrate the power)
    assert L.intensity == pytest.approx(K_M * 50.0 / (4 * math.pi), rel=1e-5)
    assert L.spot_angle == pytest.approx(math.radians(60.0), rel=1e-6)
    assert L.spot_blend == pytest.approx(0.2, rel=1e-6)
    # local -Z rotated 30° about X: (0, sin 30°, -cos 30°)
    np.testing.assert_allclose(L.direction, (0.0, 0.5, -math.sqrt(3) / 2), atol=1e-6)
    # a data sheet's 800 lm inside the cone: I = Φ / (2π (1 − cos 30°) (1 − 0.2/2))
    obj.data.spectral_gi.unit = "LUMEN"
    obj.data.spectral_gi.value = 800.0
    L, _ = export_one(ext, bpy, obj)
    assert L.intensity == pytest.approx(800.0 / (2 * math.pi * (1 - math.cos(math.radians(30))) * 0.9), rel=1e-6)


def test_sun_light(ext, bpy):
    b = ext.build
    obj = b.light("Sun", "SUN", location=(0, 0, 10), energy=3.0, angle=math.radians(0.526))
    obj.rotation_euler = (0.0, math.radians(45.0), 0.0)
    L, _ = export_one(ext, bpy, obj)
    assert L.kind == ext.core.constants.LIGHT_SUN
    assert L.illuminance == pytest.approx(K_M * 3.0, rel=1e-6)  # strength is irradiance W/m²
    assert L.angle == pytest.approx(math.radians(0.526), rel=1e-5)
    # local -Z rotated 45° about Y: (-sin 45°, 0, -cos 45°)
    np.testing.assert_allclose(L.direction, (-math.sqrt(0.5), 0.0, -math.sqrt(0.5)), atol=1e-6)
    # a uniform disc of half-angle θ gives E = L π sin²θ
    assert L.luminance == pytest.approx(L.illuminance / (math.pi * math.sin(math.radians(0.263)) ** 2), rel=1e-5)
    obj.data.spectral_gi.unit = "LUX"
    obj.data.spectral_gi.value = 100000.0
    assert export_one(ext, bpy, obj)[0].illuminance == pytest.approx(100000.0)


def test_designer_units_and_spectra(ext, bpy):
    """'1200 lm, 3000 K': lumens and a blackbody, whatever Blender's power and colour say."""
    b = ext.build
    obj = b.light("Lamp", "POINT", energy=5.0, color=(0.1, 0.9, 0.1))
    s = obj.data.spectral_gi
    s.unit, s.value, s.spectrum, s.temperature = "LUMEN", 1200.0, "BLACKBODY", 3000.0
    L, ctx = export_one(ext, bpy, obj)
    assert L.intensity == pytest.approx(1200.0 / (4 * math.pi), rel=1e-9)
    # Planckian locus at 3000 K: CIE 1931 (0.4369, 0.4041)
    np.testing.assert_allclose(chromaticity(ctx, L.spectrum), (0.4369, 0.4041), atol=2e-3)
    s.unit, s.value = "CANDELA", 250.0
    s.spectrum, s.illuminant = "ILLUMINANT", "D65"
    L, ctx = export_one(ext, bpy, obj)
    assert L.intensity == pytest.approx(250.0)
    np.testing.assert_allclose(chromaticity(ctx, L.spectrum), (0.3127, 0.3290), atol=2e-3)
    s.spectrum, s.led = "LED", "LED-B3"
    L, ctx = export_one(ext, bpy, obj)
    assert ctx.spectra.names[L.spectrum] == "LED-B3"
    # Blender's units with a named spectrum: the light counts as white (683 lm per W), its colour is ignored
    s.unit = "BLENDER"
    assert export_one(ext, bpy, obj)[0].intensity == pytest.approx(K_M * 5.0 / (4 * math.pi), rel=1e-6)


def test_area_light_photometric_units(ext, bpy):
    b = ext.build
    obj = b.light("Panel", "AREA", energy=10.0, shape="RECTANGLE", size=2.0, size_y=0.5)
    s = obj.data.spectral_gi
    s.unit, s.value = "NIT", 1500.0
    assert export_one(ext, bpy, obj)[0].luminance == pytest.approx(1500.0)
    s.unit, s.value = "LUMEN", 3000.0  # one-sided Lambertian emitter: Φ = π A L
    assert export_one(ext, bpy, obj)[0].luminance == pytest.approx(3000.0 / (math.pi * 1.0), rel=1e-6)
    s.unit, s.value = "CANDELA", 400.0  # along the normal: I = L A
    assert export_one(ext, bpy, obj)[0].luminance == pytest.approx(400.0, rel=1e-6)


def test_unit_that_does_not_apply_is_an_export_error(ext, bpy):
    obj = ext.build.light("Sun", "SUN", energy=1.0)
    obj.data.spectral_gi.unit = "LUMEN"
    with pytest.raises(ext.export.ExportError, match="Sun.*unit 'lm' does not apply"):
        export_one(ext, bpy, obj)
    obj.data.spectral_gi.unit = "LUX"
    obj.data.spectral_gi.spectrum = "ILLUMINANT"
    obj.data.spectral_gi.illuminant = "no such light"
    with pytest.raises(ext.export.ExportError, match="illuminant"):
        export_one(ext, bpy, obj)


def test_light_sizes_follow_the_unit_scale(ext, bpy):
    obj = ext.build.light("Bulb", "POINT", location=(0, 0, 300), energy=10.0, shadow_soft_size=5.0)
    L, _ = export_one(ext, bpy, obj, scale_length=0.01)  # 1 Blender unit = 1 cm
    assert L.radius == pytest.approx(0.05)
    np.testing.assert_allclose(L.position, (0, 0, 3), atol=1e-6)


# ----------------------------------------------------------------------------- cameras

def export_camera(ext, bpy):
    camera_mod = importlib.import_module(MODULE + ".addon.export.camera")
    context_mod = importlib.import_module(MODULE + ".addon.export.context")
    ctx = context_mod.ExportContext(bpy.context.scene.unit_settings.scale_length)
    return camera_mod.export_camera(ctx, bpy.context.scene, bpy.context.evaluated_depsgraph_get()), ctx


def test_orthographic_camera(ext, bpy):
    b = ext.build
    cam = b.camera(location=(0, -5, 1), rotation=(math.radians(90), 0, 0))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 4.0
    b.resolution(32, 16)
    c, _ = export_camera(ext, bpy)
    assert c.projection == ext.core.constants.CAM_ORTHOGRAPHIC
    assert c.ortho_scale == pytest.approx(4.0)
    b.scene.unit_settings.scale_length = 0.5
    assert export_camera(ext, bpy)[0].ortho_scale == pytest.approx(2.0)
    cam.data.type = "PANO"
    cam.data.panorama_type = "MIRRORBALL"
    with pytest.raises(ext.export.ExportError, match="panorama type mirrorball is not supported"):
        export_camera(ext, bpy)


@pytest.mark.parametrize("kind", ["EQUIRECTANGULAR", "FISHEYE_EQUIDISTANT", "FISHEYE_EQUISOLID"])
def test_panoramic_camera_exports_cycles_parameters(ext, bpy, kind):
    b = ext.build
    cam = b.camera(location=(0, -5, 1), rotation=(math.radians(90), 0, 0))
    d = cam.data
    d.type, d.panorama_type = "PANO", kind
    d.latitude_min, d.latitude_max, d.longitude_min, d.longitude_max = -0.4, 1.2, -2.0, 2.5
    d.fisheye_fov, d.fisheye_lens = 3.5, 8.0
    d.dof.use_dof, d.dof.aperture_fstop = True, 2.8
    b.resolution(32, 16)
    c, ctx = export_camera(ext, bpy)
    K = ext.core.constants
    assert c.projection == {"EQUIRECTANGULAR": K.CAM_EQUIRECTANGULAR, "FISHEYE_EQUIDISTANT": K.CAM_FISHEYE_EQUIDISTANT,
                            "FISHEYE_EQUISOLID": K.CAM_FISHEYE_EQUISOLID}[kind]
    assert (c.latitude_min, c.latitude_max, c.longitude_min, c.longitude_max) == pytest.approx((-0.4, 1.2, -2.0, 2.5))
    assert (c.fisheye_fov, c.fisheye_lens_mm) == pytest.approx((3.5, 8.0))
    assert c.fstop == 0.0 and "depth of field of a panoramic camera ignored" in (ctx.warning() or "")


def test_depth_of_field(ext, bpy):
    b = ext.build
    cam = b.camera(location=(0, -5, 1), rotation=(math.radians(90), 0, 0))  # looks along +Y
    b.resolution(32, 16)
    c, _ = export_camera(ext, bpy)
    assert c.fstop == 0.0  # DOF off: a pinhole
    cam.data.dof.use_dof = True
    cam.data.dof.aperture_fstop = 2.8
    cam.data.dof.focus_distance = 3.5
    c, _ = export_camera(ext, bpy)
    assert (c.fstop, c.focus_distance) == pytest.approx((2.8, 3.5))
    # a focus object: its distance along the viewing axis (Blender's rule), not the straight-line distance
    target = b.cube("Target", size=0.1, location=(2.0, 4.0, 1.5))
    cam.data.dof.focus_object = target
    c, _ = export_camera(ext, bpy)
    assert c.focus_distance == pytest.approx(9.0, rel=1e-6)


# ----------------------------------------------------------------------------- environment texture

def environment_world(bpy, img, strength=2.0, rotation_z=None, vector_type="POINT"):
    world = bpy.data.worlds.new("Sky")
    bpy.context.scene.world = world
    tree = world.node_tree
    bg = next(n for n in tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Strength"].default_value = strength
    env = tree.nodes.new("ShaderNodeTexEnvironment")
    env.image = img
    tree.links.new(env.outputs["Color"], bg.inputs["Color"])
    if rotation_z is not None:
        mapping = tree.nodes.new("ShaderNodeMapping")
        mapping.vector_type = vector_type
        mapping.inputs["Rotation"].default_value = (0.0, 0.0, rotation_z)
        coords = tree.nodes.new("ShaderNodeTexCoord")
        tree.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
        tree.links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    return world


def export_world(ext, bpy):
    world_mod = importlib.import_module(MODULE + ".addon.export.world")
    context_mod = importlib.import_module(MODULE + ".addon.export.context")
    ctx = context_mod.ExportContext(1.0)
    world = bpy.context.scene.world.evaluated_get(bpy.context.evaluated_depsgraph_get())
    return world_mod.export_world(ctx, world), ctx


def test_environment_texture_world(ext, bpy):
    w, h = 8, 4
    img = bpy.data.images.new("HDRI", width=w, height=h, float_buffer=True, alpha=True)
    px = np.zeros((h, w, 4), np.float32)  # Blender's rows bottom-up
    px[..., 0] = np.arange(w)[None, :]  # red grows to the right
    px[..., 1] = np.arange(h)[:, None]  # green grows upwards (row 0 of Blender's buffer is the bottom)
    px[..., 2] = 0.5
    px[..., 3] = 1.0
    img.pixels.foreach_set(px.reshape(-1))
    environment_world(bpy, img, strength=2.0)
    W, _ = export_world(ext, bpy)
    assert W.image is not None and W.image.dtype == np.float32 and W.image.shape == (h, w, 3)
    np.testing.assert_allclose(W.image, px[::-1, :, :3])  # core: row 0 at the zenith
    assert (W.image_scale, W.rotation, W.background) == (2.0, 0.0, -1)
    # a Mapping node rotating the lookup vector by +z turns the map by -z (matched to Cycles in
    # test_addon_compare.py::test_rotated_environment_matches_cycles)
    environment_world(bpy, img, rotation_z=0.7)
    assert export_world(ext, bpy)[0].rotation == pytest.approx(-0.7)
    environment_world(bpy, img, rotation_z=0.7, vector_type="TEXTURE")  # the inverse transform
    assert export_world(ext, bpy)[0].rotation == pytest.approx(0.7)
    ext.core.validate(ext.core.Scene(world=W))


def test_byte_srgb_environment_is_decoded(ext, bpy):
    img = bpy.data.images.new("LDR", width=2, height=1, float_buffer=False)
    img.colorspace_settings.name = "sRGB"
    img.pixels.foreach_set(np.array([0.5, 0.5, 0.5, 1.0, 1.0, 0.0, 0.0, 1.0], np.float32))
    environment_world(bpy, img, strength=1.0)
    W, _ = export_world(ext, bpy)
    # IEC 61966-2-1: sRGB 0.5 (byte 128/255 = 0.50196) is linear ((0.50196 + 0.055) / 1.055)^2.4 = 0.2158
    assert W.image[0, 0, 0] == pytest.approx(((128 / 255 + 0.055) / 1.055) ** 2.4, rel=1e-4)
    assert W.image[0, 1].tolist() == pytest.approx([1.0, 0.0, 0.0])
