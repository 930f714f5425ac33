"""Blender materials → the core's BSDF models: node mapping, Principled trees, mixes, the panel override."""
import importlib
import math

import numpy as np
import pytest

K_M = 683.0
REC709_Y = (0.2126390, 0.7151687, 0.0721923)


# ----------------------------------------------------------------------------- pure conversions (no bpy)

def test_principled_alpha_is_cycles_convention():
    from spectral_gi.addon.export.convert import principled_alpha

    assert principled_alpha(0.5) == pytest.approx((0.25, 0.25))
    ax, ay = principled_alpha(0.6, 0.8)
    aspect = math.sqrt(1.0 - 0.9 * 0.8)
    assert (ax, ay) == pytest.approx((0.36 / aspect, 0.36 * aspect))
    assert ax * ay == pytest.approx(0.36 ** 2)  # the stretch keeps the lobe's area
    assert principled_alpha(1.0, 1.0)[0] == 1.0  # clamped to the builders' range
    assert principled_alpha(-0.2, -1.0) == (0.0, 0.0)


def test_glossy_alpha_is_cycles_convention():
    from spectral_gi.addon.export.convert import glossy_alpha

    assert glossy_alpha(0.4) == pytest.approx((0.16, 0.16))
    assert glossy_alpha(0.4, 0.5) == pytest.approx((0.08, 0.32))
    assert glossy_alpha(0.4, -0.5) == pytest.approx((0.32, 0.08))
    assert glossy_alpha(0.4, 5.0)[1] == 1.0  # a clamped to 0.99, αy clamped to 1


def test_specular_level_scales_the_normal_incidence_reflectance():
    from spectral_gi.addon.export.convert import specular_level_ior

    def f0(n):
        return ((n - 1.0) / (n + 1.0)) ** 2

    assert specular_level_ior(1.5, 0.5) == 1.5
    for level in (0.0, 0.25, 1.0):
        assert f0(specular_level_ior(1.5, level)) == pytest.approx(f0(1.5) * 2.0 * level, abs=1e-12)
    assert specular_level_ior(1.33, 0.0) == pytest.approx(1.0)


def test_combine_emission():
    from spectral_gi.addon.export.convert import combine_emission, mix_first_weight

    assert combine_emission([]) == ((0.0, 0.0, 0.0), 0.0)
    assert combine_emission([((0.5, 0.5, 0.5), 0.0), ((1.0, 0.5, 0.25), 3.0)]) == ((1.0, 0.5, 0.25), 3.0)
    rgb, s = combine_emission([((1.0, 0.0, 0.0), 2.0), ((0.0, 0.0, 1.0), 1.0), ((0.0, 1.0, 0.0), 0.5)])
    np.testing.assert_allclose(np.array(rgb) * s, [2.0, 0.5, 1.0])
    assert max(rgb) == 1.0
    assert mix_first_weight(0.25) == 0.75 and mix_first_weight(2.0) == 0.0 and mix_first_weight(-1) == 1.0


def test_core_presets_on_the_grid():
    from spectral_gi import core
    from spectral_gi.core.spectra import library

    wl = core.wavelength_grid()
    assert wl.size == core.constants.N_LAMBDA and wl[0] == 360.0 and wl[-1] == 830.0
    eta, kappa = core.metal_preset("gold")
    e2, k2 = library.metal_ior("Au", wl)
    np.testing.assert_allclose(eta, e2)
    np.testing.assert_allclose(kappa, k2)
    n = core.glass_preset("BK7")
    assert n[int(587.5618 - 360.0 + 0.5)] == pytest.approx(library.glass_nd("N-BK7"), abs=2e-4)
    assert "Au" in core.metal_preset_names() and "N-BK7" in core.glass_preset_names()
    names = core.reflectance_preset_names()
    assert len(names) == 24
    # the preset's reconstruction follows the measured patch (moments, 12 coefficients)
    red = core.tabulate_reflectance(core.reflectance_preset("red"))
    ref = library.colorchecker("red", wl)
    assert np.max(np.abs(red - ref)[40:-60]) < 0.03


# ----------------------------------------------------------------------------- Blender

blender = pytest.mark.blender


def minimal(b):
    b.camera()
    b.resolution(16, 16)


def material_of(scene, mesh_name):
    mesh = next(m for m in scene.meshes if m.name == mesh_name)
    return scene.materials[int(mesh.material[0])]


def spectrum(scene, idx):
    """A bounded spectrum of the scene on the 1 nm grid (-1: white for tints)."""
    from spectral_gi import core

    if idx < 0:
        return np.ones(core.constants.N_LAMBDA)
    return core.tabulate_reflectance(scene.spectra.coeffs[idx])


def uplift(rgb):
    from spectral_gi import core

    return core.tabulate_reflectance(core.reflectance_from_rgb(rgb))


