"""Fresnel equations and refraction (compendium items 37-42) against closed forms,
an independent complex-amplitude oracle and published optical constants."""
import math

import numpy as np
import pytest

from spectral_gi.core.bsdfs import fresnel as F
from spectral_gi.core.spectra.library import metal_ior


def oracle_sp(cos_i, n_complex):
    """Amplitude reflection coefficients from complex arithmetic (Born & Wolf §1.5,
    §14.2): r_s = (cos i − N cos t)/(cos i + N cos t), r_p = (N cos i − cos t)/(N cos i + cos t)
    with N cos t = sqrt(N² − sin² i) on the decaying branch."""
    c = np.asarray(cos_i, dtype=np.complex128)
    n = np.asarray(n_complex, dtype=np.complex128)
    s2 = 1.0 - c * c
    nct = np.sqrt(n * n - s2)  # N cos t
    nct = np.where(nct.imag < 0, -nct, nct)
    rs = (c - nct) / (c + nct)
    rp = (n * n * c - nct) / (n * n * c + nct)
    return np.abs(rs) ** 2, np.abs(rp) ** 2


def test_glass_reflects_four_percent_at_normal_incidence():  # item 42
    r = F.fresnel_dielectric(1.0, 1.5)
    assert r == pytest.approx(0.04, abs=1e-12)
    assert F.normal_incidence_reflectance(1.5, 0.0) == pytest.approx(0.04, abs=1e-15)


@pytest.mark.parametrize("n", [1.33, 1.5, 2.4])
def test_p_reflectance_vanishes_at_brewster(n):  # item 42
    tb = math.atan(n)
    rs, rp = F.fresnel_dielectric_sp(math.cos(tb), n)
    assert rp < 1e-28
    assert rs > 0.01
    # from inside, Brewster's angle is atan(1/n)
    _, rp_in = F.fresnel_dielectric_sp(-math.cos(math.atan(1.0 / n)), n)
    assert rp_in < 1e-28


@pytest.mark.parametrize("n", [1.33, 1.5, 2.4])
def test_total_internal_reflection_beyond_critical_angle(n):  # items 39, 41
    tc = math.asin(1.0 / n)
    for t in np.linspace(tc + 1e-6, 0.5 * math.pi, 20):
        assert F.fresnel_dielectric(-math.cos(t), n) == 1.0
        assert F.refract_cos(-math.cos(t), n) == -1.0
    below = tc - 1e-4
    assert F.fresnel_dielectric(-math.cos(below), n) < 1.0
    assert F.refract_cos(-math.cos(below), n) > 0.0


@pytest.mark.parametrize("n", [1.33, 1.5, 2.4])
def test_snell_and_reciprocity_of_the_dielectric_fresnel(n):  # items 38-40
    for ti in np.linspace(0.0, 1.5, 16):
        ct = F.refract_cos(math.cos(ti), n)
        tt = math.acos(ct)
        assert math.sin(ti) == pytest.approx(n * math.sin(tt), rel=1e-12, abs=1e-15)
        # light crossing the other way sees the same reflectance (Stokes relations)
        assert F.fresnel_dielectric(math.cos(ti), n) == pytest.approx(F.fresnel_dielectric(-ct, n), abs=1e-12)


def test_dielectric_against_complex_oracle():
    for n in (1.1, 1.5, 2.4, 0.8):
        for c in np.linspace(0.0, 1.0, 41):
            rs, rp = F.fresnel_dielectric_sp(c, n)
            if (1.0 - c * c) / (n * n) >= 1.0:
                assert (rs, rp) == (1.0, 1.0)
                continue
            if abs((1.0 - c * c) / (n * n) - 1.0) < 1e-6:
                continue  # at the critical angle R is infinitely sensitive to rounding
            os_, op = oracle_sp(c, n)
            assert rs == pytest.approx(float(os_), abs=1e-12)
            assert rp == pytest.approx(float(op), abs=1e-12)


