"""Radiometric and photometric units and conversions (compendium items 31–36).

Compendium item 31's table, one row per quantity (radiometric → photometric):

============================  =================  =========================================
radiometric quantity          unit               photometric quantity, unit
============================  =================  =========================================
radiant energy Q              J                  luminous energy, talbot (lm·s)
radiant flux (power) Φ        W = J/s            luminous flux, lumen (lm)
irradiance E                  W/m²               illuminance, lux (lx = lm/m²)
radiant exitance M (radiosity) W/m²              luminous exitance, lm/m²
radiant intensity I           W/sr               luminous intensity, candela (cd = lm/sr)
radiance L                    W/(m²·sr)          luminance, nit (cd/m² = lm/(m²·sr))
============================  =================  =========================================

Compendium item 36: a photometric quantity is P = K_m ∫ V(λ) R(λ) dλ, where R(λ) is the
spectral concentration of the corresponding radiometric quantity (per nm here).

K_m. We use K_m = 683 lm/W (``constants.K_M``): the SI definition of the candela fixes
the luminous efficacy of monochromatic radiation of frequency 540 THz at exactly
683 lm/W (BIPM, SI Brochure, 9th ed., 2019). The compendium (item 36) writes 680 lm/W,
an older rounded value. With the CIE's 2019 tabulation of V(λ), K_m = 683.002 lm/W at
its 555 nm peak, so that K_m·V(555.016 nm) = 683 exactly. With the 1931 ȳ used here,
V(555.016 nm) = 1.0000009 (Sprague), so 540 THz radiation gets 683.0006 lm/W. These
0.0003 % differences are below every tolerance of the renderer, and 683 is what
colour-science and Blender's glTF exporter use.

V(λ). The photopic luminous efficiency function is taken as the CIE 1931 ȳ(λ) from
``presets/cie/cie1931_2deg.csv`` (360–830 nm, 1 nm; ȳ = V by definition of the 1931
observer; colour-science's "CIE 1924 Photopic Standard Observer" table equals it to
5e-13). The CIE 2019 2° V(λ) (ISO/CIE 23539:2023) is the same function, retabulated;
the two are nearly identical. Between the 1 nm
samples V is interpolated with Sprague's formula (as colour-science does when it
resamples V), so it is exact at whole nanometres; outside 360–830 nm V = 0.

Integrals of spectra over wavelength use the trapezoidal rule on the spectrum's own
samples, as colour-science's ``luminous_flux`` does, so the results agree with it.

540 THz. c / 540 THz = 555.1712 nm in vacuum (the compendium's quote "approximately
555.17 nm" is this vacuum wavelength); the CIE tables are tabulated in standard air
(n ≈ 1.00028), where it is 555.016 nm (``LAMBDA_KCD_AIR_NM``).

Every function is vectorised: spectra have shape ``(..., N)`` over the wavelengths ``(N,)``.
"""
from __future__ import annotations

import math

import numpy as np

from ..colour._common import as_float
from ..colour.tristimulus import _check_xy, cmfs, interpolate_sprague
from ..constants import K_M

# --------------------------------------------------------------------------- constants

K_CD = 683.0
"""Luminous efficacy of 540 THz radiation, lm/W (exact, SI definition of the candela)."""
K_M_CIE2019 = 683.002
"""CIE 2019: maximum luminous efficacy at the peak of V(λ) (555 nm), lm/W."""
K_M_COMPENDIUM = 680.0
"""The compendium's (item 36) rounded value, lm/W; not used."""
F_KCD_HZ = 540e12
"""Frequency of the candela definition, Hz."""
SPEED_OF_LIGHT = 299_792_458.0
"""m/s (exact)."""
LAMBDA_KCD_VACUUM_NM = SPEED_OF_LIGHT / F_KCD_HZ * 1e9
"""c / 540 THz ≈ 555.1712 nm (vacuum)."""
LAMBDA_KCD_AIR_NM = 555.016
"""540 THz in standard air (CIE convention), nm."""

LUX_PER_FOOTCANDLE = 1.0 / 0.3048**2
"""1 fc = 1 lm/ft² = 10.7639… lx (the international foot is 0.3048 m exactly)."""
NIT_PER_FOOTLAMBERT = 1.0 / (math.pi * 0.3048**2)
"""1 fL = (1/π) cd/ft² = 3.42626… cd/m²."""

UNITS = {
    "energy": ("Q", "J", "luminous energy", "talbot (lm·s)"),
    "flux": ("Φ", "W", "luminous flux", "lumen (lm)"),
    "irradiance": ("E", "W/m²", "illuminance", "lux (lx = lm/m²)"),
    "exitance": ("M", "W/m²", "luminous exitance", "lm/m²"),
    "intensity": ("I", "W/sr", "luminous intensity", "candela (cd = lm/sr)"),
    "radiance": ("L", "W/(m²·sr)", "luminance", "nit (cd/m²)"),
}
"""Compendium item 31: quantity → (symbol, radiometric unit, photometric quantity, photometric unit)."""

