"""Export coverage: the object and node types not covered elsewhere, each scene built in bpy.

Curves, text and metaballs as evaluated meshes; a subdivision modifier; geometry-nodes instances;
hide-render; mixed flat/smooth faces; Value, RGB and Blackbody nodes; square and ellipse area
lights. Export only (no renders). The table in the module's last comment maps every supported
object, material, light and world type to the test that covers it.
"""
import importlib
import math

import numpy as np
import pytest

pytestmark = pytest.mark.blender

K_M = 683.0  # lm per Blender watt
REC709_Y = (0.2126390, 0.7151687, 0.0721923)
MODULE = "bl_ext.user_default.spectral_gi"


def y_of(rgb):
    return sum(w * c for w, c in zip(REC709_Y, rgb))


def minimal(b):
    b.camera()
    b.resolution(16, 16)


def mesh_named(scene, name):
    return next(m for m in scene.meshes if m.name == name)


def material_of(scene, mesh_name):
    return scene.materials[int(mesh_named(scene, mesh_name).material[0])]


def tree_material(bpy, name, build):
    """A material whose node tree is made by ``build(tree, output)``."""
    mat = bpy.data.materials.new(name)
    tree = mat.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    build(tree, out)
    return mat


def closed_manifold(indices, positions, decimals=5):
    """True if every edge (vertices welded by position) is shared by exactly two triangles."""
    keys = np.round(positions.astype(np.float64), decimals)
    _, weld = np.unique(keys, axis=0, return_inverse=True)
    t = weld.reshape(-1)[indices]
    edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    edges = edges[edges[:, 0] != edges[:, 1]]
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return bool(np.all(counts == 2))


def enclosed_volume(indices, positions):
    p = positions.astype(np.float64)[indices]
    return float(np.sum(np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])))) / 6.0


# ----------------------------------------------------------------------------- curves, text, metaballs


def test_bevelled_curve_is_a_tube_of_its_bevel_radius(ext, bpy):
    b = ext.build
    minimal(b)
    cu = bpy.data.curves.new("Rail", "CURVE")
    cu.dimensions = "3D"
    spline = cu.splines.new("POLY")
    spline.points.add(1)
    spline.points[0].co = (0.0, 0.0, 0.0, 1.0)
    spline.points[1].co = (4.0, 0.0, 0.0, 1.0)
    cu.bevel_depth, cu.bevel_resolution, cu.use_fill_caps = 0.25, 3, True
    b.link(bpy.data.objects.new("Rail", cu)).location = (0.0, 1.0, 2.0)
    res = b.export(ext)
    assert res.warning is None
    assert len(res.scene.meshes) == 1  # once: not also from the curve object itself
    m = mesh_named(res.scene, "Rail")
    p = m.positions.astype(np.float64) - [0.0, 1.0, 2.0]
    assert p[:, 0].min() == pytest.approx(0.0, abs=1e-6) and p[:, 0].max() == pytest.approx(4.0, abs=1e-6)
    # every vertex lies on the bevel circle around the spline (caps are filled without new vertices)
    np.testing.assert_allclose(np.hypot(p[:, 1], p[:, 2]), 0.25, atol=1e-5)
    # a capped tube is closed; its volume is the prism of a regular polygon inscribed in the circle
    assert closed_manifold(m.indices, m.positions)
    sides = len(np.unique(np.round(p[p[:, 0] < 1e-6][:, 1:], 6), axis=0))
    polygon = 0.5 * sides * 0.25 ** 2 * math.sin(2 * math.pi / sides)
    assert abs(enclosed_volume(m.indices, m.positions)) == pytest.approx(4.0 * polygon, rel=1e-4)
    assert sides >= 8