@pytest.mark.parametrize("eta,kappa", [(0.2, 3.0), (1.38, 1.914), (0.13, 4.103), (2.9, 3.1), (1.5, 0.0),
                                       (1.0, 0.5)])
def test_conductor_against_complex_oracle(eta, kappa):  # item 42
    cs = np.linspace(0.0, 1.0, 101)
    for c in cs:
        fs, fp = F.fresnel_conductor_sp(c, eta, kappa)
        os_, op = oracle_sp(c, complex(eta, kappa))
        assert fs == pytest.approx(float(os_), abs=1e-12)
        assert fp == pytest.approx(float(op), abs=1e-12)
        assert F.fresnel_conductor(c, eta, kappa) == pytest.approx(0.5 * float(os_ + op), abs=1e-12)


def test_compendium_fp_as_extracted_is_wrong():
    """Item 42's F_p, as the text extraction reads it (… − 2a cos θ tan θ …), disagrees
    with the complex oracle; with sin θ tan θ it agrees (the form fresnel.py uses)."""
    eta, kappa, t = 0.2, 3.0, 1.0
    c, s = math.cos(t), math.sin(t)
    t0 = eta * eta - kappa * kappa - s * s
    a2b2 = math.sqrt(t0 * t0 + 4 * eta * eta * kappa * kappa)
    a = math.sqrt(0.5 * (a2b2 + t0))
    fs = (a2b2 - 2 * a * c + c * c) / (a2b2 + 2 * a * c + c * c)
    good = fs * (a2b2 - 2 * a * s * math.tan(t) + (s * math.tan(t)) ** 2) / (
        a2b2 + 2 * a * s * math.tan(t) + (s * math.tan(t)) ** 2)
    bad = fs * (a2b2 - 2 * a * c * math.tan(t) + (s * math.tan(t)) ** 2) / (
        a2b2 + 2 * a * c * math.tan(t) + (s * math.tan(t)) ** 2)
    _, op = oracle_sp(c, complex(eta, kappa))
    assert good == pytest.approx(float(op), abs=1e-12)
    assert abs(bad - float(op)) > 1e-3


def test_conductor_with_zero_kappa_is_the_dielectric():
    for c in np.linspace(0.0, 1.0, 21):
        assert F.fresnel_conductor(c, 1.5, 0.0) == pytest.approx(F.fresnel_dielectric(c, 1.5), abs=1e-13)


def test_gold_at_normal_incidence():  # item 42
    """R(0) = ((η−1)² + κ²)/((η+1)² + κ²) from metal_ior('Au') (Johnson & Christy 1972).

    Published values to compare with: Johnson & Christy's own rows (450.9 nm: n 1.38,
    k 1.914 → R 0.408; 704.5 nm: n 0.13, k 4.103 → R 0.971) and an independent data set,
    Yakubovsky et al., Opt. Express 25, 25574 (2017), 117 nm e-beam film (450 nm:
    n 1.492, k 1.908 → R 0.394; 700 nm: n 0.119, k 4.200 → R 0.975). Gold reflects about
    0.39–0.41 of blue light at 450 nm and about 0.97 of red light at 700 nm (a little
    more than the 0.95 sometimes quoted).
    """
    wl = np.array([450.0, 450.9, 700.0, 704.5])
    eta, k = metal_ior("Au", wl)
    r = np.array([F.fresnel_conductor(1.0, e, kk) for e, kk in zip(eta, k)])
    formula = ((eta - 1) ** 2 + k ** 2) / ((eta + 1) ** 2 + k ** 2)
    np.testing.assert_allclose(r, formula, atol=1e-14)
    np.testing.assert_allclose([F.normal_incidence_reflectance(e, kk) for e, kk in zip(eta, k)], formula,
                               atol=1e-15)
    assert r[1] == pytest.approx(0.408, abs=0.001)  # J&C row at 450.9 nm
    assert r[3] == pytest.approx(0.971, abs=0.001)  # J&C row at 704.5 nm
    assert 0.37 <= r[0] <= 0.42  # published range at 450 nm
    assert 0.95 <= r[2] <= 0.98  # published range at 700 nm


