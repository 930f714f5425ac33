"""The media record: each material's interior medium and the media's coefficient tables."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import constants as C


class MediaRecord(NamedTuple):
    """Participating media as the path kernel reads them (core/media/kernel.py); K materials,
    M media.

    mat_medium: int32 (K,) the interior medium of each material, -1 none.
    med_tab: float64 (2 M, N_LAMBDA) σa and σs rows of each medium in 1/m on the 1 nm grid;
        (0, N_LAMBDA) when the scene has neither media nor null surfaces (then the kernel
        runs none of the media code).
    med_g: float64 (M,) the Henyey–Greenstein anisotropy g of each medium.
    cam_medium: int, the medium around the camera (-1 none).
    """

    mat_medium: np.ndarray
    med_tab: np.ndarray
    med_g: np.ndarray
    cam_medium: int


def pack(scene, spec, v0, v1, v2, tri_mat_orig, measure) -> MediaRecord:
    """The record of ``scene``'s media: ``spec`` the spectrum table (rows of the scene's
    spectra first), v0, v1, v2 and tri_mat_orig its triangles before the BVH reorders them;
    ``measure``: the material table ends with the sensors' material (no interior)."""
    mat_medium, med_tab, med_g = media_tables(scene, spec)
    if measure:
        mat_medium = np.append(mat_medium, np.int32(-1))
    cam_medium = camera_medium(scene, v0, v1, v2, tri_mat_orig, mat_medium) if med_tab.shape[0] else -1
    return MediaRecord(mat_medium, med_tab, med_g, int(cam_medium))


def media_tables(scene, spec):
    """(mat_medium, med_tab, med_g) for the kernel: the coefficient rows σa = density × shape
    (1 where the shape is -1) and σs likewise, per medium, on the 1 nm grid.

    Without media and null surfaces med_tab has no rows and the kernel skips all media code.
    """
    n_mat = max(1, len(scene.materials))
    mat_medium = np.full(n_mat, -1, np.int32)
    for i, m in enumerate(scene.materials):
        mat_medium[i] = m.interior
    has_null = any(m.model == C.MAT_NULL for m in scene.materials)
    if not scene.media and not has_null:
        return mat_medium, np.zeros((0, C.N_LAMBDA)), np.zeros(1)
    n = max(1, len(scene.media))
    tab = np.zeros((2 * n, C.N_LAMBDA))
    g = np.zeros(n)
    for k, md in enumerate(scene.media):
        for r, (idx, dens) in enumerate(((md.absorption, md.absorption_density),
                                         (md.scattering, md.scattering_density))):
            shape = spec[idx].astype(np.float64) if idx >= 0 else np.ones(C.N_LAMBDA)
            tab[2 * k + r] = dens * np.maximum(shape, 0.0)
        g[k] = md.anisotropy
    return mat_medium, np.ascontiguousarray(tab), g


def camera_medium(scene, v0, v1, v2, tri_mat_orig, mat_medium):
    """The medium around the camera: along a few fixed directions, the nearest surface
    whose material has an interior medium; seen from its back side, the camera is inside.
    (One level of nesting, as the kernel tracks.) The majority of the directions decides,
    so a ray through an edge cannot."""
    from ..geometry.accel import build, closest

    bound = np.nonzero(mat_medium[tri_mat_orig] >= 0)[0] if tri_mat_orig.size else np.zeros(0, np.int64)
    if bound.size == 0:
        return -1
    eye = np.asarray(scene.camera.to_world, np.float64)[:3, 3]
    dirs = np.array([[0.2673, 0.5345, 0.8018], [-0.7071, 0.3015, -0.6396], [0.4364, -0.8729, 0.2182]])
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    a, b, c = v0[bound], v1[bound], v2[bound]
    t, hit = closest(build(a.astype(np.float32), b.astype(np.float32), c.astype(np.float32)),
                     np.repeat(eye[None], 3, 0), dirs)
    votes = []
    for k in range(3):
        if hit[k] < 0:
            votes.append(-1)
            continue
        j = bound[hit[k]]
        n = np.cross(v1[j] - v0[j], v2[j] - v0[j])
        votes.append(int(mat_medium[tri_mat_orig[j]]) if np.dot(n, dirs[k]) > 0 else -1)
    return max(set(votes), key=votes.count)
