"""Smooth shading normals, AOVs (albedo, normal, depth), time limit, noise target, resume."""
import math
import time

import numpy as np
import pytest
from helpers import flat_emission, flat_reflectance, furnace_scene

from spectral_gi.core import constants as C
from spectral_gi.core.integrators import render as R
from spectral_gi.core.film import Film
from spectral_gi.core.scene import (
    Camera, Light, Material, Mesh, RenderSettings, Scene, SceneError, SpectrumTable, validate)
from spectral_gi.core.spectra import uplift

RHO = 0.8


def quad_scene(normals=None, sun_towards=(0.0, 0.0, 1.0), res=8, spp=16, reflectance=None, half=1.0,
               ortho=4.0, cam_z=3.0):
    """The quad [-1, 1]² at z = 0 (two triangles, optional vertex normals), a delta sun of
    1000 lux shining from ``sun_towards``, and an orthographic camera at ``cam_z`` looking
    along −Z (or +Z from below) whose view spans ``ortho`` m."""
    spectra = SpectrumTable.empty()
    r = spectra.add("refl", flat_reflectance(RHO) if reflectance is None else reflectance, C.SPECTRUM_BOUNDED)
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    pos = np.array([[-half, -half, 0], [half, -half, 0], [half, half, 0], [-half, half, 0]], np.float32)
    mesh = Mesh("quad", pos, np.array([[0, 1, 2], [0, 2, 3]], np.int32), np.zeros(2, np.int32),
                normals=None if normals is None else np.asarray(normals, np.float32))
    s = np.asarray(sun_towards, float)
    sun = Light("sun", C.LIGHT_SUN, (0, 0, 0), (0, 0, 0), (0, 0, 0), e, 0.0, illuminance=1000.0,
                direction=tuple(-s / np.linalg.norm(s)))
    m = np.eye(4)
    m[:3, 3] = (0, 0, cam_z)
    if cam_z < 0:  # look up: rotate 180° about x
        m[:3, :3] = np.diag([1.0, -1.0, -1.0])
    cam = Camera(m, width=res, height=res, projection=C.CAM_ORTHOGRAPHIC, ortho_scale=ortho)
    return Scene(meshes=[mesh], spectra=spectra, materials=[Material("quad", reflectance=r)], lights=[sun],
                 camera=cam,
                 settings=RenderSettings(spp=spp, max_depth=0, seed=9, filter=C.FILTER_BOX, filter_width=1.0))


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


@pytest.mark.statistical
def test_tilted_shading_normals_shade_like_a_tilted_plane():
    """Vertex normals tilted by θ turn a Lambert plane under a sun overhead from ρE/π to ρE cos θ/π."""
    tilt = _unit((0.5, 0.0, 1.0))
    flat = quad_scene(ortho=1.0)
    smooth = quad_scene(normals=[tilt] * 4, ortho=1.0)
    lf = R.render(flat)[0].develop().luminance
    ls = R.render(smooth)[0].develop().luminance
    # only the wavelength sampling varies (a few % per pixel at 16 spp)
    for lum, expected in ((lf, RHO * 1000.0 / np.pi), (ls, RHO * 1000.0 * tilt[2] / np.pi)):
        np.testing.assert_allclose(lum, expected, rtol=0.05)
        assert lum.mean() == pytest.approx(expected, rel=0.01)


@pytest.mark.statistical
def test_light_below_the_geometric_surface_never_leaks_through_shading_normals():
    """Normals tilted 60° towards +x; a sun 10° below the horizon on that side lies in the shading
    hemisphere but behind the geometry: it must light nothing."""
    tilt = _unit((math.sin(math.radians(60)), 0.0, math.cos(math.radians(60))))
    below = (math.cos(math.radians(-10)), 0.0, math.sin(math.radians(-10)))
    assert np.dot(tilt, below) > 0.5
    sc = quad_scene(normals=[tilt] * 4, sun_towards=below, ortho=1.0, spp=8)
    assert R.render(sc)[0].develop().luminance.max() == 0.0
    sc.settings.max_depth = 3  # nor through BSDF-sampled bounces
    assert R.render(sc)[0].develop().luminance.max() == 0.0