def test_extruded_text_is_a_closed_slab(ext, bpy):
    b = ext.build
    minimal(b)
    cu = bpy.data.curves.new("Sign", "FONT")
    cu.body = "IH"
    cu.extrude = 0.1
    cu.size = 2.0
    text = b.link(bpy.data.objects.new("Sign", cu))
    text.location = (-1.0, 0.0, 0.5)
    res = b.export(ext)
    assert res.warning is None
    assert len(res.scene.meshes) == 1
    m = mesh_named(res.scene, "Sign")
    p = m.positions.astype(np.float64)
    assert m.indices.shape[0] > 20
    # the glyphs are extruded ±extrude about the text's plane (its local z = 0, here z = 0.5)
    assert p[:, 2].min() == pytest.approx(0.4, abs=1e-5) and p[:, 2].max() == pytest.approx(0.6, abs=1e-5)
    # glyphs of a 2-unit font start at the text's origin (x = -1) and are capital-height tall
    assert p[:, 0].min() >= -1.0 - 1e-6 and p[:, 0].max() > 0.0
    height = p[:, 1].max() - p[:, 1].min()
    assert 0.8 < height < 2.0
    # a closed prism: its volume is the front face's area times the 0.2 thickness
    assert closed_manifold(m.indices, m.positions)
    tri = p[m.indices]
    front = np.all(np.abs(tri[:, :, 2] - 0.6) < 1e-5, axis=1)
    area = 0.5 * np.linalg.norm(np.cross(tri[front, 1] - tri[front, 0], tri[front, 2] - tri[front, 0]), axis=1).sum()
    assert area > 0.2
    assert abs(enclosed_volume(m.indices, m.positions)) == pytest.approx(0.2 * area, rel=1e-4)


def test_metaball_is_the_isosurface_of_its_field(ext, bpy):
    b = ext.build
    minimal(b)
    mb = bpy.data.metaballs.new("Blob")
    mb.resolution = 0.1
    mb.threshold = 0.6
    el = mb.elements.new()
    el.radius, el.stiffness = 1.0, 2.0
    b.link(bpy.data.objects.new("Blob", mb)).location = (3.0, 0.0, 1.0)
    res = b.export(ext)
    assert res.warning is None
    assert len(res.scene.meshes) == 1
    m = mesh_named(res.scene, "Blob")
    p = m.positions.astype(np.float64) - [3.0, 0.0, 1.0]
    r = np.linalg.norm(p, axis=1)
    # Blender's ball field: stiffness·(1 − d²/R²)³; the surface is where it equals the threshold
    expect = math.sqrt(1.0 - (0.6 / 2.0) ** (1.0 / 3.0))
    np.testing.assert_allclose(r, expect, atol=0.05)  # polygonised at resolution 0.1
    np.testing.assert_allclose(p.mean(axis=0), 0.0, atol=0.01)
    assert closed_manifold(m.indices, m.positions)


def test_nurbs_surface_once_and_a_curve_without_surface_is_reported(ext, bpy):
    b = ext.build
    minimal(b)
    bpy.ops.surface.primitive_nurbs_surface_sphere_add(radius=1.0, location=(0.0, 0.0, 2.0))
    bpy.context.active_object.name = "Ball"
    cu = bpy.data.curves.new("Wire", "CURVE")  # no bevel, no extrusion: nothing to render
    cu.splines.new("POLY").points.add(1)
    b.link(bpy.data.objects.new("Wire", cu))
    res = b.export(ext)
    assert [m.name for m in res.scene.meshes] == ["Ball"]
    p = res.scene.meshes[0].positions.astype(np.float64) - [0.0, 0.0, 2.0]
    r = np.linalg.norm(p, axis=1)
    assert r.max() <= 1.0 + 1e-5 and r.min() > 0.5  # the NURBS sphere lies inside its control cage's radius
    assert res.warning is not None and "no surface: 'Wire'" in res.warning and "Ball" not in res.warning


# ----------------------------------------------------------------------------- modifiers and instances


