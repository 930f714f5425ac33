"""Blender scene → core scene: cameras, lights, units, meshes, materials, world, warnings, cancel."""
import math

import numpy as np
import pytest

pytestmark = pytest.mark.blender

# Rec.709 luminance weights (the Y row of the RGB→XYZ matrix from the primaries and D65)
REC709_Y = (0.2126390, 0.7151687, 0.0721923)
K_M = 683.0


def luminance_y(rgb):
    return sum(w * c for w, c in zip(REC709_Y, rgb))


def unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


def minimal(b):
    b.camera()
    b.resolution(40, 30)


# ----------------------------------------------------------------------------- camera

@pytest.mark.parametrize("fit", ["AUTO", "HORIZONTAL", "VERTICAL"])
def test_camera(ext, bpy, fit):
    b = ext.build
    cam = b.camera(location=(1, -5, 2), lens=42.0)
    cam.scale = (2.0, 3.0, 0.5)  # object scale must not leak into the camera frame
    cam.data.sensor_fit = fit
    cam.data.sensor_width, cam.data.sensor_height = 30.0, 20.0
    cam.data.shift_x, cam.data.shift_y = 0.1, -0.05
    b.resolution(640, 480, 50)
    scene = b.export(ext).scene
    C = ext.core.constants
    c = scene.camera
    assert c.sensor_fit == {"AUTO": C.FIT_AUTO, "HORIZONTAL": C.FIT_HORIZONTAL, "VERTICAL": C.FIT_VERTICAL}[fit]
    assert (c.width, c.height) == (320, 240)
    assert (c.lens_mm, c.sensor_width_mm, c.sensor_height_mm) == pytest.approx((42.0, 30.0, 20.0))
    assert (c.shift_x, c.shift_y) == pytest.approx((0.1, -0.05))
    rot = np.array(cam.matrix_world.to_3x3().normalized())
    np.testing.assert_allclose(c.to_world[:3, :3], rot, atol=1e-6)
    np.testing.assert_allclose(c.to_world[:3, 3], [1, -5, 2], atol=1e-6)


def test_no_camera_is_an_export_error(ext, bpy):
    ext.build.plane("Floor")
    with pytest.raises(ext.export.ExportError, match="no active camera"):
        ext.build.export(ext)


# ----------------------------------------------------------------------------- lights

def test_area_light_axes_and_luminance(ext, bpy):
    b = ext.build
    minimal(b)
    rgb = (1.0, 0.5, 0.25)
    li = b.light("Panel", "AREA", location=(0.5, 0.25, 3.0), energy=100.0, shape="RECTANGLE", size=2.0,
                 size_y=0.5, color=rgb)
    li.rotation_euler = (math.radians(30), math.radians(-20), math.radians(45))
    li.scale = (1.5, 2.0, 1.0)
    scene = b.export(ext).scene
    assert len(scene.lights) == 1
    L = scene.lights[0]
    assert L.kind == ext.core.constants.LIGHT_RECT
    m = np.array(li.matrix_world)
    np.testing.assert_allclose(L.position, m[:3, 3], atol=1e-6)
    np.testing.assert_allclose(np.abs(np.dot(unit(L.axis_u), unit(m[:3, 0]))), 1.0, atol=1e-6)
    assert np.linalg.norm(L.axis_u) == pytest.approx(0.5 * 2.0 * 1.5, rel=1e-5)
    assert np.linalg.norm(L.axis_v) == pytest.approx(0.5 * 0.5 * 2.0, rel=1e-5)
    # emits along the light's local -Z
    np.testing.assert_allclose(unit(np.cross(L.axis_u, L.axis_v)), unit(-m[:3, 2]), atol=1e-6)
    area = (2.0 * 1.5) * (0.5 * 2.0)
    assert L.luminance == pytest.approx(K_M * 100.0 / (math.pi * area) * luminance_y(rgb), rel=1e-5)
    assert L.visible is False  # Blender 5.0: lights are invisible to the camera by default
    assert not L.two_sided
    li.visible_camera = True
    assert b.export(ext).scene.lights[0].visible is True


