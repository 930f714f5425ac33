"""Hair curves → triangles: round tubes and camera-facing ribbons (numpy only, no kernel).

Curves (hair strands) are given as polylines: ``points`` float64 (K, 3) the keys of every
curve one after another, ``radii`` (K,) the radius at each key, ``counts`` (C,) the keys
per curve (at least 2). They are tessellated into an ordinary triangle mesh with smooth
shading normals, which the BVH and the path kernel render unchanged; a scene without
curves pays nothing.

* Round (Cycles' "3D curves"): a tube of ``sides`` faces around each segment, its rings
  oriented by a rotation-minimising frame (Wang et al. 2008, "Computation of rotation
  minimizing frames", the double-reflection method) so that the tube does not twist. The
  ring vertices lie at ``r · π / (sides · sin(π / sides))``: by Cauchy's formula the mean
  width of a convex polygon is its perimeter over π, so this radius gives the tube the
  projected area of the true cylinder, 2·r·L, averaged over the view directions around
  its axis. Seen from one direction the width is within a factor cos(π / sides) of that
  mean (the polygonal silhouette). The normals are those of the cylinder (radial).
* Keys are joined through Cycles' spline: a uniform Catmull-Rom spline through the keys
  (the first and last key repeated at the ends), radius interpolated alike.
  :func:`catmull_rom_refine` splits each segment into enough straight pieces that the
  spline turns by about ``max_angle`` at most over each, so straight strands keep their keys.
* Ribbon (Cycles' "ribbons"): a flat strip of width 2·r across each segment facing the
  eye (a perspective camera's position, or against an orthographic camera's direction).
  Its shading normals bend across the strip as those of a cylinder seen from the eye,
  N = v·b + √(1 − v²)·f for v ∈ [−1, 1] across the width (b the strip's width direction,
  f towards the eye), which is how Cycles shades ribbons; ``columns`` strips across the
  width carry that curve.
"""
import math

import numpy as np

ROUND = "round"
RIBBON = "ribbon"
DEFAULT_SIDES = 6
DEFAULT_COLUMNS = 4
MAX_SIDES = 64


def area_preserving_radius(radius, sides):
    """The circumradius of a regular ``sides``-gon whose mean width equals a circle's of ``radius``."""
    n = int(sides)
    return radius * math.pi / (n * math.sin(math.pi / n))


def silhouette_range(sides):
    """(least, most) width of the tessellated tube seen across its axis, over the round curve's 2·r."""
    n = int(sides)
    most = math.pi / (n * math.sin(math.pi / n))
    return most * math.cos(math.pi / n), most


def triangle_count(counts, shape=ROUND, sides=DEFAULT_SIDES, columns=DEFAULT_COLUMNS):
    """Triangles of the tessellated curves: 2 · (around) per segment."""
    segments = int(np.sum(np.maximum(np.asarray(counts, np.int64) - 1, 0)))
    return 2 * segments * (int(sides) if shape == ROUND else int(columns))


def _tangents(p):
    """Unit tangents (n, k, 3) of polylines (n, k, 3): central differences, one-sided at the ends."""
    t = np.empty_like(p)
    t[:, 1:-1] = p[:, 2:] - p[:, :-2]
    t[:, 0] = p[:, 1] - p[:, 0]
    t[:, -1] = p[:, -1] - p[:, -2]
    length = np.linalg.norm(t, axis=2, keepdims=True)
    bad = length[..., 0] <= 0.0
    t = np.where(length > 0.0, t / np.where(length > 0.0, length, 1.0), 0.0)
    if bad.any():  # repeated keys: borrow a neighbour's tangent, else +Z
        for j in range(1, t.shape[1]):
            fix = bad[:, j]
            t[fix, j] = t[fix, j - 1]
            bad[fix, j] = bad[fix, j - 1]
        for j in range(t.shape[1] - 2, -1, -1):
            fix = bad[:, j]
            t[fix, j] = t[fix, j + 1]
            bad[fix, j] = bad[fix, j + 1]
        t[bad] = (0.0, 0.0, 1.0)
    return t


