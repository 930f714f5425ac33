"""Particle hair and Curves objects: exported as Cycles reads them (strands, keys, Hair Shape
radii, the radius attribute, round or ribbon) into tessellated curves, the Principled Hair
substitute's colour, and a small groom rendered beside Cycles."""
import math

import numpy as np
import pytest

pytestmark = pytest.mark.blender


def hair_patch(b, bpy, count=20, children=0, floor_material=None, hair_material=None, length=0.3, size=1.0):
    floor = b.plane("Patch", size=size, material=floor_material)
    floor.modifiers.new("Hair", "PARTICLE_SYSTEM")
    psys = floor.particle_systems[0]
    psys.name = "Fur"
    ps = psys.settings
    ps.type = "HAIR"
    ps.count = count
    ps.hair_length = length
    ps.display_step = 2
    ps.render_step = 3
    if children:
        ps.child_type = "INTERPOLATED"
        ps.child_percent = children
        ps.rendered_child_count = children
    if hair_material is not None:
        floor.data.materials.append(hair_material)
        ps.material = len(floor.data.materials)
    return floor, ps


def _mesh(scene, name):
    return next(m for m in scene.meshes if m.name == name)


def _ring_radii(mesh, keys, sides):
    """Circumradius of each ring of a tube mesh (curves, keys, sides rings)."""
    rings = mesh.positions.astype(np.float64).reshape(-1, keys, sides, 3)
    centre = rings.mean(axis=2, keepdims=True)
    return np.linalg.norm(rings - centre, axis=3).mean(axis=2), centre[:, :, 0]


def test_particle_hair_strands_and_hair_shape_radii(ext, bpy):
    from spectral_gi.core.geometry.curves import area_preserving_radius

    b = ext.build
    b.camera()
    floor, ps = hair_patch(b, bpy, count=20)
    ps.root_radius, ps.tip_radius, ps.radius_scale, ps.use_close_tip = 2.0, 0.5, 0.01, False
    b.scene.cycles_curves.shape = "THICK"
    res = b.export(ext)
    mesh = _mesh(res.scene, "Patch/Fur")
    sides, keys = 6, (1 << 2) + 1  # Viewport Steps 2 in the viewport's depsgraph
    assert mesh.indices.shape[0] == 20 * (keys - 1) * sides * 2
    radii, centre = _ring_radii(mesh, keys, sides)
    z = centre[:, :, 2]
    t = (z - z[:, :1]) / (z[:, -1:] - z[:, :1])  # straight strands: the keys' fraction of length
    cycles = 0.01 * 0.5 * (2.0 - 1.5 * t)  # radius_scale · ½ · (root … tip), Shape 0
    np.testing.assert_allclose(radii, np.broadcast_to(area_preserving_radius(cycles, sides), radii.shape),
                               rtol=1e-4)
    np.testing.assert_allclose(centre[:, -1, 2] - centre[:, 0, 2], 0.3, rtol=1e-4)  # hair length, up Z
    assert "Patch/Fur: hair rendered as tubes of 6 sides" in res.warning
    assert "20 strands, 960 triangles" in res.warning
    assert "particle hair (not rendered)" not in res.warning


def test_particle_hair_children_close_tip_shape_and_object_scale(ext, bpy):
    b = ext.build
    b.camera()
    floor, ps = hair_patch(b, bpy, count=10, children=3)
    ps.shape = 0.5
    floor.scale = (2.0, 2.0, 2.0)
    b.scene.spectral_gi.hair_sides = 4
    b.scene.cycles_curves.shape = "THICK"
    mesh = _mesh(b.export(ext).scene, "Patch/Fur")
    keys = 5
    assert mesh.indices.shape[0] == 30 * (keys - 1) * 4 * 2  # the children only, as Cycles renders
    radii, centre = _ring_radii(mesh, keys, 4)
    d = np.concatenate([np.zeros((centre.shape[0], 1)),
                        np.cumsum(np.linalg.norm(np.diff(centre, axis=1), axis=2), axis=1)], axis=1)
    t = d / d[:, -1:]
    cycles = 2.0 * 0.005 * (1.0 - t) ** 2.0  # Shape 0.5: (1 − t)^(1 / (1 − 0.5)); tip 0; scale 2
    cycles[:, -1] = 0.0  # Close Tip
    np.testing.assert_allclose(radii, cycles * math.pi / (4 * math.sin(math.pi / 4)), rtol=1e-4, atol=1e-7)


