"""Image textures: lookups against a NumPy oracle, uplifted base colours, roughness and normal
maps in renders, validation and the scene file."""
import math

import numpy as np
import pytest
from helpers import flat_emission, flat_reflectance, look_at

from spectral_gi.core import constants as C
from spectral_gi.core.integrators import render as R
from spectral_gi.core.bsdfs.params import ggx_conductor_params, lambert_params, plastic_params
from spectral_gi.core.textures import kernel as KT
from spectral_gi.core.scene import (
    Camera, Light, Material, Mesh, RenderSettings, Scene, SceneError, SpectrumTable, World, load, save,
    validate)
from spectral_gi.core.spectra import moments
from spectral_gi.core.scene import Texture
from spectral_gi.core.textures import pack, reflectance_basis

# ----------------------------------------------------------------------------- the lookup


def oracle(img, interpolation, extension, u, v):
    """Naive texture lookup: Blender's UV convention (v up, row 0 at the top)."""
    h, w, c = img.shape
    if extension == "clip" and (u < 0 or u > 1 or v < 0 or v > 1):
        return np.zeros(3)

    def wrap(i, n):
        return i % n if extension == "repeat" else min(max(i, 0), n - 1)

    def texel(i, j):
        t = img[wrap(j, h), wrap(i, w)].astype(np.float64)
        return np.repeat(t, 3) if c == 1 else t

    x, y = u * w, (1 - v) * h
    if interpolation == "closest":
        return texel(math.floor(x), math.floor(y))
    x, y = x - 0.5, y - 0.5
    i, j = math.floor(x), math.floor(y)
    fx, fy = x - i, y - j
    return ((1 - fx) * (1 - fy) * texel(i, j) + fx * (1 - fy) * texel(i + 1, j)
            + (1 - fx) * fy * texel(i, j + 1) + fx * fy * texel(i + 1, j + 1))


@pytest.mark.parametrize("channels", [1, 3])
@pytest.mark.parametrize("interpolation", ["closest", "linear"])
@pytest.mark.parametrize("extension", ["repeat", "extend", "clip"])
def test_lookup_matches_the_numpy_oracle(channels, interpolation, extension):
    rng = np.random.default_rng(5)
    other = Texture("other", rng.random((2, 2, 3), dtype=np.float32))  # a texture before it: offsets
    img = rng.random((3, 5, channels), dtype=np.float32)
    data, info = pack([other, Texture("t", img, interpolation, extension)])
    for u, v in rng.uniform(-1.5, 2.5, (300, 2)):
        got = np.array(KT.sample(data, info, 1, u, v))
        np.testing.assert_allclose(got, oracle(img, interpolation, extension, u, v), atol=1e-6)
    # texel centres return the texel exactly; clip is 0 just outside
    got = KT.sample(data, info, 1, 0.5 / 5, 1 - 0.5 / 3)
    np.testing.assert_allclose(got, np.broadcast_to(img[0, 0], 3) if channels == 3 else [img[0, 0, 0]] * 3,
                               atol=1e-7)
    if extension == "clip":
        assert KT.sample(data, info, 1, -1e-3, 0.5) == (0.0, 0.0, 0.0)


def test_pack_clamps_to_the_unit_range():
    data, info = pack([Texture("hdr", np.array([[[2.0, -1.0, 0.5]]], np.float32))])
    np.testing.assert_array_equal(data, [1.0, 0.0, 0.5])
    assert tuple(info[0, :4]) == (0, 1, 1, 3)


# ----------------------------------------------------------------------------- renders

RED, GREEN, BLUE, WHITE = (0.8, 0.1, 0.1), (0.1, 0.7, 0.2), (0.1, 0.2, 0.9), (1.0, 1.0, 1.0)


def plane(material=0, corner=True):
    """The square [-1, 1]² at z = 0, UV (x + 1, y + 1) / 2 (per corner or per vertex)."""
    pos = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    idx = np.array([[0, 1, 2], [0, 2, 3]], np.int32)
    uv = (pos[:, :2] + 1) / 2
    if corner:
        return Mesh("plane", pos, idx, np.full(2, material, np.int32),
                    corner_uvs=np.ascontiguousarray(uv[idx].reshape(-1, 2)))
    return Mesh("plane", pos, idx, np.full(2, material, np.int32), uvs=np.ascontiguousarray(uv))


