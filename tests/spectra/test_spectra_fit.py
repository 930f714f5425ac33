"""Spectra from colours (compendium item 65) and in-kernel evaluation of the moments."""
import numpy as np
import pytest

from spectral_gi.core import constants as C
from spectral_gi.core.io import presets
from spectral_gi.core.colour import MATRIX_REC709_TO_XYZ, MATRIX_XYZ_TO_REC709
from spectral_gi.core.spectra import kernel as K
from spectral_gi.core.spectra import fit
from spectral_gi.core.spectra import moments as M
from spectral_gi.core.spectra import uplift

colour = pytest.importorskip("colour")


def _lab(XYZ):
    white = colour.XYZ_to_xy(MATRIX_REC709_TO_XYZ.sum(axis=1))
    return colour.XYZ_to_Lab(XYZ, white)


def _round_trip_dE(rgb):
    c = uplift.reflectance_from_rgb(rgb)
    r = M.reconstruct_bounded(c, M.grid())
    assert r.min() >= 0.0 and r.max() <= 1.0
    back = fit.reflectance_XYZ(c)
    return float(colour.delta_E(_lab(MATRIX_REC709_TO_XYZ @ np.asarray(rgb, float)), _lab(back),
                                method="CIE 2000"))


def test_uplift_round_trip_under_d65_random_colours():
    rng = np.random.default_rng(4)
    colours = np.concatenate([rng.uniform(0, 1, (40, 3)), np.eye(3), 1 - np.eye(3), [[1, 1, 1], [0.02, 0.02, 0.02]]])
    d = [_round_trip_dE(c) for c in colours]
    assert max(d) < 0.01, max(d)


def test_uplift_round_trip_colorchecker_srgb():
    cc = colour.CCS_COLOURCHECKERS["ColorChecker24 - After November 2014"]
    xyz = colour.xyY_to_XYZ(np.array(list(cc.data.values())))
    rgb = np.clip((MATRIX_XYZ_TO_REC709 @ colour.chromatic_adaptation(
        xyz, colour.xy_to_XYZ(cc.illuminant), colour.xy_to_XYZ([0.3127, 0.3290])).T).T, 0, 1)
    d = [_round_trip_dE(c) for c in rgb]
    assert max(d) < 0.01, max(d)


def test_emission_shape_keeps_chromaticity():
    for rgb in ([1, 1, 1], [1.0, 0.5, 0.1], [0.1, 0.3, 1.0]):
        c = uplift.emission_from_rgb(rgb)
        xyz = fit.emission_XYZ(c)
        want = MATRIX_REC709_TO_XYZ @ np.asarray(rgb, float)
        np.testing.assert_allclose(xyz / xyz.sum(), want / want.sum(), atol=1e-6)


def test_glassner_item_65_reproduces_XYZ_exactly():
    g, cmf = presets.cmfs()
    for XYZ in ([20.0, 21.0, 22.0], [41.2, 21.3, 1.9], [5.0, 30.0, 4.0]):
        wl, spec = fit.glassner1989(XYZ)
        cm = np.stack([np.interp(wl, g, cmf[:, k]) for k in range(3)], axis=1)
        np.testing.assert_allclose(spec @ cm, XYZ, rtol=1e-10)
    # the three-term Fourier spectrum of a saturated green goes negative: not a reflectance
    wl, spec = fit.glassner1989([15.0, 40.0, 5.0])
    assert spec.min() < 0.0


def test_glassner_dirac_basis():
    lw, w = fit.glassner1989([30.0, 30.0, 30.0], basis="dirac")
    g, cmf = presets.cmfs()
    cm = np.stack([np.interp(lw, g, cmf[:, k]) for k in range(3)])
    np.testing.assert_allclose(cm @ w, [30.0, 30.0, 30.0], rtol=1e-10)


def test_glassner_basis_functions():
    f = fit.glassner1989_basis(np.array([380.0, 480.0, 580.0, 780.0, 800.0]))
    np.testing.assert_allclose(f[:, 0], [1, 1, 1, 1, 0])
    np.testing.assert_allclose(f[:, 1], [0.5, 1.0, 0.5, 0.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(f[:, 2], [1.0, 0.5, 0.0, 1.0, 0.0], atol=1e-12)


def test_glassner_as_a_reflectance_method_is_approximate():
    c = fit.reflectance_from_XYZ(MATRIX_REC709_TO_XYZ @ [0.6, 0.3, 0.2], method="Glassner 1989")
    assert M.check_coefficients(c, C.SPECTRUM_BOUNDED) is None
    with pytest.raises(ValueError):
        fit.reflectance_from_XYZ([0.2, 0.2, 0.2], method="nonsense")


def test_kernel_evaluation_matches_numpy():
    d = presets.load_cornell_box_data()
    cs = [M.moments_from_samples(*d["reflectance"][n], 12) for n in ("white", "red", "green")]
    cs += [M.moments_from_samples(*d["light"], 12), np.zeros(12), np.r_[1.0, np.zeros(11)]]
    kinds = np.array([0, 0, 0, 1, 0, 0], np.int32)
    prep = M.prepare_table(np.array(cs), kinds)
    lams = np.linspace(350.0, 840.0, 2001)  # beyond both ends too
    for r in range(len(cs)):
        ref = M.reconstruct(cs[r], kinds[r], lams)
        got = K.eval_spectrum_batch(prep, kinds, 12, M.warp_table(), np.full(lams.size, r, np.int64), lams)
        np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-12)


def test_warp_is_monotonic_and_spans_the_phase_range():
    w = M.warp_table()
    assert w[0] == pytest.approx(-np.pi) and w[-1] == pytest.approx(0.0)
    assert np.all(np.diff(w) > 0)
    # more phase per nm at 555 nm than at 380 nm or 800 nm
    dw = np.diff(w)
    assert dw[195] > 3 * dw[20] and dw[195] > 3 * dw[440]


def test_texture_uplift_is_linear_bounded_and_nan_safe():
    rng = np.random.default_rng(8)
    tex = rng.uniform(-0.2, 1.2, (4, 5, 3))
    tex[0, 0] = [np.nan, np.inf, -np.inf]
    c = uplift.reflectance_from_rgb_array(tex)
    assert c.shape == (4, 5, C.N_COEFFS_DEFAULT)
    for row in c.reshape(-1, C.N_COEFFS_DEFAULT):
        assert M.check_coefficients(row, C.SPECTRUM_BOUNDED) is None
    np.testing.assert_allclose(c[1, 2], uplift.reflectance_from_rgb(np.clip(tex[1, 2], 0, 1), exact=False))
    np.testing.assert_allclose(c[0, 0], uplift.reflectance_from_rgb([0.0, 1.0, 0.0], exact=False))
