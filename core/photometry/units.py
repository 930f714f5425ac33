"""Unit conventions between Blender's values and physical units.

Blender's light "watts" are not radiometric watts of a real spectrum. This project
reads them as the glTF exporter does: 1 Blender W = 683 lm, i.e. a radiance of 1
Blender unit for white is a luminance of 683 cd/m² (K_m · Y). With this convention a
Cycles pixel value equals this renderer's linear Rec.709 value for the same scene,
and EXR files carry whiteLuminance = 683 cd/m².

Cycles' conventions (measured against Cycles 5.0 renders through the bpy module):
* Emission shader: radiance = strength · colour.
* Area light of power P (W) and area A (m²): radiance = P / (π A) · colour.

Blender's light units → the photometric numbers of the scene contract. The contract
gives every analytic light one photometric number: luminance (cd/m²) for area lights,
luminous intensity (cd) for point and spot lights, illuminance (lux) for the sun. This
module turns what a Blender user types into those numbers:

* Blender's own units, read as Cycles reads them (measured against Cycles 5.0) with the
  convention above, 1 Blender W = 683 lm:

  - point and spot lights of power P (W) have a radiant intensity of P/(4π) W/sr in
    every direction inside the cone (a spot's cone does not concentrate its power),
    so I = 683 · P/(4π) · Y(colour) cd;
  - a sun of strength S (W/m²) gives an irradiance S on a surface facing it, so
    E = 683 · S · Y(colour) lux;
  - an area light of power P and area A has radiance P/(π A) (above).

  Y(colour) is the Rec.709 luminance of the light's colour (1 for white).

* photometric units a lighting designer has from a data sheet: lumens (lm), candela
  (cd), lux (sun) and cd/m² (area). The spectrum then only sets the colour.

Spot lights soften their edge as Cycles does: the relative intensity at angle θ from
the axis is ``smoothstep((cos θ − cos(α/2)) / ((1 − cos(α/2)) · blend))`` for a cone
of full angle α (Blender's Spot Size) and Blender's Spot Blend, with smoothstep(x) =
3x² − 2x³ on [0, 1]. Integrating it over the sphere gives the solid angle of
:func:`spot_solid_angle`, which turns a spot's lumens into candela.
"""
from __future__ import annotations

import math

import numpy as np

from .. import constants as C
from ..colour import luminance_rec709
from .quantities import luminous_efficacy
from ..spectra import library, moments
from ..spectra.uplift import emission_from_rgb, emission_from_samples
from ..spectra.fit import emission_XYZ

BLENDER_LM_PER_W = C.K_M


def emission_luminance(rgb, strength):
    """Luminance (cd/m²) of a Blender Emission shader of colour ``rgb`` and ``strength``."""
    return BLENDER_LM_PER_W * float(strength) * max(0.0, float(luminance_rec709(rgb)))


def area_light_luminance(power_w, area_m2, rgb):
    """Luminance (cd/m²) of a Blender area light of power ``power_w`` and area ``area_m2``."""
    if not area_m2 > 0.0:
        raise ValueError(f"area light: area must be positive, got {area_m2}")
    radiance = float(power_w) / (math.pi * float(area_m2))
    return BLENDER_LM_PER_W * radiance * max(0.0, float(luminance_rec709(rgb)))


EMITTER_UNITS = ("cd/m2", "lm", "cd", "W", "blender_W")


def emitter_luminance(unit, value, area_m2, two_sided=False, shape=None):
    """Luminance (cd/m²) of a uniform Lambertian emitter given one photometric or radiometric number.

    As in pbrt-v4, the spectrum sets the colour and one number the brightness:

    * ``"cd/m2"``: the luminance itself;
    * ``"lm"``: luminous flux Φ over all emitting sides: L = Φ / (π A · sides);
    * ``"cd"``: luminous intensity along the normal: I = L A, so L = I / A;
    * ``"W"``: radiant flux of the spectrum ``shape`` = (wavelengths_nm, values):
      Φ = W · K_m ∫V S / ∫S, then as for lumens;
    * ``"blender_W"``: Blender's watts at 683 lm/W for a white light (Cycles' area lights).
    """
    v = float(value)
    a = float(area_m2)
    if not math.isfinite(v) or v < 0.0:
        raise ValueError(f"emitter {unit}: the value must be a finite number ≥ 0, got {value}")
    if unit == "cd/m2":
        return v
    if not a > 0.0:
        raise ValueError(f"emitter area must be positive, got {area_m2}")
    sides = 2.0 if two_sided else 1.0
    if unit == "lm":
        return v / (math.pi * a * sides)
    if unit == "cd":
        return v / a
    if unit == "blender_W":
        return BLENDER_LM_PER_W * v / (math.pi * a * sides)
    if unit == "W":
        if shape is None:
            raise ValueError("emitter in W: the spectrum shape is needed to turn watts into lumens")
        wl, s = shape
        return float(luminous_efficacy(wl, s)) * v / (math.pi * a * sides)
    raise ValueError(f"unknown emitter unit {unit!r}; use one of {', '.join(EMITTER_UNITS)}")


