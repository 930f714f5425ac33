"""World image (equirectangular HDRI): uplift, importance sampling, MIS, rotation, file format."""
import math

import numpy as np
import pytest
from chi2 import chi2_plane
from helpers import flat_reflectance, look_at

from spectral_gi.core import constants as C
from spectral_gi.core.integrators import render as R
from spectral_gi.core.film import develop
from spectral_gi.core.lights import record as LR
from spectral_gi.core.scene import (
    Camera, Material, Mesh, RenderSettings, Scene, SceneError, SpectrumTable, World, load, save, validate)
from spectral_gi.core.spectra import uplift

RHO = 0.5


def plane_scene(normal=(0.0, 0.0, 1.0), world=None, spp=64, res=6):
    """A large Lambert plane (ρ = 0.5) through the origin with the given normal, seen along it."""
    n = np.asarray(normal, float)
    n /= np.linalg.norm(n)
    a = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    t = np.cross(n, a)
    t /= np.linalg.norm(t)
    b = np.cross(n, t)
    s = 50.0
    quad = np.array([-s * t - s * b, s * t - s * b, s * t + s * b, -s * t + s * b], np.float32)
    spectra = SpectrumTable.empty()
    r = spectra.add("grey", flat_reflectance(RHO), C.SPECTRUM_BOUNDED)
    cam = Camera(look_at(2.0 * n, (0, 0, 0), up=tuple(b)), width=res, height=res, lens_mm=2000.0)
    return Scene(meshes=[Mesh("plane", quad, np.array([[0, 1, 2], [0, 2, 3]], np.int32), np.zeros(2, np.int32))],
                 spectra=spectra, materials=[Material("plane", reflectance=r)], camera=cam,
                 world=world or World(),
                 settings=RenderSettings(spp=spp, max_depth=0, seed=4, filter=C.FILTER_BOX, filter_width=1.0))


def hdr_map(h=16, w=32, seed=3):
    """A grey map with a smooth gradient, a bright 'sun' texel block and a dark band."""
    rng = np.random.default_rng(seed)
    v = 0.2 + 0.5 * rng.random((h, w))
    v[3:5, 20:23] = 60.0
    v[10:12, :] = 0.0
    return np.repeat(v[..., None], 3, axis=2).astype(np.float32)


def bilinear(img, u, v):
    """The map's bilinear interpolation at (u, v) in [0, 1]² between texel centres, periodic in
    u and v (Cycles' Linear interpolation of an environment texture: its first and last rows
    blend within half a texel of the poles, tests/addon/test_addon_compare.py)."""
    h, w = img.shape[:2]
    x, y = np.asarray(u) * w - 0.5, np.asarray(v) * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    tx, ty = (x - x0)[..., None], (y - y0)[..., None]
    i0 = x0.astype(int) % w
    i1 = (i0 + 1) % w
    j0 = y0.astype(int) % h
    j1 = (j0 + 1) % h
    return ((1 - tx) * (1 - ty) * img[j0, i0] + tx * (1 - ty) * img[j0, i1] + (1 - tx) * ty * img[j1, i0]
            + tx * ty * img[j1, i1])


def filtered_texels(img, sub=16):
    """(h, w, 3) mean of the bilinear map over each texel (a sub × sub midpoint rule: exact for
    the piecewise-bilinear map when sub is even)."""
    h, w = img.shape[:2]
    o = (np.arange(sub) + 0.5) / sub
    u = ((np.arange(w)[:, None] + o) / w).reshape(-1)
    v = ((np.arange(h)[:, None] + o) / h).reshape(-1)
    uu, vv = np.meshgrid(u, v)
    return bilinear(img.astype(float), uu, vv).reshape(h, sub, w, sub, 3).mean(axis=(1, 3))