def test_disk_light_exposure_and_normalize(ext, bpy):
    b = ext.build
    minimal(b)
    li = b.light("Disk", "AREA", energy=50.0, shape="DISK", size=2.0, exposure=1.0)
    L = b.export(ext).scene.lights[0]
    assert L.kind == ext.core.constants.LIGHT_ELLIPSE
    assert L.luminance == pytest.approx(K_M * 100.0 / (math.pi * math.pi), rel=1e-5)  # 50 W · 2^1 over π m²
    li.data.normalize = False  # Cycles: power not divided by the area (as if 1 square unit)
    L = b.export(ext).scene.lights[0]
    assert L.luminance == pytest.approx(K_M * 100.0 / math.pi, rel=1e-5)


def test_scale_length_converts_to_metres(ext, bpy):
    b = ext.build
    b.scene.unit_settings.scale_length = 0.01  # 1 Blender unit = 1 cm
    b.camera(location=(0, -600, 200))
    b.resolution(40, 30)
    b.cube("Cube", size=200.0, location=(100, 0, 0))
    b.light("Panel", "AREA", location=(0, 0, 300), energy=10.0, size=100.0)
    scene = b.export(ext).scene
    p = scene.meshes[0].positions
    np.testing.assert_allclose(p.min(axis=0), [0.0, -1.0, -1.0], atol=1e-6)
    np.testing.assert_allclose(p.max(axis=0), [2.0, 1.0, 1.0], atol=1e-6)
    np.testing.assert_allclose(scene.camera.to_world[:3, 3], [0, -6, 2], atol=1e-6)
    L = scene.lights[0]
    np.testing.assert_allclose(L.position, [0, 0, 3], atol=1e-6)
    assert 4 * np.linalg.norm(np.cross(L.axis_u, L.axis_v)) == pytest.approx(1.0)  # 100 cm square = 1 m²
    assert L.luminance == pytest.approx(K_M * 10.0 / math.pi, rel=1e-5)


# ----------------------------------------------------------------------------- meshes

def test_modifiers_are_applied_and_hidden_objects_skipped(ext, bpy):
    b = ext.build
    minimal(b)
    plane = b.plane("Tiles", size=1.0)
    mod = plane.modifiers.new("Array", "ARRAY")
    mod.count = 3
    mod.relative_offset_displace = (1.0, 0.0, 0.0)
    hidden = b.cube("Hidden")
    hidden.hide_render = True
    scene = b.export(ext).scene
    assert [m.name for m in scene.meshes] == ["Tiles"]
    mesh = scene.meshes[0]
    assert mesh.indices.shape == (6, 3) and mesh.indices.dtype == np.int32
    assert mesh.positions.dtype == np.float32
    assert mesh.positions[:, 0].max() - mesh.positions[:, 0].min() == pytest.approx(3.0)
    ext.core.validate(scene)


def test_world_matrix_is_applied(ext, bpy):
    b = ext.build
    minimal(b)
    cube = b.cube("Cube", size=2.0, location=(5, 0, 0))
    cube.rotation_euler = (0, 0, math.radians(45))
    cube.scale = (2, 1, 1)
    p = b.export(ext).scene.meshes[0].positions.astype(np.float64)
    local = np.array([v.co for v in cube.data.vertices])
    m = np.array(cube.matrix_world)
    world = local @ m[:3, :3].T + m[:3, 3]
    np.testing.assert_allclose(np.sort(p, axis=0), np.sort(world, axis=0), atol=1e-5)


# ----------------------------------------------------------------------------- materials

def same_spectrum(a, b):
    """Coefficients equal up to Blender storing colours as float32."""
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-6)


def material_of(scene, mesh_name):
    mesh = next(m for m in scene.meshes if m.name == mesh_name)
    return scene.materials[int(mesh.material[0])]


def coeffs(scene, idx):
    return scene.spectra.coeffs[idx]


