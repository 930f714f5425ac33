"""Emitters given as a spectrum shape plus one number (lm, cd, cd/m², W, Blender W)."""
import math

import numpy as np
import pytest
from helpers import disk_over_plane_scene

from spectral_gi.core import constants as C
from spectral_gi.core.photometry import quantities as photometry
from spectral_gi.core.integrators import render as renderer
from spectral_gi.core.film import develop
from spectral_gi.core.spectra import library
from spectral_gi.core.photometry.units import area_light_luminance, emission_luminance, emitter_luminance


def test_units_are_consistent():
    a = 0.25
    assert emitter_luminance("cd/m2", 1000.0, a) == 1000.0
    assert emitter_luminance("lm", math.pi * 1000.0 * a, a) == pytest.approx(1000.0)
    assert emitter_luminance("lm", 2 * math.pi * 1000.0 * a, a, two_sided=True) == pytest.approx(1000.0)
    assert emitter_luminance("cd", 1000.0 * a, a) == pytest.approx(1000.0)
    # a 555 nm line: 1 W is 683 lm
    wl = np.array([554.0, 555.0, 556.0])
    line = np.array([0.0, 1.0, 0.0])
    assert emitter_luminance("W", 1.0, a, shape=(wl, line)) == pytest.approx(
        683.0 * photometry.luminous_efficiency_function(555.0) / (math.pi * a), rel=1e-6)
    # Blender's watts: area light convention
    assert emitter_luminance("blender_W", 10.0, a) == pytest.approx(area_light_luminance(10.0, a, [1, 1, 1]))
    assert emission_luminance([1, 1, 1], 2.0) == pytest.approx(2 * 683.0)


def test_watts_of_a_blackbody():
    wl = np.arange(360.0, 831.0)
    b = library.blackbody(2856.0, wl)
    eff = photometry.luminous_efficacy(wl, b)
    assert emitter_luminance("W", 100.0, 1.0, shape=(wl, b)) == pytest.approx(100.0 * eff / math.pi)


@pytest.mark.parametrize("unit,value,bad", [("lm", -1.0, "≥ 0"), ("lm", float("nan"), "finite"),
                                            ("furlongs", 1.0, "unknown emitter unit")])
def test_bad_emitter_values(unit, value, bad):
    with pytest.raises(ValueError, match=bad):
        emitter_luminance(unit, value, 1.0)
    with pytest.raises(ValueError, match="shape"):
        emitter_luminance("W", 1.0, 1.0)


@pytest.mark.statistical
def test_a_disk_light_of_given_lumens_gives_the_analytic_illuminance():
    """A one-sided disk of flux Φ: L = Φ/(π A); irradiance at the centre below E = π L R²/(h²+R²)."""
    radius, h, rho = 0.5, 1.0, 0.8
    flux = 2000.0
    lum = emitter_luminance("lm", flux, math.pi * radius ** 2)
    sc = disk_over_plane_scene(radius, h, rho, lum, spp=256)
    d = develop(renderer.render(sc)[0].sums)
    E = math.pi * lum * radius ** 2 / (h ** 2 + radius ** 2)
    assert d.luminance.mean() == pytest.approx(rho * E / math.pi, rel=0.02)
    assert C.K_M == 683.0