def test_subdivision_modifier_gives_catmull_clark_points(ext, bpy):
    b = ext.build
    minimal(b)
    cube = b.cube("Box", size=1.0)
    mod = cube.modifiers.new("Subdivision", "SUBSURF")
    mod.levels, mod.use_limit_surface = 1, False
    m = mesh_named(b.export(ext).scene, "Box")
    assert m.indices.shape == (48, 3)  # 6 quads → 24 quads → 48 triangles
    v = np.unique(np.round(np.abs(m.positions.astype(np.float64)), 6), axis=0)
    # Catmull–Clark, one level on a cube of half-size h = 0.5: face points (h, 0, 0), edge points
    # (F1 + F2 + v1 + v2)/4 = (3h/4, 3h/4, 0), corners (Q + 2R)/3 with Q the mean of the 3 face points
    # (h/3)(1, 1, 1) and R the mean of the 3 edge midpoints (2h/3)(1, 1, 1): (5h/9)(1, 1, 1)
    h = 0.5
    expect = np.unique(np.round(np.array([[h, 0, 0], [0, h, 0], [0, 0, h],
                                          [0.75 * h, 0.75 * h, 0], [0.75 * h, 0, 0.75 * h], [0, 0.75 * h, 0.75 * h],
                                          [5 * h / 9] * 3]), 6), axis=0)
    np.testing.assert_allclose(v, expect, atol=1e-5)
    mod.levels = 2
    assert mesh_named(b.export(ext).scene, "Box").indices.shape == (192, 3)
    mod.show_viewport = False  # a disabled modifier is not applied
    assert mesh_named(b.export(ext).scene, "Box").indices.shape == (12, 3)


def instance_on_points_group(bpy, count, offset, scale):
    """Geometry nodes: a Mesh Line of ``count`` points, a cube of size 0.5 instanced on each, scaled."""
    group = bpy.data.node_groups.new("Scatter", "GeometryNodeTree")
    group.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    group.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    nodes, links = group.nodes, group.links
    gin = nodes.new("NodeGroupInput")
    gout = nodes.new("NodeGroupOutput")
    line = nodes.new("GeometryNodeMeshLine")
    line.inputs["Count"].default_value = count
    line.inputs["Offset"].default_value = offset
    cube = nodes.new("GeometryNodeMeshCube")
    cube.inputs["Size"].default_value = (0.5, 0.5, 0.5)
    inst = nodes.new("GeometryNodeInstanceOnPoints")
    inst.inputs["Scale"].default_value = scale
    links.new(line.outputs["Mesh"], inst.inputs["Points"])
    links.new(cube.outputs["Mesh"], inst.inputs["Instance"])
    links.new(inst.outputs["Instances"], gout.inputs[0])
    assert gin is not None
    return group


def test_geometry_nodes_instance_on_points(ext, bpy):
    b = ext.build
    minimal(b)
    host = b.plane("Host", size=1.0, location=(0.0, 2.0, 0.0))
    mod = host.modifiers.new("Scatter", "NODES")
    mod.node_group = instance_on_points_group(bpy, 4, (1.5, 0.0, 0.0), (2.0, 1.0, 1.0))
    res = b.export(ext)
    assert res.warning is None
    boxes = [m for m in res.scene.meshes if m.indices.shape[0] == 12]
    assert len(res.scene.meshes) == 4 and len(boxes) == 4  # the host's own plane is replaced by the instances
    lo = np.array(sorted(m.positions.astype(np.float64).min(axis=0).tolist() for m in boxes))
    hi = np.array(sorted(m.positions.astype(np.float64).max(axis=0).tolist() for m in boxes))
    centres = 0.5 * (lo + hi)
    np.testing.assert_allclose(centres, [[1.5 * i, 2.0, 0.0] for i in range(4)], atol=1e-5)
    np.testing.assert_allclose(hi - lo, [[1.0, 0.5, 0.5]] * 4, atol=1e-5)  # 0.5 cube scaled (2, 1, 1)
    assert all(m.name.startswith("Host") for m in boxes)
    ext.core.validate(res.scene)