def test_normal_aov_interpolates_vertex_normals_and_faces_the_camera():
    """Normals tilted −α at x = −1 and +α at x = +1: at x the AOV shows the normalised
    linear blend; seen from below, the flipped normal."""
    a = math.radians(30)
    nl = (-math.sin(a), 0.0, math.cos(a))
    nr = (math.sin(a), 0.0, math.cos(a))
    res = 8
    sc = quad_scene(normals=[nl, nr, nr, nl], res=res, ortho=2.0, spp=32)
    d = R.render(sc)[0].develop()
    x = (np.arange(res) + 0.5) / res * 2 - 1  # pixel centres in x
    t = (x + 1) / 2
    blend = (1 - t)[:, None] * np.array(nl) + t[:, None] * np.array(nr)
    expected = blend / np.linalg.norm(blend, axis=1, keepdims=True)
    # averaged over each pixel's samples: close to the blend at the centre
    np.testing.assert_allclose(d.normal.mean(axis=0), expected, atol=0.01)
    below = quad_scene(normals=[nl, nr, nr, nl], res=res, ortho=2.0, spp=4, cam_z=-3.0)
    db = R.render(below)[0].develop()
    assert np.all(db.normal[..., 2] < -0.8)
    flat = quad_scene(res=4, ortho=1.0, spp=2, cam_z=-3.0)
    np.testing.assert_allclose(R.render(flat)[0].develop().normal, np.broadcast_to([0, 0, -1.0], (4, 4, 3)),
                               atol=1e-12)


def test_albedo_and_depth_aovs():
    rgb = np.array([0.7, 0.4, 0.2])
    sc = quad_scene(reflectance=uplift.reflectance_from_rgb(rgb), ortho=4.0, spp=64, res=8)
    d = R.render(sc)[0].develop()
    inside = np.zeros((8, 8), bool)
    inside[2:6, 2:6] = True  # the quad covers the middle half of the view
    # the albedo's colour: the reflectance under D65 → the RGB it was uplifted from
    np.testing.assert_allclose(d.albedo[inside], np.broadcast_to(rgb, (16, 3)), atol=0.02)
    assert np.all(d.albedo[~inside] == 0.0)
    # orthographic rays from z = 3: distance 3 on the quad, inf where they miss
    np.testing.assert_allclose(d.depth[inside], 3.0, rtol=1e-6)
    assert np.all(np.isinf(d.depth[~inside]))
    np.testing.assert_allclose(d.normal[inside], np.broadcast_to([0, 0, 1.0], (16, 3)), atol=1e-12)
    # a white Lambert has albedo 1 (D65 white is RGB 1)
    sc = quad_scene(reflectance=flat_reflectance(1.0), ortho=1.0, spp=16, res=4)
    np.testing.assert_allclose(R.render(sc)[0].develop().albedo, 1.0, atol=0.01)


def test_time_limit_stops_the_render():
    sc = furnace_scene(spp=1 << 22, width=16, height=16)
    sc.settings.time_limit = 1.0
    R.render(furnace_scene(spp=1))  # compiled already: keep compile time out of the limit
    t0 = time.perf_counter()
    film, stats = R.render(sc)
    wall = time.perf_counter() - t0
    assert stats.stop_reason == "time_limit" and not stats.cancelled
    assert 0 < stats.spp < sc.settings.spp and np.all(film.sums[..., 3] == stats.spp)
    assert 1.0 <= stats.seconds < 1.0 + 2 * R.PASS_SECONDS + 0.5 and wall < 10.0


@pytest.mark.statistical
def test_noise_target_stops_at_the_requested_error():
    """The noise target judges each pixel (95 % of them within the target), not the image's
    mean: in a furnace, whose exact radiance L_e / (1 − ρ) is the converged image, the pixels'
    measured RMS relative error is near the target when the render stops."""
    rho, le = 0.5, 100.0
    target = 0.05
    sc = furnace_scene(rho, le, spp=1 << 20, width=16, height=16)
    sc.settings.noise_target = target
    film, stats = R.render(sc)
    assert stats.stop_reason == "noise_target" and stats.spp < sc.settings.spp
    assert stats.spp >= R.noise_min_samples(target) == 40  # Cycles' automatic minimum: ⌈16 / 0.05^0.3⌉
    assert stats.relative_error <= target and stats.relative_error == R.relative_error(film)
    err = film.develop().luminance / (le / (1 - rho)) - 1
    rms = float(np.sqrt(np.mean(err ** 2)))
    assert 0.5 * target < rms < 1.1 * target, (rms, stats.spp)
    # the image mean is far more accurate than any pixel: judging it would have stopped long before
    assert R.noise_min_samples(0.01) == 64
    # fewer samples than the noise target needs: all samples are taken
    sc.settings.spp = 4
    assert R.render(sc)[1].stop_reason == "spp"


