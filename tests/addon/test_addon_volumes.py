"""Blender Volume shaders → core media: coefficients (Cycles' definitions), units, null and glass
surfaces around a medium, Add/Mix of volumes, the world's volume, and a render of Beer–Lambert
transmittance through an absorbing cube (against e^(−σa·d) and against Cycles)."""
import math

import numpy as np
import pytest

pytestmark = pytest.mark.blender

REC709_Y = np.array([0.2126390, 0.7151687, 0.0721923])


def volume_material(bpy, name, idname, surface=None, **inputs):
    """A material whose Volume socket is one node of type ``idname`` (a Surface node too if given)."""
    mat = bpy.data.materials.new(name)
    tree = mat.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    node = tree.nodes.new(idname)
    for k, v in inputs.items():
        if k == "phase":
            node.phase = v
        else:
            node.inputs[k].default_value = v
    tree.links.new(node.outputs[0], out.inputs["Volume"])
    if surface is not None:
        s = tree.nodes.new(surface)
        tree.links.new(s.outputs[0], out.inputs["Surface"])
    return mat


def export_cube(ext, bpy, mat, scale_length=1.0):
    b = ext.build
    b.camera()
    b.resolution(8, 8)
    ext.scene.unit_settings.scale_length = scale_length
    b.cube("Box", material=mat)
    res = b.export(ext)
    scene = res.scene
    mesh = next(m for m in scene.meshes if m.name == "Box")
    return scene, scene.materials[int(mesh.material[0])], res.warning


def sigma_rgb(ext, scene, idx, density):
    """The linear Rec.709 colour of density × shape (shape −1 = flat 1)."""
    if idx < 0:
        return np.full(3, density)
    return density * np.asarray(ext.core.reflectance_to_rgb(scene.spectra.coeffs[idx]))


def coefficients(ext, scene, material):
    md = scene.media[material.interior]
    return (sigma_rgb(ext, scene, md.absorption, md.absorption_density),
            sigma_rgb(ext, scene, md.scattering, md.scattering_density), md)


def close(a, b, tol=0.01):
    a, b = np.asarray(a, float), np.asarray(b, float)
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * max(1e-9, float(np.max(np.abs(b)))))


@pytest.mark.parametrize("scale_length", [1.0, 0.01])
def test_volume_absorption_only_is_a_null_surface_around_its_medium(ext, bpy, scale_length):
    c, d = (0.2, 0.5, 0.8), 2.0
    mat = volume_material(bpy, "Ink", "ShaderNodeVolumeAbsorption", Color=(*c, 1.0), Density=d)
    scene, m, warning = export_cube(ext, bpy, mat, scale_length)
    assert m.model == ext.core.constants.MAT_NULL
    assert m.interior == 0 and len(scene.media) == 1
    sa, ss, md = coefficients(ext, scene, m)
    # Cycles: σa = density·(1 − colour), per Blender unit → per metre: / scale_length
    close(sa, [d * (1 - x) / scale_length for x in c])
    assert md.scattering_density == 0.0 and md.anisotropy == 0.0
    assert warning is None


def test_volume_scatter_colour_density_anisotropy(ext, bpy):
    c, d, g = (0.9, 0.6, 0.3), 0.5, 0.4
    mat = volume_material(bpy, "Fog", "ShaderNodeVolumeScatter", Color=(*c, 1.0), Density=d, Anisotropy=g)
    scene, m, warning = export_cube(ext, bpy, mat)
    sa, ss, md = coefficients(ext, scene, m)
    close(ss, [d * x for x in c])
    assert md.absorption_density == 0.0  # Cycles' scatter adds only σs to the extinction
    assert md.anisotropy == pytest.approx(g)
    assert warning is None


def test_non_henyey_greenstein_phase_is_noted(ext, bpy):
    mat = volume_material(bpy, "Air", "ShaderNodeVolumeScatter", Density=1.0, phase="RAYLEIGH")
    scene, m, warning = export_cube(ext, bpy, mat)
    assert scene.media[m.interior].anisotropy == 0.0  # Rayleigh's mean cosine
    assert "Rayleigh" in warning and "Henyey–Greenstein" in warning