def principled_node(mat):
    return next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")


def tree_material(bpy, name, build):
    """A material whose node tree is made by ``build(tree, output)``."""
    mat = bpy.data.materials.new(name)
    tree = mat.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    build(tree, out)
    return mat


def components(scene, m):
    assert m.model in (scene_constants(scene).MAT_MIX, scene_constants(scene).MAT_ADD)
    return scene.materials[int(m.params[1])], scene.materials[int(m.params[2])]


def scene_constants(scene):
    from spectral_gi.core import constants

    return constants


@blender
def test_diffuse_glossy_mirror(ext, bpy):
    b = ext.build
    minimal(b)
    C = ext.core.constants
    b.plane("Matte", material=b.shader("D", "ShaderNodeBsdfDiffuse", Color=(0.1, 0.7, 0.2, 1.0)))
    b.plane("Brushed", material=b.shader("G", "ShaderNodeBsdfGlossy", Color=(0.9, 0.6, 0.3, 1.0), Roughness=0.4,
                                         Anisotropy=0.5))
    b.plane("Mirror", material=b.shader("M", "ShaderNodeBsdfGlossy", Color=(0.8, 0.8, 0.9, 1.0), Roughness=0.0))
    res = b.export(ext)
    s = res.scene
    assert res.warning is None

    m = material_of(s, "Matte")
    assert m.model == C.MAT_LAMBERT and m.params[0] == 1.0
    np.testing.assert_allclose(spectrum(s, m.reflectance), uplift((0.1, 0.7, 0.2)), atol=1e-6)

    m = material_of(s, "Brushed")
    assert m.model == C.MAT_GGX_CONDUCTOR
    assert (m.params[1], m.params[2]) == pytest.approx((0.16 * 0.5, 0.16 / 0.5))
    np.testing.assert_allclose(spectrum(s, m.reflectance), uplift((0.9, 0.6, 0.3)), atol=1e-6)
    # Fresnel of a perfect conductor: η = κ = 0 gives reflectance 1 at every angle
    assert m.kappa_table == -1
    eta = s.ior_tables.values[m.eta_table]
    assert np.all(eta == 0.0)
    for cos_i in (1.0, 0.5, 0.05):
        fs, fp = conductor_fresnel(cos_i, 0.0, 0.0)
        assert fs == pytest.approx(1.0) and fp == pytest.approx(1.0)

    m = material_of(s, "Mirror")
    assert m.model == C.MAT_MIRROR
    np.testing.assert_allclose(spectrum(s, m.reflectance), uplift((0.8, 0.8, 0.9)), atol=1e-6)


def conductor_fresnel(cos_i, eta, kappa):
    """Exact (F_s, F_p) of a conductor n = η + iκ seen from air (complex Snell's law, numpy complex)."""
    n = complex(eta, kappa)
    sin2 = 1.0 - cos_i * cos_i
    cos_t = np.sqrt(1.0 - sin2 / (n * n)) if n != 0 else 1j * np.inf
    if not np.isfinite(cos_t):
        return 1.0, 1.0
    rs = (cos_i - n * cos_t) / (cos_i + n * cos_t)
    rp = (n * cos_i - cos_t) / (n * cos_i + cos_t)
    return abs(rs) ** 2, abs(rp) ** 2


@blender
def test_glass_and_refraction(ext, bpy):
    b = ext.build
    minimal(b)
    C = ext.core.constants
    b.plane("Clear", material=b.shader("Gl", "ShaderNodeBsdfGlass", Color=(0.9, 1.0, 0.95, 1.0), IOR=1.45))
    b.plane("Frosted", material=b.shader("RGl", "ShaderNodeBsdfGlass", Roughness=0.3, IOR=1.6))
    b.plane("Refr", material=b.shader("Rf", "ShaderNodeBsdfRefraction", IOR=1.33, Roughness=0.2))
    res = b.export(ext)
    s = res.scene
    m = material_of(s, "Clear")
    assert m.model == C.MAT_DIELECTRIC and m.ior == pytest.approx(1.45) and m.eta_table == -1
    np.testing.assert_allclose(spectrum(s, m.reflectance), uplift((0.9, 1.0, 0.95)), atol=1e-6)
    assert m.specular == m.reflectance  # the colour tints reflection and transmission, as in Cycles
    m = material_of(s, "Frosted")
    assert m.model == C.MAT_GGX_DIELECTRIC and m.ior == pytest.approx(1.6)
    assert (m.params[1], m.params[2]) == pytest.approx((0.09, 0.09))
    np.testing.assert_allclose(spectrum(s, m.reflectance), 1.0, atol=1e-6)
    m = material_of(s, "Refr")
    assert m.model == C.MAT_GGX_DIELECTRIC and m.ior == pytest.approx(1.33)
    np.testing.assert_allclose(spectrum(s, m.specular), 0.0, atol=1e-6)  # no reflection
    assert "Refraction BSDF" in res.warning and "Rf" in res.warning


