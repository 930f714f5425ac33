"""Calculation surfaces: the points where a lighting calculation reports illuminance.

Grid spacing follows EN 12464-1:2021 *Light and lighting — Lighting of work places —
Part 1: Indoor work places*: for a calculation area whose longer side is ``d`` metres the
maximum spacing is ``p = 0.2 · 5^log10(d)`` (1 m → 0.2 m, 5 m → 0.62 m, 10 m → 1 m;
never more than 10 m); for an area whose longer side is at least twice its shorter side,
``d`` is the shorter side (:func:`grid_size`). The number of points along a side of length ``L`` is ``L / p``
rounded up to the next whole number, ``n = ceil(L / p)``, so the real spacing ``L / n``
is never more than ``p``; the points sit at the centres of the ``n`` cells. A band
(a strip along the boundary, typically 0.5 m at the walls of a work plane) may be left
out of the calculation area: the spacing is then chosen for the area inside the band,
and the points closer than the band to the outline are dropped.

Every constructor returns a :class:`CalculationSurface`, the record a scene file stores
(``to_dict``/``from_dict``, JSON-able, versioned). Its ``weights`` are the area each point
stands for (m²), which the statistics use for the area-weighted mean:

* grids and work planes: every kept cell has the same area ``du · dv``;
* mesh vertices: one third of the area of the triangles around the vertex (the
  barycentric dual area), so the weights sum to the mesh area;
* mesh faces (points at the triangle centroids): the triangle's area.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .points import LuxError, check_points

SURFACE_FORMAT_VERSION = 1
SURFACE_KINDS = ("grid", "vertices", "faces", "workplane")
MAX_SPACING = 10.0  # m, EN 12464-1:2021
WORKPLANE_HEIGHT = 0.75  # m above the floor
WORKPLANE_BAND = 0.5  # m at the walls
_ROUND_EPS = 1e-9  # L / p within this of a whole number counts as that number (float noise)


def en12464_spacing(d: float) -> float:
    """EN 12464-1:2021 maximum grid spacing ``p = 0.2 · 5^log10(d)`` m (at most 10 m) for a
    calculation area whose longer side is ``d`` m."""
    d = float(d)
    if not (math.isfinite(d) and d > 0.0):
        raise LuxError(f"the size of a calculation area must be a positive number of metres, got {d}")
    return min(0.2 * 5.0 ** math.log10(d), MAX_SPACING)


def grid_size(side_a: float, side_b: float) -> float:
    """The ``d`` of EN 12464-1's spacing rule for a calculation area of sides ``side_a`` and
    ``side_b``: the longer side, or the shorter one when the longer is at least twice it
    (so a long corridor is not sampled more coarsely across its width than a room)."""
    lo, hi = sorted((float(side_a), float(side_b)))
    return lo if hi >= 2.0 * lo else hi


def points_per_side(length: float, spacing: float) -> int:
    """Number of grid points along a side: ``ceil(length / spacing)``, at least 1 (EN 12464-1:2021)."""
    length, spacing = float(length), float(spacing)
    if not (math.isfinite(spacing) and spacing > 0.0):
        raise LuxError(f"grid spacing must be a positive number of metres, got {spacing}")
    if not (math.isfinite(length) and length > 0.0):
        raise LuxError(f"the side of a calculation area must be a positive number of metres, got {length}")
    return max(1, math.ceil(length / spacing - _ROUND_EPS))


def maintenance_factor(llmf: float = 1.0, lsf: float = 1.0, lmf: float = 1.0, rsmf: float = 1.0) -> float:
    """CIE 97:2005 maintenance factor ``MF = LLMF · LSF · LMF · RSMF`` (lamp lumen maintenance,
    lamp survival, luminaire maintenance, room surface maintenance), each in (0, 1]."""
    mf = 1.0
    for name, v in (("LLMF", llmf), ("LSF", lsf), ("LMF", lmf), ("RSMF", rsmf)):
        v = float(v)
        if not (0.0 < v <= 1.0):
            raise LuxError(f"{name} must be in (0, 1], got {v}")
        mf *= v
    return mf


def _arr(x, shape_tail, name, dtype=np.float64):
    a = np.asarray(x, dtype=dtype)
    if a.ndim != len(shape_tail) + 1 or a.shape[1:] != shape_tail:
        raise LuxError(f"{name} must have shape (N, {', '.join(map(str, shape_tail))}), got {a.shape}")
    return a


@dataclass
class CalculationSurface:
    """Points (N, 3) with unit normals (N, 3) where illuminance is calculated, and what a report
    needs about them.

    Grids and work planes also carry their lattice: ``grid_shape`` (rows, columns), ``spacing``
    (du, dv) m, ``grid_index`` (N,) the flat index ``row · columns + column`` of each point, and
    the plane frame ``origin`` + ``axis_u``/``axis_v`` (unit vectors), so that the cell (row j,
    column i) is centred at ``origin + (i + ½) du · axis_u + (j + ½) dv · axis_v``; ``outline``
    (M, 2, 2) holds the surface's boundary segments in that frame (metres from ``origin``).
    ``maintenance_factor`` multiplies the calculated (initial) illuminance into maintained
    illuminance (CIE 97:2005).
    """

    name: str
    kind: str
    points: np.ndarray
    normals: np.ndarray
    weights: np.ndarray
    band: float = 0.0
    maintenance_factor: float = 1.0
    grid_shape: tuple | None = None
    spacing: tuple | None = None
    grid_index: np.ndarray | None = None
    origin: np.ndarray | None = None
    axis_u: np.ndarray | None = None
    axis_v: np.ndarray | None = None
    outline: np.ndarray | None = None
    version: int = field(default=SURFACE_FORMAT_VERSION)

    def __post_init__(self):
        self.validate()

    @property
    def n_points(self) -> int:
        return int(self.points.shape[0])

    @property
    def is_grid(self) -> bool:
        return self.grid_shape is not None

    @property
    def area(self) -> float:
        return float(self.weights.sum())

    def validate(self) -> CalculationSurface:
        if self.version != SURFACE_FORMAT_VERSION:
            raise LuxError(f"unknown calculation surface version {self.version!r} "
                           f"(this build reads version {SURFACE_FORMAT_VERSION})")
        if not isinstance(self.name, str) or not self.name:
            raise LuxError("a calculation surface needs a name")
        if self.kind not in SURFACE_KINDS:
            raise LuxError(f"surface {self.name!r}: unknown kind {self.kind!r} (one of {', '.join(SURFACE_KINDS)})")
        self.points, self.normals = check_points(self.points, self.normals)
        n = self.points.shape[0]
        if n == 0:
            raise LuxError(f"surface {self.name!r} has no points (is the band wider than the surface?)")
        self.weights = np.asarray(self.weights, dtype=np.float64)
        if self.weights.shape != (n,) or not np.isfinite(self.weights).all() or not (self.weights > 0).all():
            raise LuxError(f"surface {self.name!r}: weights must be ({n},) positive areas")
        try:
            band, mf = float(self.band), float(self.maintenance_factor)
        except (TypeError, ValueError):
            raise LuxError(f"surface {self.name!r}: the band and the maintenance factor must be numbers") from None
        if not (math.isfinite(band) and band >= 0.0):
            raise LuxError(f"surface {self.name!r}: the band must be ≥ 0 m, got {band}")
        if not (0.0 < mf <= 1.0):
            raise LuxError(f"surface {self.name!r}: the maintenance factor must be in (0, 1], got {mf}")
        self.band, self.maintenance_factor = band, mf
        if self.kind in ("grid", "workplane"):
            if self.grid_shape is None or self.spacing is None or self.grid_index is None or self.origin is None:
                raise LuxError(f"surface {self.name!r}: a {self.kind} needs grid_shape, spacing, grid_index "
                               "and its frame")
        if self.grid_shape is not None:
            rows, cols = (int(v) for v in self.grid_shape)
            if rows < 1 or cols < 1:
                raise LuxError(f"surface {self.name!r}: bad grid shape {self.grid_shape}")
            self.grid_shape = (rows, cols)
            du, dv = (float(v) for v in self.spacing)
            if not (du > 0 and dv > 0):
                raise LuxError(f"surface {self.name!r}: bad grid spacing {self.spacing}")
            self.spacing = (du, dv)
            gi = np.asarray(self.grid_index, dtype=np.int64)
            if gi.shape != (n,) or (gi < 0).any() or (gi >= rows * cols).any() or len(np.unique(gi)) != n:
                raise LuxError(f"surface {self.name!r}: grid_index must hold {n} distinct cells of the "
                               f"{rows} × {cols} grid")
            self.grid_index = gi
            self.origin = _arr(np.reshape(self.origin, (1, 3)), (3,), "origin")[0]
            self.axis_u = _arr(np.reshape(self.axis_u, (1, 3)), (3,), "axis_u")[0]
            self.axis_v = _arr(np.reshape(self.axis_v, (1, 3)), (3,), "axis_v")[0]
        if self.outline is not None:
            self.outline = np.asarray(self.outline, dtype=np.float64).reshape(-1, 2, 2)
        return self

    def to_dict(self) -> dict:
        """A JSON-able dict (plain lists and numbers) that :meth:`from_dict` reads back."""
        def lst(a):
            return None if a is None else np.asarray(a).tolist()
        return {
            "version": self.version, "name": self.name, "kind": self.kind,
            "points": lst(self.points), "normals": lst(self.normals), "weights": lst(self.weights),
            "band": self.band, "maintenance_factor": self.maintenance_factor,
            "grid_shape": None if self.grid_shape is None else list(self.grid_shape),
            "spacing": None if self.spacing is None else list(self.spacing),
            "grid_index": lst(self.grid_index), "origin": lst(self.origin),
            "axis_u": lst(self.axis_u), "axis_v": lst(self.axis_v), "outline": lst(self.outline),
        }

    @classmethod
    def from_dict(cls, d: dict) -> CalculationSurface:
        if not isinstance(d, dict):
            raise LuxError(f"a calculation surface must be a dict, got {type(d).__name__}")
        known = set(cls.__dataclass_fields__)
        unknown = set(d) - known
        if unknown:
            raise LuxError(f"calculation surface: unknown fields {sorted(unknown)}")
        for key in ("version", "name", "kind", "points", "normals", "weights"):
            if key not in d:
                raise LuxError(f"calculation surface: missing field {key!r}")
        kw = dict(d)
        for key in ("grid_shape", "spacing"):
            if kw.get(key) is not None:
                kw[key] = tuple(kw[key])
        return cls(**kw)

    def grid_image(self, values) -> np.ndarray:
        """Per-point ``values`` laid out on the grid, (rows, columns), NaN in cells without a point."""
        if not self.is_grid:
            raise LuxError(f"surface {self.name!r} ({self.kind}) has no grid")
        v = np.asarray(values, dtype=np.float64)
        if v.shape != (self.n_points,):
            raise LuxError(f"surface {self.name!r}: expected {self.n_points} values, got shape {v.shape}")
        img = np.full(self.grid_shape[0] * self.grid_shape[1], np.nan)
        img[self.grid_index] = v
        return img.reshape(self.grid_shape)

    def plan_extent(self) -> tuple[float, float, float, float]:
        """(u0, u1, v0, v1): the grid's extent in its plane frame, metres from ``origin``."""
        rows, cols = self.grid_shape
        return (0.0, cols * self.spacing[0], 0.0, rows * self.spacing[1])