def texel_dirs(h, w, rotation, sub=12):
    """Directions and solid angles of a sub × sub grid in every texel (Cycles' layout)."""
    o = (np.arange(sub) + 0.5) / sub
    u = (np.arange(w)[:, None] + o).reshape(-1) / w
    v = (np.arange(h)[:, None] + o).reshape(-1) / h
    uu, vv = np.meshgrid(u, v)
    th, ph = vv * np.pi, (0.5 - uu) * 2 * np.pi
    x, y, z = np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)
    c, s = math.cos(rotation), math.sin(rotation)
    d = np.stack([c * x - s * y, s * x + c * y, z], -1)
    dw = np.sin(th) * (np.pi / (h * sub)) * (2 * np.pi / (w * sub))
    return d.reshape(h, sub, w, sub, 3), dw.reshape(h, sub, w, sub)


@pytest.mark.statistical
def test_constant_colour_image_equals_the_constant_world():
    rgb = np.array([0.8, 0.5, 0.3])
    scale = 2.0
    img = np.broadcast_to(rgb.astype(np.float32), (8, 16, 3)).copy()
    a = plane_scene(world=World(image=img, image_scale=scale))
    _, y = LR.world_emission_basis()
    sc_b = plane_scene()
    e = sc_b.spectra.add("sky", uplift.emission_from_rgb(rgb), C.SPECTRUM_UNBOUNDED)
    sc_b.world = World(background=e, luminance=C.K_M * scale * float(rgb @ y))
    da = develop(R.render(a)[0].sums)
    db = develop(R.render(sc_b)[0].sums)
    # the plane sees the upper hemisphere: L_o = ρ L
    for d in (da, db):
        assert d.luminance.mean() == pytest.approx(RHO * C.K_M * scale * float(rgb @ y), rel=0.01)
    xa, xb = da.XYZ.reshape(-1, 3).mean(0), db.XYZ.reshape(-1, 3).mean(0)
    np.testing.assert_allclose(xa / xa.sum(), xb / xb.sum(), atol=3e-3)
    # the sky seen directly reproduces the image's colour (RGB 1 = Blender's 1)
    a.meshes = []
    d = develop(R.render(a)[0].sums)
    np.testing.assert_allclose(d.rgb.reshape(-1, 3).mean(0), scale * rgb, rtol=0.02)


@pytest.mark.statistical
@pytest.mark.parametrize("normal, rotation", [((0, 0, 1), 0.0), ((1, 0.3, 0.6), 0.0), ((1, 0.3, 0.6), 1.1)])
def test_hdri_furnace_converges_to_the_maps_cosine_weighted_average(normal, rotation):
    """L_o = ρ/π ∫ L(ω) max(0, n·ω) dω over the bilinearly filtered map (with a bright block
    that only importance sampling finds efficiently); turning the map turns the result."""
    img = hdr_map()
    scale = 0.5
    sc = plane_scene(normal, World(image=img, rotation=rotation, image_scale=scale), spp=128)
    d = develop(R.render(sc)[0].sums)
    h, w = img.shape[:2]
    sub = 12
    dirs, dw = texel_dirs(h, w, rotation, sub)
    o = (np.arange(sub) + 0.5) / sub
    uu, vv = np.meshgrid(((np.arange(w)[:, None] + o) / w).reshape(-1), ((np.arange(h)[:, None] + o) / h).reshape(-1))
    lum = bilinear(img.astype(float), uu, vv)[..., 1].reshape(h, sub, w, sub)
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    expected = RHO / np.pi * C.K_M * scale * float((lum * np.maximum(dirs @ n, 0.0) * dw).sum())
    se = np.sqrt(d.variance.mean() / d.luminance.size)
    assert abs(d.luminance.mean() - expected) < 4.5 * se + 0.002 * expected, (d.luminance.mean(), expected, se)
    assert abs(d.luminance.mean() / expected - 1) < 0.01