@blender
def test_emission_shader(ext, bpy):
    b = ext.build
    minimal(b)
    b.plane("Lamp", material=b.shader("E", "ShaderNodeEmission", Color=(0.9, 0.9, 1.0, 1.0), Strength=3.0))
    m = material_of(b.export(ext).scene, "Lamp")
    assert m.reflectance == -1 and m.model == ext.core.constants.MAT_LAMBERT  # black, emitting
    y = sum(w * c for w, c in zip(REC709_Y, (0.9, 0.9, 1.0)))
    assert m.emission_luminance == pytest.approx(K_M * 3.0 * y, rel=1e-5)


def gold_rgb():
    return (1.0, 0.766, 0.336)


@blender
def test_principled_metal_reproduces_its_base_colour(ext, bpy):
    if not hasattr(ext.core, "conductor_from_colour"):
        pytest.fail("core.conductor_from_colour is not in core's public names yet")
    b = ext.build
    minimal(b)
    C = ext.core.constants
    gold = b.principled("Gold", gold_rgb())
    node = principled_node(gold)
    node.inputs["Metallic"].default_value = 1.0
    node.inputs["Roughness"].default_value = 0.3
    b.plane("Gold", material=gold)
    mirror = b.principled("Polished", gold_rgb())
    principled_node(mirror).inputs["Metallic"].default_value = 1.0
    principled_node(mirror).inputs["Roughness"].default_value = 0.0
    b.plane("Polished", material=mirror)
    res = b.export(ext)
    s = res.scene
    assert res.warning is None
    m = material_of(s, "Gold")
    assert m.model == C.MAT_GGX_CONDUCTOR  # metallic 1: no mix
    assert (m.params[1], m.params[2]) == pytest.approx((0.09, 0.09))
    np.testing.assert_allclose(spectrum(s, m.reflectance), 1.0, atol=1e-6)  # white tint: colour is in η, κ
    eta = s.ior_tables.values[m.eta_table].astype(np.float64)
    kappa = s.ior_tables.values[m.kappa_table].astype(np.float64)
    r0 = ((eta - 1) ** 2 + kappa ** 2) / ((eta + 1) ** 2 + kappa ** 2)
    target = uplift(gold_rgb())
    np.testing.assert_allclose(r0, np.clip(target, 0.0, 0.9999), atol=2e-3)
    # and so its colour under D65 is the base colour
    rgb = ext.core.reflectance_to_rgb(ext.core.reflectance_from_samples(ext.core.wavelength_grid(), r0))
    np.testing.assert_allclose(rgb, gold_rgb(), atol=0.01)
    # the exact Fresnel at normal incidence agrees with R0
    fs, fp = conductor_fresnel(1.0, eta[200], kappa[200])
    assert 0.5 * (fs + fp) == pytest.approx(r0[200], rel=1e-6)
    m = material_of(s, "Polished")
    assert m.model == C.MAT_CONDUCTOR and m.eta_table == material_of(s, "Gold").eta_table


@blender
def test_metallic_bsdf(ext, bpy):
    b = ext.build
    minimal(b)
    C = ext.core.constants
    phys = b.shader("Phys", "ShaderNodeBsdfMetallic", Roughness=0.5)
    node = next(n for n in phys.node_tree.nodes if n.type == "BSDF_METALLIC")
    node.fresnel_type = "PHYSICAL_CONDUCTOR"  # (its IOR and Extinction sockets are available only now)
    node.inputs["IOR"].default_value = (0.2, 0.5, 1.4)
    node.inputs["Extinction"].default_value = (3.5, 2.4, 1.8)
    b.plane("Phys", material=phys)
    b.plane("F82", material=b.shader("F82", "ShaderNodeBsdfMetallic", Roughness=0.0,
                                     **{"Base Color": (*gold_rgb(), 1.0)}))
    res = b.export(ext)
    s = res.scene
    m = material_of(s, "Phys")
    assert m.model == C.MAT_GGX_CONDUCTOR and (m.params[1], m.params[2]) == pytest.approx((0.25, 0.25))
    eta, kappa = s.ior_tables.values[m.eta_table], s.ior_tables.values[m.kappa_table]
    for nm, e, k in ((630, 0.2, 3.5), (532, 0.5, 2.4), (465, 1.4, 1.8), (360, 1.4, 1.8), (830, 0.2, 3.5)):
        assert (eta[nm - 360], kappa[nm - 360]) == pytest.approx((e, k), rel=1e-6)
    assert "Phys" in res.warning
    m = material_of(s, "F82")
    assert m.model == C.MAT_CONDUCTOR
    eta = s.ior_tables.values[m.eta_table].astype(np.float64)
    kappa = s.ior_tables.values[m.kappa_table].astype(np.float64)
    r0 = ((eta - 1) ** 2 + kappa ** 2) / ((eta + 1) ** 2 + kappa ** 2)
    np.testing.assert_allclose(r0, np.clip(uplift(gold_rgb()), 0.0, 0.9999), atol=2e-3)