BLENDER_LM_PER_W = C.K_M  # the convention of core/units.py

# Units a light's brightness may be given in, per kind of Blender light.
LIGHT_UNITS = {
    "POINT": ("blender_W", "lm", "cd"),
    "SPOT": ("blender_W", "lm", "cd"),
    "SUN": ("blender_W", "lux"),
    "AREA": ("blender_W", "lm", "cd", "cd/m2"),
}

# Emission spectrum sources of a light.
SPECTRUM_SOURCES = ("rgb", "blackbody", "illuminant", "led")
BLACKBODY_RANGE_K = (100.0, 100000.0)


def _y(rgb):
    return max(0.0, float(luminance_rec709(np.asarray(rgb, dtype=np.float64).reshape(-1)[:3])))


def _finite_non_negative(what, v):
    v = float(v)
    if not math.isfinite(v) or v < 0.0:
        raise ValueError(f"{what}: expected a finite number ≥ 0, got {v}")
    return v


def point_light_intensity(power_w, rgb=(1.0, 1.0, 1.0)):
    """Luminous intensity (cd) of a Blender point or spot light of ``power_w`` Blender watts.

    Cycles gives both a radiant intensity of P/(4π) W/sr (for a spot: inside its cone;
    the cone does not concentrate the power); at 683 lm per Blender W that is
    683 · P/(4π) · Y(rgb) cd.
    """
    return BLENDER_LM_PER_W * _finite_non_negative("light power", power_w) / (4.0 * math.pi) * _y(rgb)


def sun_illuminance(strength, rgb=(1.0, 1.0, 1.0)):
    """Illuminance (lux) on a surface facing a Blender sun of ``strength`` W/m²: 683 · S · Y(rgb)."""
    return BLENDER_LM_PER_W * _finite_non_negative("sun strength", strength) * _y(rgb)