def test_hide_render_objects_of_every_kind_are_absent(ext, bpy):
    b = ext.build
    minimal(b)
    b.plane("Floor")
    shown = b.light("Shown", "POINT", energy=10.0)
    hidden_light = b.light("HiddenLamp", "SPOT", energy=10.0)
    cu = bpy.data.curves.new("HiddenText", "FONT")
    cu.body = "x"
    text = b.link(bpy.data.objects.new("HiddenText", cu))
    coll = bpy.data.collections.new("Props")
    prop = bpy.data.meshes.new("Prop")
    prop.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
    coll.objects.link(bpy.data.objects.new("Prop", prop))
    b.link(bpy.data.objects.new("ShownInstance", None)).instance_type = "COLLECTION"
    bpy.data.objects["ShownInstance"].instance_collection = coll
    inst = b.link(bpy.data.objects.new("HiddenInstance", None))
    inst.instance_type, inst.instance_collection = "COLLECTION", coll
    for obj in (hidden_light, text, inst):
        obj.hide_render = True
    res = b.export(ext)
    assert sorted(m.name for m in res.scene.meshes) == ["Floor", "ShownInstance/Prop"]
    assert [L.name for L in res.scene.lights] == [shown.name]
    assert res.warning is None


def test_flat_and_smooth_faces_of_one_mesh(ext, bpy):
    """Two smooth faces meeting at 90° share the averaged normal along their edge; a flat face keeps
    its face normal at every corner."""
    b = ext.build
    minimal(b)
    verts = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),  # A: floor, normal +Z
             (0, 0, 1), (0, 1, 1),  # B: wall x = 0 through (0,0,0)-(0,1,0), normal +X
             (3, 0, 0), (4, 0, 0), (4, 1, 0)]  # C: a separate flat triangle, normal +Z
    faces = [(0, 1, 2, 3), (0, 3, 5, 4), (6, 7, 8)]
    obj = b.mesh("Corner", verts, faces)
    for poly, smooth in zip(obj.data.polygons, (True, True, False)):
        poly.use_smooth = smooth
    m = mesh_named(b.export(ext).scene, "Corner")
    assert m.normals is not None
    p, n = m.positions.astype(np.float64), m.normals.astype(np.float64)
    on_edge = (np.abs(p[:, 0]) < 1e-6) & (np.abs(p[:, 2]) < 1e-6)
    np.testing.assert_allclose(n[on_edge], [[math.sqrt(0.5), 0.0, math.sqrt(0.5)]] * int(on_edge.sum()), atol=1e-5)
    floor_only = (p[:, 0] > 0.5) & (p[:, 0] < 1.5)
    np.testing.assert_allclose(n[floor_only], [[0, 0, 1]] * int(floor_only.sum()), atol=1e-5)
    flat = p[:, 0] > 2.5
    assert flat.sum() == 3
    np.testing.assert_allclose(n[flat], [[0, 0, 1]] * 3, atol=1e-6)
    wall_top = p[:, 2] > 0.5
    np.testing.assert_allclose(n[wall_top], [[1, 0, 0]] * int(wall_top.sum()), atol=1e-5)


# ----------------------------------------------------------------------------- Value, RGB, Blackbody