@blender
def test_principled_dielectric_is_plastic(ext, bpy):
    b = ext.build
    minimal(b)
    C = ext.core.constants
    p = b.principled("P", (0.2, 0.4, 0.6))
    b.plane("Plastic", material=p)
    a = b.principled("Aniso", (0.5, 0.5, 0.5))
    node = principled_node(a)
    node.inputs["Anisotropic"].default_value = 0.8
    node.inputs["Roughness"].default_value = 0.6
    node.inputs["Specular IOR Level"].default_value = 1.0
    node.inputs["Specular Tint"].default_value = (1.0, 0.5, 0.5, 1.0)
    b.plane("Aniso", material=a)
    s = b.export(ext).scene
    m = material_of(s, "Plastic")
    assert m.model == C.MAT_PLASTIC and m.ior == pytest.approx(1.5)
    assert (m.params[0], m.params[1], m.params[2]) == pytest.approx((1.0, 0.25, 0.25))
    np.testing.assert_allclose(spectrum(s, m.reflectance), uplift((0.2, 0.4, 0.6)), atol=1e-6)
    assert m.specular == -1
    m = material_of(s, "Aniso")
    aspect = math.sqrt(1.0 - 0.9 * 0.8)
    assert (m.params[1], m.params[2]) == pytest.approx((0.36 / aspect, 0.36 * aspect))
    f0 = ((m.ior - 1) / (m.ior + 1)) ** 2
    assert f0 == pytest.approx(0.04 * 2.0, rel=1e-6)  # Specular IOR Level 1 doubles F0
    np.testing.assert_allclose(spectrum(s, m.specular), uplift((1.0, 0.5, 0.5)), atol=1e-6)


@blender
def test_principled_coat_and_sheen_are_the_plastics_outer_layers(ext, bpy):
    """Coat (weight, roughness², IOR, tint spectrum in the κ slot) and sheen (weight × the tint's
    luminance, roughness) go into the plastic's row; only a coloured sheen tint is warned about."""
    b = ext.build
    minimal(b)
    C = ext.core.constants
    P = importlib.import_module(ext.core.__name__ + ".bsdfs.params")
    p = b.principled("Lacquer", (0.2, 0.4, 0.6))
    node = principled_node(p)
    node.inputs["Coat Weight"].default_value = 0.8
    node.inputs["Coat Roughness"].default_value = 0.2
    node.inputs["Coat IOR"].default_value = 1.6
    node.inputs["Coat Tint"].default_value = (0.9, 0.5, 0.3, 1.0)
    node.inputs["Sheen Weight"].default_value = 0.5
    node.inputs["Sheen Roughness"].default_value = 0.3
    node.inputs["Sheen Tint"].default_value = (1.0, 0.5, 0.5, 1.0)
    b.plane("Lacquer", material=p)
    res = b.export(ext)
    s = res.scene
    m = material_of(s, "Lacquer")
    assert m.model == C.MAT_PLASTIC and m.kappa_table >= 0
    row = m.params
    grey = 0.2126 + 0.7152 * 0.5 + 0.0722 * 0.5
    assert (row[P.P_COAT], row[P.P_COAT_ALPHA], row[P.P_COAT_IOR], row[P.P_COAT_TINTED]) == pytest.approx(
        (0.8, 0.04, 1.6, 1.0))
    assert (row[P.P_SHEEN], row[P.P_SHEEN_ROUGHNESS]) == pytest.approx((0.5 * grey, 0.3))
    np.testing.assert_allclose(s.ior_tables.values[m.kappa_table], uplift((0.9, 0.5, 0.3)), atol=1e-6)
    w = res.warning or ""
    assert "coat" not in w and "sheen tint (1.0, 0.5, 0.5)" in w, w
    ext.core.validate(s)


