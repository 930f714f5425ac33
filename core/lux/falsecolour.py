"""False colour for illuminance (lx) and luminance (cd/m²): colour lookup, legends, iso-lines.

The colour lookup is pure NumPy (Blender's Python has no matplotlib): the colour map is a
table shipped in ``presets/colormaps/`` (viridis: 256 sRGB entries, the perceptually uniform
map of van der Walt and Smith, CC0), written once from matplotlib's own data by
:func:`generate_colormap_tables` and checked against it by a test.

* Scale: ``"linear"`` or ``"log"`` (log10 between the range's ends, which must be > 0).
* Range: fixed (``vmin``/``vmax``) or automatic (:func:`auto_range`: linear from 0, or from the
  smallest value when some are negative, to the largest; log from the smallest positive value
  to the largest).
* Steps: ``steps`` equal bands of the scaled range (8 by default, as Radiance's ``falsecolor``),
  each drawn in the colour of its middle; ``steps=0`` is continuous. The band boundaries
  (:func:`legend_levels`) are the legend's labels and the iso-lines' levels.

Values outside the range take the colour of its end; non-finite values are black.
Drawing (legends, iso-lines, figures) needs matplotlib (the ``analysis`` extra), imported
inside the functions that draw, with the Agg canvas (no window, no global backend change).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..io.atomic import atomic_path, write_text
from ..io.presets import PRESETS_DIR
from .points import LuxError

COLORMAPS_DIR = "colormaps"
COLORMAP_HEADER = "r,g,b"
GENERATED_COLORMAPS = ("viridis",)
DEFAULT_STEPS = 8
SCALES = ("linear", "log")
_CACHE: dict[str, np.ndarray] = {}


# --------------------------------------------------------------------------- colour map data


def colormap_names() -> list[str]:
    return sorted(p.stem for p in (PRESETS_DIR / COLORMAPS_DIR).glob("*.csv"))


def read_colormap(path) -> np.ndarray:
    """Read a colour map table: header ``r,g,b``, one sRGB entry (three numbers in [0, 1]) a row."""
    path = Path(path)
    rows = []
    header = None
    for line_no, raw in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        if header is None:
            header = line
            if header != COLORMAP_HEADER:
                raise LuxError(f"{path}, line {line_no}: the header must be {COLORMAP_HEADER!r}, got {line!r}")
            continue
        fields = line.split(",")
        try:
            row = [float(f) for f in fields]
        except ValueError:
            raise LuxError(f"{path}, line {line_no}: not a number in {fields}") from None
        if len(row) != 3 or not all(math.isfinite(v) and 0.0 <= v <= 1.0 for v in row):
            raise LuxError(f"{path}, line {line_no}: expected three numbers in [0, 1], got {fields}")
        rows.append(row)
    if len(rows) < 2:
        raise LuxError(f"{path}: a colour map needs at least 2 entries")
    return np.asarray(rows, dtype=np.float64)


def colormap(name: str = "viridis") -> np.ndarray:
    """The shipped colour map ``name``: (K, 3) sRGB-encoded values in [0, 1]."""
    if name not in _CACHE:
        path = PRESETS_DIR / COLORMAPS_DIR / f"{name}.csv"
        if "/" in name or "\\" in name or not path.is_file():
            raise LuxError(f"unknown colour map {name!r}; available: {colormap_names()}")
        _CACHE[name] = read_colormap(path)
    return _CACHE[name].copy()


def generate_colormap_tables(out_dir: str | os.PathLike) -> list[Path]:
    """Developer tool: write ``colormaps/<name>.csv`` under ``out_dir`` (the role of ``presets/``)
    from matplotlib's colour map data, numbers as Python's ``repr`` (round-trip exact)."""
    mpl = _require_matplotlib()
    written = []
    for name in GENERATED_COLORMAPS:
        colors = np.asarray(mpl.colormaps[name].colors, dtype=np.float64)
        lines = [COLORMAP_HEADER] + [",".join(repr(float(c)) for c in row) for row in colors]
        path = Path(out_dir) / COLORMAPS_DIR / f"{name}.csv"
        write_text(path, "\n".join(lines) + "\n")
        os.chmod(path, 0o644)
        written.append(path)
    return written


# --------------------------------------------------------------------------- scale and lookup


def _check_scale(scale):
    if scale not in SCALES:
        raise LuxError(f"unknown scale {scale!r} (one of {', '.join(SCALES)})")


def auto_range(values, scale: str = "linear") -> tuple[float, float]:
    """The automatic range of ``values`` (see the module's notes); a flat field gets a range of 1
    (linear) or a decade (log) above its value."""
    _check_scale(scale)
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    if scale == "log":
        v = v[v > 0.0]
        if v.size == 0:
            raise LuxError("a logarithmic scale needs some positive values")
        lo, hi = float(v.min()), float(v.max())
        return (lo, hi) if hi > lo else (lo, lo * 10.0)
    if v.size == 0:
        raise LuxError("no finite values to take a range from")
    lo, hi = min(0.0, float(v.min())), float(v.max())
    return (lo, hi) if hi > lo else (lo, lo + 1.0)


def _range(values, vmin, vmax, scale):
    _check_scale(scale)
    if vmin is None or vmax is None:
        a, b = auto_range(values, scale)
        vmin = a if vmin is None else vmin
        vmax = b if vmax is None else vmax
    vmin, vmax = float(vmin), float(vmax)
    if not (math.isfinite(vmin) and math.isfinite(vmax) and vmax > vmin):
        raise LuxError(f"the range must have vmax > vmin, both finite; got [{vmin}, {vmax}]")
    if scale == "log" and vmin <= 0.0:
        raise LuxError(f"a logarithmic scale needs vmin > 0, got {vmin}")
    return vmin, vmax


def _check_steps(steps):
    if steps is None:
        return 0
    if isinstance(steps, bool) or int(steps) != steps or steps < 0:
        raise LuxError(f"steps must be a whole number ≥ 0 (0: continuous), got {steps!r}")
    return int(steps)


def scale_positions(values, vmin: float, vmax: float, scale: str = "linear") -> np.ndarray:
    """Where ``values`` fall in [vmin, vmax] on the scale: t in [0, 1] (clipped), NaN where not finite."""
    _check_scale(scale)
    v = np.asarray(values, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        if scale == "log":
            t = (np.log10(np.maximum(v, vmin)) - math.log10(vmin)) / (math.log10(vmax) - math.log10(vmin))
        else:
            t = (v - vmin) / (vmax - vmin)
    t = np.clip(t, 0.0, 1.0)
    t[~np.isfinite(v)] = np.nan
    return t


def legend_levels(vmin: float, vmax: float, steps: int = DEFAULT_STEPS, scale: str = "linear") -> np.ndarray:
    """The ``steps + 1`` band boundaries from vmin to vmax (linear: equal differences; log: equal
    ratios); continuous (``steps=0``): the 9 boundaries of 8 bands, for the legend's ticks."""
    vmin, vmax = _range(None, vmin, vmax, scale)
    n = _check_steps(steps) or DEFAULT_STEPS
    return np.geomspace(vmin, vmax, n + 1) if scale == "log" else np.linspace(vmin, vmax, n + 1)


def step_colours(steps: int = DEFAULT_STEPS, colormap_name: str = "viridis") -> np.ndarray:
    """The (steps, 3) colours of the bands: the map's entry nearest each band's middle."""
    steps = _check_steps(steps)
    if steps < 1:
        raise LuxError("step colours need steps ≥ 1")
    cm = colormap(colormap_name)
    idx = np.rint((np.arange(steps) + 0.5) / steps * (len(cm) - 1)).astype(int)
    return cm[idx]


def false_colour(values, vmin: float | None = None, vmax: float | None = None, steps: int = DEFAULT_STEPS,
                 scale: str = "linear", colormap_name: str = "viridis") -> np.ndarray:
    """sRGB colours (..., 3) in [0, 1] for ``values`` (any shape) in lx or cd/m² (pure NumPy)."""
    v = np.asarray(values, dtype=np.float64)
    vmin, vmax = _range(v, vmin, vmax, scale)
    steps = _check_steps(steps)
    t = scale_positions(v, vmin, vmax, scale)
    bad = np.isnan(t)
    t = np.where(bad, 0.0, t)
    if steps:
        band = np.minimum((t * steps).astype(np.int64), steps - 1)
        rgb = step_colours(steps, colormap_name)[band]
    else:
        cm = colormap(colormap_name)
        rgb = cm[np.rint(t * (len(cm) - 1)).astype(np.int64)]
    rgb[bad] = 0.0
    return rgb


def srgb_to_linear(rgb) -> np.ndarray:
    """Decode sRGB values in [0, 1] to linear (IEC 61966-2-1 transfer function)."""
    c = np.asarray(rgb, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def colour_attribute(surface, lux, vmin: float | None = None, vmax: float | None = None,
                     steps: int = DEFAULT_STEPS, scale: str = "linear", colormap_name: str = "viridis",
                     linear: bool = False) -> np.ndarray:
    """Per-point RGBA (N, 4) float32 for a calculation surface's ``lux`` (N,), alpha 1: the viewport's
    colour attribute. sRGB-encoded by default (Blender's byte colour attributes); ``linear=True``
    decodes it for float colour attributes, which Blender stores linear."""
    e = np.asarray(lux, dtype=np.float64)
    if e.shape != (surface.n_points,):
        raise LuxError(f"surface {surface.name!r}: expected {surface.n_points} lux values, got shape {e.shape}")
    rgba = np.ones((e.shape[0], 4), np.float32)
    rgb = false_colour(e, vmin, vmax, steps, scale, colormap_name)
    rgba[:, :3] = srgb_to_linear(rgb) if linear else rgb
    return rgba


def _paint_segment(rgba, a, b, colour):
    """Paint the segment a → b (pixel coordinates x, y; y down) into ``rgba`` (H, W, 4), one pixel wide."""
    h, w = rgba.shape[:2]
    n = int(np.ceil(2.0 * np.hypot(*(b - a)))) + 2
    t = np.linspace(0.0, 1.0, n)[:, None]
    xy = np.rint(a + t * (b - a)).astype(np.int64)
    ok = (xy[:, 0] >= 0) & (xy[:, 0] < w) & (xy[:, 1] >= 0) & (xy[:, 1] < h)
    rgba[xy[ok, 1], xy[ok, 0]] = colour


def plan_image(surface, lux, vmin: float | None = None, vmax: float | None = None, steps: int = DEFAULT_STEPS,
               scale: str = "linear", colormap_name: str = "viridis", size: int = 512,
               legend: bool = True) -> np.ndarray:
    """The false-colour plan of a calculation surface as an RGBA image (H, W, 4) float32, sRGB-encoded,
    row 0 at the top (pure NumPy, for Blender's Image Editor).

    A grid is drawn cell by cell (square pixels, the longer side of the grid and its outline about
    ``size`` px), the surface's outline (the band included) in dark grey, cells without a point and
    the band transparent; points on mesh vertices or faces are drawn as
    squares of their area in the plane of the points (world X/Y for a horizontal surface). With
    ``legend``, a bar of the band colours (lowest at the bottom) stands at the right; its values
    are :func:`legend_levels` of the same range."""
    e = np.asarray(lux, dtype=np.float64)
    if e.shape != (surface.n_points,):
        raise LuxError(f"surface {surface.name!r}: expected {surface.n_points} lux values, got shape {e.shape}")
    size = int(size)
    if size < 16:
        raise LuxError(f"a plan image needs at least 16 px, got {size}")
    vmin, vmax = _range(e, vmin, vmax, scale)
    steps = _check_steps(steps)
    edge = np.array([0.2, 0.2, 0.2, 1.0], np.float32)
    if surface.is_grid:
        rows, cols = surface.grid_shape
        du, dv = surface.spacing
        x0, x1, y0, y1 = 0.0, cols * du, 0.0, rows * dv  # the plane frame, metres from the grid's corner
        if surface.outline is not None and len(surface.outline):  # the whole outline, band included
            ol = surface.outline.reshape(-1, 2)
            x0, y0 = min(x0, float(ol[:, 0].min())), min(y0, float(ol[:, 1].min()))
            x1, y1 = max(x1, float(ol[:, 0].max())), max(y1, float(ol[:, 1].max()))
        ppm = size / max(x1 - x0, y1 - y0)  # pixels per metre
        w, h = max(1, int(round((x1 - x0) * ppm))), max(1, int(round((y1 - y0) * ppm)))
        img = surface.grid_image(e)
        cell = np.zeros((rows + 1, cols + 1, 4), np.float32)  # the extra row and column: outside, transparent
        cell[:rows, :cols, :3] = false_colour(img, vmin, vmax, steps, scale, colormap_name)
        cell[:rows, :cols, 3] = np.isfinite(img)
        u = x0 + (np.arange(w) + 0.5) / ppm
        v = y1 - (np.arange(h) + 0.5) / ppm  # row 0 at the top: v decreasing downwards
        ci = np.floor(u / du).astype(np.int64)
        rj = np.floor(v / dv).astype(np.int64)
        ci[(ci < 0) | (ci >= cols)] = cols
        rj[(rj < 0) | (rj >= rows)] = rows
        plan = cell[rj][:, ci]
        if surface.outline is not None:
            lim = [w - 1, h - 1]
            for a, b in surface.outline:
                pa = np.array([(a[0] - x0) * ppm, (y1 - a[1]) * ppm - 0.5])
                pb = np.array([(b[0] - x0) * ppm, (y1 - b[1]) * ppm - 0.5])
                _paint_segment(plan, np.clip(pa, 0, lim), np.clip(pb, 0, lim), edge)
    else:
        mean_n = surface.normals.mean(axis=0)
        if abs(mean_n[2]) > 0.99 * np.linalg.norm(mean_n):
            uv = surface.points[:, :2]
        else:
            c = surface.points.mean(axis=0)
            _, _, vt = np.linalg.svd(surface.points - c)
            uv = (surface.points - c) @ vt[:2].T
        half = 0.5 * np.sqrt(surface.weights)
        lo, hi = (uv - half[:, None]).min(axis=0), (uv + half[:, None]).max(axis=0)
        ppm = size / max(float((hi - lo).max()), 1e-9)
        w, h = (max(1, int(round(float(x)))) for x in (hi - lo) * ppm)
        plan = np.zeros((h, w, 4), np.float32)
        rgb = false_colour(e, vmin, vmax, steps, scale, colormap_name)
        for k in np.argsort(-surface.weights):  # small squares over large ones
            x0 = max(0, int(np.floor((uv[k, 0] - half[k] - lo[0]) * ppm)))
            x1 = max(x0 + 1, int(np.ceil((uv[k, 0] + half[k] - lo[0]) * ppm)))
            y0 = max(0, int(np.floor((hi[1] - uv[k, 1] - half[k]) * ppm)))
            y1 = max(y0 + 1, int(np.ceil((hi[1] - uv[k, 1] + half[k]) * ppm)))
            plan[y0:y1, x0:x1, :3] = rgb[k]
            plan[y0:y1, x0:x1, 3] = 1.0
    if not legend:
        return plan
    gap, bar = max(4, w // 40), max(8, w // 16)
    bands = step_colours(steps, colormap_name) if steps else colormap(colormap_name)
    k = np.minimum(((h - 1 - np.arange(h)) / h * len(bands)).astype(np.int64), len(bands) - 1)
    out = np.zeros((h, w + gap + bar, 4), np.float32)
    out[:, :w] = plan
    out[:, w + gap:, :3] = bands[k][:, None, :]
    out[:, w + gap:, 3] = 1.0
    return out


# --------------------------------------------------------------------------- drawing (matplotlib)


def _require_matplotlib():
    """matplotlib, or an ImportError that names the extra to install."""
    try:
        import matplotlib
        import matplotlib.colors  # noqa: F401
        import matplotlib.figure  # noqa: F401
        from matplotlib.backends import backend_agg  # noqa: F401
    except ImportError as exc:
        raise ImportError("drawing legends, iso-lux lines and reports needs matplotlib: install the "
                          "'analysis' extra (pip install 'spectral-gi[analysis]')") from exc
    return matplotlib


def new_figure(width_in: float, height_in: float, dpi: float = 100.0):
    """A matplotlib Figure on an Agg canvas (no pyplot, no window)."""
    mpl = _require_matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = mpl.figure.Figure(figsize=(width_in, height_in), dpi=dpi)
    FigureCanvasAgg(fig)
    return fig


def mpl_colormap_and_norm(vmin, vmax, steps=DEFAULT_STEPS, scale="linear", colormap_name="viridis"):
    """The matplotlib (colormap, norm) that draws exactly the colours of :func:`false_colour`."""
    mpl = _require_matplotlib()
    vmin, vmax = _range(None, vmin, vmax, scale)
    steps = _check_steps(steps)
    if steps:
        cmap = mpl.colors.ListedColormap(step_colours(steps, colormap_name))
        norm = mpl.colors.BoundaryNorm(legend_levels(vmin, vmax, steps, scale), steps)
    else:
        cmap = mpl.colors.ListedColormap(colormap(colormap_name))
        norm = (mpl.colors.LogNorm if scale == "log" else mpl.colors.Normalize)(vmin=vmin, vmax=vmax)
    return cmap, norm


def draw_legend(fig, cax, vmin, vmax, steps=DEFAULT_STEPS, scale="linear", unit="lx", colormap_name="viridis",
                orientation="vertical"):
    """A colour bar on axes ``cax`` labelled with the band boundaries in ``unit``; returns it."""
    _require_matplotlib()
    import matplotlib.cm

    cmap, norm = mpl_colormap_and_norm(vmin, vmax, steps, scale, colormap_name)
    sm = matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap)
    levels = legend_levels(vmin, vmax, steps, scale)
    cb = fig.colorbar(sm, cax=cax, orientation=orientation, ticks=levels, spacing="uniform")
    labels = [format_value(v) for v in levels]
    if orientation == "vertical":
        cb.ax.set_yticklabels(labels)
    else:
        cb.ax.set_xticklabels(labels)
    cb.set_label(unit)
    return cb


def format_value(v: float) -> str:
    """A legend/iso-line label: three significant figures, no exponent below 10⁶."""
    v = float(v)
    if v == 0.0:
        return "0"
    if abs(v) >= 1e6 or abs(v) < 1e-3:
        return f"{v:.3g}"
    digits = max(0, 2 - int(math.floor(math.log10(abs(v)))))
    return f"{round(v, digits):.{digits}f}"


def draw_isolux(ax, values2d, levels, x=None, y=None, colour="black", label=True, linewidths=0.8):
    """Iso-lines of a 2-D array (NaN: no data) at ``levels``, labelled; ``x``/``y`` are the column and
    row coordinates (default: pixel centres 0..W-1, 0..H-1). Returns matplotlib's ContourSet."""
    _require_matplotlib()
    z = np.ma.masked_invalid(np.asarray(values2d, dtype=np.float64))
    if z.ndim != 2 or min(z.shape) < 2:
        raise LuxError(f"iso-lines need a 2-D array of at least 2 × 2 values, got shape {z.shape}")
    h, w = z.shape
    x = np.arange(w, dtype=float) if x is None else np.asarray(x, float)
    y = np.arange(h, dtype=float) if y is None else np.asarray(y, float)
    lv = np.asarray(levels, dtype=np.float64)
    lv = lv[(lv > np.nanmin(z.filled(np.nan))) & (lv < np.nanmax(z.filled(np.nan)))] if z.count() else lv[:0]
    if lv.size == 0:
        return None
    cs = ax.contour(x, y, z, levels=lv, colors=colour, linewidths=linewidths)
    if label:
        ax.clabel(cs, fmt=format_value, fontsize=7, inline=True)
    return cs


def save_figure(fig, path, dpi=None) -> Path:
    """Save a figure atomically; the format is the file's suffix (``.png``, ``.pdf``, ``.svg``)."""
    path = Path(path)
    fmt = path.suffix.lstrip(".").lower()
    if fmt not in ("png", "pdf", "svg"):
        raise LuxError(f"{path}: figures are written as .png, .pdf or .svg")
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, dpi=dpi if dpi is not None else fig.dpi)
    return path


def false_colour_image(values2d, path=None, vmin=None, vmax=None, steps=DEFAULT_STEPS, scale="linear", unit="lx",
                       title=None, contours=True, colormap_name="viridis", dpi=100.0):
    """A false-colour figure of a rendered illuminance or luminance image (H, W) (row 0 at the top),
    with labelled iso-lines at the band boundaries and the legend in ``unit``; saved to ``path``
    (atomically) if given. Returns the Figure."""
    z = np.asarray(values2d, dtype=np.float64)
    if z.ndim != 2:
        raise LuxError(f"a false-colour image needs an (H, W) array, got shape {z.shape}")
    vmin, vmax = _range(z, vmin, vmax, scale)
    h, w = z.shape
    fig = new_figure(8.0, 8.0 * h / w * 0.85 + 0.8, dpi)
    ax = fig.add_axes((0.05, 0.08, 0.75, 0.84))
    cax = fig.add_axes((0.85, 0.08, 0.03, 0.84))
    ax.imshow(false_colour(z, vmin, vmax, steps, scale, colormap_name), interpolation="nearest",
              extent=(-0.5, w - 0.5, h - 0.5, -0.5))
    if contours:
        draw_isolux(ax, z, legend_levels(vmin, vmax, steps, scale)[1:-1], colour="white")
    ax.set_axis_off()
    if title:
        ax.set_title(title)
    draw_legend(fig, cax, vmin, vmax, steps, scale, unit, colormap_name)
    if path is not None:
        save_figure(fig, path)
    return fig
