"""The daylight of Blender's Sky Texture (core/lights/sky.py): the spectral single-scattering sky,
its colour, the sun's transmittance and its direct-normal illuminance."""
import math

import numpy as np
import pytest

from spectral_gi.core import blender_sky
from spectral_gi.core.lights import sky

WL = sky.WAVELENGTHS


def at(wl):
    return int(np.argmin(np.abs(WL - wl)))


@pytest.mark.parametrize("kind", sky.SKY_TYPES)
def test_sky_image_is_finite_and_positive(kind):
    day = blender_sky(kind, math.radians(30.0), 0.4, width=32, height=16)
    img = day.image
    assert img.shape == (16, 32, 3) and img.dtype == np.float32
    assert np.all(np.isfinite(img)) and np.all(img >= 0.0)
    assert np.all(img[:8] @ np.array([0.2126, 0.7152, 0.0722]) > 0.0)  # every texel of the sky above the horizon
    assert np.all(np.isfinite(day.sun_irradiance)) and np.all(day.sun_irradiance > 0.0)
    assert day.sun_illuminance > 0.0


def test_rayleigh_coefficient_is_that_of_standard_air():
    # Bucholtz, Appl. Opt. 34, 2765 (1995), table 2: σ(550 nm) = 4.513e-27 cm² per molecule
    beta = sky.rayleigh_coefficient(np.array([550.0]))[0]
    assert beta / 2.547e25 * 1e4 == pytest.approx(4.513e-27, rel=0.01)
    # λ⁻⁴ with the small dispersion of (n² − 1)²: between λ⁻⁴ and λ⁻⁴·²
    b400, b800 = sky.rayleigh_coefficient(np.array([400.0, 800.0]))
    assert 4.0 < math.log(b400 / b800, 2.0) < 4.2


def test_zenith_is_bluer_than_the_horizon_at_high_sun():
    """Rayleigh scattering (λ⁻⁴) makes the zenith blue; the long, optically thick path to the
    horizon scatters every wavelength and extinguishes the blue, so the horizon is whiter."""
    atm = sky.atmosphere("single")
    L = sky.sky_radiance(atm, np.radians([90.0, 2.0]), np.radians([90.0]), math.radians(60.0), 100.0)
    blue_red = L[:, 0, at(450)] / L[:, 0, at(650)]
    assert blue_red[0] > 2.0  # zenith: ≈ (650/450)⁴ = 4.4 tempered by the sun's spectrum and aerosols
    assert blue_red[0] > 1.3 * blue_red[1]
    rgb = sky.spectrum_to_rgb(L)[:, 0]
    assert rgb[0, 2] > rgb[0, 0] and rgb[0, 2] / rgb[0, 0] > rgb[1, 2] / rgb[1, 0]


def test_without_air_the_sky_is_only_aerosol_and_not_blue():
    atm = sky.atmosphere("single", air_density=0.0)
    L = sky.sky_radiance(atm, np.radians([90.0]), np.radians([90.0]), math.radians(60.0), 100.0)
    # flat aerosol scattering: the sky's spectrum follows the sun's (its ratio 450/650 nm), not λ⁻⁴
    ratio = L[0, 0, at(450)] / L[0, 0, at(650)]
    sun = sky.sun_irradiance_top()
    assert ratio == pytest.approx(sun[at(450)] / sun[at(650)], rel=0.1)


@pytest.mark.parametrize("kind", sky.SKY_TYPES)
def test_sun_transmittance_falls_with_lower_elevation(kind):
    atm = sky.atmosphere(kind)
    t = np.array([sky.sun_transmittance(atm, math.radians(e), 100.0) for e in (90.0, 60.0, 30.0, 10.0, 3.0)])
    assert np.all((t > 0.0) & (t <= 1.0))
    assert np.all(np.diff(t, axis=0) < 0.0)  # at every wavelength
    assert np.all(t[:, at(450)] < t[:, at(700)])  # blue is lost first: the low sun reddens
    # thin air: Beer–Lambert with the air mass 1/sin e at high sun (plane-parallel within 1 %)
    assert math.log(t[1, at(700)]) / math.log(t[0, at(700)]) == pytest.approx(1.0 / math.sin(math.radians(60)),
                                                                              rel=0.01)


@pytest.mark.parametrize("elevation", [90.0, 60.0])
def test_direct_normal_illuminance_at_sea_level(elevation):
    """Clear-sky direct normal illuminance at high sun, E = 127.5 klx · exp(−0.21 m) with air mass m
    (IESNA Lighting Handbook, 9th ed., ch. 8, after IES RP-21: extraterrestrial 127.5 klx,
    extinction 0.21 for a clear sky): 103 klx at the zenith. The model's clean Nishita air (no
    water vapour, aerosol optical depth 0.03) is a little clearer: within 8 %."""
    atm = sky.atmosphere("single")
    e = math.radians(elevation)
    E = sky.sun_irradiance_top() * sky.sun_transmittance(atm, e, 0.0)
    lux = 683.0 * np.sum(sky._v_lambda(WL) * E) * (WL[1] - WL[0])
    ies = 127.5e3 * math.exp(-0.21 / math.sin(e))
    assert lux == pytest.approx(ies, rel=0.08)


