"""Lighting analysis: calculation surfaces, illuminance statistics, reports and false colour.

What a lighting designer does with DIALux, Relux or Radiance, around the renderer's kernel:

* :mod:`.points` — sensor points in (Radiance ``.pts``: ``x y z nx ny nz`` a line) and the
  results CSV out (``x,y,z,nx,ny,nz,lux,std_error``, one row per point in input order);
  :class:`LuxError` (a ValueError) for every bad input.
* :mod:`.grids` — calculation surfaces (:class:`CalculationSurface`, versioned, JSON-able):
  grids over rectangles, planar polygons and planar face sets with the EN 12464-1:2021 spacing
  ``p = 0.2 · 5^log10(d)`` and ``ceil(L / p)`` points a side at the cell centres, an optional
  band at the boundary; work planes over a floor polygon; points on mesh vertices or faces.
  Every point carries the area it stands for (its weight in the mean).
* :mod:`.report` — Ē (area-weighted), Emin, Emax, U0, Ud, the Monte Carlo error, the CIE 97:2005
  maintenance factor; per-point CSV, JSON summary and a one-page PNG/PDF report.
* :mod:`.falsecolour` — colour lookup (pure NumPy, the viridis table in ``presets/colormaps``),
  linear/log scales, N steps or continuous, the plan image (NumPy), legends and labelled iso-lux lines (matplotlib).
* :mod:`.cie171` — CIE 171:2006 analytic test cases as scenes, points and expected lux.
* :mod:`.calculate` — runs an integrator on points, a ``.pts`` file or a surface and checks
  what it returns.

Drawing needs matplotlib (the ``analysis`` extra), imported only inside the functions that
draw; everything else needs NumPy only, so it runs in Blender's Python.

The illuminance integrator (built on the path kernel, not here) fills one interface::

    illuminance(scene, points (N, 3), normals (N, 3), samples=..., seed=...) -> (lux (N,), std_error (N,))

initial illuminance in lx on the side each normal faces (cosine-weighted hemisphere sampling
with next-event estimation, delta lights counted, the points invisible to the scene) and the
standard error of each estimate. Everything here takes those two arrays:
``statistics(surface, lux, std_error, samples)``, ``write_surface_csv``,
``write_summary_json``, ``render_report`` and ``colour_attribute``; ``calculate_pts_file(illuminance,
scene, "in.pts", "out.csv")`` is the ``rtrace -I+`` workflow.
"""

from .calculate import calculate_points, calculate_pts_file, calculate_surface, check_result
from .falsecolour import (
    DEFAULT_STEPS,
    auto_range,
    colour_attribute,
    colormap,
    draw_isolux,
    draw_legend,
    false_colour,
    false_colour_image,
    generate_colormap_tables,
    legend_levels,
    plan_image,
    scale_positions,
)
from .grids import (
    SURFACE_FORMAT_VERSION,
    CalculationSurface,
    en12464_spacing,
    face_set_grid,
    maintenance_factor,
    mesh_face_points,
    mesh_vertex_points,
    points_per_side,
    polygon_grid,
    rectangle_grid,
    workplane,
)
from .points import LuxError, parse_pts, read_pts, read_results_csv, write_pts, write_results_csv
from .report import (
    SurfaceStatistics,
    read_summary_json,
    render_report,
    statistics,
    summary,
    write_summary_json,
    write_surface_csv,
)

__all__ = [
    "CalculationSurface",
    "DEFAULT_STEPS",
    "LuxError",
    "SURFACE_FORMAT_VERSION",
    "SurfaceStatistics",
    "auto_range",
    "calculate_points",
    "calculate_pts_file",
    "calculate_surface",
    "check_result",
    "colormap",
    "colour_attribute",
    "draw_isolux",
    "draw_legend",
    "en12464_spacing",
    "face_set_grid",
    "false_colour",
    "false_colour_image",
    "generate_colormap_tables",
    "legend_levels",
    "maintenance_factor",
    "mesh_face_points",
    "mesh_vertex_points",
    "parse_pts",
    "plan_image",
    "points_per_side",
    "polygon_grid",
    "read_pts",
    "read_results_csv",
    "read_summary_json",
    "rectangle_grid",
    "render_report",
    "scale_positions",
    "statistics",
    "summary",
    "workplane",
    "write_pts",
    "write_results_csv",
    "write_summary_json",
    "write_surface_csv",
]