def test_value_and_rgb_nodes_feed_their_inputs(ext, bpy):
    b = ext.build
    minimal(b)
    C = ext.core.constants

    def build(tree, out):
        bsdf = tree.nodes.new("ShaderNodeBsdfPrincipled")
        rough = tree.nodes.new("ShaderNodeValue")
        rough.outputs[0].default_value = 0.3
        colour = tree.nodes.new("ShaderNodeRGB")
        colour.outputs[0].default_value = (0.6, 0.3, 0.1, 1.0)
        tree.links.new(rough.outputs[0], bsdf.inputs["Roughness"])
        tree.links.new(colour.outputs[0], bsdf.inputs["Base Color"])
        mix = tree.nodes.new("ShaderNodeMixShader")
        fac = tree.nodes.new("ShaderNodeValue")
        fac.outputs[0].default_value = 0.2
        tree.links.new(fac.outputs[0], mix.inputs["Factor"])
        tree.links.new(bsdf.outputs[0], mix.inputs[1])
        tree.links.new(tree.nodes.new("ShaderNodeBsdfDiffuse").outputs[0], mix.inputs[2])
        tree.links.new(mix.outputs[0], out.inputs["Surface"])

    b.plane("Panel", material=tree_material(bpy, "Nodes", build))
    res = b.export(ext)
    assert res.warning is None  # constant Value and RGB nodes are read exactly
    s = res.scene
    m = material_of(s, "Panel")
    assert m.model == C.MAT_MIX and m.params[0] == pytest.approx(0.8)  # Blender: first shader weight 1 − fac
    plastic = s.materials[int(m.params[1])]
    assert plastic.model == C.MAT_PLASTIC
    assert (plastic.params[1], plastic.params[2]) == pytest.approx((0.09, 0.09))  # α = roughness²
    coeffs = s.spectra.coeffs[plastic.reflectance]
    np.testing.assert_allclose(coeffs, ext.core.reflectance_from_rgb((0.6, 0.3, 0.1)), atol=1e-6)
    np.testing.assert_allclose(ext.core.reflectance_to_rgb(coeffs), (0.6, 0.3, 0.1), atol=5e-3)


def planck_xy(temperature):
    import colour

    return colour.XYZ_to_xy(colour.sd_to_XYZ(colour.sd_blackbody(temperature)))


def emission_xy(coeffs):
    from spectral_gi.core.spectra.fit import emission_XYZ

    XYZ = emission_XYZ(coeffs)
    return XYZ[:2] / XYZ.sum()


def blackbody_emitter(bpy, name, kelvin, strength, principled=False):
    def build(tree, out):
        node = tree.nodes.new("ShaderNodeBsdfPrincipled" if principled else "ShaderNodeEmission")
        bb = tree.nodes.new("ShaderNodeBlackbody")
        bb.inputs["Temperature"].default_value = kelvin
        tree.links.new(bb.outputs[0], node.inputs["Emission Color" if principled else "Color"])
        node.inputs["Emission Strength" if principled else "Strength"].default_value = strength
        tree.links.new(node.outputs[0], out.inputs["Surface"])

    return tree_material(bpy, name, build)


def test_blackbody_node_emits_plancks_spectrum(ext, bpy):
    b = ext.build
    minimal(b)
    b.plane("Ember", material=blackbody_emitter(bpy, "Ember", 3000.0, 2.0))
    b.plane("Hot", material=blackbody_emitter(bpy, "Hot", 3000.0, 5.0, principled=True))
    lamp = b.light("Lamp", "POINT", energy=10.0)
    lamp.data.spectral_gi.spectrum, lamp.data.spectral_gi.temperature = "BLACKBODY", 3000.0
    res = b.export(ext)
    assert res.warning is None
    s = res.scene
    m = material_of(s, "Ember")
    np.testing.assert_allclose(emission_xy(s.spectra.coeffs[m.emission]), planck_xy(3000.0), atol=1e-3)
    # Cycles' Blackbody colour has luminance 1: the emitter's luminance is 683 · strength
    assert m.emission_luminance == pytest.approx(K_M * 2.0, rel=1e-6)
    hot = material_of(s, "Hot")
    assert hot.emission == m.emission == s.lights[0].spectrum  # one Planck spectrum, shared with the light
    assert hot.emission_luminance == pytest.approx(K_M * 5.0, rel=1e-6)
    for kelvin in (1500.0, 6500.0):
        b.plane(f"B{kelvin:g}", material=blackbody_emitter(bpy, f"B{kelvin:g}", kelvin, 1.0))
    s = b.export(ext).scene
    for kelvin in (1500.0, 6500.0):
        m = material_of(s, f"B{kelvin:g}")
        np.testing.assert_allclose(emission_xy(s.spectra.coeffs[m.emission]), planck_xy(kelvin), atol=1e-3)


