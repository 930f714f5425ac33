"""Slow NumPy oracles for the radiosity kernel (core/integrators/radiosity/kernel.py)."""
import math

import numpy as np

from spectral_gi.core.integrators.radiosity.form_factors import form_factor_point_polygon

from oracles.geometry import brute_force_closest


def form_factor_rows(points, normals, senders, occluders=None):
    """OP_FORM_FACTORS without its shadow-ray estimate: the mean over each receiver's points
    of Lambert's formula (item 57) for each sending triangle, times 1 when the segment from
    the point to the triangle's centroid is free (brute-force ray casting against
    ``occluders``), else 0 (exact for occluders that hide a sender wholly or not at all)."""
    points = np.asarray(points, np.float64)
    r, k = points.shape[:2]
    out = np.zeros((r, len(senders)))
    for i in range(r):
        for j, tri in enumerate(senders):
            acc = 0.0
            for s in range(k):
                f = form_factor_point_polygon(points[i, s], normals[i], tri)
                if f > 0 and occluders is not None and len(occluders):
                    d = tri.mean(axis=0) - points[i, s]
                    dist = np.linalg.norm(d)
                    t, _ = brute_force_closest(occluders[:, 0], occluders[:, 1], occluders[:, 2],
                                               points[i, s][None] + 1e-9 * d[None], (d / dist)[None])
                    if t[0] < dist * (1 - 1e-6):
                        f = 0.0
                acc += f
            out[i, j] = acc / k
    return out


def point_light_irradiance(p, n, light_pos, intensity, occluders=None):
    """Irradiance I cos θ / d² of a point light of intensity I at p (normal n), 0 if occluded."""
    d = np.asarray(light_pos, np.float64) - p
    dist = float(np.linalg.norm(d))
    c = float(np.dot(n, d)) / dist
    if c <= 0:
        return 0.0
    if occluders is not None and len(occluders):
        t, _ = brute_force_closest(occluders[:, 0], occluders[:, 1], occluders[:, 2], p[None] + 1e-9 * d[None],
                                   (d / dist)[None])
        if t[0] < dist:
            return 0.0
    return intensity * c / dist ** 2


def rect_light_irradiance(p, n, corners, radiance):
    """Irradiance π L F_{dA→rect} of a uniform Lambertian rectangle (corners counter-clockwise
    seen from its emitting side), unoccluded."""
    return math.pi * radiance * form_factor_point_polygon(p, n, corners)


def first_patches(patches, origins, directions):
    """OP_CAMERA / OP_GATHER by brute force: for each ray the patch it reaches first (the
    front or back patch of the closest geometry triangle, by the side the ray meets; -1
    none) and the barycentric coordinates (b1, b2) of the hit on the patch's corners."""
    g = np.asarray(patches.geometry, np.float64)
    origins = np.asarray(origins, np.float64)
    directions = np.asarray(directions, np.float64)
    t, tri = brute_force_closest(g[:, 0], g[:, 1], g[:, 2], origins, directions)
    out = np.zeros((origins.shape[0], 3))
    out[:, 0] = -1
    for k in np.nonzero(tri >= 0)[0]:
        gn = np.cross(g[tri[k], 1] - g[tri[k], 0], g[tri[k], 2] - g[tri[k], 0])
        j = patches.tri_patch[tri[k], 0 if directions[k] @ gn < 0 else 1]
        if j < 0:
            continue
        c = patches.corners[j]
        e1, e2 = c[1] - c[0], c[2] - c[0]
        w = origins[k] + t[k] * directions[k] - c[0]
        m = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
        out[k] = (j, *np.linalg.solve(m, [w @ e1, w @ e2]))
    return out


def gauss_seidel_sweep(F, rho, E, B):
    """One Gauss–Seidel sweep of B = E + ρ F B, row by row in Python (item 61)."""
    F = np.asarray(F, np.float64)
    B = np.array(B, np.float64)
    for i in range(F.shape[0]):
        B[i] = E[i] + rho[i] * (F[i] @ B)
    return B
