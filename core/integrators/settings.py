"""The settings record: the render settings and scene-wide scalars the path kernel reads."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import constants as C


class SettingsRecord(NamedTuple):
    """Scalars of one render.

    seed: int, the RNG seed (every random number is a pure function of seed, pixel, sample
        and dimension).
    max_depth: int, the most bounces (0: direct light only; a path scatters at most
        max_depth + 1 times); rr_depth: int, the depth from which Russian roulette runs.
    sampler: int, SAMPLER_* tag; n_total: int, the render's samples per pixel (the
        Hammersley set's size).
    nee: int, 0: the naive reference estimator (BSDF and phase sampling only, every emitter
        hit counted with weight 1), else next-event estimation with MIS.
    sensor_mat: int, ≥ 0: measuring mode (illuminance sensors), the index of the white
        two-sided Lambert a sensor triangle hit by the camera ray takes; -1 otherwise.
    film_transparent: int, ≠ 0: camera rays that hit nothing leave the pixel transparent.
    sph_lo, sph_hi: float, sr: an emissive triangle seen under a solid angle in [sph_lo,
        sph_hi] is sampled uniformly in solid angle, else by area (sph_lo > sph_hi: area only).
    scene_scale: float, ≥ 1, the largest coordinate magnitude of the scene, m (ray offsets
        are relative to it).
    """

    seed: int
    max_depth: int
    rr_depth: int
    sampler: int
    n_total: int
    nee: int
    sensor_mat: int
    film_transparent: int
    sph_lo: float
    sph_hi: float
    scene_scale: float


def pack(settings, sensor_mat, scene_scale) -> SettingsRecord:
    """The record of a scene's RenderSettings, the sensors' material and the scene's scale."""
    st = settings
    return SettingsRecord(int(st.seed), int(st.max_depth), int(st.rr_depth), int(st.sampler), int(st.spp),
                          int(bool(st.next_event)), int(sensor_mat), int(bool(st.film_transparent)),
                          float(st.tri_solid_angle_min), float(st.tri_solid_angle_max), float(scene_scale))


def scene_scale(v0, v1, v2, light_kind, light_geo):
    """The largest coordinate magnitude of the triangles and the lights but the sun (at
    least 1 m)."""
    pts = [np.abs(v0).max(initial=0), np.abs(v1).max(initial=0), np.abs(v2).max(initial=0)]
    not_sun = light_kind != C.LIGHT_SUN
    if np.any(not_sun):
        pts.append(np.abs(light_geo[not_sun, :3]).max() + light_geo[not_sun, 13].max())
    return max(1.0, float(max(pts)))
