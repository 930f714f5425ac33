"""The radiosity kernel: one entry kernel, ``radiosity_rays``, whose integer ``op`` picks
one of three loops over rows of receivers (points with a normal):

* OP_FORM_FACTORS: out[r, c] = F_{r→cols[c]}, the form factor from receiver r (the mean
  over its K sample points) to patch cols[c], with visibility (compendium item 58 in its
  second form, a point-to-area integral averaged over the receiver): at each sample point
  x the unoccluded factor of the whole triangle by Lambert's formula (item 57, the
  triangle clipped to the hemisphere above x), times the visible share of n_vis shadow
  rays from x to stratified points of the triangle (a scrambled (0, 2)-net), each ray
  weighted by the differential form factor cos θ_x cos θ_y / r² (item 55) of its point, so
  that the share is that of the factor, ∫ V dF / ∫ dF, and not of the area.
  Exact where nothing occludes, and the closure Σ_j F_{x→j} = 1 of a closed scene then
  holds at every sample point (item 60);
* OP_DIRECT: out[r, l] = the mean over r's sample points and n_vis light samples of
  cos θ · fac / pdf · V for analytic light l (core/lights/kernel.py ``sample_light``:
  area lights by area, spheres and the sun by cone, delta lights exactly), i.e. the direct
  irradiance from light l per unit of its ``light_scale · shape``; column L (one past the
  lights): π times the fraction of cosine-distributed rays that leave the scene, the
  irradiance from a constant sky of radiance 1;
* OP_SHOOT: hits[k] = the patch that ray k, leaving a uniform point of patch src[k] in a
  cosine-distributed direction about its normal, reaches first (-1: none, or a side that
  is not a patch): the step of the stochastic shooting solver;
* OP_CAMERA: row r is pixel own[r] of a cols[0] × cols[1] image; n_vis camera rays
  through it (core/camera/kernel.py ``camera_ray``, the path tracer's camera and pixel
  filter) find the patch each reaches first: out[r, 3s:3s+3] = (patch, b1, b2) of ray s,
  the patch (-1: none) and the barycentric coordinates of the hit on its corners
  v0 + b1 e1 + b2 e2: the first hits of the final gather;
* OP_GATHER: row r is a point pts[r, 0] on a patch with normal nrm[r] (key own[r]); n_vis
  cosine-distributed gather rays from it (stratified, a scrambled (0, 2)-net) find the
  patch each reaches first: out[r, 3s:3s+3] = (patch, b1, b2) as for OP_CAMERA: the
  final gather's reading of the solution;
* OP_EMITTERS: OP_FORM_FACTORS with adaptive visibility, for the pairs that carry direct
  light (an emitting patch and its receivers): the first EMIT_FIRST shadow rays of each
  (point, patch) pair and three rays to the patch's corners decide; where some arrive and
  some do not (the point is in a penumbra of that patch; a straight shadow edge across the
  triangle always separates its corners) the pair goes on to n_vis rays, continuing the
  same (0, 2)-sequence, so a penumbra's visibility is resolved by n_vis rays where a full
  or an empty view costs EMIT_FIRST + 3.

Random numbers are a pure function of (seed, row, sample point, column, ray), the row being
the receiver's own patch where it has one, so results do not depend on threads or on how
rows are split or batched: the shadow rays and light samples of one
(point, column) pair are the first points of an Owen-scrambled (0, 2)-sequence
(core/sampling/rng.py ``sobol_pair_both``), a shot ray's four numbers independent uniforms
(``uniform``). The kernel is serial and releases the GIL;
the callers run blocks of rows on a pool of threads.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ...camera.kernel import camera_ray
from ...jit import function, inline, kernel
from ...geometry.bvh import trace_closest, trace_occluded
from ...lights.kernel import sample_light
from ...sampling.rng import mix64, sobol_pair_both, uniform
from ...sampling.warps import sample_cosine_hemisphere, sample_triangle_area

OP_FORM_FACTORS = 0
OP_DIRECT = 1
OP_SHOOT = 2
OP_CAMERA = 3
OP_GATHER = 4
OP_EMITTERS = 5
EMIT_FIRST = 16  # OP_EMITTERS: shadow rays per pair before it decides whether the pair is in a penumbra

INV_TWO_PI = 0.5 / math.pi


class PatchRecord(NamedTuple):
    """n patches (oriented triangles) and the BVH of the scene's geometry.

    v0, e1, e2: float64 (n, 3) each patch's first corner and edges, counter-clockwise seen
        from its front; nrm: float64 (n, 3) unit front normals.
    nodes, tris: the BVH (core/geometry/bvh.py) over the geometry triangles.
    tri_patch: int32 (T, 2) for each triangle in the BVH's leaf order the patch of its
        front side (column 0, the side of e1 × e2 of the geometry triangle) and of its
        back (column 1); -1 where that side is not a patch.
    tri_nrm: float64 (T, 3) the geometric normals of the triangles in leaf order.
    occ_nodes, occ_tris: the BVH that shadow rays (OP_FORM_FACTORS, OP_DIRECT) test: over
        the scene's triangles before subdivision, which cover the same surface as the
        patches' geometry with far fewer nodes (or the same tree as nodes, tris).
    """

    v0: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    nrm: np.ndarray
    nodes: np.ndarray
    tris: np.ndarray
    tri_patch: np.ndarray
    tri_nrm: np.ndarray
    occ_nodes: np.ndarray
    occ_tris: np.ndarray


class QueryRecord(NamedTuple):
    """R receivers: pts float64 (R, K, 3) sample points, nrm float64 (R, 3) unit normals,
    own int32 (R,) the receiver's own patch (skipped; -1 none; OP_CAMERA: the pixel; OP_GATHER:
    the key of its random numbers), cols int32 (C,) the patches of OP_FORM_FACTORS' columns
    (OP_CAMERA: the image's width and height), src int32 (N,) the source patch of each ray
    of OP_SHOOT, cam and filt float64 the camera vector and pixel-filter distribution
    (core/camera/record.py) of OP_CAMERA."""

    pts: np.ndarray
    nrm: np.ndarray
    own: np.ndarray
    cols: np.ndarray
    src: np.ndarray
    cam: np.ndarray
    filt: np.ndarray


class LightRecord(NamedTuple):
    """The analytic lights as core/lights/record.py packs them: kind int32 (L,), geo float64
    (L, LG_SIZE), prof float64, two int32 (L,)."""

    kind: np.ndarray
    geo: np.ndarray
    prof: np.ndarray
    two: np.ndarray


@inline
def _seed(seed, a, b, c):
    k = mix64(np.uint64(seed) * np.uint64(0x9E3779B97F4A7C15) + np.uint64(0x2545F4914F6CDD1D))
    k = mix64(k ^ (np.uint64(a) * np.uint64(0xBF58476D1CE4E5B9)))
    k = mix64(k ^ (np.uint64(b) * np.uint64(0x94D049BB133111EB)))
    return mix64(k ^ (np.uint64(c) * np.uint64(0x9E3779B97F4A7C15)))


@function
def ff_point_triangle(px, py, pz, nx, ny, nz, v0, e1, e2, nrm, j, poly):
    """Item 57 for patch j seen from p (unit normal n): the triangle clipped to the
    hemisphere n · (y − p) ≥ 0 (Sutherland–Hodgman into ``poly``, float64 (≥ 4, 3)), then
    −1/(2π) Σ γ_k n · (R_k × R_k+1)/|R_k × R_k+1|. 0 when p is behind the triangle or in
    its plane."""
    ax = v0[j, 0] - px
    ay = v0[j, 1] - py
    az = v0[j, 2] - pz
    # in the triangle's plane (to rounding) counts as behind: a point sees a polygon in its own
    # plane edge-on, F = 0, where the formula would give 1 for a point inside it (the patch on
    # the other side of a receiver's own triangle)
    if -(ax * nrm[j, 0] + ay * nrm[j, 1] + az * nrm[j, 2]) <= 1e-9 * (abs(ax) + abs(ay) + abs(az)):
        return 0.0
    m = 0
    for k in range(3):
        # corner k and k + 1 relative to p
        if k == 0:
            cx, cy, cz = ax, ay, az
        elif k == 1:
            cx, cy, cz = ax + e1[j, 0], ay + e1[j, 1], az + e1[j, 2]
        else:
            cx, cy, cz = ax + e2[j, 0], ay + e2[j, 1], az + e2[j, 2]
        if k == 0:
            dx, dy, dz = ax + e1[j, 0], ay + e1[j, 1], az + e1[j, 2]
        elif k == 1:
            dx, dy, dz = ax + e2[j, 0], ay + e2[j, 1], az + e2[j, 2]
        else:
            dx, dy, dz = ax, ay, az
        dc = nx * cx + ny * cy + nz * cz
        dd = nx * dx + ny * dy + nz * dz
        if dc >= 0.0:
            poly[m, 0] = cx
            poly[m, 1] = cy
            poly[m, 2] = cz
            m += 1
        if (dc >= 0.0) != (dd >= 0.0):
            t = dc / (dc - dd)
            poly[m, 0] = cx + t * (dx - cx)
            poly[m, 1] = cy + t * (dy - cy)
            poly[m, 2] = cz + t * (dz - cz)
            m += 1
    if m < 3:
        return 0.0
    s = 0.0
    for k in range(m):
        k1 = k + 1 if k + 1 < m else 0
        rx, ry, rz = poly[k, 0], poly[k, 1], poly[k, 2]
        qx, qy, qz = poly[k1, 0], poly[k1, 1], poly[k1, 2]
        cx = ry * qz - rz * qy
        cy = rz * qx - rx * qz
        cz = rx * qy - ry * qx
        lc = math.sqrt(cx * cx + cy * cy + cz * cz)
        if lc == 0.0:
            continue
        g = math.atan2(lc, rx * qx + ry * qy + rz * qz)
        s += g * (nx * cx + ny * cy + nz * cz) / lc
    return max(0.0, -INV_TWO_PI * s)


@inline
def _triangle_point(v0, e1, e2, j, u, v):
    _b0, b1, b2 = sample_triangle_area(u, v)
    return (v0[j, 0] + b1 * e1[j, 0] + b2 * e2[j, 0], v0[j, 1] + b1 * e1[j, 1] + b2 * e2[j, 1],
            v0[j, 2] + b1 * e1[j, 2] + b2 * e2[j, 2])


@inline
def _frame(nx, ny, nz):
    """Orthonormal tangents (t, b) of the unit vector n (Duff et al. 2017)."""
    sgn = 1.0 if nz >= 0.0 else -1.0
    a = -1.0 / (sgn + nz)
    b = nx * ny * a
    return 1.0 + sgn * nx * nx * a, sgn * b, -sgn * nx, b, sgn + ny * ny * a, -ny


@inline
def _corners_seen(pat, j, ox, oy, oz, eps, stack):
    """How many of patch j's three corners (each moved in by 1e-3 of the way to the
    opposite edge's ends, off the edges) the point o sees past the occluders."""
    n = 0
    for k in range(3):
        b1 = 0.998 if k == 1 else 0.001
        b2 = 0.998 if k == 2 else 0.001
        dx = pat.v0[j, 0] + b1 * pat.e1[j, 0] + b2 * pat.e2[j, 0] - ox
        dy = pat.v0[j, 1] + b1 * pat.e1[j, 1] + b2 * pat.e2[j, 1] - oy
        dz = pat.v0[j, 2] + b1 * pat.e1[j, 2] + b2 * pat.e2[j, 2] - oz
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        if d <= eps or not trace_occluded(ox, oy, oz, dx / d, dy / d, dz / d, 0.0, d - eps, pat.occ_nodes,
                                          pat.occ_tris, stack):
            n += 1
    return n


@function
def _form_factor_row(pat, qry, r, n_first, n_vis, seed, eps, out, poly, stack):
    nx = qry.nrm[r, 0]
    ny = qry.nrm[r, 1]
    nz = qry.nrm[r, 2]
    n_pts = qry.pts.shape[1]
    inv_k = 1.0 / n_pts
    own = qry.own[r]
    key = own if own >= 0 else r  # a patch's row gets the same numbers however rows are batched
    for c in range(qry.cols.shape[0]):
        j = qry.cols[c]
        if j == own:
            out[r, c] = 0.0
            continue
        acc = 0.0
        for s in range(n_pts):
            px = qry.pts[r, s, 0]
            py = qry.pts[r, s, 1]
            pz = qry.pts[r, s, 2]
            f = ff_point_triangle(px, py, pz, nx, ny, nz, pat.v0, pat.e1, pat.e2, pat.nrm, j, poly)
            if f <= 0.0:
                continue
            if n_vis > 0:
                ox = px + eps * nx
                oy = py + eps * ny
                oz = pz + eps * nz
                ps = _seed(seed, key, s, j)
                seen = 0
                cast = 0
                w_all = 0.0
                w_seen = 0.0
                corners = -1  # how many of the triangle's corners x sees (-1: not asked)
                if n_first < n_vis:
                    corners = _corners_seen(pat, j, ox, oy, oz, eps, stack)
                for m in range(n_vis):
                    # after the first n_first rays, go on only where they or the corners disagree (a
                    # penumbra: a straight shadow edge across the triangle separates its corners); the
                    # rays are a prefix of one (0, 2)-sequence, so each count is a stratified net
                    if m == n_first and ((seen == 0 and corners <= 0) or (seen == m and corners != 0
                                                                           and corners != 1 and corners != 2)):
                        break
                    cast += 1
                    u, v = sobol_pair_both(np.uint64(m), ps, np.uint64(0))
                    yx, yy, yz = _triangle_point(pat.v0, pat.e1, pat.e2, j, u, v)
                    dx = yx - ox
                    dy = yy - oy
                    dz = yz - oz
                    d = math.sqrt(dx * dx + dy * dy + dz * dz)
                    if d <= eps:
                        seen += 1
                        continue
                    # the ray's weight: the differential form factor cos θ_x cos θ_y / r² (item 55)
                    cx = (nx * dx + ny * dy + nz * dz) / d
                    cy = -(pat.nrm[j, 0] * dx + pat.nrm[j, 1] * dy + pat.nrm[j, 2] * dz) / d
                    w = max(cx, 0.0) * max(cy, 0.0) / (d * d)
                    w_all += w
                    if not trace_occluded(ox, oy, oz, dx / d, dy / d, dz / d, 0.0, d - eps, pat.occ_nodes,
                                          pat.occ_tris, stack):
                        seen += 1
                        w_seen += w
                # the visible share of the unoccluded factor: the rays weighted by the differential form
                # factor, so a hidden part counts by its share of F, not of the area (the ray count where
                # every weight is 0)
                f *= w_seen / w_all if w_all > 0.0 else seen / cast
            acc += f
        out[r, c] = acc * inv_k


@function
def _direct_row(pat, qry, lit, r, n_vis, seed, eps, out, stack):
    nx = qry.nrm[r, 0]
    ny = qry.nrm[r, 1]
    nz = qry.nrm[r, 2]
    n_pts = qry.pts.shape[1]
    n_l = lit.kind.shape[0]
    for li in range(n_l + 1):
        acc = 0.0
        cnt = 0
        for s in range(n_pts):
            ox = qry.pts[r, s, 0] + eps * nx
            oy = qry.pts[r, s, 1] + eps * ny
            oz = qry.pts[r, s, 2] + eps * nz
            ps = _seed(seed, r, s, li + 1000003)
            for m in range(n_vis):
                u, v = sobol_pair_both(np.uint64(m), ps, np.uint64(1))
                cnt += 1
                if li == n_l:  # the sky: π times the fraction of cosine-distributed rays that escape
                    lx, ly, lz, _pdf = sample_cosine_hemisphere(u, v)
                    tx, ty, tz, bx, by, bz = _frame(nx, ny, nz)
                    wx = lx * tx + ly * bx + lz * nx
                    wy = lx * ty + ly * by + lz * ny
                    wz = lx * tz + ly * bz + lz * nz
                    if not trace_occluded(ox, oy, oz, wx, wy, wz, 0.0, np.inf, pat.occ_nodes, pat.occ_tris, stack):
                        acc += math.pi
                    continue
                wx, wy, wz, dist, pdf, fac = sample_light(lit.kind[li], lit.geo, lit.prof, li, lit.two[li] != 0,
                                                          ox, oy, oz, u, v)
                cos_n = nx * wx + ny * wy + nz * wz
                if not (fac > 0.0 and pdf > 0.0 and cos_n > 0.0):
                    continue
                tmax = dist * (1.0 - 1e-7) if dist < np.inf else np.inf
                if trace_occluded(ox, oy, oz, wx, wy, wz, 0.0, tmax, pat.occ_nodes, pat.occ_tris, stack):
                    continue
                if pdf == np.inf:
                    acc += cos_n * fac
                else:
                    acc += cos_n * fac / pdf
        out[r, li] = acc / max(cnt, 1)


@function
def _shoot_ray(pat, qry, k, seed, eps, hits, stack):
    i = qry.src[k]
    key = _seed(seed, i, k, 7)
    px, py, pz = _triangle_point(pat.v0, pat.e1, pat.e2, i, uniform(key, 0), uniform(key, 1))
    u = uniform(key, 2)
    v = uniform(key, 3)
    nx = pat.nrm[i, 0]
    ny = pat.nrm[i, 1]
    nz = pat.nrm[i, 2]
    lx, ly, lz, _pdf = sample_cosine_hemisphere(u, v)
    tx, ty, tz, bx, by, bz = _frame(nx, ny, nz)
    wx = lx * tx + ly * bx + lz * nx
    wy = lx * ty + ly * by + lz * ny
    wz = lx * tz + ly * bz + lz * nz
    t, prim, _bu, _bv = trace_closest(px + eps * nx, py + eps * ny, pz + eps * nz, wx, wy, wz, 0.0, np.inf,
                                      pat.nodes, pat.tris, stack)
    if prim < 0:
        hits[k] = -1
        return
    side = 0 if (wx * pat.tri_nrm[prim, 0] + wy * pat.tri_nrm[prim, 1] + wz * pat.tri_nrm[prim, 2]) < 0.0 else 1
    hits[k] = pat.tri_patch[prim, side]


@inline
def _hit_record(pat, ox, oy, oz, dx, dy, dz, eps, out, r, col, stack):
    """Trace the ray (o, d) to the first patch and write (patch, b1, b2) into out[r, col:col+3]
    (patch -1 when the ray leaves or reaches a side that is not a patch)."""
    t, prim, _bu, _bv = trace_closest(ox, oy, oz, dx, dy, dz, 0.0, np.inf, pat.nodes, pat.tris, stack)
    out[r, col] = -1.0
    out[r, col + 1] = 0.0
    out[r, col + 2] = 0.0
    if prim < 0:
        return
    side = 0 if (dx * pat.tri_nrm[prim, 0] + dy * pat.tri_nrm[prim, 1] + dz * pat.tri_nrm[prim, 2]) < 0.0 else 1
    j = pat.tri_patch[prim, side]
    if j < 0:
        return
    wx = ox + t * dx - pat.v0[j, 0]
    wy = oy + t * dy - pat.v0[j, 1]
    wz = oz + t * dz - pat.v0[j, 2]
    d11 = pat.e1[j, 0] * pat.e1[j, 0] + pat.e1[j, 1] * pat.e1[j, 1] + pat.e1[j, 2] * pat.e1[j, 2]
    d12 = pat.e1[j, 0] * pat.e2[j, 0] + pat.e1[j, 1] * pat.e2[j, 1] + pat.e1[j, 2] * pat.e2[j, 2]
    d22 = pat.e2[j, 0] * pat.e2[j, 0] + pat.e2[j, 1] * pat.e2[j, 1] + pat.e2[j, 2] * pat.e2[j, 2]
    w1 = wx * pat.e1[j, 0] + wy * pat.e1[j, 1] + wz * pat.e1[j, 2]
    w2 = wx * pat.e2[j, 0] + wy * pat.e2[j, 1] + wz * pat.e2[j, 2]
    den = d11 * d22 - d12 * d12
    b1 = (d22 * w1 - d12 * w2) / den if den > 0.0 else 0.0
    b2 = (d11 * w2 - d12 * w1) / den if den > 0.0 else 0.0
    # a hit in the geometry triangle lies in its patch: clamp rounding to the triangle
    b1 = min(max(b1, 0.0), 1.0)
    b2 = min(max(b2, 0.0), 1.0 - b1)
    out[r, col] = float(j)
    out[r, col + 1] = b1
    out[r, col + 2] = b2


@function
def _camera_row(pat, qry, r, n_vis, seed, eps, out, stack):
    pix = qry.own[r]
    w = qry.cols[0]
    h = qry.cols[1]
    x = pix % w
    y = pix // w
    for s in range(n_vis):
        key = _seed(seed, pix, s, 11)
        ox, oy, oz, dx, dy, dz = camera_ray(qry.cam, qry.filt, x, y, w, h, uniform(key, 0), uniform(key, 1),
                                            uniform(key, 2), uniform(key, 3))
        if dx == 0.0 and dy == 0.0 and dz == 0.0:  # a fisheye's pixel outside its image circle
            out[r, 3 * s] = -1.0
            out[r, 3 * s + 1] = 0.0
            out[r, 3 * s + 2] = 0.0
            continue
        _hit_record(pat, ox, oy, oz, dx, dy, dz, eps, out, r, 3 * s, stack)


@function
def _gather_row(pat, qry, r, n_vis, seed, eps, out, stack):
    nx = qry.nrm[r, 0]
    ny = qry.nrm[r, 1]
    nz = qry.nrm[r, 2]
    ox = qry.pts[r, 0, 0] + eps * nx
    oy = qry.pts[r, 0, 1] + eps * ny
    oz = qry.pts[r, 0, 2] + eps * nz
    tx, ty, tz, bx, by, bz = _frame(nx, ny, nz)
    ps = _seed(seed, qry.own[r], 13, 17)
    for s in range(n_vis):
        u, v = sobol_pair_both(np.uint64(s), ps, np.uint64(2))
        lx, ly, lz, _pdf = sample_cosine_hemisphere(u, v)
        wx = lx * tx + ly * bx + lz * nx
        wy = lx * ty + ly * by + lz * ny
        wz = lx * tz + ly * bz + lz * nz
        _hit_record(pat, ox, oy, oz, wx, wy, wz, eps, out, r, 3 * s, stack)


@kernel(refcount=False)
def radiosity_rays(op, r0, r1, pat, qry, lit, n_vis, seed, eps, out, hits, poly, stack):
    """Rows r0 .. r1-1 of operation ``op`` (OP_*, see the module text) into ``out`` (float64
    (R, C)) or, for OP_SHOOT, rays r0 .. r1-1 into ``hits`` (int32 (N,)). pat, qry, lit: the
    records above; n_vis: shadow rays per (point, patch) pair, light samples per point, or
    camera or gather rays per row (OP_EMITTERS: at most, per pair);
    seed: the RNG seed; eps: the ray offset, m; poly: float64 (8, 3) and stack: int32
    (STACK_SIZE,) scratch of the calling thread."""
    for r in range(r0, r1):
        if op == OP_FORM_FACTORS:
            _form_factor_row(pat, qry, r, n_vis, n_vis, seed, eps, out, poly, stack)
        elif op == OP_EMITTERS:
            _form_factor_row(pat, qry, r, min(n_vis, EMIT_FIRST), n_vis, seed, eps, out, poly, stack)
        elif op == OP_DIRECT:
            _direct_row(pat, qry, lit, r, n_vis, seed, eps, out, stack)
        elif op == OP_CAMERA:
            _camera_row(pat, qry, r, n_vis, seed, eps, out, stack)
        elif op == OP_GATHER:
            _gather_row(pat, qry, r, n_vis, seed, eps, out, stack)
        else:
            _shoot_ray(pat, qry, r, seed, eps, hits, stack)