def test_blackbody_colour_follows_cycles(ext, bpy):
    """The node's colour (used where it feeds anything but an emitter alone): Rec.709 of Planck's
    spectrum with luminance 1, held above 12000 K as Cycles does."""
    nodes = importlib.import_module(MODULE + ".addon.export.nodes")
    context = importlib.import_module(MODULE + ".addon.export.context")
    mat = bpy.data.materials.new("BB")
    node = mat.node_tree.nodes.new("ShaderNodeBlackbody")
    ctx = context.ExportContext(1.0)
    for kelvin in (1200.0, 3000.0, 6500.0, 12000.0):
        node.inputs["Temperature"].default_value = kelvin
        rgb = nodes.blackbody_colour(ctx, "BB", node)
        assert rgb.temperature == kelvin and y_of(rgb) == pytest.approx(1.0, abs=1e-6) and min(rgb) >= 0.0
    # Cycles' value for 12000 K and above (its fit's upper end; intern/cycles blackbody)
    np.testing.assert_allclose(rgb, (0.8263, 0.9945, 1.5663), atol=5e-3)
    node.inputs["Temperature"].default_value = 30000.0
    assert nodes.blackbody_colour(ctx, "BB", node).temperature == 12000.0
    assert "held to" in ctx.warning()
    # mixed with another emitter: rendered as its colour (noted)
    b = ext.build
    minimal(b)

    def build(tree, out):
        add = tree.nodes.new("ShaderNodeAddShader")
        e1 = tree.nodes.new("ShaderNodeEmission")
        bb = tree.nodes.new("ShaderNodeBlackbody")
        bb.inputs["Temperature"].default_value = 3000.0
        tree.links.new(bb.outputs[0], e1.inputs["Color"])
        e2 = tree.nodes.new("ShaderNodeEmission")
        e2.inputs["Color"].default_value = (0.0, 0.0, 1.0, 1.0)
        tree.links.new(e1.outputs[0], add.inputs[0])
        tree.links.new(e2.outputs[0], add.inputs[1])
        tree.links.new(add.outputs[0], out.inputs["Surface"])

    b.plane("Both", material=tree_material(bpy, "Both", build))
    res = b.export(ext)
    m = material_of(res.scene, "Both")
    assert m.emission_luminance == pytest.approx(K_M * (1.0 + REC709_Y[2]), rel=1e-5)
    assert "blackbody" in res.warning


# ----------------------------------------------------------------------------- the one warning