def plane_scene(materials, textures=(), spectra=None, lights=(), world=None, res=8, spp=32, corner=True):
    """An orthographic camera looking down at exactly the plane (image top = +y)."""
    cam = Camera(look_at((0, 0, 1), (0, 0, 0), up=(0, 1, 0)), width=res, height=res,
                 projection=C.CAM_ORTHOGRAPHIC, ortho_scale=2.0)
    return Scene(meshes=[plane(0, corner)], spectra=spectra or SpectrumTable.empty(), materials=list(materials),
                 textures=list(textures), lights=list(lights), camera=cam, world=world or World(),
                 settings=RenderSettings(spp=spp, max_depth=0, seed=9, filter=C.FILTER_BOX, filter_width=1.0))


def uniform_world(spectra, luminance=300.0):
    return World(background=spectra.add("flat sky", flat_emission(), C.SPECTRUM_UNBOUNDED), luminance=luminance)


def expected_xyz(scene, rgb):
    """XYZ of ρ(λ) L(λ) with ρ the Mallett–Yuksel uplift of rgb, L the uniform world (a Lambert
    plane sees the whole upper hemisphere: L_o = ρ L)."""
    prep = R.prepare(scene)
    rho = np.asarray(rgb) @ reflectance_basis()
    le = prep.emitters.world_scale * prep.materials.spec[prep.emitters.world_spec].astype(np.float64)
    return (rho * le) @ prep.cmf[:, :3].astype(np.float64) * C.LAMBDA_STEP


@pytest.mark.parametrize("corner", [True, False])
def test_base_colour_checker_renders_each_texels_uplift(corner):
    """A 2×2 checker (top row red, green; bottom blue, white) in the quadrants the UVs put it."""
    sp = SpectrumTable.empty()
    world = uniform_world(sp)
    img = np.array([[RED, GREEN], [BLUE, WHITE]], np.float32)
    sc = plane_scene([Material("tex", params=lambert_params(), base_colour_texture=0)],
                     [Texture("checker", img, "closest", "repeat")], sp, world=world, corner=corner, spp=128)
    film, _ = R.render(sc)
    d = film.develop()
    quads = {RED: d.XYZ[:4, :4], GREEN: d.XYZ[:4, 4:], BLUE: d.XYZ[4:, :4], WHITE: d.XYZ[4:, 4:]}
    for rgb, block in quads.items():
        want = expected_xyz(sc, rgb)
        # spectral noise only (cosine sampling of a Lambert under a uniform sky is exact per λ)
        np.testing.assert_allclose(block.reshape(-1, 3).mean(0), want, rtol=0.03, err_msg=str(rgb))
        # the albedo AOV is the texel's colour (the uplift reproduces rgb under D65 closely)
        alb = d.albedo[:4, :4] if rgb == RED else None
        if alb is not None:
            np.testing.assert_allclose(alb.reshape(-1, 3).mean(0), rgb, atol=0.02)
    # white: ρ = 1 exactly, L_o = L
    y = d.luminance[4:, 4:].mean()
    assert y == pytest.approx(300.0, rel=0.01)


@pytest.mark.statistical
def test_constant_texture_equals_the_constant_material():
    rgb = (0.6, 0.35, 0.2)
    sp = SpectrumTable.empty()
    world = uniform_world(sp)
    rho = np.asarray(rgb) @ reflectance_basis()
    s = sp.add("uplift", moments.moments_from_samples(moments.grid(), np.clip(rho, 0, 1), C.N_COEFFS_DEFAULT),
               C.SPECTRUM_BOUNDED)
    img = np.broadcast_to(np.asarray(rgb, np.float32), (4, 4, 3)).copy()
    a = plane_scene([Material("tex", params=lambert_params(), base_colour_texture=0)], [Texture("c", img)], sp,
                    world=world, spp=64)
    b = plane_scene([Material("const", params=lambert_params(), reflectance=s)], [], sp, world=world, spp=64)
    da, db = R.render(a)[0].develop(), R.render(b)[0].develop()
    xa, xb = da.XYZ.reshape(-1, 3).mean(0), db.XYZ.reshape(-1, 3).mean(0)
    se = np.sqrt(da.variance.mean() / da.luminance.size) / C.K_M
    np.testing.assert_allclose(xa, xb, rtol=0.01, atol=5 * se)
    np.testing.assert_allclose(da.albedo.reshape(-1, 3).mean(0), db.albedo.reshape(-1, 3).mean(0), atol=0.01)