@blender
def test_principled_tree_and_unsupported_inputs(ext, bpy):
    b = ext.build
    minimal(b)
    C = ext.core.constants
    p = b.principled("Layered", gold_rgb())
    node = principled_node(p)
    node.inputs["Metallic"].default_value = 0.3
    node.inputs["Transmission Weight"].default_value = 0.6
    node.inputs["Roughness"].default_value = 0.0
    node.inputs["IOR"].default_value = 1.45
    node.inputs["Coat Weight"].default_value = 0.5
    node.inputs["Sheen Weight"].default_value = 0.2
    node.inputs["Subsurface Weight"].default_value = 0.1
    node.inputs["Thin Film Thickness"].default_value = 300.0
    node.inputs["Emission Color"].default_value = (1.0, 0.5, 0.2, 1.0)
    node.inputs["Emission Strength"].default_value = 2.0
    b.plane("Layered", material=p)
    res = b.export(ext)
    s = res.scene
    root = material_of(s, "Layered")
    assert root.name == "Layered" and root.model == C.MAT_MIX and root.params[0] == pytest.approx(0.3)
    metal, rest = components(s, root)
    assert metal.model == C.MAT_CONDUCTOR and metal.eta_table >= 0 and metal.kappa_table >= 0
    assert rest.model == C.MAT_MIX and rest.params[0] == pytest.approx(0.6)
    glass, plastic = components(s, rest)
    assert glass.model == C.MAT_DIELECTRIC and glass.ior == pytest.approx(1.45)
    np.testing.assert_allclose(spectrum(s, glass.reflectance), uplift(gold_rgb()), atol=1e-6)
    assert plastic.model == C.MAT_PLASTIC and plastic.ior == pytest.approx(1.45)
    # emission sits on the root (the kernel reads it before choosing a component)
    assert root.emission >= 0 and metal.emission == -1 and plastic.emission == -1
    y = sum(w * c for w, c in zip(REC709_Y, (1.0, 0.5, 0.2)))
    assert root.emission_luminance == pytest.approx(K_M * 2.0 * y, rel=1e-5)
    w = res.warning
    assert "\n" not in w and w.count("Not exported") == 1
    P = importlib.import_module(ext.core.__name__ + ".bsdfs.params")
    assert plastic.params[P.P_COAT] == pytest.approx(0.5) and plastic.params[P.P_SHEEN] == pytest.approx(0.2)
    for what in ("coat 0.5 (on the metallic and transmission components ignored",
                 "sheen 0.2 (on the metallic and transmission components ignored",
                 "subsurface 0.1 (diffuse base colour)", "thin film 300 (ignored)"):
        assert what in w, (what, w)
    ext.core.validate(s)


@blender
def test_principled_weights_of_zero_and_one_make_no_mix(ext, bpy):
    b = ext.build
    minimal(b)
    C = ext.core.constants
    g = b.principled("AllGlass", (1.0, 1.0, 1.0))
    principled_node(g).inputs["Transmission Weight"].default_value = 1.0
    principled_node(g).inputs["Roughness"].default_value = 0.2
    b.plane("AllGlass", material=g)
    n_before = 0
    s = b.export(ext).scene
    m = material_of(s, "AllGlass")
    assert m.model == C.MAT_GGX_DIELECTRIC and (m.params[1], m.params[2]) == pytest.approx((0.04, 0.04))
    assert len(s.materials) == n_before + 1
    assert not any(x.model in (C.MAT_MIX, C.MAT_ADD) for x in s.materials)


@blender
def test_principled_alpha_mixes_in_a_transparent_surface(ext, bpy):
    b = ext.build
    minimal(b)
    C = ext.core.constants
    p = b.principled("Leaf", (0.2, 0.6, 0.1))
    principled_node(p).inputs["Alpha"].default_value = 0.25
    b.plane("Leaf", material=p)
    res = b.export(ext)
    root = material_of(res.scene, "Leaf")
    assert root.model == C.MAT_MIX and root.params[0] == pytest.approx(0.25)
    surface, clear = components(res.scene, root)
    assert surface.model == C.MAT_PLASTIC
    assert clear.model == C.MAT_DIELECTRIC and clear.ior == 1.0  # η = 1: no reflection, no bending
    assert "alpha 0.25" in res.warning


def mix_of(bpy, name, fac, first, second, add=False):
    """Mix (or Add) Shader of two single-node shaders ``(idname, {input: value})``."""
    def build(tree, out):
        mix = tree.nodes.new("ShaderNodeAddShader" if add else "ShaderNodeMixShader")
        if not add:
            mix.inputs["Factor"].default_value = fac
        for k, (idname, inputs) in enumerate((first, second)):
            node = tree.nodes.new(idname)
            for key, v in inputs.items():
                node.inputs[key].default_value = v
            tree.links.new(node.outputs[0], mix.inputs[1 + k - (1 if add else 0)])
        tree.links.new(mix.outputs[0], out.inputs["Surface"])
    return tree_material(bpy, name, build)


