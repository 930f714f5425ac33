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
    """L_o = ρ/π ∫ L(ω) max(0, n·ω) dω, summed over the map's texels (with a bright block
    that only importance sampling finds efficiently); turning the map turns the result."""
    img = hdr_map()
    scale = 0.5
    sc = plane_scene(normal, World(image=img, rotation=rotation, image_scale=scale), spp=128)
    d = develop(R.render(sc)[0].sums)
    h, w = img.shape[:2]
    dirs, dw = texel_dirs(h, w, rotation)
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    cosw = (np.maximum(dirs @ n, 0.0) * dw).sum(axis=(1, 3))  # (h, w)
    expected = RHO / np.pi * C.K_M * scale * float((img[..., 1] * cosw).sum())
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
    lum = img[..., 1].astype(float)
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
    out = np.array([env_sample(prep.emitters.world_dist, prep.emitters.world_par, a, b)[:4] for a, b in u])
    dirs, p = out[:, :3], out[:, 3]
    np.testing.assert_allclose(np.linalg.norm(dirs, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(p, pdf(dirs), rtol=1e-9)
    # the kernel's lookup agrees with the sampler's pdf and texel
    for k in range(200):
        i, j, pl = env_lookup(prep.emitters.world_dist, prep.emitters.world_par, w, h, *dirs[k])
        assert pl == pytest.approx(p[k], rel=1e-9)
    # goodness of fit in map coordinates, where the density is piecewise constant (in (cos θ, φ)
    # cells the 1/sin θ density at the poles defeats the quadrature of the expected counts)
    res = chi2_plane(to_uv(dirs), pdf_uv, alpha, f"world image rot {rotation}", nx=2 * w, ny=2 * h)
    assert res.passed, res.message


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