def sun_scene(normal_img=None, strength=1.0, sun_dir=(0.0, 0.0, -1.0), corner=True):
    sp = SpectrumTable.empty()
    r = sp.add("grey", flat_reflectance(0.5), C.SPECTRUM_BOUNDED)
    e = sp.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    sun = Light("sun", C.LIGHT_SUN, (0, 0, 0), (0, 0, 0), (0, 0, 0), e, 0.0, direction=tuple(sun_dir),
                illuminance=1000.0)
    tex = [] if normal_img is None else [Texture("n", np.asarray(normal_img, np.float32), "closest", colour=False)]
    mat = Material("m", params=lambert_params(), reflectance=r, normal_texture=0 if tex else -1,
                   normal_strength=strength)
    return plane_scene([mat], tex, sp, lights=[sun], spp=16, corner=corner)


def test_flat_normal_map_is_identical_to_none():
    a = R.render(sun_scene(np.full((2, 2, 3), (0.5, 0.5, 1.0))))[0]
    b = R.render(sun_scene())[0]
    np.testing.assert_array_equal(a.sums, b.sums)


@pytest.mark.parametrize("channel, axis", [(0, 0), (1, 1)])
def test_tilted_normal_map_changes_the_lambert_cosine(channel, axis):
    """A map tilting the normal by 30° towards +u (red) or +v (green, OpenGL +Y) under a sun 30°
    off the zenith on that side: the normal faces the sun, cos 1; on the other side cos 60°."""
    th = math.radians(30.0)
    n_t = np.array([0.0, 0.0, math.cos(th)])
    n_t[channel] = math.sin(th)
    img = np.full((2, 2, 3), (n_t + 1) / 2)
    toward = np.zeros(3)
    toward[axis] = math.sin(th)
    toward[2] = math.cos(th)  # unit vector towards the sun
    rho, e = 0.5, 1000.0
    for sign, cos_want in ((1.0, 1.0), (-1.0, math.cos(2 * th))):
        d = -np.array([sign * toward[0], sign * toward[1], toward[2]])
        lum = R.render(sun_scene(img, sun_dir=d))[0].develop().luminance.mean()
        assert lum == pytest.approx(rho * e / math.pi * cos_want, rel=0.01), (sign, lum)
    # strength 0: the interpolated normal, cos 30°
    d = -toward
    lum = R.render(sun_scene(img, strength=0.0, sun_dir=d))[0].develop().luminance.mean()
    assert lum == pytest.approx(rho * e / math.pi * math.cos(th), rel=0.01)


def glossy_scene(materials, textures=()):
    """Sun at 40° from the zenith, camera looking down: a rough conductor's sheen depends on α."""
    sp = SpectrumTable.empty()
    r = sp.add("grey", flat_reflectance(0.9), C.SPECTRUM_BOUNDED)
    e = sp.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    for m in materials:
        m.reflectance = r
    th = math.radians(40.0)
    sun = Light("sun", C.LIGHT_SUN, (0, 0, 0), (0, 0, 0), (0, 0, 0), e, 0.0,
                direction=(-math.sin(th), 0.0, -math.cos(th)), illuminance=1000.0)
    return plane_scene(materials, textures, sp, lights=[sun], spp=8)


@pytest.mark.parametrize("model, params", [(C.MAT_GGX_CONDUCTOR, ggx_conductor_params),
                                           (C.MAT_PLASTIC, plastic_params)])
def test_roughness_texture_equals_constant_roughness(model, params):
    """A checker of roughness 0.3 | 0.7: each half is pixel for pixel the material with α = r²."""
    img = np.array([[[0.3], [0.7]]], np.float32)
    tex = glossy_scene([Material("t", model=model, params=params(0.5), roughness_texture=0, ior=1.5)],
                       [Texture("r", img, "closest", colour=False)])
    a = R.render(tex)[0].sums
    for half, r in ((slice(0, 4), 0.3), (slice(4, 8), 0.7)):
        alpha = float(np.float32(r)) ** 2
        b = R.render(glossy_scene([Material("c", model=model, params=params(alpha), ior=1.5)]))[0].sums
        np.testing.assert_array_equal(a[:, half], b[:, half])
    if model == C.MAT_GGX_CONDUCTOR:  # the roughness matters here (the plastic's diffuse base dominates)
        assert a[:, :4, 1].mean() != pytest.approx(a[:, 4:, 1].mean(), rel=0.05)