@blender
def test_mix_and_add_shaders(ext, bpy):
    b = ext.build
    minimal(b)
    C = ext.core.constants
    diffuse = ("ShaderNodeBsdfDiffuse", {"Color": (0.5, 0.1, 0.1, 1.0)})
    glossy = ("ShaderNodeBsdfGlossy", {"Roughness": 0.5})
    emit = ("ShaderNodeEmission", {"Color": (1.0, 1.0, 1.0, 1.0), "Strength": 4.0})
    b.plane("Mix", material=mix_of(bpy, "Mix", 0.25, diffuse, glossy))
    b.plane("MixZero", material=mix_of(bpy, "MixZero", 0.0, diffuse, glossy))
    b.plane("MixOne", material=mix_of(bpy, "MixOne", 1.0, diffuse, glossy))
    b.plane("Add", material=mix_of(bpy, "Add", None, diffuse, glossy, add=True))
    b.plane("GlowMix", material=mix_of(bpy, "GlowMix", 0.75, emit, diffuse))
    b.plane("GlowAdd", material=mix_of(bpy, "GlowAdd", None, diffuse, emit, add=True))
    res = b.export(ext)
    s = res.scene
    assert res.warning is None
    m = material_of(s, "Mix")  # Blender: fac 0 is the first shader; MAT_MIX's weight is the first's
    assert m.model == C.MAT_MIX and m.params[0] == pytest.approx(0.75)
    a, c = components(s, m)
    assert a.model == C.MAT_LAMBERT and c.model == C.MAT_GGX_CONDUCTOR
    assert material_of(s, "MixZero").model == C.MAT_LAMBERT
    assert material_of(s, "MixOne").model == C.MAT_GGX_CONDUCTOR
    m = material_of(s, "Add")
    assert m.model == C.MAT_ADD
    a, c = components(s, m)
    assert (a.model, c.model) == (C.MAT_LAMBERT, C.MAT_GGX_CONDUCTOR)
    # emission inside a mix: weighted by its factor; its BSDF share is black
    m = material_of(s, "GlowMix")
    assert m.model == C.MAT_MIX and m.params[0] == pytest.approx(0.25)
    black, a = components(s, m)
    assert black.model == C.MAT_LAMBERT and black.reflectance == -1 and a.model == C.MAT_LAMBERT
    assert m.emission_luminance == pytest.approx(K_M * 4.0 * 0.25, rel=1e-5)
    # emission added to a BSDF: the BSDF alone, emitting
    m = material_of(s, "GlowAdd")
    assert m.model == C.MAT_LAMBERT and m.reflectance >= 0
    assert m.emission_luminance == pytest.approx(K_M * 4.0, rel=1e-5)
    ext.core.validate(s)


@blender
@pytest.mark.parametrize("driver", ["ShaderNodeFresnel", "ShaderNodeAmbientOcclusion"])
def test_linked_mix_factor_is_a_program_or_one_half_with_a_warning(ext, bpy, driver):
    """A Factor a supported graph drives is a mix program (per shading point, no warning); one
    a node the programs cannot evaluate drives is 0.5, named in the warning."""
    b = ext.build
    minimal(b)

    def build(tree, out):
        mix = tree.nodes.new("ShaderNodeMixShader")
        node = tree.nodes.new(driver)
        node.name = "Driver"
        tree.links.new(node.outputs[0], mix.inputs["Factor"])
        tree.links.new(tree.nodes.new("ShaderNodeBsdfDiffuse").outputs[0], mix.inputs[1])
        tree.links.new(tree.nodes.new("ShaderNodeBsdfGlossy").outputs[0], mix.inputs[2])
        tree.links.new(mix.outputs[0], out.inputs["Surface"])

    b.plane("Coated", material=tree_material(bpy, "Coated", build))
    res = b.export(ext)
    m = material_of(res.scene, "Coated")
    assert m.model == ext.core.constants.MAT_MIX
    if driver == "ShaderNodeFresnel":
        assert m.mix_program >= 0 and len(res.scene.programs) == 1
        assert not res.warning or "Driver" not in res.warning, res.warning
    else:
        assert m.mix_program == -1 and m.params[0] == 0.5
        assert "Driver" in res.warning and "Coated" in res.warning, res.warning


@blender
def test_unsupported_shader_is_listed_with_a_diffuse_substitute(ext, bpy):
    b = ext.build
    minimal(b)
    b.plane("Cartoon", material=b.shader("Toon", "ShaderNodeBsdfToon", Color=(0.3, 0.6, 0.9, 1.0)))
    res = b.export(ext)
    m = material_of(res.scene, "Cartoon")
    assert m.model == ext.core.constants.MAT_LAMBERT
    np.testing.assert_allclose(spectrum(res.scene, m.reflectance), uplift((0.3, 0.6, 0.9)), atol=1e-6)
    assert "Toon/Toon BSDF" in res.warning


# ----------------------------------------------------------------------------- the panel's override

OVERRIDES = ("LAMBERT", "PHONG", "BLINN_PHONG", "WARD", "LAFORTUNE", "MIRROR", "CONDUCTOR", "GLASS")


