"""Statistics and reports of a calculation surface, as lighting designers read them.

Per surface (EN 12464-1:2021 quantities; DIALux evo and Relux report the same):

* Ē: area-weighted mean illuminance, ``Σ wᵢ Eᵢ / Σ wᵢ`` with the surface's point weights
  (grid cells all weigh the same, so on a grid Ē is the plain mean; a mesh vertex weighs a
  third of its triangles' area, a face centre its triangle's area);
* Emin, Emax over the points; U0 = Emin / Ē; Ud = Emin / Emax;
* the Monte Carlo quality: samples per point and the largest and mean relative standard
  error (standard error / E, over the points with E > 0).

The integrator returns initial illuminance (new lamps, clean room). Reported numbers are
maintained illuminance ``Em = MF × E`` (CIE 97:2005: MF = LLMF · LSF · LMF · RSMF, see
:func:`spectral_gi.core.lux.grids.maintenance_factor`, or one number), with the surface's
``maintenance_factor``; pass ``maintained=False`` for initial values. Every output says which.

Outputs: per-point CSV, a JSON summary (statistics, grid metadata, luminaire schedule) and a
one-page report (PNG and PDF, A4 landscape: plan view in false colour with labelled iso-lux
lines and legend, statistics table, luminaire schedule, title block). All are written atomically.
A luminaire schedule is a list of dicts with ``type`` (str), ``count`` (int ≥ 1), ``lumens``
(lm per luminaire, ≥ 0) and optionally ``profile`` (the IES/LDT file name); other keys are kept
in the JSON only.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..io.atomic import write_text
from . import falsecolour as fc
from .grids import CalculationSurface
from .points import LuxError, check_values, write_results_csv

SUMMARY_FORMAT = "spectral_gi lux summary"
SUMMARY_VERSION = 1
A4_LANDSCAPE_MM = (297.0, 210.0)
REPORT_DPI = 150.0


def report_size_px(dpi: float = REPORT_DPI) -> tuple[int, int]:
    """The report PNG's (width, height) in pixels: A4 landscape at ``dpi``, rounded to whole pixels."""
    return tuple(int(round(mm / 25.4 * dpi)) for mm in A4_LANDSCAPE_MM)

WEIGHTING = {
    "grid": "equal (grid cells of equal area)",
    "workplane": "equal (grid cells of equal area)",
    "vertices": "a third of the adjacent triangles' area per vertex",
    "faces": "triangle area per face centre",
}


@dataclass
class SurfaceStatistics:
    surface: str
    kind: str
    n_points: int
    mean: float  # lx, area-weighted
    minimum: float  # lx
    maximum: float  # lx
    u0: float | None  # Emin / Ē (None when Ē = 0)
    ud: float | None  # Emin / Emax (None when Emax = 0)
    maintenance_factor: float
    maintained: bool  # True: the numbers are MF × initial illuminance
    area: float  # m², the sum of the point weights
    weighting: str
    samples: int | None = None  # per point
    max_rel_std_error: float | None = None
    mean_rel_std_error: float | None = None

    def to_dict(self) -> dict:
        return asdict(self)


def _lux_of(surface, lux, std_error, maintained):
    if not isinstance(surface, CalculationSurface):
        raise LuxError(f"expected a CalculationSurface, got {type(surface).__name__}")
    e = check_values("lux", lux, surface.n_points)
    s = check_values("std_error", std_error, surface.n_points, allow_none=True)
    k = surface.maintenance_factor if maintained else 1.0
    return e * k, (None if s is None else s * k)


def statistics(surface: CalculationSurface, lux, std_error=None, samples: int | None = None,
               maintained: bool = True) -> SurfaceStatistics:
    """The statistics of ``lux`` (N,) (initial illuminance from the integrator) on ``surface``."""
    e, s = _lux_of(surface, lux, std_error, maintained)
    if samples is not None and (isinstance(samples, bool) or int(samples) != samples or samples < 1):
        raise LuxError(f"samples must be a whole number ≥ 1, got {samples!r}")
    w = surface.weights
    mean = float((w * e).sum() / w.sum())
    lo, hi = float(e.min()), float(e.max())
    max_rse = mean_rse = None
    if s is not None and (e > 0).any():
        rse = s[e > 0] / e[e > 0]
        max_rse, mean_rse = float(rse.max()), float(rse.mean())
    return SurfaceStatistics(
        surface=surface.name, kind=surface.kind, n_points=surface.n_points, mean=mean, minimum=lo, maximum=hi,
        u0=lo / mean if mean > 0 else None, ud=lo / hi if hi > 0 else None,
        maintenance_factor=surface.maintenance_factor, maintained=bool(maintained), area=surface.area,
        weighting=WEIGHTING[surface.kind], samples=None if samples is None else int(samples),
        max_rel_std_error=max_rse, mean_rel_std_error=mean_rse)


