"""Comparison maths (core/compare.py) against colour-science and closed forms."""
import numpy as np
import pytest

from spectral_gi.core.colour import compare as CM


def test_identical_images():
    rng = np.random.default_rng(1)
    a = rng.random((6, 7, 3))
    r, de = CM.compare_images(a, a)
    assert r["luminance_ratio"] == 1.0 and r["relative_rmse"] == 0.0
    assert np.all(de == 0.0) and r["delta_e00_p95"] == 0.0


def test_scaled_image_ratio_and_rmse():
    rng = np.random.default_rng(2)
    b = rng.random((5, 9, 3)) + 0.1
    r, _ = CM.compare_images(1.1 * b, b)
    y = 683.0 * (b @ np.array([0.2126729, 0.7151522, 0.0721750]))  # Rec.709 Y row (to 1e-6)
    assert r["luminance_ratio"] == pytest.approx(1.1, rel=1e-12)
    assert r["relative_rmse"] == pytest.approx(0.1 * np.sqrt(np.mean(y ** 2)) / y.mean(), rel=1e-5)
    assert r["mean_luminance_reference"] == pytest.approx(y.mean(), rel=1e-5)


def test_delta_e00_against_colour_science():
    colour = pytest.importorskip("colour")
    rng = np.random.default_rng(3)
    a = rng.random((4, 4, 3))
    b = np.clip(a + rng.normal(0, 0.05, a.shape), 0, None)
    white = 300.0
    wxy = np.array([0.3127, 0.3290])

    def lab(rgb):
        XYZ = colour.RGB_to_XYZ(rgb, colour.RGB_COLOURSPACES["ITU-R BT.709"], apply_cctf_decoding=False)
        return colour.XYZ_to_Lab(XYZ * 683.0 / white, wxy)

    ref = colour.delta_E(lab(a), lab(b), method="CIE 2000")
    r, de = CM.compare_images(a, b, white_luminance=white)
    np.testing.assert_allclose(de, ref, rtol=1e-5, atol=1e-6)
    assert r["delta_e00_p95"] == pytest.approx(np.percentile(ref, 95), rel=1e-5)


def test_false_colour_and_legend():
    m = CM.delta_e_image(np.array([[0.0, 5.0, 10.0, 50.0]] * 3))
    assert m.shape[1] == 4 and m.shape[0] > 3
    assert np.all(m[0, 2] == m[0, 3])  # clamped at vmax
    assert m[0, 0, 2] > m[0, 0, 0] and m[0, 2, 0] > m[0, 2, 2]  # blue at 0, red at vmax
    leg = CM.legend_bar(320)
    assert leg.max() == 1.0  # white ticks / numbers are drawn
    with pytest.raises(ValueError, match="differ in size"):
        CM.compare_images(np.zeros((2, 2, 3)), np.zeros((2, 3, 3)))
    sbs = CM.side_by_side(np.ones((2, 2, 3)), np.zeros((2, 2, 3)), gap=1)
    assert sbs.shape == (2, 5, 3) and sbs[:, :2].min() == 1.0 and sbs[:, 2:].max() == 0.0
