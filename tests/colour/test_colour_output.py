"""Colour output (Rec.709 / ACEScg / XYZ), the observer setting (CIE 1931 2° / 1964 10°)
and their EXR, scene-file, film-checkpoint and CLI plumbing. Oracle: colour-science 0.4.6."""
import subprocess
import sys

import numpy as np
import pytest
from helpers import flat_emission, look_at

from spectral_gi.core import constants as C
from spectral_gi.core.integrators import render as R
from spectral_gi.core.film import CHROMATICITIES, Film, develop
from spectral_gi.core.film import record as FR
from spectral_gi.core.io.exr import read_channels, write_render
from spectral_gi.core.scene import (
    Camera, RenderSettings, Scene, SceneError, SpectrumTable, World, load, save, validate)
from spectral_gi.core.scene.builtin import cornell_box
from spectral_gi.core.spectra import moments

colour = pytest.importorskip("colour")

D65 = np.array([0.3127, 0.3290])
XYZ_SAMPLES = np.array([[0.20654008, 0.12197225, 0.05136952],  # colour-science's docstring example
                        [0.3127 / 0.3290, 1.0, (1 - 0.3127 - 0.3290) / 0.3290],  # the D65 white
                        [0.1, 0.3, 0.6]])


def sums_of(XYZ, n=4.0):
    """Film sums whose developed XYZ is ``XYZ`` (Y² consistent with zero variance)."""
    XYZ = np.asarray(XYZ, float).reshape(1, -1, 3)
    s = np.zeros(XYZ.shape[:2] + (C.FILM_CHANNELS,))
    s[..., :3] = XYZ * n
    s[..., 3] = n
    s[..., 4] = XYZ[..., 1] ** 2 * n
    return s


def test_acescg_output_matches_colour_science():
    dev = develop(sums_of(XYZ_SAMPLES), colour_space="acescg")
    ref = colour.XYZ_to_RGB(XYZ_SAMPLES, colour.RGB_COLOURSPACES["ACEScg"], illuminant=D65,
                            chromatic_adaptation_transform="Bradford")
    np.testing.assert_allclose(dev.output[0], ref, rtol=0, atol=2e-6)
    # the D65 white is neutral in ACEScg once adapted to the ACES white
    np.testing.assert_allclose(dev.output[0, 1], [1.0, 1.0, 1.0], atol=1e-6)
    # Rec.709 stays what Blender displays, whatever the output space
    ref709 = colour.XYZ_to_RGB(XYZ_SAMPLES, colour.RGB_COLOURSPACES["ITU-R BT.709"], illuminant=None)
    np.testing.assert_allclose(dev.rgb[0], ref709, atol=2e-6)
    assert dev.colour_space == "acescg"


def test_xyz_output_is_the_films_xyz_and_rec709_is_the_default():
    s = sums_of(XYZ_SAMPLES)
    dev = develop(s, colour_space="xyz", white_balance=(0.4476, 0.4074))
    np.testing.assert_array_equal(dev.output, dev.XYZ)  # passthrough, never white-balanced
    np.testing.assert_allclose(dev.output[0], XYZ_SAMPLES, rtol=1e-15)
    default = develop(s)
    assert default.colour_space == "rec709"
    np.testing.assert_array_equal(default.output, default.rgb)
    with pytest.raises(ValueError, match="colour space"):
        develop(s, colour_space="p3")