# --------------------------------------------------------------------------- V(λ)


def luminous_efficiency_function(wavelengths):
    """Photopic V(λ) at ``wavelengths`` (nm, any shape): CIE 1931 ȳ, Sprague-interpolated, 0 outside 360–830 nm.

    Domain: wavelengths in nm (air). Range: [0, 1], V(555 nm) = 1.
    """
    wl_c, xyz_bar = cmfs("1931")
    w = as_float(wavelengths)
    inside = (w >= wl_c[0]) & (w <= wl_c[-1])
    with np.errstate(all="ignore"):
        v = interpolate_sprague(wl_c, xyz_bar[:, 1], np.where(inside, w, wl_c[0]).ravel()).reshape(w.shape)
    return np.where(inside, v, np.where(np.isnan(w), np.nan, 0.0))


def _trapezoid(wl, values):
    with np.errstate(all="ignore"):
        d = np.diff(wl)
        return np.sum((values[..., 1:] + values[..., :-1]) * d, axis=-1) / 2.0


def radiant_quantity(wavelengths, spd):
    """∫ R(λ) dλ by the trapezoidal rule: e.g. W from W/nm. Domain ``(..., N)``; Range ``(...)``."""
    wl, spd = _check_xy(wavelengths, spd)
    return _trapezoid(wl, spd)


def _photometric(wavelengths, spd, K_m):
    wl, spd = _check_xy(wavelengths, spd)
    with np.errstate(all="ignore"):
        return as_float(K_m) * _trapezoid(wl, luminous_efficiency_function(wl) * spd)


def luminous_flux(wavelengths, spd, K_m=K_M):
    """Luminous flux Φ_v = K_m ∫ V(λ) Φ_e(λ) dλ in lm, from a spectral radiant flux Φ_e(λ) in W/nm.

    Domain: ``wavelengths`` (N,) nm; ``spd`` (..., N), W/nm (any spacing; trapezoidal rule).
    Range: lm, shape ``(...)``. Agrees with colour-science's ``luminous_flux`` (same rule).

    References: CIE 015:2018; compendium item 36; BIPM SI Brochure (2019), candela.
    """
    return _photometric(wavelengths, spd, K_m)


def luminous_energy(wavelengths, spd, K_m=K_M):
    """Luminous energy in talbot (lm·s) from a spectral radiant energy in J/nm (same integral).

    Domain: (..., N) J/nm. Range: talbot, shape (...). References: compendium items 31, 36.
    """
    return _photometric(wavelengths, spd, K_m)


def luminous_intensity(wavelengths, spd, K_m=K_M):
    """Luminous intensity in cd (lm/sr) from a spectral radiant intensity in W/(sr·nm).

    Domain: (..., N) W/(sr·nm). Range: cd, shape (...). References: compendium items 34, 36.
    """
    return _photometric(wavelengths, spd, K_m)


def illuminance(wavelengths, spd, K_m=K_M):
    """Illuminance in lux (lm/m²) from a spectral irradiance in W/(m²·nm).

    Domain: (..., N) W/(m²·nm). Range: lx, shape (...). References: compendium items 33, 36.
    """
    return _photometric(wavelengths, spd, K_m)


def luminous_exitance(wavelengths, spd, K_m=K_M):
    """Luminous exitance in lm/m² from a spectral radiant exitance in W/(m²·nm).

    Domain: (..., N) W/(m²·nm). Range: lm/m², shape (...). References: compendium items 33, 36.
    """
    return _photometric(wavelengths, spd, K_m)


def luminance(wavelengths, spd, K_m=K_M):
    """Luminance in cd/m² (nit) from a spectral radiance in W/(m²·sr·nm).

    Domain: (..., N) W/(m²·sr·nm). Range: cd/m², shape (...). References: compendium items 35, 36.
    """
    return _photometric(wavelengths, spd, K_m)


def luminous_efficiency(wavelengths, spd):
    """Luminous efficiency ∫ V Φ dλ / ∫ Φ dλ, dimensionless in [0, 1] (colour-science's definition).

    Domain: (..., N), any unit. Range: [0, 1], shape (...). References: CIE 015:2018.
    """
    wl, spd = _check_xy(wavelengths, spd)
    with np.errstate(all="ignore"):
        return _trapezoid(wl, luminous_efficiency_function(wl) * spd) / _trapezoid(wl, spd)


