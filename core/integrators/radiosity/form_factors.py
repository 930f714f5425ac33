"""Form factors (Dutré's Global Illumination Compendium, items 55–60).

The compendium names the sender first: F_{i→j} is the fraction of the power leaving a
diffuse patch i that arrives at patch j. These are the NumPy forms, exact where the item
is a closed form; the matrix of a whole scene, with visibility, is computed by the kernel
in ``kernel.py`` from the point-to-polygon formula of item 57 written for triangles.

* item 55, the differential form factor
  dF_{dA_x→dA_y} = cos θ_x cos θ_y / (π r²) · V(x, y) dA_y  (:func:`differential_form_factor`);
* item 57, a point to a polygon without occlusion, Lambert's formula
  F_{dA_x→j} = (1/2π) Σ_i n_x · Γ_i, with Γ_i the unit normal of the plane through x,
  V_i and V_{i+1} scaled by the angle γ_i the edge subtends at x; the polygon is first
  clipped to the hemisphere above x, where the formula holds (:func:`form_factor_point_polygon`);
* item 59, polygon to polygon without occlusion by Stokes' theorem,
  A_i F_{i→j} = (1/2π) ∮_{C_i} ∮_{C_j} ln r dx_i · dx_j (Sparrow 1963; Baum, Rushmeier
  and Winget 1989). Each polygon is clipped to the half-space in front of the other, so
  the pair sees each other only from the front; the inner line integral of ln r over an
  edge is taken in closed form and the outer one by Gauss–Legendre quadrature graded
  towards both ends of each edge, where the integrand's derivative has the logarithmic
  singularity of edges that touch. So pairs that share an edge or a corner are exact to
  about 1e-9 (:func:`form_factor_polygon_polygon`); coplanar pairs give 0;
* item 60, reciprocity A_i F_{i→j} = A_j F_{j→i} and closure Σ_j F_{i→j} = 1 in a closed
  scene: properties the tests check.

Polygons are (N, 3) arrays of vertices, counter-clockwise seen from the side they face
(their front: the normal is (V_1 − V_0) × (V_2 − V_0) for a convex polygon). Surfaces are
one-sided: a point behind a polygon's plane sees none of it.
"""
from __future__ import annotations

import math

import numpy as np

INV_TWO_PI = 0.5 / math.pi