def check_luminaires(luminaires) -> list[dict]:
    """The luminaire schedule, checked: a list of dicts with type, count, lumens[, profile]."""
    out = []
    for i, lum in enumerate(luminaires or ()):
        if not isinstance(lum, dict):
            raise LuxError(f"luminaire {i}: expected a dict, got {type(lum).__name__}")
        for key in ("type", "count", "lumens"):
            if key not in lum:
                raise LuxError(f"luminaire {i}: missing {key!r} (a schedule entry has type, count, lumens, profile)")
        if not isinstance(lum["type"], str) or not lum["type"]:
            raise LuxError(f"luminaire {i}: type must be a non-empty string")
        c = lum["count"]
        if isinstance(c, bool) or not isinstance(c, (int, np.integer)) or c < 1:
            raise LuxError(f"luminaire {i} ({lum['type']}): count must be a whole number ≥ 1, got {c!r}")
        f = lum["lumens"]
        if isinstance(f, bool) or not isinstance(f, (int, float, np.number)) or not math.isfinite(f) or f < 0:
            raise LuxError(f"luminaire {i} ({lum['type']}): lumens must be a number ≥ 0, got {f!r}")
        p = lum.get("profile", "")
        if not isinstance(p, str):
            raise LuxError(f"luminaire {i} ({lum['type']}): profile must be a file name (str)")
        entry = dict(lum)
        entry.update(type=lum["type"], count=int(c), lumens=float(f), profile=p)
        out.append(entry)
    return out


def write_surface_csv(path, surface: CalculationSurface, lux, std_error, maintained: bool = True) -> None:
    """Per-point CSV (``x,y,z,nx,ny,nz,lux,std_error``), maintained values unless ``maintained=False``."""
    e, s = _lux_of(surface, lux, std_error, maintained)
    if s is None:
        raise LuxError("the per-point CSV needs the standard errors")
    write_results_csv(path, surface.points, surface.normals, e, s)


def _surface_meta(surface):
    d = surface.to_dict()
    for key in ("points", "normals", "weights", "grid_index", "outline"):
        d.pop(key)
    d["n_points"] = surface.n_points
    d["area"] = surface.area
    return d


def summary(surface, lux, std_error=None, samples=None, luminaires=(), project="", date="",
            maintained=True, unlit=None) -> dict:
    """The JSON summary as a dict: statistics, surface metadata, luminaire schedule, title fields, and
    ``unlit_points``: the points that look outside the lit geometry (``unlit``, the dict of
    ``core.unlit_points(...).to_dict()``: count, indices, reasons, ...), null when not checked."""
    st = statistics(surface, lux, std_error, samples, maintained)
    if unlit is not None and not (isinstance(unlit, dict) and "count" in unlit and "indices" in unlit):
        raise LuxError(f"unlit: expected the dict of unlit_points(...).to_dict(), got {type(unlit).__name__}")
    return {
        "format": SUMMARY_FORMAT, "version": SUMMARY_VERSION, "project": str(project), "date": str(date),
        "values": "maintained illuminance (MF x initial), lx" if maintained else "initial illuminance, lx",
        "statistics": st.to_dict(), "surface": _surface_meta(surface), "luminaires": check_luminaires(luminaires),
        "unlit_points": None if unlit is None else dict(unlit),
    }


def write_summary_json(path, surface, lux, std_error=None, samples=None, luminaires=(), project="", date="",
                       maintained=True, unlit=None) -> dict:
    """Write :func:`summary` as JSON atomically; returns the dict."""
    d = summary(surface, lux, std_error, samples, luminaires, project, date, maintained, unlit)
    write_text(path, json.dumps(d, indent=2, allow_nan=False) + "\n")
    return d