# --------------------------------------------------------------------------- planar grids


def _unit(v, name):
    v = np.asarray(v, dtype=np.float64)
    n = float(np.linalg.norm(v))
    if not (math.isfinite(n) and n > 0.0):
        raise LuxError(f"{name} must be a non-zero finite vector, got {v.tolist()}")
    return v / n


def _frame(normal, hint_u=None):
    """An orthonormal (u, v, n) with n = normal; u along ``hint_u`` (projected), else world X for a
    horizontal plane, else the horizontal direction in the plane."""
    n = _unit(normal, "normal")
    if hint_u is not None:
        u = np.asarray(hint_u, float) - (np.dot(hint_u, n)) * n
    elif abs(n[2]) > 1.0 - 1e-9:
        u = np.array([1.0, 0.0, 0.0])
    else:
        u = np.cross((0.0, 0.0, 1.0), n)
    u = _unit(u, "the grid's u axis")
    return u, np.cross(n, u), n


def _segment_distance(p, a, b):
    """Distance (N, M) from 2-D points p (N, 2) to segments a→b (M, 2)."""
    ab = b - a
    L2 = np.maximum((ab * ab).sum(axis=1), 1e-300)
    ap = p[:, None, :] - a[None, :, :]
    t = np.clip((ap * ab[None]).sum(axis=2) / L2[None], 0.0, 1.0)
    d = ap - t[..., None] * ab[None]
    return np.sqrt((d * d).sum(axis=2))


