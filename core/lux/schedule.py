"""The luminaire schedule of a scene, as a lighting report lists it: each analytic light's
type, count, luminous flux (lm) and photometric profile file.

Fluxes from the contract's photometric numbers: a point light of intensity I emits 4π I; a
spot, I times the solid angle of its softened cone (:func:`..photometry.units.spot_solid_angle`);
a profiled light, the flux of its profile (scaled as its ``profile_mode`` says; a spot's cone
included); a rectangle or ellipse of luminance L and area A, π L A per emitting side. Suns
(a flux over an unbounded plane) and emissive meshes are not luminaires and are left out.
"""
from __future__ import annotations

import math

import numpy as np

from .. import constants as C
from ..photometry.profiles import flux as profile_flux
from ..photometry.units import spot_falloff, spot_solid_angle

KIND_NAMES = {C.LIGHT_RECT: "area (rectangle)", C.LIGHT_ELLIPSE: "area (ellipse)", C.LIGHT_POINT: "point",
              C.LIGHT_SPOT: "spot"}


def light_lumens(scene, light) -> float:
    """The luminous flux (lm) of one analytic light of ``scene`` (not a sun)."""
    k = light.kind
    if k in (C.LIGHT_RECT, C.LIGHT_ELLIPSE):
        half = float(np.linalg.norm(np.cross(light.axis_u, light.axis_v)))
        area = 4.0 * half if k == C.LIGHT_RECT else math.pi * half
        return math.pi * light.luminance * area * (2.0 if light.two_sided else 1.0)
    if light.profile >= 0:
        pr = scene.profiles[light.profile]
        mask = None
        if k == C.LIGHT_SPOT:
            def mask(cos_t):
                return spot_falloff(cos_t, light.spot_angle, light.spot_blend)
        raw = profile_flux(pr, mask)
        if light.profile_mode == "flux":
            return float(light.flux)
        if light.profile_mode == "peak":
            peak = float(pr.candela.max())
            return raw * (light.intensity / peak) if peak > 0 else 0.0
        return raw
    if k == C.LIGHT_SPOT:
        return light.intensity * spot_solid_angle(light.spot_angle, light.spot_blend)
    return 4.0 * math.pi * light.intensity


def luminaire_schedule(scene) -> list[dict]:
    """[{type, count, lumens, profile}] with equal luminaires (same type, flux and profile) counted
    together, in the order they first appear."""
    rows: dict[tuple, dict] = {}
    for li in scene.lights:
        if li.kind == C.LIGHT_SUN:
            continue
        profile = (scene.profiles[li.profile].source or scene.profiles[li.profile].name) if li.profile >= 0 else ""
        lm = round(light_lumens(scene, li), 6)
        key = (KIND_NAMES[li.kind], lm, profile)
        if key in rows:
            rows[key]["count"] += 1
        else:
            rows[key] = {"type": key[0], "count": 1, "lumens": lm, "profile": profile}
    return list(rows.values())