def test_degenerate_fresnel_inputs_are_finite():
    vals = [F.fresnel_dielectric(c, e) for c in (0.0, -0.0, 1.0, -1.0, 1.0000001, float("nan"))
            for e in (1.0, 1.0 + 1e-16, 1.5, 0.0, -1.0, float("inf"), float("nan"))]
    vals += [F.fresnel_conductor(c, e, k) for c in (0.0, 1.0, -1.0) for e in (0.0, 1.0, 1.5)
             for k in (0.0, 1.0, float("nan"))]
    assert all(math.isfinite(v) and 0.0 <= v <= 1.0 for v in vals)
    assert F.fresnel_dielectric(0.0, 1.0) == 0.0  # no interface
    assert F.fresnel_dielectric(0.0, 1.5) == 1.0  # grazing limit


def _diffuse_reflectance_oracle(eta):
    """2 ∫₀¹ R(μ) μ dμ of the complex-amplitude oracle, split at the critical cosine."""
    from scipy.integrate import quad

    def f(mu):
        rs, rp = oracle_sp(mu, eta)
        return float(rs + rp) * mu  # 2 · (R_s + R_p)/2 · μ

    pts = [math.sqrt(1.0 - eta * eta)] if eta < 1.0 else None
    return quad(f, 0.0, 1.0, points=pts, epsabs=1e-14, epsrel=1e-13, limit=400)[0]


@pytest.mark.parametrize("eta", [1.0002, 1.0009, 1.001, 1.003, 1.05, 1.33, 1.5, 2.4, 4.0, 50.0])
def test_fresnel_diffuse_reflectance(eta):
    """F̄(η) = 2 ∫ F(μ) μ dμ (the plastic's normalisation) from the outside and the inside,
    against quadrature of the oracle; known values 0.0918 (η 1.5) and 0.5963 from inside glass."""
    tol = 1e-9 if eta >= 1.001 else 2e-6
    for e in (eta, 1.0 / eta):
        assert F.fresnel_diffuse_reflectance(e) == pytest.approx(_diffuse_reflectance_oracle(e), abs=tol)
    # the identity used for η < 1: 1 − F̄(1/n) = (1 − F̄(n)) / n²
    assert 1.0 - F.fresnel_diffuse_reflectance(1.0 / eta) == pytest.approx(
        (1.0 - F.fresnel_diffuse_reflectance(eta)) / eta ** 2, rel=1e-12)
    if eta == 1.5:
        assert F.fresnel_diffuse_reflectance(1.5) == pytest.approx(0.091778, abs=1e-6)
        assert F.fresnel_diffuse_reflectance(1.0 / 1.5) == pytest.approx(0.596346, abs=1e-6)


def test_fresnel_diffuse_reflectance_limits():
    assert F.fresnel_diffuse_reflectance(1.0) == 0.0
    for bad in (0.0, -1.0, math.nan, math.inf):
        assert F.fresnel_diffuse_reflectance(bad) == 0.0
    big = F.fresnel_diffuse_reflectance(1e12)
    assert 1.0 - 1e-5 < big < 1.0
    assert F.fresnel_diffuse_reflectance(1e-12) == pytest.approx(1.0, abs=1e-15)
    # continuous across the interpolated stretch near 1
    a, b = F.fresnel_diffuse_reflectance(1.001 - 1e-12), F.fresnel_diffuse_reflectance(1.001 + 1e-12)
    assert a == pytest.approx(b, abs=1e-10)


# -- Gulbrandsen 2014: artist-friendly conductor parameters ------------------------------------

