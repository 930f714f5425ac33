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

from . import constants as C
from .colour import luminance_rec709

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