def _inside_polygon(p, poly):
    """Even-odd rule: (N,) bool for 2-D points p (N, 2) inside the closed polygon (K, 2)."""
    x, y = p[:, 0][:, None], p[:, 1][:, None]
    a, b = poly, np.roll(poly, -1, axis=0)
    cond = (a[None, :, 1] > y) != (b[None, :, 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = a[None, :, 0] + (y - a[None, :, 1]) * (b[None, :, 0] - a[None, :, 0]) / (b[None, :, 1] - a[None, :, 1])
    return (cond & (x < xc)).sum(axis=1) % 2 == 1


def _inside_triangles(p, tri2d):
    """(N,) bool: 2-D points p (N, 2) inside any triangle of tri2d (T, 3, 2)."""
    inside = np.zeros(p.shape[0], bool)
    a, b, c = tri2d[:, 0], tri2d[:, 1], tri2d[:, 2]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    ok = np.abs(det) > 1e-300
    for k in np.nonzero(ok)[0]:
        d = p - a[k]
        l1 = (d[:, 0] * (c[k, 1] - a[k, 1]) - (c[k, 0] - a[k, 0]) * d[:, 1]) / det[k]
        l2 = ((b[k, 0] - a[k, 0]) * d[:, 1] - d[:, 0] * (b[k, 1] - a[k, 1])) / det[k]
        inside |= (l1 >= -1e-12) & (l2 >= -1e-12) & (l1 + l2 <= 1 + 1e-12)
    return inside


def _planar_grid(name, kind, origin, u, v, n, lo, hi, inside, segments, spacing, band, mf):
    """The grid over the box [lo, hi] (plane coordinates) shrunk by ``band``, kept where ``inside``
    and at least ``band`` from the outline ``segments`` (M, 2, 2)."""
    band = float(band)
    if not (math.isfinite(band) and band >= 0.0):
        raise LuxError(f"surface {name!r}: the band must be ≥ 0 m, got {band}")
    lo = lo + band
    size = hi - band - lo
    if not (size > 0.0).all():
        raise LuxError(f"surface {name!r}: a band of {band} m leaves no area "
                       f"(the surface spans {(hi - lo + 2 * band).round(6).tolist()} m)")
    if spacing is None:
        p = en12464_spacing(grid_size(size[0], size[1]))
        pu = pv = p
    else:
        pu, pv = (float(spacing), float(spacing)) if np.ndim(spacing) == 0 else (float(s) for s in spacing)
    cols, rows = points_per_side(size[0], pu), points_per_side(size[1], pv)
    du, dv = size[0] / cols, size[1] / rows
    jj, ii = np.mgrid[0:rows, 0:cols]
    st = np.stack([lo[0] + (ii.ravel() + 0.5) * du, lo[1] + (jj.ravel() + 0.5) * dv], axis=1)
    keep = inside(st)
    if band > 0.0 and len(segments):
        keep &= _segment_distance(st, segments[:, 0], segments[:, 1]).min(axis=1) >= band - 1e-12
    idx = np.nonzero(keep)[0]
    if idx.size == 0:
        raise LuxError(f"surface {name!r}: no grid point falls inside the surface (band {band} m)")
    corner = origin + lo[0] * u + lo[1] * v
    pts = origin + st[idx, :1] * u + st[idx, 1:] * v
    return CalculationSurface(
        name=name, kind=kind, points=pts, normals=np.tile(n, (idx.size, 1)), weights=np.full(idx.size, du * dv),
        band=band, maintenance_factor=mf, grid_shape=(rows, cols), spacing=(du, dv), grid_index=idx,
        origin=corner, axis_u=u, axis_v=v, outline=segments - lo[None, None, :])


def rectangle_grid(origin, edge_u, edge_v, *, name="grid", normal=None, spacing=None, band=0.0,
                   maintenance_factor=1.0) -> CalculationSurface:
    """A grid over the rectangle ``origin + s · edge_u + t · edge_v`` (s, t in [0, 1]), in any
    orientation. The edges must be perpendicular. The points face ``cross(edge_u, edge_v)``, or
    ``normal`` if given (it must be perpendicular to the rectangle; either side)."""
    origin = np.asarray(origin, dtype=np.float64).reshape(3)
    eu, ev = np.asarray(edge_u, float).reshape(3), np.asarray(edge_v, float).reshape(3)
    u, v = _unit(eu, "edge_u"), _unit(ev, "edge_v")
    if abs(float(np.dot(u, v))) > 1e-9:
        raise LuxError(f"surface {name!r}: the rectangle's edges must be perpendicular (cos = {np.dot(u, v):.3g})")
    n = np.cross(u, v)
    if normal is not None:
        nn = _unit(normal, "normal")
        if abs(abs(float(np.dot(nn, n))) - 1.0) > 1e-9:
            raise LuxError(f"surface {name!r}: the normal must be perpendicular to the rectangle")
        n = nn
    a, b = float(np.linalg.norm(eu)), float(np.linalg.norm(ev))
    corners = np.array([[0, 0], [a, 0], [a, b], [0, b]], float)
    segs = np.stack([corners, np.roll(corners, -1, axis=0)], axis=1)
    return _planar_grid(name, "grid", origin, u, v, n, np.zeros(2), np.array([a, b]),
                        lambda st: np.ones(st.shape[0], bool), segs, spacing, band, maintenance_factor)


def _plane_of(points, name, tol):
    c = points.mean(axis=0)
    _, s, vt = np.linalg.svd(points - c)
    n = vt[2]
    scale = max(float(np.ptp(points, axis=0).max()), 1e-12)
    off = np.abs((points - c) @ n).max()
    if off > tol * scale:
        raise LuxError(f"surface {name!r} is not planar (a vertex lies {off:.3g} m off its plane)")
    return c, n


def _polygon3(vertices, name, what="a polygon"):
    verts = np.asarray(vertices, dtype=np.float64)
    if verts.ndim == 2 and verts.shape[1] == 2:
        verts = np.concatenate([verts, np.zeros((verts.shape[0], 1))], axis=1)
    if verts.ndim != 2 or verts.shape[1] != 3 or verts.shape[0] < 3 or not np.isfinite(verts).all():
        raise LuxError(f"surface {name!r}: {what} needs at least 3 finite vertices (K, 3), got {verts.shape}")
    return verts


def polygon_grid(vertices, *, name="grid", normal=None, axis_u=None, spacing=None, band=0.0,
                 maintenance_factor=1.0, kind="grid", holes=(), hole_band=None) -> CalculationSurface:
    """A grid over a planar simple polygon (K, 3) (or (K, 2): in the plane z = 0): points at the
    cell centres of a regular grid over the polygon's bounding box in its plane, kept where
    inside the polygon and at least ``band`` m from its outline. The points face the side the
    vertex order winds counter-clockwise around (right-hand rule), or ``normal``.

    ``holes``: polygons (each (K, 3) or (K, 2), in the same plane, inside the outline, either
    winding) cut out of the area (a courtyard, a column, a stair well): points inside a hole are
    dropped, and points closer than ``hole_band`` m to a hole's edge too (None: ``band``, the
    band at the walls). EN 12464-1 leaves the band around columns and other obstacles to the
    designer; 0 keeps every point outside the holes."""
    verts = _polygon3(vertices, name)
    hole_list = [_polygon3(h, name, f"hole {k}") for k, h in enumerate(holes)]
    hole_band = band if hole_band is None else hole_band
    try:
        hole_band = float(hole_band)
    except (TypeError, ValueError):
        raise LuxError(f"surface {name!r}: the band at the holes must be a number of metres") from None
    if not (math.isfinite(hole_band) and hole_band >= 0.0):
        raise LuxError(f"surface {name!r}: the band at the holes must be ≥ 0 m, got {hole_band}")
    c, n = _plane_of(verts, name, 1e-6)
    newell = np.cross(verts, np.roll(verts, -1, axis=0)).sum(axis=0)
    if np.linalg.norm(newell) <= 1e-12:
        raise LuxError(f"surface {name!r}: the polygon has no area")
    n = newell / np.linalg.norm(newell)
    if normal is not None:
        nn = _unit(normal, "normal")
        if abs(abs(float(np.dot(nn, n))) - 1.0) > 1e-6:
            raise LuxError(f"surface {name!r}: the normal must be perpendicular to the polygon")
        n = nn
    u, v, n = _frame(n, axis_u)
    st = np.stack([(verts - c) @ u, (verts - c) @ v], axis=1)
    segs = np.stack([st, np.roll(st, -1, axis=0)], axis=1)
    scale = max(float(np.ptp(verts, axis=0).max()), 1e-12)
    hole_st = []
    for k, h in enumerate(hole_list):
        off = np.abs((h - c) @ n).max()
        if off > 1e-6 * scale:
            raise LuxError(f"surface {name!r}: hole {k} is not in the polygon's plane (a vertex lies {off:.3g} m "
                           "off it)")
        hs = np.stack([(h - c) @ u, (h - c) @ v], axis=1)
        if not _inside_polygon(hs, st).all():
            raise LuxError(f"surface {name!r}: hole {k} is not inside the outline")
        hole_st.append(hs)

    def inside(q):
        keep = _inside_polygon(q, st)
        for hs in hole_st:
            keep &= ~_inside_polygon(q, hs)
            if hole_band > 0.0:
                hseg = np.stack([hs, np.roll(hs, -1, axis=0)], axis=1)
                keep &= _segment_distance(q, hseg[:, 0], hseg[:, 1]).min(axis=1) >= hole_band - 1e-12
        return keep

    if hole_st:
        segs = np.concatenate([segs] + [np.stack([hs, np.roll(hs, -1, axis=0)], axis=1) for hs in hole_st])
    grid = _planar_grid(name, kind, c, u, v, n, st.min(axis=0), st.max(axis=0), inside,
                        segs[:len(st)], spacing, band, maintenance_factor)
    if hole_st:  # the outline drawn on plans: the walls and the holes' edges
        grid.outline = segs - (grid.origin - c) @ np.stack([u, v], axis=1)[None, None, :]
    return grid


def face_set_grid(positions, triangles, *, name="grid", normal=None, axis_u=None, spacing=None, band=0.0,
                  maintenance_factor=1.0) -> CalculationSurface:
    """A grid over a planar set of triangles (positions (V, 3), triangles (T, 3)): cell centres of a
    regular grid over the set's plane, kept where inside a triangle and at least ``band`` m from
    the set's outline (its edges used by one triangle only, holes included). The points face the
    triangles' area-weighted normal, or ``normal``."""
    pos = _arr(positions, (3,), "positions")
    tri = _arr(triangles, (3,), "triangles", dtype=np.int64)
    if tri.shape[0] == 0 or tri.min() < 0 or tri.max() >= pos.shape[0]:
        raise LuxError(f"surface {name!r}: triangles must index the {pos.shape[0]} positions")
    used = pos[np.unique(tri)]
    c, plane_n = _plane_of(used, name, 1e-6)
    fn = np.cross(pos[tri[:, 1]] - pos[tri[:, 0]], pos[tri[:, 2]] - pos[tri[:, 0]])
    total = fn.sum(axis=0)
    if normal is not None:
        total = _unit(normal, "normal")
        if abs(abs(float(np.dot(total, plane_n))) - 1.0) > 1e-6:
            raise LuxError(f"surface {name!r}: the normal must be perpendicular to the faces")
    if np.linalg.norm(total) <= 1e-12:
        raise LuxError(f"surface {name!r}: the faces have no net area (give the normal)")
    u, v, n = _frame(total, axis_u)
    st = np.stack([(pos - c) @ u, (pos - c) @ v], axis=1)
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(edges, axis=0, return_counts=True)
    boundary = uniq[count == 1]
    segs = np.stack([st[boundary[:, 0]], st[boundary[:, 1]]], axis=1)
    tri2d = st[tri]
    return _planar_grid(name, "grid", c, u, v, n, st[np.unique(tri)].min(axis=0), st[np.unique(tri)].max(axis=0),
                        lambda q: _inside_triangles(q, tri2d), segs, spacing, band, maintenance_factor)


def workplane(floor, *, height=WORKPLANE_HEIGHT, band=WORKPLANE_BAND, spacing=None, name="work plane",
              maintenance_factor=1.0, holes=(), hole_band=None) -> CalculationSurface:
    """A horizontal work plane ``height`` m above a room's floor polygon (K, 2) (floor at z = 0) or
    (K, 3) (a horizontal floor), normal up, grid axes along world X and Y, ``band`` m left out at
    the walls (EN 12464-1:2021). ``holes``: polygons of the floor's holes (a courtyard, a column's
    footprint), at the floor's level, with ``hole_band`` m left out around them (None: ``band``;
    see :func:`polygon_grid`)."""
    fl = np.asarray(floor, dtype=np.float64)
    if fl.ndim == 2 and fl.shape[1] == 2:
        fl = np.concatenate([fl, np.zeros((fl.shape[0], 1))], axis=1)
    if fl.ndim != 2 or fl.shape[1] != 3 or fl.shape[0] < 3 or not np.isfinite(fl).all():
        raise LuxError(f"surface {name!r}: the floor must be a polygon (K, 2) or (K, 3), got {fl.shape}")
    if np.ptp(fl[:, 2]) > 1e-6:
        raise LuxError(f"surface {name!r}: the floor polygon must be horizontal")
    h = float(height)
    if not math.isfinite(h):
        raise LuxError(f"surface {name!r}: the work plane height must be finite, got {height}")
    lift = np.array([0.0, 0.0, h])
    plane = fl + lift
    raised = []
    for k, hole in enumerate(holes):
        hp = _polygon3(hole, name, f"hole {k}")
        if np.asarray(hole).shape[-1] == 2:
            hp[:, 2] = fl[0, 2]
        if np.abs(hp[:, 2] - fl[0, 2]).max() > 1e-6:
            raise LuxError(f"surface {name!r}: hole {k} must lie at the floor's level")
        raised.append(hp + lift)
    return polygon_grid(plane, name=name, normal=(0.0, 0.0, 1.0), axis_u=(1.0, 0.0, 0.0), spacing=spacing,
                        band=band, maintenance_factor=maintenance_factor, kind="workplane", holes=raised,
                        hole_band=hole_band)


# --------------------------------------------------------------------------- mesh points


def _mesh(positions, triangles, name):
    pos = _arr(positions, (3,), "positions")
    tri = _arr(triangles, (3,), "triangles", dtype=np.int64)
    if tri.shape[0] == 0 or tri.min() < 0 or tri.max() >= pos.shape[0]:
        raise LuxError(f"surface {name!r}: triangles must index the {pos.shape[0]} positions")
    cross = np.cross(pos[tri[:, 1]] - pos[tri[:, 0]], pos[tri[:, 2]] - pos[tri[:, 0]])
    return pos, tri, cross


def mesh_vertex_points(positions, triangles, *, normals=None, name="vertices",
                       maintenance_factor=1.0) -> CalculationSurface:
    """Points on a mesh's vertices (those used by a triangle), with the given vertex ``normals``
    (V, 3) or area-weighted face normals; each weighs a third of its triangles' area."""
    pos, tri, cross = _mesh(positions, triangles, name)
    area = 0.5 * np.linalg.norm(cross, axis=1)
    w = np.zeros(pos.shape[0])
    acc = np.zeros_like(pos)
    for k in range(3):
        np.add.at(w, tri[:, k], area / 3.0)
        np.add.at(acc, tri[:, k], cross)
    used = np.unique(tri)
    if normals is not None:
        acc = _arr(normals, (3,), "normals")
        if acc.shape != pos.shape:
            raise LuxError(f"surface {name!r}: normals must have the positions' shape {pos.shape}")
    bad = used[(np.linalg.norm(acc[used], axis=1) <= 0.0) | (w[used] <= 0.0)]
    if bad.size:
        raise LuxError(f"surface {name!r}: vertex {int(bad[0])} has no normal or no area (degenerate triangles)")
    return CalculationSurface(name=name, kind="vertices", points=pos[used], normals=acc[used], weights=w[used],
                              maintenance_factor=maintenance_factor)


def mesh_face_points(positions, triangles, *, name="faces", maintenance_factor=1.0) -> CalculationSurface:
    """Points at a mesh's triangle centroids with the face normals; each weighs its triangle's area."""
    pos, tri, cross = _mesh(positions, triangles, name)
    area = 0.5 * np.linalg.norm(cross, axis=1)
    if not (area > 0.0).all():
        raise LuxError(f"surface {name!r}: triangle {int(np.argmin(area))} is degenerate")
    return CalculationSurface(name=name, kind="faces", points=pos[tri].mean(axis=1), normals=cross, weights=area,
                              maintenance_factor=maintenance_factor)