def test_conductor_from_colour_round_trip():
    """R(0°) of the resulting (η, κ) is the reflectivity r, grazing incidence reflects
    everything, and colour_from_conductor gives (r, g) back."""
    from spectral_gi.core.bsdfs.artist import colour_from_conductor, conductor_from_colour
    rng = np.random.default_rng(4)
    r = np.concatenate([rng.random(400), [1e-6, 0.02, 0.5, 0.95, 0.999, 0.9999]])
    g = np.concatenate([rng.random(400), [0.0, 1.0, 0.5, 0.999, 0.0, 1.0]])
    eta, kappa = conductor_from_colour(r, g)
    assert eta.shape == r.shape and np.all(eta > 0) and np.all(kappa >= 0)
    for ri, e, k in zip(r, eta, kappa):
        assert F.fresnel_conductor(1.0, e, k) == pytest.approx(ri, abs=1e-6)
        assert F.normal_incidence_reflectance(e, k) == pytest.approx(ri, rel=1e-9)
        assert F.fresnel_conductor(0.0, e, k) == 1.0
        # ... approached continuously (1 − F ∝ cos θ near grazing, slope ~|N|)
        assert 1.0 - F.fresnel_conductor(1e-9, e, k) < 1e-5
        assert F.fresnel_conductor(1e-9, e, k) >= F.fresnel_conductor(1e-5, e, k) - 1e-12
        # against the complex-amplitude oracle at an oblique angle
        rs, rp = oracle_sp(0.3, complex(e, k))
        assert F.fresnel_conductor(0.3, e, k) == pytest.approx(0.5 * (rs + rp), rel=1e-9)
    r2, g2 = colour_from_conductor(eta, kappa)
    np.testing.assert_allclose(r2, r, rtol=1e-9, atol=1e-15)
    ok = r > 1e-3  # g is ill-conditioned where η_max − η_min → 0
    np.testing.assert_allclose(g2[ok], g[ok], atol=1e-7)


def test_conductor_from_colour_edge_tint_and_validation():
    """g = 0 is the κ = 0 end (η_max), g = 1 the η_min end; a larger edge tint reflects
    more near grazing at equal r; clipping and clear errors."""
    from spectral_gi.core.bsdfs.artist import conductor_from_colour
    r = 0.6
    e0, k0 = conductor_from_colour(r, 0.0)
    e1, k1 = conductor_from_colour(r, 1.0)
    sr = math.sqrt(r)
    assert float(e0) == pytest.approx((1 + sr) / (1 - sr), rel=1e-12) and float(k0) == pytest.approx(0.0, abs=1e-6)
    assert float(e1) == pytest.approx((1 - r) / (1 + r), rel=1e-12)
    assert float(k1) == pytest.approx(2 * sr / (1 + r), rel=1e-12)  # κ² = 4r/(1+r)² there
    c80 = math.cos(math.radians(80.0))
    assert F.fresnel_conductor(c80, float(e1), float(k1)) > F.fresnel_conductor(c80, float(e0), float(k0))
    # per-wavelength arrays broadcast; r is clipped to [0, 0.9999] and g to [0, 1]
    eta, kappa = conductor_from_colour([0.9, 1.5, -0.2], 0.5)
    assert eta.shape == (3,) and np.all(np.isfinite(eta)) and np.all(np.isfinite(kappa))
    assert F.normal_incidence_reflectance(eta[1], kappa[1]) == pytest.approx(0.9999, rel=1e-9)
    assert (eta[2], kappa[2]) == (1.0, 0.0)
    np.testing.assert_array_equal(conductor_from_colour(0.5, 2.0)[0], conductor_from_colour(0.5, 1.0)[0])
    with pytest.raises(ValueError, match="r .*NaN"):
        conductor_from_colour([0.5, math.nan], 0.5)
    with pytest.raises(ValueError, match="edge tint.*NaN"):
        conductor_from_colour(0.5, [math.nan])