# ----------------------------------------------------------------------------- validation and files


def good_scene():
    sp = SpectrumTable.empty()
    world = uniform_world(sp)
    img = np.array([[RED, GREEN]], np.float32)
    return plane_scene([Material("tex", params=lambert_params(), base_colour_texture=0)],
                       [Texture("checker", img, "closest", "clip", True)], sp, world=world)


@pytest.mark.parametrize("mutate, field", [
    (lambda s: s.textures[0].image.__setitem__((0, 0, 1), np.nan), "textures[0] ('checker').image"),
    (lambda s: setattr(s.textures[0], "image", np.zeros((2, 2, 2), np.float32)), "textures[0] ('checker').image"),
    (lambda s: setattr(s.textures[0], "image", np.zeros((2, 2), np.float32)), "textures[0] ('checker').image"),
    (lambda s: setattr(s.textures[0], "image", np.zeros((2, 2, 3))), "textures[0] ('checker').image"),
    (lambda s: setattr(s.textures[0], "interpolation", "cubic"), "textures[0] ('checker').interpolation"),
    (lambda s: setattr(s.textures[0], "extension", "mirror"), "textures[0] ('checker').extension"),
    (lambda s: setattr(s.materials[0], "base_colour_texture", 1), "materials[0] ('tex').base_colour_texture"),
    (lambda s: setattr(s.materials[0], "normal_texture", -2), "materials[0] ('tex').normal_texture"),
    (lambda s: setattr(s.materials[0], "roughness_texture", 0), "materials[0] ('tex').roughness_texture"),
    (lambda s: setattr(s.materials[0], "normal_strength", -1.0), "materials[0] ('tex').normal_strength"),
    (lambda s: setattr(s.meshes[0], "corner_uvs", None), "meshes[0] ('plane').uvs"),
    (lambda s: setattr(s.meshes[0], "corner_uvs", np.zeros((5, 2), np.float32)), "meshes[0] ('plane').corner_uvs"),
])
def test_validation_names_the_field(mutate, field):
    sc = good_scene()
    validate(sc)
    mutate(sc)
    with pytest.raises(SceneError) as e:
        validate(sc)
    assert str(e.value).startswith(field), str(e.value)


def test_roughness_texture_needs_a_ggx_model_and_one_channel():
    sc = good_scene()
    sc.textures.append(Texture("r", np.zeros((1, 1, 1), np.float32), colour=False))
    sc.materials[0].base_colour_texture = -1
    sc.materials[0].roughness_texture = 1
    with pytest.raises(SceneError, match="no GGX roughness"):
        validate(sc)
    sc.materials[0].model = C.MAT_PLASTIC
    sc.materials[0].params = plastic_params(0.2)
    validate(sc)
    sc.materials[0].roughness_texture = 0
    with pytest.raises(SceneError, match="one channel"):
        validate(sc)


def test_save_load_round_trips_textures(tmp_path):
    sc = good_scene()
    sc.textures.append(Texture("n", np.random.default_rng(1).random((3, 2, 3), dtype=np.float32), "linear",
                               "extend", False))
    sc.materials[0].normal_texture = 1
    sc.materials[0].normal_strength = 0.5
    back = load(save(sc, tmp_path / "s.json"))
    assert len(back.textures) == 2
    for a, b in zip(sc.textures, back.textures):
        assert (a.name, a.interpolation, a.extension, a.colour) == (b.name, b.interpolation, b.extension, b.colour)
        np.testing.assert_array_equal(a.image, b.image)
    np.testing.assert_array_equal(back.meshes[0].corner_uvs, sc.meshes[0].corner_uvs)
    m = back.materials[0]
    assert (m.base_colour_texture, m.normal_texture, m.normal_strength) == (0, 1, 0.5)
    np.testing.assert_array_equal(R.render(back)[0].sums, R.render(sc)[0].sums)
