"""The glue between an illuminance integrator and the lighting-analysis outputs.

An integrator is any callable ``illuminance(scene, points (N, 3), normals (N, 3), **options)``
returning ``(lux (N,), std_error (N,))``: initial illuminance in lx on the side each normal
faces and the standard error of each estimate. These functions call it, check what it returns
(shapes, finite, non-negative) and hand the arrays to the writers, so a ``.pts`` file becomes a
results CSV as with Radiance's ``rtrace -I+``, and a calculation surface becomes its statistics.
"""

from __future__ import annotations

import numpy as np

from .grids import CalculationSurface
from .points import LuxError, check_points, check_values, read_pts, write_results_csv


def check_result(result, n: int) -> tuple[np.ndarray, np.ndarray]:
    """An integrator's ``(lux, std_error)`` for ``n`` points, checked and as float64 arrays."""
    if not isinstance(result, tuple) or len(result) != 2:
        raise LuxError(f"an illuminance integrator must return (lux, std_error), got {type(result).__name__}")
    lux = check_values("the integrator's lux", result[0], n)
    se = check_values("the integrator's std_error", result[1], n)
    return lux, se


def calculate_points(illuminance, scene, points, normals, **options) -> tuple[np.ndarray, np.ndarray]:
    """Run ``illuminance`` at ``points`` facing ``normals`` (normalised first); checked results."""
    p, n = check_points(points, normals)
    if p.shape[0] == 0:
        raise LuxError("no points to calculate")
    return check_result(illuminance(scene, p, n, **options), p.shape[0])


def calculate_surface(illuminance, scene, surface: CalculationSurface, **options) -> tuple[np.ndarray, np.ndarray]:
    """Initial illuminance and standard errors at a calculation surface's points."""
    if not isinstance(surface, CalculationSurface):
        raise LuxError(f"expected a CalculationSurface, got {type(surface).__name__}")
    return calculate_points(illuminance, scene, surface.points, surface.normals, **options)


def calculate_pts_file(illuminance, scene, pts_path, csv_path, **options) -> tuple[np.ndarray, np.ndarray]:
    """Read sensor points from a ``.pts`` file, run ``illuminance`` and write the results CSV
    (one row per input point, in input order, atomically). Returns ``(lux, std_error)``."""
    p, n = read_pts(pts_path)
    lux, se = calculate_points(illuminance, scene, p, n, **options)
    write_results_csv(csv_path, p, n, lux, se)
    return lux, se