@blender
@pytest.mark.parametrize("model", OVERRIDES)
def test_panel_override(ext, bpy, model):
    b = ext.build
    minimal(b)
    C = ext.core.constants
    core = ext.core
    mat = b.principled("Over", (0.3, 0.5, 0.7))
    principled_node(mat).inputs["Emission Strength"].default_value = 1.5  # kept under any override
    st = mat.spectral_gi
    st.model = model
    st.exponent = 80.0
    st.alpha_x, st.alpha_y = 0.2, 0.05
    st.ward_variant = "DUER"
    st.lobe_count = 2
    st.lobe_1 = (-1.0, -1.0, 1.0, 30.0)
    st.lobe_2 = (0.5, 0.5, 0.5, 5.0)
    st.two_sided = False
    st.specular_color = (0.3, 0.3, 0.3)
    b.plane("Over", material=mat)
    s = b.export(ext).scene
    m = material_of(s, "Over")
    assert m.emission_luminance == pytest.approx(K_M * 1.5, rel=1e-5)
    node_rgb = uplift((0.3, 0.5, 0.7))
    expect = {
        "LAMBERT": (C.MAT_LAMBERT, core.lambert_params(False)),
        "PHONG": (C.MAT_PHONG, core.phong_params(80.0, False)),
        "BLINN_PHONG": (C.MAT_BLINN_PHONG, core.blinn_phong_params(80.0, False)),
        "WARD": (C.MAT_WARD, core.ward_params(0.2, 0.05, "duer", False)),
        "LAFORTUNE": (C.MAT_LAFORTUNE, core.lafortune_params([(-1, -1, 1, 30), (0.5, 0.5, 0.5, 5)], False)),
        "MIRROR": (C.MAT_MIRROR, core.mirror_params(False)),
        "CONDUCTOR": (C.MAT_GGX_CONDUCTOR, core.ggx_conductor_params(0.2, 0.05, False)),
        "GLASS": (C.MAT_GGX_DIELECTRIC, core.ggx_dielectric_params(0.2, 0.05)),
    }[model]
    assert m.model == expect[0]
    np.testing.assert_allclose(np.asarray(m.params), expect[1], rtol=1e-6, atol=1e-6)
    if model in ("LAMBERT", "PHONG", "BLINN_PHONG", "WARD", "LAFORTUNE", "MIRROR"):
        np.testing.assert_allclose(spectrum(s, m.reflectance), node_rgb, atol=1e-6)
        if model not in ("LAMBERT", "MIRROR"):
            np.testing.assert_allclose(spectrum(s, m.specular), uplift((0.3, 0.3, 0.3)), atol=1e-6)
        # a measured preset instead of the node colour
        st.spectrum = "PRESET"
        st.reflectance_preset = "red"
        s = b.export(ext).scene
        m = material_of(s, "Over")
        np.testing.assert_allclose(s.spectra.coeffs[m.reflectance], core.reflectance_preset("red"))
    elif model == "CONDUCTOR":
        st.spectrum = "PRESET"
        st.metal_preset = "Au"
        st.alpha_x = st.alpha_y = 0.0
        s = b.export(ext).scene
        m = material_of(s, "Over")
        assert m.model == C.MAT_CONDUCTOR
        eta, kappa = core.metal_preset("Au")
        np.testing.assert_allclose(s.ior_tables.values[m.eta_table], eta, rtol=1e-6)
        np.testing.assert_allclose(s.ior_tables.values[m.kappa_table], kappa, rtol=1e-6)
        np.testing.assert_allclose(spectrum(s, m.reflectance), 1.0, atol=1e-6)
    else:
        assert m.ior == pytest.approx(1.5) and m.eta_table == -1
        st.spectrum = "PRESET"
        st.glass_preset = "N-SF11"
        st.alpha_x = st.alpha_y = 0.0
        s = b.export(ext).scene
        m = material_of(s, "Over")
        assert m.model == C.MAT_DIELECTRIC
        np.testing.assert_allclose(s.ior_tables.values[m.eta_table], core.glass_preset("N-SF11"), rtol=1e-6)
    core.validate(s)