@pytest.mark.slow
def test_f12_renders_the_render_steps_and_rendered_children(ext, bpy, monkeypatch):
    """A final render reads the strands from the render depsgraph: Render Steps and the rendered
    child count (the viewport's export, above, reads Viewport Steps and the display amount)."""
    from importlib import import_module

    curves = import_module(ext.module.__name__ + ".addon.export.curves")
    seen = []
    strands = curves.particle_strands

    def spy(obj, psys, render):
        out = strands(obj, psys, render)
        seen.append((render, len(out[1]), int(out[1][0])))
        return out

    monkeypatch.setattr(curves, "particle_strands", spy)
    b = ext.build
    b.camera()
    floor, ps = hair_patch(b, bpy, count=10, children=3)
    ps.rendered_child_count = 5
    b.resolution(8, 8)
    b.scene.render.engine = "SPECTRAL_GI"
    b.scene.spectral_gi.samples = 1
    assert bpy.ops.render.render() == {"FINISHED"}
    assert seen == [(True, 10 * 5, (1 << 3) + 1)], seen


def test_particle_hair_renders_without_its_emitter_and_with_its_material(ext, bpy):
    b = ext.build
    b.camera()
    hair_mat = b.shader("Hair", "ShaderNodeBsdfHairPrincipled")
    floor, ps = hair_patch(b, bpy, count=5, floor_material=b.principled("Ground"), hair_material=hair_mat)
    floor.show_instancer_for_render = False
    floor.show_instancer_for_viewport = False
    res = b.export(ext)
    names = [m.name for m in res.scene.meshes]
    assert names == ["Patch/Fur"], names
    core = ext.core
    mat = res.scene.materials[int(res.scene.meshes[0].material[0])]
    assert mat.model == core.constants.MAT_PLASTIC
    assert "Principled Hair BSDF" in res.warning and "'Hair/Principled Hair BSDF" in res.warning


@pytest.mark.parametrize("component", ["Reflection", "Transmission"])
def test_hair_bsdf_components(ext, bpy, component):
    b = ext.build
    b.camera()
    mat = b.shader("Fibre", "ShaderNodeBsdfHair", Color=(0.6, 0.4, 0.2, 1.0), RoughnessU=0.2)
    node = next(n for n in mat.node_tree.nodes if n.type == "BSDF_HAIR")
    node.component = component
    hair_patch(b, bpy, count=3, hair_material=mat)
    res = b.export(ext)
    core = ext.core
    m = res.scene.materials[int(_mesh(res.scene, "Patch/Fur").material[0])]
    if component == "Reflection":
        assert m.model == core.constants.MAT_GGX_CONDUCTOR
        assert "Hair BSDF (Reflection" in res.warning
    else:
        assert (m.model, m.ior) == (core.constants.MAT_DIELECTRIC, 1.0)
        assert "Hair BSDF (Transmission" in res.warning


def test_a_groom_too_large_is_a_clear_error(ext, bpy, monkeypatch):
    from importlib import import_module

    curves = import_module(ext.module.__name__ + ".addon.export.curves")
    b = ext.build
    b.camera()
    hair_patch(b, bpy, count=20)
    monkeypatch.setattr(curves, "MAX_TRIANGLES", 100)
    with pytest.raises(ext.export.ExportError, match=r"Patch/Fur: 20 strands would make [0-9,]+ triangles"):
        b.export(ext)


def _curves_object(bpy, b, radius=True, poly=False):
    cv = bpy.data.hair_curves.new("Strands")
    cv.add_curves([3, 4])
    pts = np.array([[0, 0, 0], [0, 0, 0.5], [0, 0, 1.0], [1, 0, 0], [1, 0, 0.2], [1, 0, 0.4], [1, 0, 0.6]],
                   np.float32)
    cv.position_data.foreach_set("vector", pts.ravel())
    if radius:
        attr = cv.attributes.get("radius") or cv.attributes.new("radius", "FLOAT", "POINT")
        attr.data.foreach_set("value", np.array([0.02, 0.015, 0.01, 0.03, 0.03, 0.02, 0.01], np.float32))
    if poly:
        cv.set_types(type="POLY")
    obj = bpy.data.objects.new("Strands", cv)
    obj.scale = (2.0, 2.0, 2.0)
    b.link(obj)
    return obj


