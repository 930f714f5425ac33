"""Lighting analysis in Blender: calculation surfaces, Calculate Illuminance, the stored statistics."""
import importlib
import math

import pytest

pytestmark = pytest.mark.blender

H = 2.0  # m, the light above the plane
I_CD = 100.0


def lux_ops(ext):
    return importlib.import_module(ext.module.__name__ + ".addon.operators.lux")


def open_floor(ext, bpy):
    b = ext.build
    b.camera()
    grey = b.shader("Grey", "ShaderNodeBsdfDiffuse", Color=(0.0, 0.0, 0.0, 1.0))
    plane = b.plane("Target", size=2.0, material=grey)
    plane.hide_render = True
    light = b.light("Bulb", "POINT", location=(0, 0, H), energy=10.0)
    light.data.shadow_soft_size = 0.0
    light.data.spectral_gi.unit = "CANDELA"
    light.data.spectral_gi.value = I_CD
    s = plane.spectral_gi_lux
    s.enabled, s.kind, s.spacing_mode, s.spacing, s.samples = True, "GRID", "USER", 0.5, 8
    return plane


def test_grid_surface_matches_the_closed_form(ext, bpy, tmp_path):
    ops = lux_ops(ext)
    plane = open_floor(ext, bpy)
    bpy.context.view_layer.objects.active = plane
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    s = plane.spectral_gi_lux
    assert s.valid and s.n_points == 16
    surface = ops.build_surface(plane)
    p = surface.points
    want = I_CD * H / ((p[:, 0] ** 2 + p[:, 1] ** 2 + H * H) ** 1.5)  # I cos θ / d²
    assert s.mean == pytest.approx(want.mean(), rel=1e-3)
    assert s.minimum == pytest.approx(want.min(), rel=1e-3)
    assert s.u0 == pytest.approx(want.min() / want.mean(), rel=3e-3)
    core_scene = ext.build.export(ext).scene
    e, _se, _n = ext.core.point_illuminance(core_scene, p, surface.normals, spp=8)
    assert s.mean == pytest.approx(float(e.mean()), rel=1e-5)  # the same integrator on the same points
    assert s.minimum == pytest.approx(float(e.min()), rel=1e-5)
    grid = bpy.data.objects[f"{plane.name} lux grid"]
    attr = grid.data.color_attributes[ops.ATTRIBUTE]
    assert len(grid.data.polygons) == 16 and attr.domain == "CORNER" and len(attr.data) == 64
    path = tmp_path / "lux.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    s2 = bpy.data.objects["Target"].spectral_gi_lux
    assert s2.valid and s2.mean == pytest.approx(want.mean(), rel=1e-3) and s2.n_points == 16


def test_faces_kind_and_bad_input(ext, bpy):
    ops = lux_ops(ext)
    plane = open_floor(ext, bpy)
    plane.spectral_gi_lux.kind = "FACES"
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    attr = plane.data.color_attributes[ops.ATTRIBUTE]
    assert attr.domain == "CORNER" and plane.spectral_gi_lux.n_points == 2
    plane.spectral_gi_lux.enabled = False
    assert ops.marked_objects(bpy.context.scene) == []
    bent = ext.build.mesh("Bent", [(0, 0, 0), (1, 0, 0), (1, 1, 0.5), (0, 1, 0)], [(0, 1, 2, 3)])
    bent.spectral_gi_lux.enabled = True
    with pytest.raises(ops.LuxInputError, match="not planar"):
        ops.build_surface(bent)
    with pytest.raises(RuntimeError, match="not planar"):  # bpy.ops turns the operator's ERROR report into this
        bpy.ops.spectral_gi.lux_calculate()


def test_add_work_plane(ext, bpy):
    room = ext.build.cube("Room", size=4.0, location=(0, 0, 2))
    bpy.context.view_layer.objects.active = room
    assert bpy.ops.spectral_gi.lux_add_workplane() == {"FINISHED"}
    wp = bpy.data.objects["Work Plane"]
    zs = [v.co.z for v in wp.data.vertices]
    assert all(math.isclose(z, 0.75, abs_tol=1e-6) for z in zs) and wp.spectral_gi_lux.enabled
    assert wp.hide_render