@pytest.mark.parametrize("space", ["rec709", "acescg", "xyz"])
def test_exr_rgb_and_chromaticities_follow_the_colour_space(tmp_path, space):
    dev = develop(sums_of(XYZ_SAMPLES), colour_space=space)
    path = write_render(tmp_path / f"{space}.exr", dev)
    chans, header = read_channels(path)
    np.testing.assert_allclose(header["chromaticities"], CHROMATICITIES[space], atol=1e-7)
    rgb = np.stack([chans["R"], chans["G"], chans["B"]], -1)
    np.testing.assert_allclose(rgb, dev.output, rtol=1e-6, atol=1e-7)
    # the header's chromaticities give back the XYZ: the file is self-describing
    c = np.asarray(header["chromaticities"], float)
    M = colour.normalised_primary_matrix(c[:6].reshape(3, 2), c[6:8])
    xyz_back = rgb.astype(float) @ M.T
    if space == "acescg":  # AP1 data is ACES-white referred: adapt back to D65 to compare
        xyz_back = colour.chromatic_adaptation(xyz_back, colour.xy_to_XYZ(c[6:8]), colour.xy_to_XYZ(D65),
                                               method="Von Kries", transform="Bradford")
    np.testing.assert_allclose(xyz_back, dev.XYZ, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(np.stack([chans["XYZ.X"], chans["XYZ.Y"], chans["XYZ.Z"]], -1), dev.XYZ, rtol=1e-6)


def test_settings_are_validated_and_survive_save_and_load(tmp_path):
    scene = cornell_box(width=4, height=4, spp=1)
    scene.settings.colour_space = "acescg"
    scene.settings.observer = "1964"
    back = load(save(scene, tmp_path / "s.json"))
    assert (back.settings.colour_space, back.settings.observer) == ("acescg", "1964")
    scene.settings.colour_space = "AP0"
    with pytest.raises(SceneError, match="settings.colour_space"):
        validate(scene)
    scene.settings.colour_space = "xyz"
    scene.settings.observer = "1978"
    with pytest.raises(SceneError, match="settings.observer"):
        validate(scene)


def test_cmf_table_keeps_v_lambda_beside_the_10_degree_observer():
    c2 = FR.cmf_table("1931")
    c10 = FR.cmf_table("1964")
    assert c2.shape == (C.N_LAMBDA, 3) and c10.shape == (C.N_LAMBDA, 4)
    np.testing.assert_array_equal(c10[:, 3], c2[:, 1])
    cs10 = colour.MSDS_CMFS["CIE 1964 10 Degree Standard Observer"]
    g = moments.grid()
    np.testing.assert_allclose(c10[:, :3], cs10.copy().align(colour.SpectralShape(360, 830, 1)).values[
        np.searchsorted(np.arange(360, 831), g.astype(int))], atol=1e-6)


def world_scene(observer, spp=64, res=4, luminance=100.0):
    """The camera sees only a constant world of a flat spectrum: every sample is that radiance."""
    spectra = SpectrumTable.empty()
    w = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    cam = Camera(look_at((0, 0, 0), (0, 1, 0)), width=res, height=res)
    return Scene(spectra=spectra, camera=cam, world=World(background=w, luminance=luminance),
                 settings=RenderSettings(spp=spp, max_depth=0, seed=3, observer=observer))


def test_10_degree_xyz_of_a_flat_world_matches_colour_science():
    scene = world_scene("1964", spp=1024)
    film, _ = R.render(scene, threads=1)
    assert film.sums.shape[2] == 6 and film.observer == "1964"
    dev = film.develop()
    # expected: the renderer's spectrum (radiance W/(m² sr nm)) integrated with colour-science's CMFs
    shape = moments.tabulate(scene.spectra.coeffs, scene.spectra.kind)[0].astype(float)
    g = moments.grid()
    cmf10 = colour.MSDS_CMFS["CIE 1964 10 Degree Standard Observer"].copy().align(colour.SpectralShape(360, 830, 1))
    cmf2 = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(colour.SpectralShape(360, 830, 1))
    assert np.array_equal(cmf10.wavelengths, g)
    scale = 100.0 / (C.K_M * float(shape @ cmf2.values[:, 1]))  # luminance is set with V = 1931 ȳ
    expected = scale * shape @ cmf10.values
    mean = dev.XYZ.reshape(-1, 3).mean(axis=0)
    np.testing.assert_allclose(mean, expected, rtol=0.01)
    # and not the 2° values (the 10° functions integrate to about 9 % more)
    assert np.all(np.abs(mean / (scale * shape @ cmf2.values) - 1) > 0.05)
    # the luminance is photometric: the world's 100 cd/m²
    assert dev.luminance.mean() == pytest.approx(100.0, rel=0.01)
    assert dev.white_xy == pytest.approx((0.31382, 0.33100))


def test_luminance_pass_does_not_depend_on_the_observer():
    base = cornell_box(width=10, height=8, spp=4)
    devs = {}
    for obs in ("1931", "1964"):
        scene = cornell_box(width=10, height=8, spp=4)
        scene.settings.observer = obs
        film, stats = R.render(scene, threads=1)
        devs[obs] = film.develop()
        devs[obs + "err"] = stats.relative_error
    np.testing.assert_allclose(devs["1964"].luminance, devs["1931"].luminance, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(devs["1964"].variance, devs["1931"].variance, rtol=1e-9)
    assert devs["1964err"] == pytest.approx(devs["1931err"], rel=1e-9)
    # the colour does change: X differs between the observers
    assert not np.allclose(devs["1964"].XYZ[..., 0], devs["1931"].XYZ[..., 0], rtol=1e-3)
    assert base.settings.observer == "1931"


def test_10_degree_film_checkpoint_round_trip_and_resume(tmp_path):
    scene = cornell_box(width=6, height=5, spp=4)
    scene.settings.observer = "1964"
    full, _ = R.render(scene, threads=1)
    scene.settings.spp = 2
    half, _ = R.render(scene, threads=1)
    back = Film.load(half.save(tmp_path / "half.npz"))
    assert back.observer == "1964" and back.sums.shape == (5, 6, 6)
    scene.settings.spp = 4
    resumed, _ = R.render(scene, threads=1, resume=back)
    np.testing.assert_array_equal(resumed.sums, full.sums)
    scene.settings.observer = "1931"
    with pytest.raises(SceneError, match="observer"):
        R.render(scene, threads=1, resume=back)


@pytest.mark.slow
def test_cli_writes_acescg_with_its_chromaticities(tmp_path):
    r = subprocess.run([sys.executable, "-m", "spectral_gi.cli", "render", "--width", "6", "--height", "5",
                        "--spp", "1", "--colour-space", "acescg", "--observer", "1964", "--out", "a.exr"],
                       cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    chans, header = read_channels(tmp_path / "a.exr")
    np.testing.assert_allclose(header["chromaticities"], CHROMATICITIES["acescg"], atol=1e-7)
    assert header["spectralgi.observer"] == "CIE 1964 10 degree"


# --------------------------------------------------------------------------- Fourier order


def _reconstruction_rms(patch, orders):
    from spectral_gi.core.bsdfs.presets import reflectance_preset, tabulate_reflectance, wavelength_grid
    from spectral_gi.core.spectra import library

    g = wavelength_grid()
    truth = np.clip(library.colorchecker(patch, g), 0.0, 1.0)
    vis = (g >= 380) & (g <= 780)
    return np.array([np.sqrt(np.mean((tabulate_reflectance(reflectance_preset(patch, k)) - truth)[vis] ** 2))
                     for k in orders])


ORDERS = (C.N_COEFFS_MIN, 6, 9, 12, C.N_COEFFS_MAX)


@pytest.mark.parametrize("patch", ["dark skin", "foliage", "blue flower", "purple"])
def test_reconstruction_error_falls_with_the_fourier_order(patch):
    err = _reconstruction_rms(patch, ORDERS)
    assert np.all(np.diff(err) < 0), dict(zip(ORDERS, err))
    assert err[-1] < 0.5 * err[0]


def test_mean_reconstruction_error_of_the_colorchecker_falls_with_the_order():
    from spectral_gi.core.bsdfs.presets import reflectance_preset
    from spectral_gi.core.spectra import library

    err = np.array([_reconstruction_rms(p, ORDERS) for p in library.colorchecker_names()])
    assert np.all(err[:, -1] <= err[:, 0])  # every patch: order 16 no worse than 3
    mean = err.mean(axis=0)
    assert np.all(np.diff(mean) < 0), dict(zip(ORDERS, mean))
    assert reflectance_preset("blue", 7).shape == (7,)  # a table of that width


def test_fourier_order_range_is_validated():
    for k in (C.N_COEFFS_MIN, C.N_COEFFS_MAX):
        scene = cornell_box(width=4, height=4, spp=1, n_coeffs=k)
        assert scene.spectra.coeffs.shape[1] == k
        validate(scene)
    scene = cornell_box(width=4, height=4, spp=1, n_coeffs=C.N_COEFFS_MAX)
    scene.spectra.coeffs = np.concatenate([scene.spectra.coeffs, np.zeros((len(scene.spectra), 1))], axis=1)
    with pytest.raises(SceneError, match="number of coefficients"):
        validate(scene)