@pytest.mark.parametrize("shape", ["THICK", "RIBBONS"])
def test_curves_object_points_and_radius_attribute(ext, bpy, shape):
    b = ext.build
    cam = b.camera(location=(0.5, -6.0, 0.5), rotation=(math.radians(90), 0, 0))
    cam.data.type = "ORTHO"  # ribbons face against the view direction
    _curves_object(bpy, b)
    b.scene.cycles_curves.shape = shape
    res = b.export(ext)
    mesh = _mesh(res.scene, "Strands")
    radius = 2.0 * np.array([0.02, 0.015, 0.01, 0.03, 0.03, 0.02, 0.01])  # × the object's scale
    if shape == "THICK":
        assert mesh.indices.shape[0] == (2 + 3) * 6 * 2
        rings = mesh.positions.astype(np.float64).reshape(7, 6, 3)
        r = np.linalg.norm(rings - rings.mean(axis=1, keepdims=True), axis=2).mean(axis=1)
        np.testing.assert_allclose(r, radius * math.pi / 3.0, rtol=1e-4)
    else:
        assert mesh.indices.shape[0] == (2 + 3) * 4 * 2
        cols = mesh.positions.astype(np.float64).reshape(7, 5, 3)
        np.testing.assert_allclose(np.linalg.norm(cols[:, -1] - cols[:, 0], axis=1), 2.0 * radius, rtol=1e-4)
        np.testing.assert_allclose(cols[:, :, 1], 0.0, atol=1e-6)  # across the view of a camera looking down +Y
    assert "hair curves objects (not rendered)" not in (res.warning or "")


def test_curves_object_defaults_poly_and_view_layer_filter(ext, bpy):
    b = ext.build
    b.camera()
    _curves_object(bpy, b, radius=False, poly=True)
    b.scene.cycles_curves.shape = "RIBBONS"  # poly curves are always round in Cycles
    mesh = _mesh(b.export(ext).scene, "Strands")
    rings = mesh.positions.astype(np.float64).reshape(7, 6, 3)
    r = np.linalg.norm(rings - rings.mean(axis=1, keepdims=True), axis=2).mean(axis=1)
    np.testing.assert_allclose(r, 2.0 * 0.005 * math.pi / 3.0, rtol=1e-4)  # Cycles' radius without one
    bpy.context.view_layer.use_strand = False
    assert not any(m.name == "Strands" for m in b.export(ext).scene.meshes)


@pytest.mark.parametrize("poly", [False, True])
def test_bent_curves_follow_cycles_spline_and_poly_curves_their_points(ext, bpy, poly):
    b = ext.build
    b.camera()
    cv = bpy.data.hair_curves.new("Arc")
    cv.add_curves([5])
    a = np.linspace(0.0, math.pi, 5)
    cv.position_data.foreach_set("vector", np.stack([np.cos(a), np.zeros(5), np.sin(a)], 1).astype(np.float32).ravel())
    if poly:
        cv.set_types(type="POLY")
    b.link(bpy.data.objects.new("Arc", cv))
    b.scene.cycles_curves.shape = "THICK"
    mesh = _mesh(b.export(ext).scene, "Arc")
    n_segments = mesh.indices.shape[0] // (6 * 2)
    if poly:
        assert n_segments == 4
    else:  # 45° per segment: pieces of about 15° along the Catmull-Rom spline
        assert n_segments >= 10
        centres = mesh.positions.astype(np.float64).reshape(-1, 6, 3).mean(axis=1)
        inner = (centres[:, 2] > math.sin(math.pi / 4) - 1e-6)  # the inner segments: near the circle
        np.testing.assert_allclose(np.linalg.norm(centres[inner][:, [0, 2]], axis=1), 1.0, atol=0.02)


def test_principled_hair_absorption_and_fibre_albedo(ext):
    from importlib import import_module

    H = import_module(ext.module.__name__ + ".addon.export.hair")
    for c in ((0.5, 0.3, 0.1), (0.9, 0.9, 0.9), (0.02, 0.01, 0.005)):
        for beta_n in (0.0, 0.3, 1.0):
            sigma = H.principled_hair_sigma("COLOR", c, 0, 0, (1, 1, 1), (0, 0, 0), beta_n)
            np.testing.assert_allclose(H.colour_from_sigma(sigma, beta_n), c, rtol=1e-9)  # Chiang's relation
    # melanin 1 − 1/e is one unit of concentration: σ_a = Cycles' eumelanin / pheomelanin coefficients
    np.testing.assert_allclose(H.sigma_from_melanin(1.0 - math.exp(-1.0), 0.0), H.EUMELANIN_SIGMA)
    np.testing.assert_allclose(H.sigma_from_melanin(1.0 - math.exp(-1.0), 1.0), H.PHEOMELANIN_SIGMA)
    np.testing.assert_allclose(H.principled_hair_sigma("MELANIN", None, 0.0, 0.5, (1, 1, 1), None, 0.3), 0.0)
    np.testing.assert_allclose(H.principled_hair_sigma("ABSORPTION", None, 0, 0, None, (0.2, 0.5, 1.0), 0.3),
                               (0.2, 0.5, 1.0))
    # a fibre that absorbs nothing scatters everything; an opaque one only its Fresnel reflection
    f_mean, total = H.fibre_energies([0.0, 1e9], 1.55)
    assert total[0] == pytest.approx(1.0, abs=1e-12) and total[1] == pytest.approx(f_mean, abs=1e-12)
    h = np.sin(np.linspace(-math.pi / 2, math.pi / 2, 200_001))  # F̄ over the offsets, as ∫ F(γ) cos γ dγ / 2
    gamma = np.arcsin(h)
    f_gamma = H.fresnel_dielectric(np.cos(gamma), 1.55) * np.cos(gamma)
    integral = np.sum(0.5 * (f_gamma[1:] + f_gamma[:-1]) * np.diff(gamma)) / 2.0
    assert f_mean == pytest.approx(integral, rel=2e-4)
    assert H.fresnel_dielectric(1.0, 1.55) == pytest.approx(((1.55 - 1) / (1.55 + 1)) ** 2)
    dark = H.principled_hair_albedo(H.sigma_from_melanin(0.9, 0.0), 1.55)
    light = H.principled_hair_albedo(H.sigma_from_melanin(0.3, 0.0), 1.55)
    assert all(0.0 <= d < lt < 1.0 for d, lt in zip(dark, light))
    assert light[0] > light[1] > light[2]  # melanin absorbs blue most


