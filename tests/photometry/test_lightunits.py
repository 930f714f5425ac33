"""Blender light units → contract photometry (core/photometry/units.py), by hand and by integration."""
import math

import numpy as np
import pytest

from spectral_gi.core.photometry import units as LU
from spectral_gi.core.photometry.units import emitter_luminance


def test_point_light_follows_cycles_intensity_at_683_lm_per_watt():
    # Cycles: a point light of P W has radiant intensity P/(4π) W/sr; 1 Blender W = 683 lm.
    assert LU.point_light_intensity(100.0) == pytest.approx(683.0 * 100.0 / (4.0 * math.pi), rel=1e-12)
    # the colour scales it by its Rec.709 luminance: pure green weighs 0.7152
    assert LU.point_light_intensity(100.0, (0, 1, 0)) == pytest.approx(683 * 100 / (4 * math.pi) * 0.7152, rel=1e-4)
    # same convention for spots (the cone does not concentrate the power)
    assert LU.light_photometric("SPOT", "blender_W", 50.0, spot_angle=0.3) == \
        pytest.approx(683.0 * 50.0 / (4.0 * math.pi))


def test_sun_strength_is_irradiance():
    assert LU.sun_illuminance(3.0) == pytest.approx(3.0 * 683.0)
    assert LU.light_photometric("SUN", "lux", 100000.0) == 100000.0


@pytest.mark.parametrize("angle_deg,blend", [(45.0, 0.0), (45.0, 0.15), (90.0, 1.0), (180.0, 0.5), (10.0, 0.7)])
def test_spot_solid_angle_integrates_the_falloff(angle_deg, blend):
    a = math.radians(angle_deg)
    mu = np.linspace(-1.0, 1.0, 400001)
    f = LU.spot_falloff(mu, a, blend)
    numeric = 2.0 * math.pi * float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(mu)))
    assert LU.spot_solid_angle(a, blend) == pytest.approx(numeric, rel=1e-4)


def test_spot_falloff_shape():
    a = math.radians(60.0)
    c = math.cos(a / 2)
    assert LU.spot_falloff(1.0, a, 0.5) == 1.0
    assert LU.spot_falloff(c - 1e-9, a, 0.5) == 0.0
    # halfway through the softened band smoothstep is 1/2
    assert LU.spot_falloff(c + 0.25 * (1 - c), a, 0.5) == pytest.approx(0.5)
    assert LU.spot_falloff(c + 1e-9, a, 0.0) == 1.0


def test_lumens_to_candela():
    assert LU.light_photometric("POINT", "lm", 1200.0) == pytest.approx(1200.0 / (4.0 * math.pi))
    a, b = math.radians(40.0), 0.2
    cd = LU.light_photometric("SPOT", "lm", 800.0, spot_angle=a, spot_blend=b)
    assert cd * LU.spot_solid_angle(a, b) == pytest.approx(800.0)
    # a hemisphere-wide hard spot: Φ = 2π I
    assert LU.light_photometric("SPOT", "lm", 2 * math.pi, spot_angle=math.pi, spot_blend=0.0) == pytest.approx(1.0)


def test_area_units_agree_with_core_units():
    assert LU.light_photometric("AREA", "lm", 1000.0, area_m2=0.5) == pytest.approx(
        emitter_luminance("lm", 1000.0, 0.5))
    assert LU.light_photometric("AREA", "blender_W", 10.0, area_m2=2.0) == pytest.approx(683 * 10 / (math.pi * 2))
    assert LU.light_photometric("AREA", "cd/m2", 123.0, area_m2=2.0) == 123.0


def test_bad_units_are_named():
    with pytest.raises(ValueError, match="sun light: unit 'lm'"):
        LU.light_photometric("SUN", "lm", 1.0)
    with pytest.raises(ValueError, match="unknown light type"):
        LU.light_photometric("LASER", "lm", 1.0)
    with pytest.raises(ValueError, match="finite"):
        LU.light_photometric("POINT", "lm", float("nan"))
    with pytest.raises(ValueError, match="blackbody temperature"):
        LU.light_emission_coeffs("blackbody", temperature=20.0)


def test_spectrum_sources():
    from spectral_gi.core.spectra.fit import emission_XYZ

    assert "D65" in LU.light_spectrum_names("illuminant") and "LED-B3" not in LU.light_spectrum_names("illuminant")
    assert "LED-B3" in LU.light_spectrum_names("led")
    # a 3000 K blackbody: CIE 1931 chromaticity (0.4369, 0.4041) (Planckian locus)
    XYZ = emission_XYZ(LU.light_emission_coeffs("blackbody", temperature=3000.0))
    assert XYZ[0] / XYZ.sum() == pytest.approx(0.4369, abs=2e-3)
    assert XYZ[1] / XYZ.sum() == pytest.approx(0.4041, abs=2e-3)
    XYZ = emission_XYZ(LU.light_emission_coeffs("illuminant", name="D65"))
    assert XYZ[0] / XYZ.sum() == pytest.approx(0.3127, abs=2e-3)


def test_scene_white_is_the_brightest_emitter():
    from spectral_gi.core.scene.builtin import cornell_box

    scene = cornell_box(8, 8)
    x, y = LU.scene_white_xy(scene)
    # the Cornell light is warm (its published spectrum), well away from D65
    assert 0.40 < x < 0.48 and 0.38 < y < 0.45
    for m in scene.materials:
        m.emission = -1
    assert LU.scene_white_xy(scene) is None