def _polygon(name, a):
    arr = np.asarray(a, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3 or arr.shape[0] < 3:
        raise ValueError(f"{name}: expected an (N ≥ 3, 3) array of vertices, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: contains NaN or Inf")
    return arr


def polygon_normal(poly):
    """Newell's area vector of a planar polygon: its unit normal times twice its area."""
    a = poly
    b = np.roll(poly, -1, axis=0)
    return np.array([np.sum((a[:, 1] - b[:, 1]) * (a[:, 2] + b[:, 2])),
                     np.sum((a[:, 2] - b[:, 2]) * (a[:, 0] + b[:, 0])),
                     np.sum((a[:, 0] - b[:, 0]) * (a[:, 1] + b[:, 1]))])


def polygon_area(poly):
    """Area of a planar polygon (N, 3)."""
    return 0.5 * float(np.linalg.norm(polygon_normal(np.asarray(poly, np.float64))))


def clip_half_space(poly, n, c):
    """The part of polygon ``poly`` where n · x ≥ c (Sutherland–Hodgman against one plane);
    an (M, 3) array, M = 0 when nothing is left."""
    d = poly @ n - c
    out = []
    m = len(poly)
    for k in range(m):
        a, b = poly[k], poly[(k + 1) % m]
        da, db = d[k], d[(k + 1) % m]
        if da >= 0.0:
            out.append(a)
        if (da >= 0.0) != (db >= 0.0):
            t = da / (da - db)
            out.append(a + t * (b - a))
    return np.array(out).reshape(-1, 3)


def differential_form_factor(x, nx, y, ny, visible=True):
    """Item 55: dF_{dA_x→dA_y} / dA_y = cos θ_x cos θ_y V(x, y) / (π r²), per unit area of
    the receiving element at y (unit normals nx, ny; arrays broadcast over leading axes);
    0 where either element faces away. ``visible``: V(x, y) (a bool or array)."""
    x, nx, y, ny = (np.asarray(a, np.float64) for a in (x, nx, y, ny))
    d = y - x
    r2 = np.sum(d * d, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        cx = np.sum(nx * d, axis=-1)
        cy = -np.sum(ny * d, axis=-1)
        f = np.where((cx > 0) & (cy > 0) & (r2 > 0), cx * cy / (np.pi * r2 * r2), 0.0)
    return f * np.asarray(visible, np.float64)


def form_factor_point_polygon(p, n, polygon):
    """Item 57: the form factor F_{dA_p→Q} from a differential element at ``p`` with unit
    normal ``n`` to the polygon Q, without occlusion. Q is clipped to the hemisphere above
    p first; a point behind Q's plane (seeing its back) gives 0."""
    p = np.asarray(p, np.float64).reshape(3)
    n = np.asarray(n, np.float64).reshape(3)
    n = n / np.linalg.norm(n)
    q = _polygon("polygon", polygon)
    nq = polygon_normal(q)
    if not float(nq @ (p - q[0])) > 0.0:
        return 0.0
    r = clip_half_space(q - p, n, 0.0)
    if len(r) < 3:
        return 0.0
    s = 0.0
    for k in range(len(r)):
        a, b = r[k], r[(k + 1) % len(r)]
        c = np.cross(a, b)
        lc = np.linalg.norm(c)
        if lc == 0.0:
            continue
        g = math.atan2(lc, float(a @ b))
        s += g * float(n @ c) / lc
    return max(0.0, -INV_TWO_PI * s)


# Gauss–Legendre rule for the outer edge integral, on sub-intervals graded towards both ends
_GL_X, _GL_W = np.polynomial.legendre.leggauss(10)
_GRADE = 0.25
_N_GRADE = 12


def _outer_rule():
    """Nodes and weights on [0, 1]: sub-intervals [q^(k+1)/2, q^k/2] towards each end."""
    edges = 0.5 * _GRADE ** np.arange(_N_GRADE + 1)
    cuts = np.concatenate([[0.0], edges[::-1], 1.0 - edges[1:]])
    cuts = np.unique(np.concatenate([cuts, [1.0]]))
    xs, ws = [], []
    for a, b in zip(cuts[:-1], cuts[1:]):
        xs.append(a + (b - a) * 0.5 * (_GL_X + 1.0))
        ws.append(0.5 * (b - a) * _GL_W)
    return np.concatenate(xs), np.concatenate(ws)


_OUTER_X, _OUTER_W = _outer_rule()


def _log_distance_integral(x, b0, db):
    """∫_0^1 ln |x − (b0 + t db)| dt for points x (..., 3): in closed form."""
    ln = float(np.linalg.norm(db))
    u = db / ln
    w = x - b0
    a = w @ u
    h2 = np.maximum(np.sum(w * w, axis=-1) - a * a, 0.0)
    h = np.sqrt(h2)

    def g(t):
        q = t * t + h2
        with np.errstate(divide="ignore", invalid="ignore"):
            lg = np.where(q > 0.0, t * np.log(np.where(q > 0.0, q, 1.0)), 0.0)
            at = np.where(h > 0.0, 2.0 * h * np.arctan(t / np.where(h > 0.0, h, 1.0)), 0.0)
        return 0.5 * (lg - 2.0 * t + at)

    return (g(ln - a) - g(-a)) / ln


def form_factor_polygon_polygon(P, Q):
    """Item 59: the form factor F_{P→Q} between two polygons without occlusion, by the
    double contour integral of Stokes' theorem (see the module text). Returns 0 when they
    cannot see each other's front (coplanar, back to back, or one behind the other)."""
    p = _polygon("P", P)
    q = _polygon("Q", Q)
    n_p = polygon_normal(p)
    n_q = polygon_normal(q)
    a_p = 0.5 * np.linalg.norm(n_p)
    a_q = 0.5 * np.linalg.norm(n_q)
    if not (a_p > 0.0 and a_q > 0.0):
        return 0.0
    n_p /= 2.0 * a_p
    n_q /= 2.0 * a_q
    scale = max(np.ptp(np.concatenate([p, q]), axis=0).max(), 1e-300)
    tol = 1e-12 * scale
    # each polygon's part in front of the other
    p_c = clip_half_space(p, n_q, float(n_q @ q[0]) + tol)
    q_c = clip_half_space(q, n_p, float(n_p @ p[0]) + tol)
    if len(p_c) < 3 or len(q_c) < 3 or polygon_area(p_c) <= 1e-14 * a_p or polygon_area(q_c) <= 1e-14 * a_q:
        return 0.0
    total = 0.0
    for k in range(len(p_c)):
        a0 = p_c[k]
        da = p_c[(k + 1) % len(p_c)] - a0
        if not np.any(da):
            continue
        xs = a0 + _OUTER_X[:, None] * da
        for m in range(len(q_c)):
            b0 = q_c[m]
            db = q_c[(m + 1) % len(q_c)] - b0
            dot = float(da @ db)
            if dot == 0.0:
                continue
            total += dot * float(_OUTER_W @ _log_distance_integral(xs, b0, db))
    return max(0.0, INV_TWO_PI * total / a_p)