# ----------------------------------------------------------------------------- beside Cycles


def groom_scene(b, bpy, hair_shader, shape="THICK", samples=64):
    """A 1 m patch of 400 straight 0.25 m strands (radius 4 mm) on a grey diffuse plane under a sun
    30° off the zenith, seen by an orthographic camera 50° off the normal; 32 × 32 pixels, 6 sides."""
    ground = b.shader("Ground", "ShaderNodeBsdfDiffuse", Color=(0.5, 0.5, 0.5, 1.0))
    floor, ps = hair_patch(b, bpy, count=400, floor_material=ground, hair_material=hair_shader, length=0.25,
                           size=1.0)
    ps.root_radius, ps.tip_radius, ps.radius_scale, ps.use_close_tip = 1.0, 1.0, 0.008, False
    sun = b.light("Sun", "SUN", location=(0, 0, 5), energy=3.0, angle=math.radians(1.0))
    sun.rotation_euler = (math.radians(30.0), 0.0, math.radians(30.0))
    tilt = math.radians(50.0)
    cam = b.camera(location=(0.0, -4.0 * math.sin(tilt), 0.1 + 4.0 * math.cos(tilt)), rotation=(tilt, 0.0, 0.0))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 0.6
    b.scene.cycles_curves.shape = shape
    b.resolution(32, 32)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.seed = samples, 8, 1
    return floor


def _compare(bpy, b, tmp_path):
    s = b.scene.spectral_gi
    s.compare_output_dir = str(tmp_path)
    assert bpy.ops.spectral_gi.compare_cycles() == {"FINISHED"}
    assert s.compare_valid
    return s.compare_luminance_ratio


@pytest.mark.slow
@pytest.mark.parametrize("shape,tolerance", [("THICK", 0.03), ("RIBBONS", 0.06)])
def test_diffuse_groom_matches_cycles(ext, bpy, tmp_path, shape, tolerance):
    """Where the physics agrees (diffuse strands): the tessellated curves against Cycles' curves.
    Sub-pixel strands make the comparison itself scatter by about ±2 % with the resolution; ribbons
    face the camera also for shadow and indirect rays (Cycles turns them to each ray), a few % darker."""
    b = ext.build
    groom_scene(b, bpy, b.shader("Strand", "ShaderNodeBsdfDiffuse", Color=(0.6, 0.45, 0.3, 1.0)), shape)
    ratio = _compare(bpy, b, tmp_path)
    print(f"diffuse groom ({shape}): luminance ratio {ratio:.4f}")
    assert ratio == pytest.approx(1.0, abs=tolerance)


@pytest.mark.slow
def test_principled_hair_groom_beside_cycles(ext, bpy, tmp_path):
    """The Principled Hair substitute (an opaque plastic of the fibre's albedo) against Cycles' Chiang
    model: brighter, as the light a strand sends on forward (TT) comes back towards the camera here."""
    b = ext.build
    mat = b.shader("Strand", "ShaderNodeBsdfHairPrincipled")
    node = next(n for n in mat.node_tree.nodes if n.type == "BSDF_HAIR_PRINCIPLED")
    node.model = "CHIANG"
    node.parametrization = "COLOR"
    node.inputs["Color"].default_value = (0.6, 0.45, 0.3, 1.0)
    groom_scene(b, bpy, mat)
    ratio = _compare(bpy, b, tmp_path)
    print(f"Principled Hair groom: luminance ratio {ratio:.4f}")
    assert 0.9 < ratio < 1.35