def read_summary_json(path) -> dict:
    d = json.loads(Path(path).read_text(encoding="utf-8"))
    if d.get("format") != SUMMARY_FORMAT or d.get("version") != SUMMARY_VERSION:
        raise LuxError(f"{path}: not a {SUMMARY_FORMAT} version {SUMMARY_VERSION}")
    return d


# --------------------------------------------------------------------------- one-page report


def _fmt(v, digits=None):
    if v is None:
        return "–"
    if digits is not None:
        return f"{v:.{digits}f}"
    return fc.format_value(v)


def statistics_rows(surface, st: SurfaceStatistics) -> list[tuple[str, str]]:
    """The rows of the report's statistics table."""
    def pct(x):
        return "–" if x is None else f"{100 * x:.2f} %"

    which = "maintained" if st.maintained else "initial"
    return [
        (f"Ē ({which}, lx)", _fmt(st.mean)),
        ("Emin (lx)", _fmt(st.minimum)),
        ("Emax (lx)", _fmt(st.maximum)),
        ("U0 = Emin/Ē", _fmt(st.u0, 2)),
        ("Ud = Emin/Emax", _fmt(st.ud, 2)),
        ("grid", "–" if surface.grid_shape is None else f"{surface.grid_shape[1]} × {surface.grid_shape[0]}"),
        ("spacing (m)", "–" if surface.spacing is None else f"{surface.spacing[0]:.3f} × {surface.spacing[1]:.3f}"),
        ("points", str(st.n_points)),
        ("band (m)", f"{surface.band:.2f}"),
        ("maintenance factor", f"{st.maintenance_factor:.3f}"),
        ("samples per point", "–" if st.samples is None else str(st.samples)),
        ("max / mean rel. std. error", f"{pct(st.max_rel_std_error)} / {pct(st.mean_rel_std_error)}"),
    ]


def luminaire_rows(luminaires) -> list[tuple[str, str, str, str]]:
    return [(lum["type"], str(lum["count"]), _fmt(lum["lumens"]), Path(lum["profile"]).name or "–")
            for lum in check_luminaires(luminaires)]


def _plan_view(fig, ax, cax, surface, e, vmin, vmax, steps, scale):
    if surface.is_grid:
        img = surface.grid_image(e)
        rgba = np.zeros(img.shape + (4,))
        ok = np.isfinite(img)
        rgba[..., :3] = fc.false_colour(img, vmin, vmax, steps, scale)
        rgba[..., 3] = ok
        u0 = float(surface.origin @ surface.axis_u)
        v0 = float(surface.origin @ surface.axis_v)
        x0, x1, y0, y1 = surface.plan_extent()
        ax.imshow(rgba, origin="lower", extent=(u0 + x0, u0 + x1, v0 + y0, v0 + y1), interpolation="nearest")
        rows, cols = surface.grid_shape
        xs = u0 + (np.arange(cols) + 0.5) * surface.spacing[0]
        ys = v0 + (np.arange(rows) + 0.5) * surface.spacing[1]
        fc.draw_isolux(ax, img, fc.legend_levels(vmin, vmax, steps, scale)[1:-1], xs, ys)
        if surface.outline is not None:
            for (a, b) in surface.outline:
                ax.plot([u0 + a[0], u0 + b[0]], [v0 + a[1], v0 + b[1]], color="0.2", linewidth=1.0)
        horizontal = abs(abs(float(np.cross(surface.axis_u, surface.axis_v)[2])) - 1.0) < 1e-9
        ax.set_xlabel("x (m)" if horizontal and surface.axis_u[0] > 0.999 else "u (m)")
        ax.set_ylabel("y (m)" if horizontal and surface.axis_v[1] > 0.999 else "v (m)")
    else:
        mean_n = surface.normals.mean(axis=0)
        if abs(mean_n[2]) > 0.99 * np.linalg.norm(mean_n):  # a horizontal surface: world X and Y
            uv, labels = surface.points[:, :2], ("x (m)", "y (m)")
        else:  # the plane of the points' two principal axes
            c = surface.points.mean(axis=0)
            _, _, vt = np.linalg.svd(surface.points - c)
            uv, labels = (surface.points - c) @ vt[:2].T, ("u (m, principal axis)", "v (m)")
        ax.scatter(uv[:, 0], uv[:, 1], c=fc.false_colour(e, vmin, vmax, steps, scale), s=12)
        try:
            import matplotlib.tri as mtri
            tri = mtri.Triangulation(uv[:, 0], uv[:, 1])
            levels = fc.legend_levels(vmin, vmax, steps, scale)[1:-1]
            levels = levels[(levels > e.min()) & (levels < e.max())]
            if levels.size:
                cs = ax.tricontour(tri, e, levels=levels, colors="black", linewidths=0.8)
                ax.clabel(cs, fmt=fc.format_value, fontsize=7)
        except (ValueError, RuntimeError):
            pass  # points on a line or too few: no iso-lines
        ax.set_xlabel(labels[0])
        ax.set_ylabel(labels[1])
        lo, hi = uv.min(axis=0), uv.max(axis=0)
        pad = 0.05 * max(float((hi - lo).max()), 1e-6)
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    fc.draw_legend(fig, cax, vmin, vmax, steps, scale, "lx")