def smoothstep(x):
    """3x² − 2x³ on [0, 1], clamped outside."""
    t = np.clip(np.asarray(x, dtype=np.float64), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def spot_falloff(cos_theta, spot_angle, spot_blend):
    """Relative intensity of a spot light at ``cos_theta`` from its axis (1 on the axis, 0 outside).

    ``spot_angle``: full cone angle (rad); ``spot_blend`` in [0, 1] softens the edge over
    that fraction of (1 − cos(α/2)), as Cycles does. Blend 0 is a hard edge.
    """
    c = math.cos(0.5 * float(spot_angle))
    mu = np.asarray(cos_theta, dtype=np.float64)
    b = float(spot_blend)
    if b <= 0.0:
        return np.where(mu > c, 1.0, 0.0)
    return smoothstep((mu - c) / ((1.0 - c) * b))


def spot_solid_angle(spot_angle, spot_blend):
    """∫ spot_falloff dω over the sphere (sr): 2π (1 − cos(α/2)) (1 − blend/2).

    On the softened band the falloff is smoothstep of a linear function of cos θ, and the
    mean of smoothstep over [0, 1] is 1/2; the rest of the cone counts fully.
    """
    a = float(spot_angle)
    b = min(max(float(spot_blend), 0.0), 1.0)
    if not 0.0 < a <= math.pi:
        raise ValueError(f"spot angle must be in (0, π], got {a}")
    return 2.0 * math.pi * (1.0 - math.cos(0.5 * a)) * (1.0 - 0.5 * b)


def light_photometric(kind, unit, value, *, rgb=(1.0, 1.0, 1.0), area_m2=None, spot_angle=None,
                      spot_blend=0.0, two_sided=False):
    """The contract's photometric number for a Blender light of type ``kind``.

    kind: "POINT", "SPOT", "SUN" or "AREA" (Blender's ``Light.type``).
    unit: one of LIGHT_UNITS[kind]; ``value`` is in that unit ("blender_W" is the light's
    power in W, or a sun's strength in W/m², already scaled by its exposure).
    rgb: the light's colour; only used with "blender_W", where it scales the brightness as
    in Cycles. With photometric units the value alone sets the brightness.
    Returns candela (POINT, SPOT), lux (SUN) or cd/m² (AREA).
    Lumens of a spot are the flux inside its cone (edge softening included).
    """
    kind = str(kind).upper()
    if kind not in LIGHT_UNITS:
        raise ValueError(f"unknown light type {kind!r}; expected one of {', '.join(LIGHT_UNITS)}")
    if unit not in LIGHT_UNITS[kind]:
        raise ValueError(f"{kind.lower()} light: unit {unit!r} does not apply; "
                         f"use one of {', '.join(LIGHT_UNITS[kind])}")
    v = _finite_non_negative(f"{kind.lower()} light {unit}", value)
    if kind in ("POINT", "SPOT"):
        if unit == "blender_W":
            return point_light_intensity(v, rgb)
        if unit == "cd":
            return v
        if kind == "POINT":
            return v / (4.0 * math.pi)
        return v / spot_solid_angle(spot_angle, spot_blend)
    if kind == "SUN":
        return sun_illuminance(v, rgb) if unit == "blender_W" else v
    # AREA
    if area_m2 is None or not float(area_m2) > 0.0:
        raise ValueError(f"area light: area must be positive, got {area_m2}")
    if unit == "blender_W":
        return float(area_light_luminance(v, float(area_m2), rgb))
    return float(emitter_luminance(unit, v, float(area_m2), two_sided=two_sided))


def light_spectrum_names(source):
    """Choices for a light's spectrum ``source``: CIE illuminants (without LEDs) or CIE LED series."""

    if source == "illuminant":
        return [n for n in library.illuminant_names() if not n.startswith("LED-")]
    if source == "led":
        return library.led_names()
    raise ValueError(f"light spectrum source {source!r} has no named choices; use 'illuminant' or 'led'")


def light_emission_coeffs(source, *, rgb=(1.0, 1.0, 1.0), temperature=6500.0, name="D65",
                          n_coeffs=C.N_COEFFS_DEFAULT):
    """Fourier coefficients of a light's emission *shape* from its spectrum source.

    source "rgb": the uplift of ``rgb``; "blackbody": Planck's law at ``temperature`` K;
    "illuminant" / "led": the CIE table ``name``.
    """

    if source == "rgb":
        return emission_from_rgb(tuple(float(x) for x in np.asarray(rgb).reshape(-1)[:3]), n_coeffs)
    g = moments.grid()
    if source == "blackbody":
        t = float(temperature)
        lo, hi = BLACKBODY_RANGE_K
        if not lo <= t <= hi:
            raise ValueError(f"blackbody temperature must be in [{lo:g}, {hi:g}] K, got {t:g}")
        s = library.blackbody(t, g)
    elif source in ("illuminant", "led"):
        s = library.illuminant(name, g)
    else:
        raise ValueError(f"unknown light spectrum source {source!r}; use one of {', '.join(SPECTRUM_SOURCES)}")
    return emission_from_samples(g, s / float(np.max(s)), n_coeffs)


def scene_white_xy(scene):
    """CIE 1931 xy chromaticity of the brightest emitter of ``scene`` (by luminance), or None without one.

    For white-balancing a render to its main light (develop(white_balance=...)).
    """

    emitters = [(li.luminance if li.kind in (C.LIGHT_RECT, C.LIGHT_ELLIPSE) else
                 max(getattr(li, "intensity", 0.0), getattr(li, "illuminance", 0.0)), li.spectrum)
                for li in scene.lights]
    emitters += [(m.emission_luminance, m.emission) for m in scene.materials if m.emission >= 0]
    if scene.world.background >= 0:
        emitters.append((scene.world.luminance, scene.world.background))
    emitters = [e for e in emitters if e[0] > 0.0 and e[1] >= 0]
    if not emitters:
        return None
    _, s = max(emitters, key=lambda e: e[0])
    XYZ = emission_XYZ(scene.spectra.coeffs[s])
    total = float(np.sum(XYZ))
    if not total > 0.0:
        return None
    return (float(XYZ[0]) / total, float(XYZ[1]) / total)


def luminance_scale(shape_row, cmf, luminance, what):
    """Factor turning a spectrum shape into spectral radiance W/(m² sr nm) of ``luminance`` cd/m²."""
    from ..film.record import v_lambda
    from ..scene import SceneError

    y = float(np.sum(shape_row.astype(np.float64) * v_lambda(cmf)) * C.LAMBDA_STEP)
    if luminance == 0.0:
        return 0.0
    if not y > 0.0:
        raise SceneError(f"{what}: its spectrum has no visible power, so a luminance cannot be set")
    return luminance / (C.K_M * y)