@pytest.mark.statistical
@pytest.mark.parametrize("rotation", [0.0, 2.0])
def test_world_image_sampling_matches_its_pdf(rotation, alpha):
    from spectral_gi.core.lights.kernel import env_lookup, env_sample

    img = hdr_map(8, 16)
    sc = plane_scene(world=World(image=img, rotation=rotation))
    prep = R.prepare(sc)
    h, w = img.shape[:2]
    lum = filtered_texels(img)[..., 1]  # the distribution follows the filtered map
    theta = np.pi * (np.arange(h) + 0.5) / h
    f = lum * np.sin(theta)[:, None]
    mean_f = f.mean()

    def to_uv(dirs):
        """The map coordinates of directions (Cycles' equirectangular layout, turned by −rotation)."""
        c, s = math.cos(rotation), math.sin(rotation)
        x = c * dirs[:, 0] + s * dirs[:, 1]
        y = -s * dirs[:, 0] + c * dirs[:, 1]
        z = np.clip(dirs[:, 2], -1, 1)
        return np.stack([np.mod(0.5 - np.arctan2(y, x) / (2 * np.pi), 1.0), np.arccos(z) / np.pi], 1)

    def pdf_uv(uu, vv):
        i = np.minimum((np.asarray(uu) * w).astype(int), w - 1)
        j = np.minimum((np.asarray(vv) * h).astype(int), h - 1)
        return f[j, i] / mean_f

    def pdf(dirs):
        """Solid-angle density: dω = 2π² sin θ du dv."""
        st = np.sqrt(np.maximum(1 - np.clip(dirs[:, 2], -1, 1) ** 2, 1e-300))
        uv = to_uv(dirs)
        return pdf_uv(uv[:, 0], uv[:, 1]) / (2 * np.pi ** 2 * st)

    rng = np.random.default_rng(11)
    n = 40000
    u = rng.random((n, 2))
    em = prep.emitters
    out = np.array([env_sample(em.world_img, em.world_dist, em.world_par, a, b) for a, b in u])
    dirs, p = out[:, :3], out[:, 3]
    np.testing.assert_allclose(np.linalg.norm(dirs, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(p, pdf(dirs), rtol=1e-8)  # the test filters by quadrature
    # the sampler's colour is the bilinear map at the sampled direction
    uv = to_uv(dirs[:500])
    np.testing.assert_allclose(out[:500, 4:7], bilinear(img.astype(float), uv[:, 0], uv[:, 1]), rtol=1e-5, atol=1e-6)
    # the kernel's lookup agrees with the sampler's pdf and colour
    for k in range(200):
        r, g, b, pl = env_lookup(em.world_img, em.world_dist, em.world_par, *dirs[k])
        assert pl == pytest.approx(p[k], rel=1e-9)
        assert (r, g, b) == pytest.approx(tuple(out[k, 4:7]), rel=1e-9, abs=1e-12)
    # goodness of fit in map coordinates, where the density is piecewise constant (in (cos θ, φ)
    # cells the 1/sin θ density at the poles defeats the quadrature of the expected counts)
    res = chi2_plane(to_uv(dirs), pdf_uv, alpha, f"world image rot {rotation}", nx=2 * w, ny=2 * h)
    assert res.passed, res.message


def test_world_pdf_integrates_to_one_and_covers_the_filtered_map():
    """Built from the filtered map, the sampling density is positive wherever the bilinear
    lookup is (a lone bright texel lights its neighbours' halves too) and ∫ pdf dω = 1."""
    from spectral_gi.core.lights.kernel import env_lookup

    img = np.zeros((4, 8, 3), np.float32)
    img[1, 2] = 5.0
    img[3, 7] = (1.0, 2.0, 0.5)  # at the bottom row (which also lights the top) and the seam
    em = R.prepare(plane_scene(world=World(image=img, rotation=0.4))).emitters
    n = 200
    u = (np.arange(2 * n) + 0.5) / (2 * n)
    v = (np.arange(n) + 0.5) / n
    uu, vv = np.meshgrid(u, v)
    th, ph = vv * np.pi, (0.5 - uu) * 2 * np.pi + 0.4
    d = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1).reshape(-1, 3)
    out = np.array([env_lookup(em.world_img, em.world_dist, em.world_par, *x) for x in d])
    dw = (2 * np.pi ** 2 * np.sin(th) / (2 * n * n)).reshape(-1)
    assert float((out[:, 3] * dw).sum()) == pytest.approx(1.0, rel=2e-3)
    lit = out[:, :3].max(axis=1) > 0
    assert lit.mean() > 0.15 and np.all(out[lit, 3] > 0.0)
    np.testing.assert_allclose(out[:, :3], bilinear(img.astype(float), uu, vv).reshape(-1, 3), rtol=1e-5, atol=1e-6)


@pytest.mark.statistical
def test_a_coarse_hdri_seen_directly_is_a_smooth_gradient():
    """A 4 × 2 map seen through an equirectangular camera looking along +X (up +Z) covers the
    image exactly as the map's own layout: each pixel is the mean of the bilinear map over its
    footprint, a gradient with no steps at the texel edges."""
    vals = np.array([[1.0, 3.0, 0.5, 2.0], [0.2, 1.5, 4.0, 0.8]])
    img = np.repeat(vals[..., None], 3, axis=2).astype(np.float32)
    w, h = 32, 16
    cam = Camera(look_at((0, 0, 0), (1, 0, 0)), width=w, height=h, projection=C.CAM_EQUIRECTANGULAR)
    sc = Scene(camera=cam, world=World(image=img),
               settings=RenderSettings(spp=64, max_depth=0, seed=2, filter=C.FILTER_BOX, filter_width=1.0))
    lum = develop(R.render(sc)[0].sums).luminance
    sub = 8
    o = (np.arange(sub) + 0.5) / sub
    uu, vv = np.meshgrid(((np.arange(w)[:, None] + o) / w).reshape(-1), ((np.arange(h)[:, None] + o) / h).reshape(-1))
    expected = C.K_M * bilinear(vals[..., None], uu, vv)[..., 0].reshape(h, sub, w, sub).mean(axis=(1, 3))
    np.testing.assert_allclose(lum, expected, rtol=0.03)
    # a gradient, not 8 blocks: many levels along a row, and steps far smaller than the texels'
    assert len(np.unique(np.round(lum[5] / C.K_M, 2))) > 16
    assert np.abs(np.diff(lum[5])).max() < 0.3 * C.K_M * np.abs(np.diff(vals[0])).max()


@pytest.mark.statistical
def test_hdri_light_sampling_agrees_with_bsdf_sampling():
    """The same plane under a contrasty map with next-event estimation (env_sample: the
    filtered distribution, MIS) and without (BSDF rays only, env_lookup): equal within noise."""
    img = hdr_map(4, 8, seed=5)
    img[1, 3] = 25.0
    sc = plane_scene((0.3, -0.2, 1.0), World(image=img, rotation=0.7), spp=512, res=4)
    a = develop(R.render(sc)[0].sums)
    sc.settings.next_event = False
    b = develop(R.render(sc)[0].sums)
    se = np.sqrt(a.variance.mean() / a.luminance.size + b.variance.mean() / b.luminance.size)
    assert abs(a.luminance.mean() - b.luminance.mean()) < 4.5 * se + 1e-3 * a.luminance.mean(), (
        a.luminance.mean(), b.luminance.mean(), se)


@pytest.mark.parametrize("mutate, match", [
    (lambda w: setattr(w, "image", np.zeros((4, 8, 3))), "world.image: expected dtype float32"),
    (lambda w: setattr(w, "image", np.zeros((4, 8, 4), np.float32)), r"world.image: expected shape"),
    (lambda w: w.image.__setitem__((1, 2, 0), np.nan), "world.image: contains NaN"),
    (lambda w: w.image.__setitem__((1, 2, 0), -1.0), "world.image: negative"),
    (lambda w: setattr(w, "rotation", float("nan")), "world.rotation"),
    (lambda w: setattr(w, "image_scale", -1.0), "world.image_scale")])
def test_world_image_fields_are_validated(mutate, match):
    sc = plane_scene(world=World(image=np.ones((4, 8, 3), np.float32)))
    validate(sc)
    mutate(sc.world)
    with pytest.raises(SceneError, match=match):
        validate(sc)


def test_world_image_survives_save_and_load(tmp_path):
    img = hdr_map(4, 8)
    sc = plane_scene(world=World(image=img, rotation=0.25, image_scale=3.0))
    back = load(save(sc, tmp_path / "w.json"))
    assert np.array_equal(back.world.image, img) and back.world.image.dtype == np.float32
    assert back.world.rotation == 0.25 and back.world.image_scale == 3.0
    sc.world = World()
    assert load(save(sc, tmp_path / "v.json")).world.image is None