def render_report(surface: CalculationSurface, lux, std_error=None, samples=None, luminaires=(), *, project="",
                  date="", png_path=None, pdf_path=None, maintained=True, vmin=None, vmax=None,
                  steps=fc.DEFAULT_STEPS, scale="linear", dpi=REPORT_DPI):
    """The one-page report (A4 landscape) as a matplotlib Figure, saved to ``png_path`` and/or
    ``pdf_path`` atomically (the PNG is 297 × 210 mm at ``dpi``: 1754 × 1240 px at 150 dpi)."""
    fc._require_matplotlib()
    from matplotlib.patches import Rectangle

    e, _ = _lux_of(surface, lux, std_error, maintained)
    st = statistics(surface, lux, std_error, samples, maintained)
    lums = check_luminaires(luminaires)
    vmin, vmax = fc._range(e, vmin, vmax, scale)
    w_px, h_px = report_size_px(dpi)
    fig = fc.new_figure((w_px + 0.25) / dpi, (h_px + 0.25) / dpi, dpi=dpi)  # + ¼ px: the canvas truncates

    title = fig.add_axes((0.03, 0.90, 0.94, 0.08))
    title.set_axis_off()
    title.add_patch(Rectangle((0, 0), 1, 1, transform=title.transAxes, fill=False, linewidth=1.0, clip_on=False))
    title.text(0.01, 0.62, project or "Lighting calculation", fontsize=14, weight="bold", va="center")
    which = "maintained illuminance Em = MF × initial" if maintained else "initial illuminance"
    title.text(0.01, 0.22, f"Surface: {surface.name} ({surface.kind}) — {which}, lx", fontsize=10, va="center")
    title.text(0.99, 0.62, str(date), fontsize=10, ha="right", va="center")
    title.text(0.99, 0.22, "Spectral GI", fontsize=9, ha="right", va="center", color="0.4")

    ax = fig.add_axes((0.06, 0.08, 0.50, 0.78))
    cax = fig.add_axes((0.58, 0.08, 0.015, 0.78))
    _plan_view(fig, ax, cax, surface, e, vmin, vmax, steps, scale)
    ax.set_title("Plan view with iso-lux lines (lx)", fontsize=10)

    tab = fig.add_axes((0.66, 0.40, 0.31, 0.46))
    tab.set_axis_off()
    tab.set_title("Statistics", fontsize=10)
    t = tab.table(cellText=[list(r) for r in statistics_rows(surface, st)], colWidths=[0.6, 0.4], loc="upper center",
                  cellLoc="left")
    t.auto_set_font_size(False)
    t.set_fontsize(8)
    t.scale(1.0, 1.25)

    sch = fig.add_axes((0.66, 0.06, 0.31, 0.28))
    sch.set_axis_off()
    sch.set_title("Luminaire schedule", fontsize=10)
    rows = [list(r) for r in luminaire_rows(lums)] or [["–", "–", "–", "–"]]
    t2 = sch.table(cellText=rows, colLabels=["type", "count", "lm each", "profile"], colWidths=[0.38, 0.14, 0.18, 0.3],
                   loc="upper center", cellLoc="left")
    t2.auto_set_font_size(False)
    t2.set_fontsize(8)
    t2.scale(1.0, 1.25)

    if png_path is not None:
        fc.save_figure(fig, png_path)
    if pdf_path is not None:
        fc.save_figure(fig, pdf_path)
    return fig