@blender
def test_panel_registration_and_drawing(ext, bpy):
    from unittest import mock

    panel = bpy.types.SPECTRALGI_PT_material
    assert (panel.bl_space_type, panel.bl_region_type, panel.bl_context) == ("PROPERTIES", "WINDOW", "material")
    mat = bpy.data.materials.new("Drawn")
    props = mat.spectral_gi.bl_rna.properties
    assert props["model"].enum_items.keys()[0] == "AUTO"
    assert set(OVERRIDES) <= set(props["model"].enum_items.keys())
    core = ext.core
    assert list(props["reflectance_preset"].enum_items.keys()) == core.reflectance_preset_names()
    assert list(props["metal_preset"].enum_items.keys()) == core.metal_preset_names()
    assert list(props["glass_preset"].enum_items.keys()) == core.glass_preset_names()
    assert panel.poll(mock.MagicMock(material=mat))
    assert not panel.poll(mock.MagicMock(material=None))
    draw = __import__(ext.module.__name__ + ".addon.ui.material_panel", fromlist=["draw_settings"]).draw_settings
    for model in ("AUTO",) + OVERRIDES:
        mat.spectral_gi.model = model
        for source in ("NODE", "PRESET"):
            mat.spectral_gi.spectrum = source
            drawn = []
            layout = mock.MagicMock()
            layout.column.return_value = layout
            layout.prop.side_effect = lambda data, name, **kw: drawn.append(name)
            draw(layout, mat.spectral_gi)
            assert drawn[0] == "model"
            for name in drawn:
                assert name in props, name
            if model != "AUTO" and source == "PRESET":
                want = {"CONDUCTOR": "metal_preset", "GLASS": "glass_preset"}.get(model, "reflectance_preset")
                assert want in drawn
    sub = bpy.types.SPECTRALGI_PT_material_surface
    scene = mock.MagicMock()
    scene.render.engine = "SPECTRAL_GI"
    assert sub.poll(mock.MagicMock(material=mat, scene=scene))
    scene.render.engine = "CYCLES"
    assert not sub.poll(mock.MagicMock(material=mat, scene=scene))


# ----------------------------------------------------------------------------- a tiny render of everything

@blender
def test_every_mapped_shader_renders(ext, bpy):
    b = ext.build
    C = ext.core.constants
    shaders = [
        b.shader("D", "ShaderNodeBsdfDiffuse", Color=(0.7, 0.3, 0.2, 1.0)),
        b.shader("G", "ShaderNodeBsdfGlossy", Roughness=0.3, Anisotropy=0.4),
        b.shader("M", "ShaderNodeBsdfGlossy", Roughness=0.0),
        b.shader("Gl", "ShaderNodeBsdfGlass"),
        b.shader("RG", "ShaderNodeBsdfGlass", Roughness=0.3),
        b.shader("Rf", "ShaderNodeBsdfRefraction"),
        b.shader("T", "ShaderNodeBsdfTransparent"),
        b.principled("P", (0.2, 0.4, 0.6)),
        mix_of(bpy, "Mix", 0.3, ("ShaderNodeBsdfDiffuse", {}), ("ShaderNodeBsdfGlossy", {})),
        mix_of(bpy, "Add", None, ("ShaderNodeBsdfDiffuse", {}), ("ShaderNodeBsdfGlossy", {}), add=True),
        mix_of(bpy, "Glow", 0.5, ("ShaderNodeBsdfDiffuse", {}), ("ShaderNodeEmission", {"Strength": 0.5})),
    ]
    metal = b.principled("PM", gold_rgb())
    principled_node(metal).inputs["Metallic"].default_value = 0.7
    principled_node(metal).inputs["Transmission Weight"].default_value = 0.5
    principled_node(metal).inputs["Alpha"].default_value = 0.8
    shaders.append(metal)
    polished = b.principled("Polished", (0.9, 0.9, 0.9))
    principled_node(polished).inputs["Metallic"].default_value = 1.0
    principled_node(polished).inputs["Roughness"].default_value = 0.0
    shaders.append(polished)
    for model in OVERRIDES:
        mat = bpy.data.materials.new(f"O{model}")
        mat.spectral_gi.model = model
        shaders.append(mat)
    for i, mat in enumerate(shaders):
        b.cube(f"C{i}", size=0.8, location=((i % 5) - 2.0, 0.0, 0.4 + 1.0 * (i // 5)), material=mat)
    b.plane("Floor", size=10.0, material=b.shader("F", "ShaderNodeBsdfDiffuse"))
    b.light("Key", "AREA", location=(0, -2, 5), energy=500.0, size=2.0)
    b.camera(location=(0, -8, 2.5), rotation=(math.radians(80), 0, 0), lens=28.0)
    b.resolution(16, 16)
    res = b.export(ext)
    s = res.scene
    models = {m.model for m in s.materials}
    for tag in (C.MAT_LAMBERT, C.MAT_PHONG, C.MAT_BLINN_PHONG, C.MAT_WARD, C.MAT_LAFORTUNE, C.MAT_MIRROR,
                C.MAT_DIELECTRIC, C.MAT_CONDUCTOR, C.MAT_GGX_CONDUCTOR, C.MAT_GGX_DIELECTRIC, C.MAT_MIX, C.MAT_ADD,
                C.MAT_PLASTIC):
        assert tag in models, tag
    s.settings.spp = 4
    s.settings.max_depth = 6
    film, stats = ext.core.render(s, threads=2)
    rgb = film.develop().rgb
    assert rgb.shape == (16, 16, 3)
    assert np.all(np.isfinite(rgb))
    assert rgb.mean() > 0.0