def luminous_efficacy(wavelengths, spd, K_m=K_M):
    """Luminous efficacy of radiation K = Φ_v / Φ_e in lm/W (at most K_m, for 555 nm light).

    Domain: ``spd`` (..., N), any radiometric spectral concentration (its unit cancels).
    Range: lm/W, shape ``(...)``, in [0, K_m].
    """
    with np.errstate(all="ignore"):
        return as_float(K_m) * luminous_efficiency(wavelengths, spd)


def luminous_flux_monochromatic(wavelength, power, K_m=K_M):
    """Luminous flux (lm) of monochromatic radiation: K_m V(λ) P, with P in W and λ in nm (air).

    Domain: λ in nm (air), P in W, broadcastable. Range: lm, in [0, K_m·P].
    """
    with np.errstate(all="ignore"):
        return as_float(K_m) * luminous_efficiency_function(wavelength) * as_float(power)


def radiometric_scale_for(wavelengths, shape, photometric_value, K_m=K_M):
    """Factor s such that ``s * shape`` has the photometric value ``photometric_value``.

    pbrt-v4's idea (``SpectrumToPhotometric``): a light is described by a spectrum *shape*
    (relative, any scale) and one photometric number; s = value / (K_m ∫ V(λ) shape(λ) dλ).
    The unit of ``s * shape`` follows the photometric unit: lm → W/nm, cd → W/(sr·nm),
    lx → W/(m²·nm), cd/m² → W/(m²·sr·nm).

    Domain: ``shape`` (..., N) ≥ 0 with some visible power; ``photometric_value`` broadcastable
    to ``(...)``. Range: s ≥ 0, shape ``(...)``; ``inf`` if the shape has no visible power.
    """
    with np.errstate(all="ignore"):
        return as_float(photometric_value) / _photometric(wavelengths, shape, K_m)


# --------------------------------------------------------------------------- unit conversions


def isotropic_flux_to_intensity(flux):
    """Intensity of an isotropic point source: I = Φ / (4π) (lm → cd, or W → W/sr).

    Domain: flux ≥ 0, any shape. Range: intensity, same shape. References: compendium item 34.
    """
    return as_float(flux) / (4.0 * math.pi)


def isotropic_intensity_to_flux(intensity):
    """Flux of an isotropic point source: Φ = 4π I (cd → lm, or W/sr → W).

    Domain: intensity ≥ 0, any shape. Range: flux, same shape. References: compendium item 34.
    """
    return as_float(intensity) * (4.0 * math.pi)


def lambertian_exitance_to_radiance(exitance):
    """Radiance of a Lambertian emitter or reflector: L = M / π (lm/m² → cd/m², W/m² → W/(m²·sr)).

    Domain: exitance ≥ 0, any shape. Range: radiance. References: compendium item 35 (B = ∫ L cos θ dω = π L).
    """
    return as_float(exitance) / math.pi


def lambertian_radiance_to_exitance(radiance):
    """Exitance of a Lambertian surface: M = π L (cd/m² → lm/m², W/(m²·sr) → W/m²).

    Domain: radiance ≥ 0, any shape. Range: exitance. References: compendium item 35.
    """
    return as_float(radiance) * math.pi


def point_source_illuminance(intensity, distance, cos_theta=1.0):
    """Inverse-square law: E = I cos θ / d² (cd and m → lx; W/sr and m → W/m²).

    Domain: I ≥ 0, d > 0, cos θ in [0, 1], broadcastable. Range: illuminance ≥ 0.
    """
    with np.errstate(all="ignore"):
        return as_float(intensity) * as_float(cos_theta) / as_float(distance) ** 2


def lux_to_footcandle(lux):
    """Illuminance in lux → foot-candles (1 fc = 1 lm/ft² = 10.7639 lx).

    Domain: lx, any shape. Range: fc. References: NIST SP 811 (1 ft = 0.3048 m).
    """
    return as_float(lux) / LUX_PER_FOOTCANDLE


def footcandle_to_lux(fc):
    """Illuminance in foot-candles → lux.

    Domain: fc, any shape. Range: lx. References: NIST SP 811.
    """
    return as_float(fc) * LUX_PER_FOOTCANDLE


def nit_to_footlambert(nit):
    """Luminance in cd/m² → foot-lamberts (1 fL = 1/π cd/ft² = 3.42626 cd/m²).

    Domain: cd/m², any shape. Range: fL. References: NIST SP 811.
    """
    return as_float(nit) / NIT_PER_FOOTLAMBERT


def footlambert_to_nit(fl):
    """Luminance in foot-lamberts → cd/m².

    Domain: fL, any shape. Range: cd/m². References: NIST SP 811.
    """
    return as_float(fl) * NIT_PER_FOOTLAMBERT
