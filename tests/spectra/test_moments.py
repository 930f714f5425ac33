"""Fourier-basis spectra (compendium item 65, Peters et al. 2019)."""
import numpy as np
import pytest

from spectral_gi.core import constants as C
from spectral_gi.core.io import presets
from spectral_gi.core.spectra import moments as M
from spectral_gi.core.spectra import uplift


def _cornell():
    return presets.load_cornell_box_data()


FINE = np.linspace(C.LAMBDA_MIN, C.LAMBDA_MAX, 9401)  # 0.05 nm: quadrature of reconstructions


@pytest.mark.parametrize("n", [3, 4, 6, 8, 12, 16])
@pytest.mark.parametrize("name", ["white", "red", "green"])
def test_bounded_reconstruction_matches_moments_and_bounds(n, name):
    wl, v = _cornell()["reflectance"][name]
    c = M.moments_from_samples(wl, v, n)
    r = M.reconstruct_bounded(c, FINE)
    assert r.min() >= 0.0 and r.max() <= 1.0
    # the reconstruction's own moments equal the input moments (quadrature error ~1e-7)
    np.testing.assert_allclose(M.moments_from_samples(FINE, r, n), c, atol=1e-6)


@pytest.mark.parametrize("n", [3, 8, 16])
def test_unbounded_reconstruction_is_positive_and_matches_moments(n):
    wl, v = _cornell()["light"]
    c = M.moments_from_samples(wl, v, n)
    r = M.reconstruct_unbounded(c, FINE)
    assert r.min() > 0.0
    np.testing.assert_allclose(M.moments_from_samples(FINE, r, n), c, rtol=1e-6, atol=1e-6)


def test_fourier_series_has_exact_moments_but_can_leave_bounds():
    wl, v = [C.LAMBDA_MIN, 549.9, 550.0, C.LAMBDA_MAX], [0.0, 0.0, 0.95, 0.95]  # a sharp cut-on filter
    c = M.moments_from_samples(wl, v, 8)
    f = M.reconstruct_fourier(c, FINE)
    np.testing.assert_allclose(M.moments_from_samples(FINE, f, 8), c, atol=1e-6)
    assert f.min() < 0.0 and f.max() > 1.0  # the ringing the bounded MESE avoids
    b = M.reconstruct_bounded(c, FINE)
    assert b.min() >= 0.0 and b.max() <= 1.0


def test_more_coefficients_fit_better():
    wl, v = _cornell()["reflectance"]["green"]
    g = M.grid()
    ref = np.interp(g, wl, v)
    err = [np.sqrt(np.mean((M.reconstruct_bounded(M.moments_from_samples(wl, v, n), g) - ref)[40:341] ** 2))
           for n in (3, 6, 16)]
    assert err[0] > err[1] > err[2]
    assert err[2] < 0.01


def test_constant_spectra_are_exact():
    g = M.grid()
    for rho in (0.0, 0.25, 0.5, 1.0):
        c = M.moments_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX], [rho, rho], 8)
        np.testing.assert_allclose(M.reconstruct_bounded(c, g), rho, atol=1e-9)
    c = M.moments_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX], [3.0, 3.0], 8)
    np.testing.assert_allclose(M.reconstruct_unbounded(c, g), 3.0, rtol=1e-9)


def test_phase_maps_range_to_minus_pi_zero():
    assert M.phase(C.LAMBDA_MIN) == pytest.approx(-np.pi)
    assert M.phase(C.LAMBDA_MAX) == pytest.approx(0.0)


def test_check_coefficients():
    assert M.check_coefficients(np.array([0.5, 0.1, 0.0]), C.SPECTRUM_BOUNDED) is None
    assert "negative" in M.check_coefficients(np.array([-0.1, 0.0, 0.0]), C.SPECTRUM_BOUNDED)
    assert "no reflectance" in M.check_coefficients(np.array([0.5, 0.5, 0.5]), C.SPECTRUM_BOUNDED)
    assert "NaN" in M.check_coefficients(np.array([np.nan, 0.0, 0.0]), C.SPECTRUM_UNBOUNDED)
    assert "no non-negative" in M.check_coefficients(np.array([1.0, 2.0, 0.0]), C.SPECTRUM_UNBOUNDED)


def test_uplifted_reflectance_stays_bounded_and_keeps_white():
    g = M.grid()
    rng = np.random.default_rng(0)
    for rgb in rng.uniform(0, 1, (20, 3)):
        r = M.reconstruct_bounded(uplift.reflectance_from_rgb(rgb), g)
        assert r.min() >= 0.0 and r.max() <= 1.0
    white = M.reconstruct_bounded(uplift.reflectance_from_rgb([1, 1, 1]), g)
    assert np.all(np.abs(white[20:421] - 1.0) < 0.02)


def test_uplifted_colours_keep_their_hue():
    """Red, green and blue reflectances uplift to spectra whose Rec.709 colour is still that hue."""
    from spectral_gi.core.colour import XYZ_to_sRGB_linear
    wl, cmf = presets.cmfs()
    dwl, d65 = presets.illuminant("D65")
    g = M.grid()
    ill = np.interp(g, dwl, d65)
    xyz_bar = np.stack([np.interp(g, wl, cmf[:, k]) for k in range(3)], 1)
    norm = ill @ xyz_bar[:, 1]
    for k, rgb in enumerate(np.eye(3) * 0.8):
        r = M.reconstruct_bounded(uplift.reflectance_from_rgb(rgb), g)
        out = XYZ_to_sRGB_linear((r * ill) @ xyz_bar / norm)
        assert np.argmax(out) == k, out


def test_bad_samples_raise():
    with pytest.raises(ValueError):
        M.moments_from_samples([400, 400, 500], [0.1, 0.2, 0.3])
    with pytest.raises(ValueError):
        M.moments_from_samples([400, 500], [0.1, np.nan])
    with pytest.raises(ValueError):
        uplift.reflectance_from_samples([400, 500], [0.1, 1.5])
    with pytest.raises(ValueError):
        uplift.reflectance_from_rgb([0.1, np.inf, 0.2])


@pytest.mark.parametrize("m", [1, 2, 5, 12, 16])
def test_levinson_solves_the_hermitian_toeplitz_system(m):
    """solve_toeplitz_e0 (Levinson's recursion) against a dense LAPACK solve, for the moment
    matrices of random positive densities on the circle: complex ones (a density that is not
    even, as behind the bounded MESE's exponential moments) and real ones (Burg's estimate)."""
    rng = np.random.default_rng(m)
    phi = np.linspace(-np.pi, np.pi, 512, endpoint=False)
    for _ in range(20):
        k = np.arange(6)
        g = np.exp(rng.normal(size=6) @ np.cos(np.outer(k, phi)) + rng.normal(size=6) @ np.sin(np.outer(k, phi)))
        r = np.array([np.mean(g * np.exp(-1j * j * phi)) for j in range(m)])
        for col in (r, r.real):
            t = M._toeplitz_hermitian(col.astype(np.complex128))
            e0 = np.zeros(m)
            e0[0] = 1.0
            want = np.linalg.solve(t if np.iscomplexobj(col) else t.real, e0)
            got = M.solve_toeplitz_e0(col)
            assert got.dtype == want.dtype
            np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-12 * np.abs(want).max())