def test_sun_above_the_atmosphere_is_the_solar_constant():
    # 5778 K blackbody of the nominal solar radius at 1 au: σT⁴(R/au)² = 1367 W/m² (the solar constant is
    # 1361 W/m², Kopp and Lean, Geophys. Res. Lett. 38, L01706 (2011))
    wl = np.arange(100.0, 20000.0, 1.0)
    assert np.sum(sky.sun_irradiance_top(wl)) == pytest.approx(1361.0, rel=0.01)


def test_sun_light_follows_blenders_rotation():
    """Sun rotation 0 puts the Sun towards +Y (Cycles' sky, checked against its renders); the light
    travels away from it, and the image is brightest at the Sun's azimuth."""
    e = math.radians(20.0)
    day = blender_sky("single", e, 0.0, width=64, height=32)
    assert day.sun_direction == pytest.approx((0.0, -math.cos(e), -math.sin(e)), abs=1e-9)
    day = blender_sky("single", e, math.pi / 2, width=64, height=32)  # towards +X: the image's centre
    assert day.sun_direction == pytest.approx((-math.cos(e), 0.0, -math.sin(e)), abs=1e-9)
    y = day.image[:16] @ np.array([0.2126, 0.7152, 0.0722])
    assert abs(np.unravel_index(np.argmax(y), y.shape)[1] + 0.5 - 32) <= 1.0


def test_no_sun_light_without_the_disc_or_below_the_horizon():
    assert blender_sky("single", 0.3, 0.0, sun_disc=False, width=16, height=8).sun_direction is None
    assert blender_sky("single", -0.05, 0.0, width=16, height=8).sun_direction is None
    assert blender_sky("single", -0.05, 0.0, width=16, height=8).sun_illuminance == 0.0


def test_sun_intensity_scales_the_sun_only():
    a = blender_sky("single", 0.5, 0.0, width=16, height=8)
    b = blender_sky("single", 0.5, 0.0, sun_intensity=2.0, width=16, height=8)
    assert b.sun_illuminance == pytest.approx(2.0 * a.sun_illuminance)
    np.testing.assert_array_equal(a.image, b.image)


def test_preetham_zenith_is_its_closed_form():
    """At the zenith the Perez functions divide out: Y is the zenith luminance of Preetham et al.
    (1999), Y_z = (4.0453 T − 4.9710) tan χ − 0.2155 T + 2.4192 kcd/m², χ = (4/9 − T/120)(π − 2θs),
    × Cycles' 0.06; the sky is brightest towards the Sun and finite, positive everywhere."""
    T, ts = 3.0, math.radians(40.0)
    s = (math.sin(ts), 0.0, math.cos(ts))
    img = sky.preetham_sky(s, T, width=64, height=64)
    assert np.all(np.isfinite(img)) and np.all(img >= 0.0)
    chi = (4 / 9 - T / 120) * (math.pi - 2 * ts)
    yz = ((4.0453 * T - 4.9710) * math.tan(chi) - 0.2155 * T + 2.4192) * 0.06
    zenith = sky.preetham_sky(s, T, width=4, height=1000)[0].mean(0) @ np.array([0.2126, 0.7152, 0.0722])
    assert zenith == pytest.approx(yz, rel=2e-3)
    y = img[:32] @ np.array([0.2126, 0.7152, 0.0722])
    row, col = np.unravel_index(np.argmax(y), y.shape)
    assert abs(col + 0.5 - 32) <= 1.0  # the Sun is along +X: the image's centre column
    with pytest.raises(ValueError, match="turbidity"):
        sky.preetham_sky(s, 0.5)


def test_sun_light_follows_cycles_disc_conventions():
    """Cycles' disc: centre radiance E·T/Ω, limb darkening 1 − 0.6(1 − cos ψ) (mean 0.8 over the disc);
    its single-scattering sun leaves ozone out, its multiple-scattering one does not."""
    e, alt = math.radians(35.0), 300.0
    for kind, ozone in (("single", False), ("multiple", True)):
        atm = sky.atmosphere(kind)
        day = blender_sky(kind, e, 0.0, altitude=alt, width=16, height=8)
        expected = sky.sun_irradiance_top() * atm.sun_scale * sky.sun_transmittance(atm, e, alt, ozone=ozone) * 0.8
        np.testing.assert_allclose(day.sun_irradiance, expected, rtol=1e-9)
    atm = sky.atmosphere("single")
    assert np.all(sky.sun_transmittance(atm, e, alt, ozone=True) < sky.sun_transmittance(atm, e, alt, ozone=False))


def test_bad_sky_type_is_a_clear_error():
    with pytest.raises(ValueError, match="sky type"):
        blender_sky("preetham")