def _perpendicular(t):
    """A unit vector perpendicular to each unit vector of ``t`` (n, 3)."""
    axis = np.where(np.abs(t[:, :1]) < 0.9, np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 0.0]]))
    u = np.cross(t, axis)
    return u / np.linalg.norm(u, axis=1, keepdims=True)


def _rotation_minimising_frames(p, t):
    """Reference vectors u (n, k, 3) perpendicular to the tangents, transported without twist."""
    n, k, _ = p.shape
    u = np.empty_like(p)
    u[:, 0] = _perpendicular(t[:, 0])
    for j in range(k - 1):
        v1 = p[:, j + 1] - p[:, j]
        c1 = np.einsum("ij,ij->i", v1, v1)[:, None]
        safe1 = np.where(c1 > 0.0, c1, 1.0)
        r_l = u[:, j] - (2.0 / safe1) * np.einsum("ij,ij->i", v1, u[:, j])[:, None] * v1
        t_l = t[:, j] - (2.0 / safe1) * np.einsum("ij,ij->i", v1, t[:, j])[:, None] * v1
        r_l = np.where(c1 > 0.0, r_l, u[:, j])
        t_l = np.where(c1 > 0.0, t_l, t[:, j])
        v2 = t[:, j + 1] - t_l
        c2 = np.einsum("ij,ij->i", v2, v2)[:, None]
        safe2 = np.where(c2 > 0.0, c2, 1.0)
        nxt = r_l - (2.0 / safe2) * np.einsum("ij,ij->i", v2, r_l)[:, None] * v2
        nxt = np.where(c2 > 1e-30, nxt, r_l)
        # keep it exactly perpendicular and of unit length (rounding over many keys)
        nxt -= np.einsum("ij,ij->i", nxt, t[:, j + 1])[:, None] * t[:, j + 1]
        length = np.linalg.norm(nxt, axis=1, keepdims=True)
        ok = length[:, 0] > 1e-12
        nxt[ok] /= length[ok]
        if not ok.all():
            nxt[~ok] = _perpendicular(t[~ok, j + 1])
        u[:, j + 1] = nxt
    return u


def _grid_indices(n_curves, n_keys, around, closed):
    """Triangles of a grid of ``n_keys`` rings of ``around`` (+1 when open) vertices per curve."""
    ring = around if closed else around + 1
    k = np.arange(n_keys - 1)[:, None]
    s = np.arange(around)[None, :]
    s1 = (s + 1) % ring if closed else s + 1
    a = k * ring + s
    b = k * ring + s1
    c = (k + 1) * ring + s1
    d = (k + 1) * ring + s
    quad = np.stack([np.stack([a, b, c], -1), np.stack([a, c, d], -1)], -2).reshape(-1, 3)
    base = (np.arange(n_curves) * n_keys * ring)[:, None, None]
    return (quad[None] + base).reshape(-1, 3)


def _group(points, radii, counts):
    """Yield (curve indices, points (n, k, 3), radii (n, k)) for the curves of each key count k."""
    counts = np.asarray(counts, np.int64)
    first = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    for k in np.unique(counts):
        if k < 2:
            continue
        sel = np.nonzero(counts == k)[0]
        idx = first[sel][:, None] + np.arange(k)[None, :]
        yield sel, points[idx], radii[idx]


