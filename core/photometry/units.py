"""Unit conventions between Blender's values and physical units.

Blender's light "watts" are not radiometric watts of a real spectrum. This project
reads them as the glTF exporter does: 1 Blender W = 683 lm, i.e. a radiance of 1
Blender unit for white is a luminance of 683 cd/m² (K_m · Y). With this convention a
Cycles pixel value equals this renderer's linear Rec.709 value for the same scene,
and EXR files carry whiteLuminance = 683 cd/m².

Cycles' conventions (measured in Cycles 5.0, see shared/design/facts.md):
* Emission shader: radiance = strength · colour.
* Area light of power P (W) and area A (m²): radiance = P / (π A) · colour.
"""
import math

from .. import constants as C
from ..colour import luminance_rec709

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
    from .quantities import luminous_efficacy

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
