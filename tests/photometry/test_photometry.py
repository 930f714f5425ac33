"""core.photometry: compendium items 31–36 (radiometric and photometric units, K_m ∫ V R dλ)."""
import math
import warnings

import numpy as np
import pytest

from spectral_gi.core import constants
from spectral_gi.core.photometry import quantities as P
from spectral_gi.core.io import presets
from spectral_gi.core import colour as C

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # colour warns about the missing matplotlib
    import colour  # test dependency (colour-science 0.4.6): the oracle


@pytest.fixture
def colour_photometry(monkeypatch):
    """colour-science 0.4.6's photometry calls ``np.trapezoid``, numpy 2's new name of
    ``np.trapz``; numpy 1.26 (which Blender and bpy 5.0 pin) only has ``np.trapz``. The
    two are the same function, so give numpy 1.26 the new name for the oracle's sake."""
    if not hasattr(np, "trapezoid"):
        monkeypatch.setattr(np, "trapezoid", np.trapz, raising=False)
    return colour


def oracle(f, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return float(f(*args, **kwargs))


# --------------------------------------------------------------------------- K_m and V(λ)


def test_K_m_is_683_from_constants():
    assert P.K_M == constants.K_M == 683.0 == P.K_CD
    assert P.K_M_COMPENDIUM == 680.0  # the compendium's item 36 value, not used
    assert P.K_M_CIE2019 == 683.002


def test_V_is_the_cie_1931_ybar():
    wl, xyz = presets.cmfs("1931")
    np.testing.assert_array_equal(P.luminous_efficiency_function(wl), xyz[:, 1])
    assert P.luminous_efficiency_function(555.0) == 1.0  # the table's V(555 nm)
    assert P.luminous_efficiency_function(wl).max() == 1.0
    np.testing.assert_array_equal(P.luminous_efficiency_function([300.0, 359.9, 830.1, 1000.0]), 0.0)
    # colour-science's CIE 1924 photopic V(λ) is the same table.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from colour.colorimetry import SDS_LEFS_PHOTOPIC
    V = SDS_LEFS_PHOTOPIC["CIE 1924 Photopic Standard Observer"]
    np.testing.assert_allclose(P.luminous_efficiency_function(V.wavelengths), V.values, rtol=0, atol=1e-12)


def test_555nm_monochromatic_1W_is_683_lm():
    assert P.luminous_flux_monochromatic(555.0, 1.0) == pytest.approx(683.0, rel=1e-3)
    # The same as a spectrum: 1 W in a triangle 554–556 nm peaking at 555 nm (trapezoid: exact).
    wl = np.array([554.0, 555.0, 556.0])
    spd = np.array([0.0, 1.0, 0.0])  # W/nm
    assert P.radiant_quantity(wl, spd) == 1.0
    assert P.luminous_flux(wl, spd) == pytest.approx(683.0, rel=1e-3)
    assert P.luminous_flux(wl, spd) == 683.0 * P.luminous_efficiency_function(555.0)


def test_540THz_is_555_016nm_in_air_and_683_lm_per_W():
    assert P.LAMBDA_KCD_VACUUM_NM == pytest.approx(555.1712, abs=1e-4)  # the compendium's "555.17 nm"
    n_air = P.LAMBDA_KCD_VACUUM_NM / P.LAMBDA_KCD_AIR_NM
    assert n_air == pytest.approx(1.00028, abs=1e-5)  # standard air at 555 nm
    K = P.luminous_flux_monochromatic(P.LAMBDA_KCD_AIR_NM, 1.0)
    assert K == pytest.approx(683.0, rel=1e-3)
    assert abs(K - 683.0) < 1e-3  # 683.0006 with the 1931 ȳ interpolated by Sprague
    # Definition of the candela: 1/683 W/sr at 540 THz is 1 cd; 4π/683 W = 18.3988 mW in all directions.
    assert P.luminous_flux_monochromatic(P.LAMBDA_KCD_AIR_NM, 1.0 / 683.0) == pytest.approx(1.0, rel=1e-5)
    assert P.isotropic_intensity_to_flux(1.0 / 683.0) == pytest.approx(18.3988e-3, abs=1e-7)


# --------------------------------------------------------------------------- against colour-science


@pytest.mark.parametrize("name", ["D65", "A"])
def test_flux_and_efficacy_match_colour(colour_photometry, name):
    sd = colour_photometry.SDS_ILLUMINANTS[name]
    wl, spd = presets.illuminant(name)
    np.testing.assert_array_equal(wl, sd.wavelengths)
    assert P.luminous_flux(wl, spd) == pytest.approx(oracle(colour_photometry.luminous_flux, sd), rel=1e-6)
    assert P.luminous_efficacy(wl, spd) == pytest.approx(oracle(colour_photometry.luminous_efficacy, sd), rel=1e-6)
    assert P.luminous_efficiency(wl, spd) == pytest.approx(oracle(colour_photometry.luminous_efficiency, sd),
                                                           rel=1e-6)


def test_colour_docstring_example(colour_photometry):
    sd = colour_photometry.SDS_LIGHT_SOURCES["Neodimium Incandescent"]
    assert P.luminous_flux(sd.wavelengths, sd.values) == pytest.approx(23807.6555273, abs=1e-6)
    assert P.luminous_efficacy(sd.wavelengths, sd.values) == pytest.approx(136.2170803, abs=1e-6)
    assert P.luminous_efficiency(sd.wavelengths, sd.values) == pytest.approx(0.1994393, abs=1e-7)


def test_random_spectra_match_colour(colour_photometry):
    rng = np.random.default_rng(7)
    for wl in (np.arange(360.0, 831.0, 1.0), np.arange(380.0, 781.0, 10.0), np.arange(400.5, 700.0, 2.5)):
        for _ in range(5):
            v = rng.uniform(0.0, 2.0, wl.size)
            sd = colour_photometry.SpectralDistribution(v, wl)
            assert P.luminous_flux(wl, v) == pytest.approx(oracle(colour_photometry.luminous_flux, sd), rel=1e-6)
            assert P.luminous_flux(wl, v, K_m=100.0) == pytest.approx(
                oracle(colour_photometry.luminous_flux, sd, K_m=100.0), rel=1e-6)


def test_consistent_with_sd_to_XYZ():
    """K_m Σ ȳ Φ Δλ (sd_to_XYZ with k = K_m) and the trapezoid differ only by the end half-samples."""
    wl, xyz = presets.cmfs("1931")
    rng = np.random.default_rng(3)
    phi = rng.uniform(0.0, 1.0, (10, wl.size))
    Y = C.sd_to_XYZ(wl, phi, k=P.K_M)[:, 1]
    end = P.K_M * 0.5 * (xyz[0, 1] * phi[:, 0] + xyz[-1, 1] * phi[:, -1])
    np.testing.assert_allclose(P.luminance(wl, phi), Y - end, rtol=1e-12)


# --------------------------------------------------------------------------- radiometric_scale_for


@pytest.mark.parametrize("value", [1000.0, 1.0, 0.37, 5e6])
def test_radiometric_scale_for_returns_the_photometric_value(value):
    """pbrt-v4's idea: shape + one photometric number → absolute radiometric spectrum."""
    shapes = []
    for name in ("D65", "A", "FL2"):
        shapes.append(presets.illuminant(name))
    wl = np.arange(360.0, 831.0, 1.0)
    T = 3000.0  # a blackbody shape (relative), Planck's law
    c2 = 1.4387769e-2
    shapes.append((wl, 1.0 / ((wl * 1e-9) ** 5 * np.expm1(c2 / (wl * 1e-9 * T)))))
    shapes.append((np.array([554.0, 555.0, 556.0]), np.array([0.0, 3.0, 0.0])))
    for wl_s, shape in shapes:
        for f in (P.luminous_flux, P.luminous_intensity, P.illuminance, P.luminance):
            s = P.radiometric_scale_for(wl_s, shape, value)
            assert f(wl_s, s * shape) == pytest.approx(value, rel=1e-12)


def test_radiometric_scale_for_nd_and_no_visible_power():
    rng = np.random.default_rng(11)
    wl = np.arange(380.0, 781.0, 5.0)
    shape = rng.uniform(0.1, 1.0, (2, 3, 4, wl.size))
    values = rng.uniform(1.0, 1e4, (2, 3, 4))
    s = P.radiometric_scale_for(wl, shape, values)
    assert s.shape == (2, 3, 4)
    np.testing.assert_allclose(P.luminous_flux(wl, s[..., None] * shape), values, rtol=1e-12)
    # A purely infrared shape has no luminous flux: the factor is infinite, without raising.
    with np.errstate(all="raise"):
        assert np.isinf(P.radiometric_scale_for(np.array([900.0, 1000.0]), np.array([1.0, 1.0]), 100.0))


# --------------------------------------------------------------------------- item 31: units


def test_unit_table_of_item_31():
    assert set(P.UNITS) == {"energy", "flux", "irradiance", "exitance", "intensity", "radiance"}
    assert P.UNITS["energy"][3].startswith("talbot")
    assert P.UNITS["flux"][1:] == ("W", "luminous flux", "lumen (lm)")
    assert P.UNITS["irradiance"][3].startswith("lux")
    assert P.UNITS["intensity"][3].startswith("candela")
    assert P.UNITS["radiance"][1:3] == ("W/(m²·sr)", "luminance")
    assert P.UNITS["radiance"][3].startswith("nit")


def test_unit_conversions_round_trip():
    x = np.random.default_rng(5).uniform(0.0, 1e5, (2, 3, 4))
    for f, g in ((P.isotropic_flux_to_intensity, P.isotropic_intensity_to_flux),
                 (P.lambertian_exitance_to_radiance, P.lambertian_radiance_to_exitance),
                 (P.lux_to_footcandle, P.footcandle_to_lux),
                 (P.nit_to_footlambert, P.footlambert_to_nit)):
        np.testing.assert_allclose(g(f(x)), x, rtol=1e-14)
        np.testing.assert_allclose(f(g(x)), x, rtol=1e-14)
        assert f(x).shape == x.shape


def test_unit_conversion_values():
    assert P.isotropic_intensity_to_flux(1.0) == pytest.approx(4.0 * math.pi)  # Φ = 4π I
    assert P.isotropic_flux_to_intensity(1000.0) == pytest.approx(1000.0 / (4.0 * math.pi))
    assert P.lambertian_radiance_to_exitance(1.0) == pytest.approx(math.pi)  # M = π L
    assert P.footcandle_to_lux(1.0) == pytest.approx(10.763910417, rel=1e-10)
    assert P.footlambert_to_nit(1.0) == pytest.approx(3.4262591, rel=1e-7)
    # Inverse-square law: a sensor 2 m under a 1000 cd point source reads 250 lx; at 60° half that.
    assert P.point_source_illuminance(1000.0, 2.0) == pytest.approx(250.0)
    assert P.point_source_illuminance(1000.0, 2.0, math.cos(math.pi / 3)) == pytest.approx(125.0)


def test_isotropic_source_flux_from_spectral_intensity():
    """Luminous intensity of a spectral source times 4π equals its luminous flux."""
    wl, S = presets.illuminant("A")
    I_spd = S * 1e-3  # W/(sr nm)
    cd = P.luminous_intensity(wl, I_spd)
    lm = P.luminous_flux(wl, P.isotropic_intensity_to_flux(I_spd))
    assert lm == pytest.approx(P.isotropic_intensity_to_flux(cd), rel=1e-14)


def test_nd_and_nan_spectra():
    wl, S = presets.illuminant("D65")
    spd = np.broadcast_to(S, (2, 3, 4, S.size)).copy()
    out = P.luminance(wl, spd)
    assert out.shape == (2, 3, 4)
    np.testing.assert_allclose(out, P.luminance(wl, S), rtol=1e-14)
    spd[0, 0, 0, 10] = np.nan
    spd[1, 2, 3, 50] = np.inf
    with np.errstate(all="raise"), warnings.catch_warnings():
        warnings.simplefilter("error")
        out = P.illuminance(wl, spd)
        eff = P.luminous_efficacy(wl, spd)
        V = P.luminous_efficiency_function(np.array([np.nan, np.inf, 555.0]))
    assert np.isnan(out[0, 0, 0]) and np.isinf(out[1, 2, 3])
    assert np.isfinite(out).sum() == out.size - 2
    assert not np.isfinite(eff[0, 0, 0]) and not np.isfinite(eff[1, 2, 3])
    assert np.isnan(V[0]) and V[2] == 1.0
    with pytest.raises(ValueError):
        P.luminous_flux(wl, S[:-1])