def test_principled_volume_follows_cycles(ext, bpy):
    c, d, a, g = (0.6, 0.4, 0.2), 3.0, (0.25, 0.5, 1.0), -0.3
    mat = volume_material(bpy, "Smoke", "ShaderNodeVolumePrincipled", Color=(*c, 1.0), Density=d,
                          **{"Absorption Color": (*a, 1.0), "Anisotropy": g, "Emission Strength": 2.0})
    scene, m, warning = export_cube(ext, bpy, mat)
    sa, ss, md = coefficients(ext, scene, m)
    close(ss, [d * x for x in c])
    # Cycles (svm_node_principled_volume): σa = d·(1 − c)·(1 − √absorption colour)
    close(sa, [d * (1 - x) * (1 - math.sqrt(y)) for x, y in zip(c, a)])
    assert md.anisotropy == pytest.approx(g)
    assert "volume emission" in warning


def test_volume_coefficients_node(ext, bpy):
    mat = volume_material(bpy, "Coef", "ShaderNodeVolumeCoefficients",
                          **{"Absorption Coefficients": (1.0, 2.0, 3.0), "Scatter Coefficients": (0.5, 0.5, 0.5)})
    scene, m, _ = export_cube(ext, bpy, mat)
    sa, ss, md = coefficients(ext, scene, m)
    close(sa, [1.0, 2.0, 3.0])
    assert md.scattering == -1 and md.scattering_density == pytest.approx(0.5)  # a grey is a flat spectrum


def test_glass_with_a_volume_inside(ext, bpy):
    mat = volume_material(bpy, "Wine", "ShaderNodeVolumeAbsorption", surface="ShaderNodeBsdfGlass",
                          Color=(0.8, 0.1, 0.2, 1.0), Density=5.0)
    scene, m, warning = export_cube(ext, bpy, mat)
    assert m.model == ext.core.constants.MAT_DIELECTRIC  # the surface is kept
    sa, _, _ = coefficients(ext, scene, m)
    close(sa, [5.0 * 0.2, 5.0 * 0.9, 5.0 * 0.8])


def combined(bpy, name, kind, fac=0.5, g=(0.0, 0.0)):
    """Volume Absorption (grey 0.5, density 2) and Volume Scatter (colour (0.2, 0.4, 0.8), density 1)
    joined by an Add or Mix shader; the scatter's anisotropy g[1] (an extra scatter of g[0] for Add)."""
    mat = bpy.data.materials.new(name)
    tree = mat.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    ab = tree.nodes.new("ShaderNodeVolumeAbsorption")
    ab.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1.0)
    ab.inputs["Density"].default_value = 2.0
    sc = tree.nodes.new("ShaderNodeVolumeScatter")
    sc.inputs["Color"].default_value = (0.2, 0.4, 0.8, 1.0)
    sc.inputs["Density"].default_value = 1.0
    sc.inputs["Anisotropy"].default_value = g[1]
    join = tree.nodes.new("ShaderNodeAddShader" if kind == "ADD" else "ShaderNodeMixShader")
    if kind == "MIX":
        join.inputs["Fac"].default_value = fac
    shaders = [s for s in join.inputs if s.type == "SHADER"]
    tree.links.new(ab.outputs[0], shaders[0])
    tree.links.new(sc.outputs[0], shaders[1])
    root = join
    if kind == "ADD" and g[0] != g[1]:  # add a second scatter with another anisotropy
        sc2 = tree.nodes.new("ShaderNodeVolumeScatter")
        sc2.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        sc2.inputs["Density"].default_value = 3.0
        sc2.inputs["Anisotropy"].default_value = g[0]
        root = tree.nodes.new("ShaderNodeAddShader")
        tree.links.new(join.outputs[0], root.inputs[0])
        tree.links.new(sc2.outputs[0], root.inputs[1])
    tree.links.new(root.outputs[0], out.inputs["Volume"])
    return mat


def test_add_of_absorption_and_scatter(ext, bpy):
    scene, m, warning = export_cube(ext, bpy, combined(bpy, "Add", "ADD"))
    assert m.model == ext.core.constants.MAT_NULL
    sa, ss, md = coefficients(ext, scene, m)
    close(sa, [1.0, 1.0, 1.0])
    assert md.absorption == -1  # grey: flat
    close(ss, [0.2, 0.4, 0.8])
    assert warning is None