def test_materials(ext, bpy):
    b = ext.build
    minimal(b)
    core = ext.core
    b.plane("Principled", material=b.principled("P", (0.2, 0.4, 0.6)))
    b.plane("Glowing", material=b.principled("G", (0.5, 0.5, 0.5), emission=(1.0, 0.8, 0.6), strength=5.0))
    b.plane("Lamp", material=b.shader("E", "ShaderNodeEmission", Color=(0.9, 0.9, 1.0, 1.0), Strength=3.0))
    b.plane("Matte", material=b.shader("D", "ShaderNodeBsdfDiffuse", Color=(0.1, 0.7, 0.2, 1.0)))
    b.plane("Bare")
    viewport = bpy.data.materials.new("NoNodes")
    viewport.node_tree.nodes.clear()
    viewport.diffuse_color = (0.3, 0.2, 0.1, 1.0)
    b.plane("Viewport", material=viewport)
    scene = b.export(ext).scene
    core.validate(scene)

    m = material_of(scene, "Principled")
    same_spectrum(coeffs(scene, m.reflectance), core.reflectance_from_rgb((0.2, 0.4, 0.6)))
    assert m.emission == -1 and m.emission_luminance == 0.0

    m = material_of(scene, "Glowing")
    same_spectrum(coeffs(scene, m.emission), core.emission_from_rgb((1.0, 0.8, 0.6)))
    assert m.emission_luminance == pytest.approx(core.emission_luminance((1.0, 0.8, 0.6), 5.0))
    assert m.emission_luminance == pytest.approx(K_M * 5.0 * luminance_y((1.0, 0.8, 0.6)), rel=1e-5)

    m = material_of(scene, "Lamp")
    assert m.reflectance == -1
    assert m.emission_luminance == pytest.approx(K_M * 3.0 * luminance_y((0.9, 0.9, 1.0)), rel=1e-5)

    m = material_of(scene, "Matte")
    same_spectrum(coeffs(scene, m.reflectance), core.reflectance_from_rgb((0.1, 0.7, 0.2)))

    m = material_of(scene, "Bare")
    same_spectrum(coeffs(scene, m.reflectance), core.reflectance_from_rgb((0.8, 0.8, 0.8)))

    m = material_of(scene, "Viewport")
    same_spectrum(coeffs(scene, m.reflectance), core.reflectance_from_rgb((0.3, 0.2, 0.1)))