def tessellate(points, radii, counts, shape=ROUND, sides=DEFAULT_SIDES, columns=DEFAULT_COLUMNS, eye=None,
               view_dir=None):
    """(positions float32 (V, 3), indices int32 (T, 3), normals float32 (V, 3), curve int32 (T,)) of curves.

    ``shape`` ROUND (tubes of ``sides`` faces) or RIBBON (strips of ``columns`` columns facing
    ``eye``, a point, or facing against ``view_dir``, a direction; one of them is needed).
    ``curve`` gives each triangle's curve (an index into ``counts``). Curves of fewer than 2
    keys are dropped.
    """
    points = np.asarray(points, np.float64).reshape(-1, 3)
    radii = np.asarray(radii, np.float64).reshape(-1)
    counts = np.asarray(counts, np.int64).reshape(-1)
    if points.shape[0] != radii.shape[0] or int(counts.sum()) != points.shape[0]:
        raise ValueError(f"curves: {points.shape[0]} points, {radii.shape[0]} radii and {int(counts.sum())} "
                         "keys counted do not agree")
    if shape not in (ROUND, RIBBON):
        raise ValueError(f"curves: unknown shape {shape!r} (round or ribbon)")
    if shape == ROUND and not 3 <= int(sides) <= MAX_SIDES:
        raise ValueError(f"curves: {sides} sides (3 to {MAX_SIDES})")
    if shape == RIBBON and eye is None and view_dir is None:
        raise ValueError("curves: a ribbon needs the eye or the view direction it faces")
    pos_parts, idx_parts, nrm_parts, cur_parts = [], [], [], []
    n_vertices = 0
    for sel, p, r in _group(points, radii, counts):
        n, k, _ = p.shape
        t = _tangents(p)
        if shape == ROUND:
            u = _rotation_minimising_frames(p, t)
            w = np.cross(t, u)
            theta = 2.0 * math.pi * np.arange(sides) / sides
            cos, sin = np.cos(theta), np.sin(theta)
            normal = cos[None, None, :, None] * u[:, :, None, :] + sin[None, None, :, None] * w[:, :, None, :]
            rr = area_preserving_radius(1.0, sides) * r
            pos = p[:, :, None, :] + rr[:, :, None, None] * normal
            idx = _grid_indices(n, k, sides, closed=True)
            per_curve = 2 * (k - 1) * sides
        else:
            if eye is not None:
                to_eye = np.asarray(eye, np.float64).reshape(1, 1, 3) - p
            else:
                to_eye = np.broadcast_to(-np.asarray(view_dir, np.float64).reshape(1, 1, 3), p.shape).copy()
            f = to_eye - np.einsum("nkj,nkj->nk", to_eye, t)[..., None] * t
            length = np.linalg.norm(f, axis=2, keepdims=True)
            along = length[..., 0] <= 1e-12  # the eye on the curve's line: any perpendicular
            if along.any():
                f[along] = _perpendicular(t[along])
                length[along] = 1.0
            f = f / length
            b = np.cross(t, f)
            v = np.linspace(-1.0, 1.0, columns + 1)
            normal = (v[None, None, :, None] * b[:, :, None, :]
                      + np.sqrt(np.maximum(1.0 - v * v, 0.0))[None, None, :, None] * f[:, :, None, :])
            pos = p[:, :, None, :] + (r[:, :, None] * v[None, None, :])[..., None] * b[:, :, None, :]
            idx = _grid_indices(n, k, columns, closed=False)
            per_curve = 2 * (k - 1) * columns
        pos_parts.append(pos.reshape(-1, 3))
        nrm_parts.append(normal.reshape(-1, 3))
        idx_parts.append(idx + n_vertices)
        cur_parts.append(np.repeat(sel, per_curve))
        n_vertices += pos.shape[0] * pos.shape[1] * pos.shape[2]
    if not pos_parts:
        return (np.zeros((0, 3), np.float32), np.zeros((0, 3), np.int32), np.zeros((0, 3), np.float32),
                np.zeros(0, np.int32))
    if n_vertices >= 2**31:
        raise ValueError(f"curves: {n_vertices} vertices (more than a mesh can index)")
    return (np.ascontiguousarray(np.concatenate(pos_parts), np.float32),
            np.ascontiguousarray(np.concatenate(idx_parts), np.int32),
            np.ascontiguousarray(np.concatenate(nrm_parts), np.float32),
            np.ascontiguousarray(np.concatenate(cur_parts), np.int32))


def _catmull_rom(p0, p1, p2, p3, t):
    """The uniform Catmull-Rom spline through p1 (t = 0) and p2 (t = 1); t broadcasts as (n, 1)."""
    t2 = t * t
    t3 = t2 * t
    return 0.5 * ((-t3 + 2.0 * t2 - t) * p0 + (3.0 * t3 - 5.0 * t2 + 2.0) * p1
                  + (-3.0 * t3 + 4.0 * t2 + t) * p2 + (t3 - t2) * p3)