def test_a_strict_noise_target_does_not_stop_a_noisy_image_early():
    """The error of the image's mean is far below its pixels' (it falls with the pixel count:
    at 5 spp a large image's mean is known to 1 % while its pixels are noisy): a noise target of 0.01
    takes at least Cycles' 64 samples and then judges the pixels."""
    from spectral_gi.core.scene.builtin import cornell_box

    sc = cornell_box(16, 16, spp=5, max_depth=4, seed=1)
    film, _ = R.render(sc)
    d = film.develop()
    image_mean_error = np.sqrt(d.variance.sum()) / d.luminance.sum()
    assert image_mean_error < 0.25 * R.relative_error(film)
    sc.settings.spp, sc.settings.noise_target = 96, 0.01
    film, stats = R.render(sc)
    assert stats.stop_reason == "spp" and stats.spp == 96 and stats.relative_error > 0.01


def test_pixel_relative_errors_judge_dark_pixels_against_the_image():
    """Relative standard error per pixel from the Y and Y² sums; a pixel darker than
    NOISE_DARK × the image's mean is judged against that luminance; a black pixel is converged."""
    f = Film(3, 1)
    y = np.array([[4.0, 0.01, 0.0]])
    sd = np.array([[0.4, 0.01, 0.0]])  # per-sample standard deviation of Y
    n = 100
    f.sums[..., 1] = n * y
    f.sums[..., 3] = n
    f.sums[..., 4] = n * (y ** 2 + sd ** 2 * (n - 1) / n)
    err = R.pixel_relative_errors(f)
    image_mean = y.mean()
    expect = sd / np.sqrt(n) / np.maximum(y, R.NOISE_DARK * image_mean)
    np.testing.assert_allclose(err, expect, rtol=1e-9)
    assert err[0, 2] == 0.0
    f.sums[0, 0, 3] = 1
    assert np.isinf(R.pixel_relative_errors(f)).all()


@pytest.mark.parametrize("sampler", [C.SAMPLER_INDEPENDENT, C.SAMPLER_HALTON])
def test_resume_from_a_saved_film_is_bit_identical(sampler, tmp_path):
    from spectral_gi.core.scene.builtin import cornell_box
    sc = cornell_box(width=12, height=10, spp=8, max_depth=3, seed=3)
    sc.settings.sampler = sampler
    half, _ = R.render(sc, spectral_bins=3)
    path = Film.save(half, tmp_path / "ckpt.npz")
    loaded = Film.load(path)
    assert loaded.spp == 8 and np.array_equal(loaded.sums, half.sums) and np.array_equal(loaded.aov, half.aov)
    sc.settings.spp = 16
    resumed, stats = R.render(sc, resume=loaded, threads=2)
    assert loaded.spp == 8 and stats.spp == 16  # the checkpoint itself is left as it was
    full, _ = R.render(sc, spectral_bins=3, threads=1)
    for a in ("sums", "aov", "spectral"):
        assert np.array_equal(getattr(resumed, a), getattr(full, a)), a
    with pytest.raises(SceneError, match="resume"):
        sc.settings.spp = 4
        R.render(sc, resume=loaded)
    (tmp_path / "bad.npz").write_bytes(b"not a film")
    with pytest.raises(ValueError, match="cannot read"):
        Film.load(tmp_path / "bad.npz")


@pytest.mark.parametrize("field, value", [("time_limit", -1.0), ("noise_target", -0.1),
                                          ("time_limit", float("nan"))])
def test_stop_settings_are_validated(field, value):
    sc = furnace_scene()
    setattr(sc.settings, field, value)
    with pytest.raises(SceneError, match=f"settings.{field}"):
        validate(sc)