def test_one_warning_names_objects_nodes_and_substitutes(ext, bpy):
    b = ext.build
    minimal(b)
    toon = b.shader("Toon", "ShaderNodeBsdfToon", Color=(0.3, 0.6, 0.9, 1.0))
    b.plane("Cartoon", material=toon)
    b.plane("Sketch", material=toon, location=(3, 0, 0))
    coated = b.principled("Lacquer")
    lacquer = next(n for n in coated.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    lacquer.inputs["Coat Weight"].default_value = 0.5
    lacquer.inputs["Metallic"].default_value = 1.0  # a coat layers the dielectric base only
    b.plane("Table", material=coated)
    b.plane("Clean", material=b.principled("Plain"))
    b.link(bpy.data.objects.new("Fog", bpy.data.volumes.new("Fog")))
    res = b.export(ext)
    w = res.warning
    assert isinstance(w, str) and "\n" not in w
    # node names with their substitute
    assert "'Toon/Toon BSDF'" in w and "diffuse surface of their colour" in w
    assert "Lacquer/Principled BSDF: coat 0.5 (on the metallic and transmission components ignored" in w
    assert "volume objects: 'Fog'" in w
    # and the objects that use each material named
    assert "'Toon': 'Cartoon', 'Sketch'" in w and "'Lacquer': 'Table'" in w
    assert "Plain" not in w and "Clean" not in w
    m = material_of(res.scene, "Sketch")  # the substitute: a Lambert of the node's colour
    assert m.model == ext.core.constants.MAT_LAMBERT
    np.testing.assert_allclose(res.scene.spectra.coeffs[m.reflectance],
                               ext.core.reflectance_from_rgb((0.3, 0.6, 0.9)), atol=1e-6)


# ----------------------------------------------------------------------------- area light shapes


def test_square_and_ellipse_area_lights(ext, bpy):
    b = ext.build
    minimal(b)
    C = ext.core.constants
    b.light("Square", "AREA", energy=40.0, shape="SQUARE", size=2.0, size_y=7.0)  # size_y unused
    b.light("Oval", "AREA", location=(2, 0, 3), energy=40.0, shape="ELLIPSE", size=2.0, size_y=0.5,
            color=(1.0, 0.5, 0.25))
    lights = {L.name: L for L in b.export(ext).scene.lights}
    sq, ov = lights["Square"], lights["Oval"]
    assert sq.kind == C.LIGHT_RECT
    assert (np.linalg.norm(sq.axis_u), np.linalg.norm(sq.axis_v)) == pytest.approx((1.0, 1.0))
    assert sq.luminance == pytest.approx(K_M * 40.0 / (math.pi * 4.0), rel=1e-5)  # P / (π A), A = 4 m²
    assert ov.kind == C.LIGHT_ELLIPSE
    assert (np.linalg.norm(ov.axis_u), np.linalg.norm(ov.axis_v)) == pytest.approx((1.0, 0.25))
    area = math.pi * 1.0 * 0.25
    assert ov.luminance == pytest.approx(K_M * 40.0 / (math.pi * area) * y_of((1.0, 0.5, 0.25)), rel=1e-5)
    np.testing.assert_allclose(ov.position, (2, 0, 3), atol=1e-6)


# ----------------------------------------------------------------------------- export coverage map
#
# objects: meshes (test_addon_export::test_world_matrix_is_applied), curves
# (test_bevelled_curve_is_a_tube_of_its_bevel_radius), text (test_extruded_text_is_a_closed_slab),
# metaballs (test_metaball_is_the_isosurface_of_its_field), modifiers (test_addon_export::
# test_modifiers_are_applied_and_hidden_objects_skipped, test_subdivision_modifier_gives_catmull_clark_points),
# collection instances (test_addon_export::test_collection_instances_are_exported_once_per_instance),
# geometry-nodes instances (test_geometry_nodes_instance_on_points), hide-render
# (test_hide_render_objects_of_every_kind_are_absent), smooth/flat (test_addon_export::
# test_smooth_shading_exports_corner_normals, test_flat_and_smooth_faces_of_one_mesh), particle hair and
# Curves objects (test_addon_hair).
# materials: Principled, Diffuse, Glossy, Glass, Refraction, Emission, Mix, Add (test_addon_materials),
# Principled Hair (test_addon_hair), Hair BSDF (test_addon_hair::test_hair_bsdf_components),
# RGB and Value (test_value_and_rgb_nodes_feed_their_inputs), Blackbody
# (test_blackbody_node_emits_plancks_spectrum, test_blackbody_colour_follows_cycles), volumes
# (test_addon_volumes). lights: point, spot, sun (test_addon_lights), rect and disk (test_addon_export),
# square and ellipse (test_square_and_ellipse_area_lights). world colour (test_addon_export::
# test_world_background), HDRI (test_addon_lights::test_environment_texture_world), DOF
# (test_addon_lights::test_depth_of_field), unsupported nodes (test_addon_export::
# test_unsupported_things_are_listed_in_one_warning, test_one_warning_names_objects_nodes_and_substitutes).
# Image Texture, UV maps, Normal Map and holdout are covered by the tests of their own work.