def catmull_rom_refine(points, radii, counts, max_angle=math.radians(15.0), max_pieces=4):
    """(points, radii, counts) of the curves with each segment split along the Catmull-Rom spline
    through the keys into ceil(turn / ``max_angle``) pieces (at most ``max_pieces``), ``turn``
    the angle the spline's tangent turns through over the segment. The keys stay."""
    points = np.asarray(points, np.float64).reshape(-1, 3)
    radii = np.asarray(radii, np.float64).reshape(-1)
    counts = np.asarray(counts, np.int64).reshape(-1)
    first = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    last = first + counts - 1
    curve_of_seg = np.repeat(np.arange(counts.size), np.maximum(counts - 1, 0))
    if curve_of_seg.size == 0:
        return points, radii, counts
    segs = np.maximum(counts - 1, 0)
    seg_first = np.concatenate([[0], np.cumsum(segs)[:-1]]).astype(np.int64)
    seg_start = first[curve_of_seg] + np.arange(curve_of_seg.size) - seg_first[curve_of_seg]
    k0, k1 = seg_start, seg_start + 1
    ka = np.maximum(k0 - 1, first[curve_of_seg])
    kb = np.minimum(k1 + 1, last[curve_of_seg])
    q = np.concatenate([points, radii[:, None]], axis=1)  # position and radius, interpolated alike
    # the spline's turning over the segment: the angles between its tangents at 5 points along it
    tt = np.linspace(0.0, 1.0, 5)
    w = 0.5 * np.stack([-3.0 * tt**2 + 4.0 * tt - 1.0, 9.0 * tt**2 - 10.0 * tt, -9.0 * tt**2 + 8.0 * tt + 1.0,
                        3.0 * tt**2 - 2.0 * tt], 1)  # d/dt of the Catmull-Rom weights
    tangent = sum(w[None, :, i, None] * points[k][:, None, :] for i, k in enumerate((ka, k0, k1, kb)))
    length = np.linalg.norm(tangent, axis=2, keepdims=True)
    tangent = np.where(length > 0.0, tangent / np.where(length > 0.0, length, 1.0), 0.0)
    cos = (tangent[:, 1:] * tangent[:, :-1]).sum(axis=2)
    turn = np.arccos(np.clip(cos, -1.0, 1.0)).sum(axis=1)
    pieces = np.clip(np.ceil(turn / max_angle - 1e-9), 1, max_pieces).astype(np.int64)
    seg_of_piece = np.repeat(np.arange(k0.size), pieces)
    offset = np.concatenate([[0], np.cumsum(pieces)[:-1]])
    t = ((np.arange(seg_of_piece.size) - offset[seg_of_piece]) / pieces[seg_of_piece])[:, None]
    s = seg_of_piece
    inner = _catmull_rom(q[ka[s]], q[k0[s]], q[k1[s]], q[kb[s]], t)
    # each curve: its segments' pieces, then its last key
    per_curve = np.bincount(curve_of_seg, weights=pieces, minlength=counts.size).astype(np.int64)
    new_counts = np.where(counts >= 2, per_curve + 1, counts)
    out = np.empty((int(new_counts.sum()), 4))
    new_first = np.concatenate([[0], np.cumsum(new_counts)[:-1]]).astype(np.int64)
    piece_curve = curve_of_seg[s]
    piece_first = np.concatenate([[0], np.cumsum(per_curve)[:-1]]).astype(np.int64)
    out[new_first[piece_curve] + np.arange(s.size) - piece_first[piece_curve]] = inner
    ends = np.nonzero(counts >= 2)[0]
    out[new_first[ends] + new_counts[ends] - 1] = q[last[ends]]
    single = np.nonzero(counts == 1)[0]
    out[new_first[single]] = q[first[single]]
    return out[:, :3], np.maximum(out[:, 3], 0.0), new_counts


def shape_radius(shape, root, tip, time):
    """Cycles' radius along a particle hair strand: ``time`` ∈ [0, 1] root → tip, ``shape`` ∈ [−1, 1]
    bends the taper (0 linear; negative thicker towards the root, positive towards the tip)."""
    x = 1.0 - np.clip(np.asarray(time, np.float64), 0.0, 1.0)
    if shape < 0.0:
        x = x ** (1.0 + shape)
    elif shape > 0.0:
        x = x ** (1.0 / (1.0 - shape)) if shape < 1.0 else np.where(x >= 1.0, 1.0, 0.0)
    return x * (root - tip) + tip