def test_add_of_different_anisotropies_is_noted(ext, bpy):
    scene, m, warning = export_cube(ext, bpy, combined(bpy, "Add2", "ADD", g=(0.8, 0.2)))
    sa, ss, md = coefficients(ext, scene, m)
    close(ss, [3.2, 3.4, 3.8])
    w1, w2 = 0.2 + 0.4 + 0.8, 9.0  # σs weights (sum of RGB) of the two scatters
    assert md.anisotropy == pytest.approx((0.2 * w1 + 0.8 * w2) / (w1 + w2), rel=1e-6)
    assert "anisotropies" in warning


def test_mix_weights_the_coefficients(ext, bpy):
    scene, m, _ = export_cube(ext, bpy, combined(bpy, "Mix", "MIX", fac=0.25))
    sa, ss, _ = coefficients(ext, scene, m)
    close(sa, [0.75 * 1.0] * 3)  # first shader: weight 1 − fac
    close(ss, [0.25 * x for x in (0.2, 0.4, 0.8)])


def test_world_volume_is_listed_as_not_exported(ext, bpy):
    b = ext.build
    b.camera()
    b.resolution(8, 8)
    world = bpy.data.worlds.new("Foggy")
    tree = world.node_tree
    out = next(n for n in tree.nodes if n.type == "OUTPUT_WORLD")
    fog = tree.nodes.new("ShaderNodeVolumeScatter")
    tree.links.new(fog.outputs[0], out.inputs["Volume"])
    ext.scene.world = world
    res = b.export(ext)
    assert "world volume" in res.warning and "Foggy" in res.warning
    assert not res.scene.media


# ----------------------------------------------------------------------------- Beer–Lambert render

def absorbing_cube_scene(ext, bpy, density, grey=0.5, size=1.0):
    """Orthographic camera looking along +Y through an axis-aligned cube of Volume Absorption
    (every ray crosses ``size`` m of it) at a large white emissive plane (strength 1)."""
    b = ext.build
    cam = b.camera(location=(0.0, -4.0, 0.0), rotation=(math.radians(90), 0.0, 0.0))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 0.5 * size  # the whole view sees through the cube
    b.resolution(16, 16)
    mat = volume_material(bpy, "Grey ink", "ShaderNodeVolumeAbsorption", Color=(grey, grey, grey, 1.0),
                          Density=density)
    b.cube("Box", size=size, material=mat)
    em = b.shader("Light", "ShaderNodeEmission", Color=(1.0, 1.0, 1.0, 1.0), Strength=1.0)
    h = 3.0
    b.mesh("Wall", [(-h, 3, -h), (h, 3, -h), (h, 3, h), (-h, 3, h)], [(0, 1, 2, 3)], material=em)
    ext.scene.world = None
    s = ext.scene.spectral_gi
    s.samples, s.max_bounces = 16, 8
    return b


@pytest.mark.slow
def test_absorbing_cube_transmits_beer_lambert(ext, bpy):
    import importlib

    compare = importlib.import_module(ext.module.__name__ + ".addon.operators.compare")
    density, grey, d = 2.0, 0.5, 1.0  # σa = 2·(1 − 0.5) = 1 /m over 1 m: e^(−1)
    absorbing_cube_scene(ext, bpy, density, grey, d)
    dg = bpy.context.evaluated_depsgraph_get()
    core_scene, film, _, warning = compare.render_ours(ext.scene, dg, spp=16)
    assert core_scene.media and core_scene.media[0].absorption == -1  # grey: a flat σa
    dev = film.develop()
    y = float(np.mean(dev.rgb @ REC709_Y))
    expected = math.exp(-density * (1.0 - grey) * d)  # the wall's Y is 1 (white, strength 1)
    assert y == pytest.approx(expected, rel=0.01), (y, expected)
    cycles = compare.render_cycles_rgb(ext.scene, samples=16, max_bounces=8)
    y_cycles = float(np.mean(cycles @ REC709_Y))
    assert y == pytest.approx(y_cycles, rel=0.03), (y, y_cycles)