def test_linked_inputs_compile_to_programs_or_use_a_substitute_and_warn(ext, bpy):
    b = ext.build
    minimal(b)
    mat = b.principled("Textured", (0.25, 0.5, 0.75))
    tree = mat.node_tree
    bsdf = next(n for n in tree.nodes if n.type == "BSDF_PRINCIPLED")
    tex = tree.nodes.new("ShaderNodeTexGabor")  # not supported by shader programs
    tex.name = "Checker"
    tree.links.new(tex.outputs[0], bsdf.inputs["Base Color"])
    b.plane("Floor", material=mat)
    prog = b.principled("Programmed")
    bsdf3 = next(n for n in prog.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    checker = prog.node_tree.nodes.new("ShaderNodeTexChecker")
    prog.node_tree.links.new(checker.outputs["Color"], bsdf3.inputs["Base Color"])
    b.plane("Tiles", material=prog)
    const = b.principled("Constant")
    bsdf2 = next(n for n in const.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    rgb_node = const.node_tree.nodes.new("ShaderNodeRGB")
    rgb_node.outputs[0].default_value = (0.6, 0.3, 0.1, 1.0)
    const.node_tree.links.new(rgb_node.outputs[0], bsdf2.inputs["Base Color"])
    b.plane("Wall", material=const)
    res = b.export(ext)
    m = material_of(res.scene, "Floor")
    same_spectrum(coeffs(res.scene, m.reflectance), ext.core.reflectance_from_rgb((0.25, 0.5, 0.75)))
    m = material_of(res.scene, "Wall")  # a constant RGB node is read exactly, without a warning
    same_spectrum(coeffs(res.scene, m.reflectance), ext.core.reflectance_from_rgb((0.6, 0.3, 0.1)))
    assert res.warning is not None and "Checker" in res.warning and "Textured" in res.warning
    assert "RGB" not in res.warning
    # a supported node graph becomes the base colour program of the plastic leaf
    assert any(mm.base_colour_program >= 0 for mm in res.scene.materials if mm.name.startswith("Programmed"))
    assert len(res.scene.programs) == 1 and "Programmed" not in res.warning


def test_world_background(ext, bpy):
    b = ext.build
    minimal(b)
    world = bpy.data.worlds.new("Sky")
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (0.2, 0.3, 0.4, 1.0)
    bg.inputs["Strength"].default_value = 2.0
    b.scene.world = world
    scene = b.export(ext).scene
    core = ext.core
    assert scene.world.luminance == pytest.approx(core.emission_luminance((0.2, 0.3, 0.4), 2.0))
    same_spectrum(coeffs(scene, scene.world.background), core.emission_from_rgb((0.2, 0.3, 0.4)))
    bg.inputs["Strength"].default_value = 0.0
    assert b.export(ext).scene.world.background == -1


# ----------------------------------------------------------------------------- warnings and cancel

def test_unsupported_things_are_listed_in_one_warning(ext, bpy):
    b = ext.build
    minimal(b)
    # (point, spot and sun lights are exported since the engine work: tests/addon/test_addon_lights.py)
    b.link(bpy.data.objects.new("Fog", bpy.data.volumes.new("Fog")))
    b.link(bpy.data.objects.new("Helper", None))  # an empty: nothing to render, not reported
    # (Glossy, Glass, Mix, ... are exported since the material work: tests/addon/test_addon_materials.py)
    b.plane("Flat", material=b.shader("Cartoon", "ShaderNodeBsdfToon"))
    res = b.export(ext)
    assert isinstance(res.warning, str) and "\n" not in res.warning
    for name in ("Fog", "Cartoon/Toon BSDF"):
        assert name in res.warning, (name, res.warning)
    assert "Helper" not in res.warning
    assert res.scene.lights == []
    ext.core.validate(res.scene)


def test_clean_scene_has_no_warning(ext, bpy):
    b = ext.build
    minimal(b)
    b.plane("Floor")
    b.light("Panel", "AREA")
    assert b.export(ext).warning is None


def test_cancel_is_checked_between_objects(ext, bpy):
    b = ext.build
    minimal(b)
    for i in range(5):
        b.cube(f"Cube{i}", location=(i * 2, 0, 0))
    calls = []

    def should_cancel():
        calls.append(1)
        return len(calls) >= 3

    with pytest.raises(ext.export.ExportCancelled):
        b.export(ext, should_cancel=should_cancel)
    assert len(calls) == 3


def test_collection_instances_are_exported_once_per_instance(ext, bpy):
    b = ext.build
    minimal(b)
    coll = bpy.data.collections.new("Props")  # not linked to the scene: only its instances render
    cube_mesh = bpy.data.meshes.new("Box")
    cube_mesh.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [], [(0, 1, 2, 3)])
    coll.objects.link(bpy.data.objects.new("Box", cube_mesh))
    for i in range(3):
        inst = bpy.data.objects.new(f"Instance{i}", None)
        inst.instance_type = "COLLECTION"
        inst.instance_collection = coll
        inst.location = (10.0 * i, 0, 0)
        b.link(inst)
    scene = b.export(ext).scene
    assert len(scene.meshes) == 3
    xs = sorted(float(m.positions[:, 0].min()) for m in scene.meshes)
    assert xs == pytest.approx([0.0, 10.0, 20.0])
    assert all("Box" in m.name for m in scene.meshes)


# ----------------------------------------------------------------------------- shading normals

def test_smooth_shading_exports_corner_normals(ext, bpy):
    """A smooth-shaded, non-uniformly scaled icosphere exports unit world normals close to the
    radial direction of the ellipsoid's gradient; a flat cube exports no normals."""
    b = ext.build
    minimal(b)
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3, radius=1.0, location=(0.5, 0.0, 1.0))
    sphere = bpy.context.active_object
    sphere.name = "Ball"
    sphere.scale = (2.0, 1.0, 1.0)
    bpy.ops.object.shade_smooth()
    b.cube("Box", location=(3, 0, 0))
    scene = b.export(ext).scene
    ball = next(m for m in scene.meshes if m.name.startswith("Ball"))
    box = next(m for m in scene.meshes if m.name.startswith("Box"))
    assert box.normals is None
    assert ball.normals is not None and ball.normals.shape == ball.positions.shape
    n = ball.normals.astype(np.float64)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-5)
    # world normal of the ellipsoid x²/4 + y² + z² = 1 around (0.5, 0, 1): ∇ = (x/4, y, z)
    p = ball.positions.astype(np.float64) - [0.5, 0.0, 1.0]
    g = p * [0.25, 1.0, 1.0]
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    cos = np.sum(n * g, axis=1)
    assert cos.min() > 0.97  # the mesh's averaged corner normals vs the smooth surface's
    assert np.median(cos) > 0.995
    # three vertices per triangle (unwelded corners) and the same surface as the flat export
    assert ball.indices.shape[0] * 3 == ball.positions.shape[0]
