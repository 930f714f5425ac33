"""Film development: luminance, Rec.709, xyY, Lab, Luv, variance, white balance."""
import numpy as np
import pytest

from spectral_gi.core import constants as C
from spectral_gi.core.film import develop

colour = pytest.importorskip("colour")


def _film(XYZ, n=4):
    sums = np.zeros(XYZ.shape[:2] + (5,))
    sums[..., :3] = XYZ * n
    sums[..., 3] = n
    sums[..., 4] = XYZ[..., 1] ** 2 * n
    return sums


def test_layers_agree_with_colour_science():
    rng = np.random.default_rng(2)
    XYZ = rng.uniform(0.01, 1.2, (6, 5, 3))
    d = develop(_film(XYZ), white_luminance=2 * C.K_M)
    np.testing.assert_allclose(d.luminance, C.K_M * XYZ[..., 1], rtol=1e-12)
    np.testing.assert_allclose(d.xyY[..., :2], colour.XYZ_to_xy(XYZ), atol=1e-12)
    np.testing.assert_allclose(d.xyY[..., 2], C.K_M * XYZ[..., 1], rtol=1e-12)
    wp = np.array([0.3127, 0.3290])
    np.testing.assert_allclose(d.Lab, colour.XYZ_to_Lab(XYZ / 2, wp), atol=1e-9)
    np.testing.assert_allclose(d.Luv, colour.XYZ_to_Luv(XYZ / 2, wp), atol=1e-9)
    rgb = colour.XYZ_to_RGB(XYZ, colour.RGB_COLOURSPACES["sRGB"], chromatic_adaptation_transform=None,
                            apply_cctf_encoding=False)
    np.testing.assert_allclose(d.rgb, rgb, atol=5e-4)  # colour uses the rounded 4-digit sRGB matrix
    from spectral_gi.core.colour import MATRIX_XYZ_TO_REC709
    np.testing.assert_allclose(d.rgb, XYZ @ MATRIX_XYZ_TO_REC709.T, rtol=1e-12)


def test_constant_pixels_have_zero_variance_and_empty_pixels_are_black():
    XYZ = np.full((2, 2, 3), 0.5)
    sums = _film(XYZ)
    sums[0, 0] = 0.0
    d = develop(sums)
    assert np.all(d.XYZ[0, 0] == 0) and np.isinf(d.variance[0, 0])
    np.testing.assert_allclose(d.variance[1, 1], 0.0, atol=1e-12)


def test_variance_of_the_mean_matches_the_sample_variance():
    rng = np.random.default_rng(3)
    y = rng.exponential(1.0, 1000)
    sums = np.zeros((1, 1, 5))
    sums[0, 0, 1] = y.sum()
    sums[0, 0, 3] = y.size
    sums[0, 0, 4] = np.sum(y * y)
    d = develop(sums)
    assert d.variance[0, 0] == pytest.approx(C.K_M ** 2 * np.var(y, ddof=1) / y.size, rel=1e-9)


def test_white_balance_neutralises_the_light():
    """A grey lit by illuminant A has A's chromaticity; balanced to A it becomes neutral RGB."""
    xy_a = np.array([0.44757, 0.40745])
    XYZ = colour.xyY_to_XYZ(np.array([xy_a[0], xy_a[1], 0.2]))[None, None, :]
    raw = develop(_film(XYZ)).rgb[0, 0]
    bal = develop(_film(XYZ), white_balance=xy_a).rgb[0, 0]
    assert raw[0] > 1.5 * raw[2]
    np.testing.assert_allclose(bal, bal.mean(), rtol=1e-6)
    # XYZ and Lab are never adapted
    np.testing.assert_allclose(develop(_film(XYZ), white_balance=xy_a).XYZ, XYZ)
