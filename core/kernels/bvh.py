"""Bounding volume hierarchy over triangles: binned SAH build, flattened nodes, ordered stack traversal.

Node layout (struct of arrays, index 0 is the root):

* ``bmin``, ``bmax``  float32 (N, 3) node bounds, rounded outwards
* ``child``  int32: internal node → index of its left child (the right child is
  ``child + 1``); leaf → index of its first triangle in leaf order
* ``count``  int32: 0 for an internal node, the number of triangles for a leaf
* ``axis``   int32: split axis of an internal node

Triangles are stored in leaf order as ``v0`` (float32 (T, 3), the first corner rounded
to float32) and ``e1 = v1 - v0``, ``e2 = v2 - v0`` (float64 (T, 3)), the differences of
the float32-rounded corners. Those differences are exact in float64 (unless a corner's
coordinates differ by more than 2^29 in magnitude), so ``v0 + e1`` gives back the very
corner every neighbouring triangle sees: the watertight triangle test relies on it.

The tree depth is at most ``MAX_DEPTH``: below ``FALLBACK_DEPTH`` the builder splits by
SAH, deeper it halves the triangle range, which needs at most 31 more levels for fewer
than 2^31 triangles. Traversal pushes at most one node per level, so ``STACK_SIZE``
entries always suffice.
"""
import numpy as np
from numba import prange

from ..jit import inline, kernel

N_BINS = 16
MAX_LEAF = 8  # ranges this small always become leaves (fewer nodes, same ray speed as 4)
MAX_LEAF_SAH = 16  # SAH may keep ranges up to this size as leaves
FALLBACK_DEPTH = 32
MAX_DEPTH = FALLBACK_DEPTH + 32
STACK_SIZE = 128
TRAVERSAL_COST = 1.0  # relative to one triangle test
EDGE_DTYPE = np.float64


@inline
def _area(ex, ey, ez):
    if ex < 0.0 or ey < 0.0 or ez < 0.0:
        return 0.0
    return 2.0 * (ex * ey + ey * ez + ez * ex)


@inline
def _down(x):
    return np.nextafter(np.float32(x), np.float32(-np.inf))


@inline
def _up(x):
    return np.nextafter(np.float32(x), np.float32(np.inf))


@inline
def _range_bounds(lo, hi, s, e):
    """Bounds of triangles [s, e): box (6) and doubled-centroid box (6)."""
    l0 = np.inf; l1 = np.inf; l2 = np.inf
    h0 = -np.inf; h1 = -np.inf; h2 = -np.inf
    cl0 = np.inf; cl1 = np.inf; cl2 = np.inf
    ch0 = -np.inf; ch1 = -np.inf; ch2 = -np.inf
    for k in range(s, e):
        a0 = lo[k, 0]; a1 = lo[k, 1]; a2 = lo[k, 2]
        b0 = hi[k, 0]; b1 = hi[k, 1]; b2 = hi[k, 2]
        l0 = min(l0, a0); l1 = min(l1, a1); l2 = min(l2, a2)
        h0 = max(h0, b0); h1 = max(h1, b1); h2 = max(h2, b2)
        c0 = np.float64(a0) + b0; c1 = np.float64(a1) + b1; c2 = np.float64(a2) + b2
        cl0 = min(cl0, c0); cl1 = min(cl1, c1); cl2 = min(cl2, c2)
        ch0 = max(ch0, c0); ch1 = max(ch1, c1); ch2 = max(ch2, c2)
    return l0, l1, l2, h0, h1, h2, cl0, cl1, cl2, ch0, ch1, ch2


@inline
def _bin(c, cmin, scale):
    b = int((c - cmin) * scale)
    if b >= N_BINS:
        b = N_BINS - 1
    if b < 0:
        b = 0
    return b


@inline
def _swap(lo, hi, prims, i, j):
    for q in range(3):
        t = lo[i, q]; lo[i, q] = lo[j, q]; lo[j, q] = t
        t = hi[i, q]; hi[i, q] = hi[j, q]; hi[j, q] = t
    tp = prims[i]; prims[i] = prims[j]; prims[j] = tp


@inline
def _set_box(bmin, bmax, node, l0, l1, l2, h0, h1, h2):
    bmin[node, 0] = _down(l0); bmin[node, 1] = _down(l1); bmin[node, 2] = _down(l2)
    bmax[node, 0] = _up(h0); bmax[node, 1] = _up(h1); bmax[node, 2] = _up(h2)


@kernel
def build_bvh(v0, v1, v2):
    """Binned-SAH build over corners (T, 3) (float32 or float64; rounded to float32).

    Returns (bmin, bmax, child, count, axis, prims, tri_v0, tri_e1, tri_e2, bad): ``prims``
    maps leaf order to input order; ``bad`` is the index of the first triangle with a
    non-finite coordinate, or -1 (the tree is then not valid).
    """
    n_tri = v0.shape[0]
    max_nodes = max(1, 2 * n_tri - 1)
    bmin = np.empty((max_nodes, 3), np.float32)
    bmax = np.empty((max_nodes, 3), np.float32)
    child = np.zeros(max_nodes, np.int32)
    count = np.zeros(max_nodes, np.int32)
    axis = np.zeros(max_nodes, np.int32)
    prims = np.empty(n_tri, np.int32)
    bad = -1
    n_nodes = 1
    if n_tri == 0:
        bmin[0, :] = 0.0
        bmax[0, :] = -1.0
    else:
        # per-triangle bounds of the float32 corners; partitioned in place with prims
        lo = np.empty((n_tri, 3), np.float32)
        hi = np.empty((n_tri, 3), np.float32)
        for i in range(n_tri):
            for q in range(3):
                a = np.float32(v0[i, q]); b = np.float32(v1[i, q]); c = np.float32(v2[i, q])
                lo[i, q] = min(a, min(b, c))
                hi[i, q] = max(a, max(b, c))
                if bad < 0 and not (np.isfinite(a) and np.isfinite(b) and np.isfinite(c)):
                    bad = i
            prims[i] = i
        if bad >= 0:
            return bmin[:1].copy(), bmax[:1].copy(), child[:1].copy(), count[:1].copy(), axis[:1].copy(), \
                prims, np.empty((0, 3), np.float32), np.empty((0, 3), EDGE_DTYPE), \
                np.empty((0, 3), EDGE_DTYPE), bad

        b_cnt = np.zeros((3, N_BINS), np.int64)
        b_lo = np.empty((3, N_BINS, 3), np.float32)
        b_hi = np.empty((3, N_BINS, 3), np.float32)
        r_area = np.empty(N_BINS)
        r_cnt = np.empty(N_BINS, np.int64)
        c_min = np.empty(3)
        c_scale = np.empty(3)
        cb = np.empty(6)  # centroid bounds of the node being processed
        # stack of pending ranges: node, start, end, depth; their doubled-centroid bounds
        st_i = np.empty((2 * MAX_DEPTH + 4, 4), np.int64)
        st_c = np.empty((2 * MAX_DEPTH + 4, 6))

        l0, l1, l2, h0, h1, h2, cl0, cl1, cl2, ch0, ch1, ch2 = _range_bounds(lo, hi, 0, n_tri)
        _set_box(bmin, bmax, 0, l0, l1, l2, h0, h1, h2)
        st_i[0, 0] = 0; st_i[0, 1] = 0; st_i[0, 2] = n_tri; st_i[0, 3] = 1
        st_c[0, 0] = cl0; st_c[0, 1] = cl1; st_c[0, 2] = cl2
        st_c[0, 3] = ch0; st_c[0, 4] = ch1; st_c[0, 5] = ch2
        sp = 1
        while sp > 0:
            sp -= 1
            node = st_i[sp, 0]; s = st_i[sp, 1]; e = st_i[sp, 2]; depth = st_i[sp, 3]
            for q in range(6):
                cb[q] = st_c[sp, q]
            n = e - s
            if n <= MAX_LEAF:
                child[node] = s
                count[node] = n
                continue

            best_axis = -1
            best_split = 0
            best_cost = np.inf
            if depth < FALLBACK_DEPTH:
                # one binning pass for the three axes
                any_axis = False
                for a in range(3):
                    ext = cb[3 + a] - cb[a]
                    c_min[a] = cb[a]
                    if ext > 0.0:
                        c_scale[a] = N_BINS * (1.0 - 1e-9) / ext
                        any_axis = True
                    else:
                        c_scale[a] = 0.0
                    for b in range(N_BINS):
                        b_cnt[a, b] = 0
                        for q in range(3):
                            b_lo[a, b, q] = np.inf
                            b_hi[a, b, q] = -np.inf
                if any_axis:
                    for k in range(s, e):
                        x0 = lo[k, 0]; x1 = lo[k, 1]; x2 = lo[k, 2]
                        y0 = hi[k, 0]; y1 = hi[k, 1]; y2 = hi[k, 2]
                        for a in range(3):
                            if c_scale[a] == 0.0:
                                continue
                            b = _bin(np.float64(lo[k, a]) + hi[k, a], c_min[a], c_scale[a])
                            b_cnt[a, b] += 1
                            b_lo[a, b, 0] = min(b_lo[a, b, 0], x0)
                            b_lo[a, b, 1] = min(b_lo[a, b, 1], x1)
                            b_lo[a, b, 2] = min(b_lo[a, b, 2], x2)
                            b_hi[a, b, 0] = max(b_hi[a, b, 0], y0)
                            b_hi[a, b, 1] = max(b_hi[a, b, 1], y1)
                            b_hi[a, b, 2] = max(b_hi[a, b, 2], y2)
                    node_area = max(_area(np.float64(bmax[node, 0]) - bmin[node, 0],
                                          np.float64(bmax[node, 1]) - bmin[node, 1],
                                          np.float64(bmax[node, 2]) - bmin[node, 2]), 1e-300)
                    for a in range(3):
                        if c_scale[a] == 0.0:
                            continue
                        rl0 = np.inf; rl1 = np.inf; rl2 = np.inf
                        rh0 = -np.inf; rh1 = -np.inf; rh2 = -np.inf
                        rc = 0
                        for b in range(N_BINS - 1, 0, -1):
                            rc += b_cnt[a, b]
                            rl0 = min(rl0, b_lo[a, b, 0]); rl1 = min(rl1, b_lo[a, b, 1])
                            rl2 = min(rl2, b_lo[a, b, 2])
                            rh0 = max(rh0, b_hi[a, b, 0]); rh1 = max(rh1, b_hi[a, b, 1])
                            rh2 = max(rh2, b_hi[a, b, 2])
                            r_cnt[b] = rc
                            r_area[b] = _area(np.float64(rh0) - rl0, np.float64(rh1) - rl1,
                                              np.float64(rh2) - rl2) if rc > 0 else 0.0
                        ll0 = np.inf; ll1 = np.inf; ll2 = np.inf
                        lh0 = -np.inf; lh1 = -np.inf; lh2 = -np.inf
                        lc = 0
                        for b in range(0, N_BINS - 1):
                            lc += b_cnt[a, b]
                            ll0 = min(ll0, b_lo[a, b, 0]); ll1 = min(ll1, b_lo[a, b, 1])
                            ll2 = min(ll2, b_lo[a, b, 2])
                            lh0 = max(lh0, b_hi[a, b, 0]); lh1 = max(lh1, b_hi[a, b, 1])
                            lh2 = max(lh2, b_hi[a, b, 2])
                            if lc == 0 or r_cnt[b + 1] == 0:
                                continue
                            la = _area(np.float64(lh0) - ll0, np.float64(lh1) - ll1, np.float64(lh2) - ll2)
                            cost = TRAVERSAL_COST + (la * lc + r_area[b + 1] * r_cnt[b + 1]) / node_area
                            if cost < best_cost:
                                best_cost = cost
                                best_axis = a
                                best_split = b + 1
                if best_axis >= 0 and best_cost >= n and n <= MAX_LEAF_SAH:
                    child[node] = s
                    count[node] = n
                    continue
                if best_axis < 0 and n <= MAX_LEAF_SAH:
                    child[node] = s
                    count[node] = n
                    continue

            left = n_nodes
            right = left + 1
            n_nodes += 2
            child[node] = left
            count[node] = 0
            if best_axis >= 0:
                # partition by bin; the children's boxes are the unions of their bins
                a = best_axis
                cmin = c_min[a]
                scale = c_scale[a]
                pl0 = np.inf; pl1 = np.inf; pl2 = np.inf; ph0 = -np.inf; ph1 = -np.inf; ph2 = -np.inf
                ql0 = np.inf; ql1 = np.inf; ql2 = np.inf; qh0 = -np.inf; qh1 = -np.inf; qh2 = -np.inf
                i = s
                j = e - 1
                while True:
                    while i <= j:
                        c0 = np.float64(lo[i, 0]) + hi[i, 0]
                        c1 = np.float64(lo[i, 1]) + hi[i, 1]
                        c2 = np.float64(lo[i, 2]) + hi[i, 2]
                        c = c0 if a == 0 else (c1 if a == 1 else c2)
                        if _bin(c, cmin, scale) >= best_split:
                            break
                        pl0 = min(pl0, c0); pl1 = min(pl1, c1); pl2 = min(pl2, c2)
                        ph0 = max(ph0, c0); ph1 = max(ph1, c1); ph2 = max(ph2, c2)
                        i += 1
                    while i <= j:
                        c0 = np.float64(lo[j, 0]) + hi[j, 0]
                        c1 = np.float64(lo[j, 1]) + hi[j, 1]
                        c2 = np.float64(lo[j, 2]) + hi[j, 2]
                        c = c0 if a == 0 else (c1 if a == 1 else c2)
                        if _bin(c, cmin, scale) < best_split:
                            break
                        ql0 = min(ql0, c0); ql1 = min(ql1, c1); ql2 = min(ql2, c2)
                        qh0 = max(qh0, c0); qh1 = max(qh1, c1); qh2 = max(qh2, c2)
                        j -= 1
                    if i > j:
                        break
                    _swap(lo, hi, prims, i, j)
                    # i now holds a left triangle, j a right one; the loops above account for them
                mid = i
                l0 = np.inf; l1 = np.inf; l2 = np.inf; h0 = -np.inf; h1 = -np.inf; h2 = -np.inf
                for b in range(best_split):
                    l0 = min(l0, b_lo[a, b, 0]); l1 = min(l1, b_lo[a, b, 1]); l2 = min(l2, b_lo[a, b, 2])
                    h0 = max(h0, b_hi[a, b, 0]); h1 = max(h1, b_hi[a, b, 1]); h2 = max(h2, b_hi[a, b, 2])
                _set_box(bmin, bmax, left, l0, l1, l2, h0, h1, h2)
                l0 = np.inf; l1 = np.inf; l2 = np.inf; h0 = -np.inf; h1 = -np.inf; h2 = -np.inf
                for b in range(best_split, N_BINS):
                    l0 = min(l0, b_lo[a, b, 0]); l1 = min(l1, b_lo[a, b, 1]); l2 = min(l2, b_lo[a, b, 2])
                    h0 = max(h0, b_hi[a, b, 0]); h1 = max(h1, b_hi[a, b, 1]); h2 = max(h2, b_hi[a, b, 2])
                _set_box(bmin, bmax, right, l0, l1, l2, h0, h1, h2)
                axis[node] = a
            else:
                # deep (or all centroids equal): halve the range, which bounds the depth
                mid = s + n // 2
                a = 0
                if cb[4] - cb[1] > cb[3 + a] - cb[a]:
                    a = 1
                if cb[5] - cb[2] > cb[3 + a] - cb[a]:
                    a = 2
                axis[node] = a
                l0, l1, l2, h0, h1, h2, pl0, pl1, pl2, ph0, ph1, ph2 = _range_bounds(lo, hi, s, mid)
                _set_box(bmin, bmax, left, l0, l1, l2, h0, h1, h2)
                l0, l1, l2, h0, h1, h2, ql0, ql1, ql2, qh0, qh1, qh2 = _range_bounds(lo, hi, mid, e)
                _set_box(bmin, bmax, right, l0, l1, l2, h0, h1, h2)
            # push right, then left (processed next)
            st_i[sp, 0] = right; st_i[sp, 1] = mid; st_i[sp, 2] = e; st_i[sp, 3] = depth + 1
            st_c[sp, 0] = ql0; st_c[sp, 1] = ql1; st_c[sp, 2] = ql2
            st_c[sp, 3] = qh0; st_c[sp, 4] = qh1; st_c[sp, 5] = qh2
            sp += 1
            st_i[sp, 0] = left; st_i[sp, 1] = s; st_i[sp, 2] = mid; st_i[sp, 3] = depth + 1
            st_c[sp, 0] = pl0; st_c[sp, 1] = pl1; st_c[sp, 2] = pl2
            st_c[sp, 3] = ph0; st_c[sp, 4] = ph1; st_c[sp, 5] = ph2
            sp += 1

    # triangles in leaf order (lo and hi are no longer needed)
    tv0 = np.empty((n_tri, 3), np.float32)
    te1 = np.empty((n_tri, 3), EDGE_DTYPE)
    te2 = np.empty((n_tri, 3), EDGE_DTYPE)
    for k in range(n_tri):
        p = prims[k]
        for q in range(3):
            a32 = np.float32(v0[p, q])
            tv0[k, q] = a32
            te1[k, q] = np.float64(np.float32(v1[p, q])) - np.float64(a32)
            te2[k, q] = np.float64(np.float32(v2[p, q])) - np.float64(a32)
    return bmin[:n_nodes].copy(), bmax[:n_nodes].copy(), child[:n_nodes].copy(), \
        count[:n_nodes].copy(), axis[:n_nodes].copy(), prims, tv0, te1, te2, bad


@inline
def _slab(ox, oy, oz, ix, iy, iz, bmin, bmax, node, tmax):
    """Entry distance of the ray into the node's box within [0, tmax], inf if it misses."""
    t0 = (bmin[node, 0] - ox) * ix
    t1 = (bmax[node, 0] - ox) * ix
    tn = min(t0, t1)
    tf = max(t0, t1)
    t0 = (bmin[node, 1] - oy) * iy
    t1 = (bmax[node, 1] - oy) * iy
    tn = max(tn, min(t0, t1))
    tf = min(tf, max(t0, t1))
    t0 = (bmin[node, 2] - oz) * iz
    t1 = (bmax[node, 2] - oz) * iz
    tn = max(tn, min(t0, t1))
    tf = min(tf, max(t0, t1))
    tn = max(tn, 0.0)
    tf = min(tf, tmax)
    if tn <= tf:
        return tn
    return np.inf


@inline
def _pick(x, y, z, k):
    if k == 0:
        return x
    if k == 1:
        return y
    return z


@inline
def ray_setup(dx, dy, dz):
    """Watertight-test constants of a ray: the axes (kx, ky, kz), kz the dominant one, and
    the shear (sx, sy, sz) mapping the direction to +z (Woop, Benthin, Wald 2013)."""
    ax = abs(dx); ay = abs(dy); az = abs(dz)
    kz = 0  # the first axis of largest |d|
    if ay > ax:
        kz = 1
        ax = ay
    if az > ax:
        kz = 2
    kx = kz + 1 if kz < 2 else 0
    ky = kx + 1 if kx < 2 else 0
    dk = _pick(dx, dy, dz, kz)
    if dk < 0.0:
        t = kx; kx = ky; ky = t  # keep the winding
    sz = 1.0 / dk
    sx = _pick(dx, dy, dz, kx) * sz
    sy = _pick(dx, dy, dz, ky) * sz
    return kx, ky, kz, sx, sy, sz


@inline
def intersect_triangle(okx, oky, okz, kx, ky, kz, sx, sy, sz, v0, e1, e2, p, tmin, tmax):
    """Watertight ray/triangle test (Woop, Benthin, Wald, JCGT 2(1), 2013) in float64.

    ``okx, oky, okz`` are the ray origin's coordinates on the axes of ``ray_setup``.
    Corners are rebuilt as v0, v0 + e1, v0 + e2 (exact), moved to the ray origin and
    sheared so the ray runs along +z; the signs of the three edge functions decide the
    hit, and a shared edge gets the same edge function (negated) in both its triangles,
    so no ray slips between them. Returns (t, u, v) with u, v the weights of v1, v2; t =
    inf on a miss.
    """
    pax = np.float64(v0[p, kx]); pay = np.float64(v0[p, ky]); paz = np.float64(v0[p, kz])
    az = paz - okz
    ax = (pax - okx) - sx * az
    ay = (pay - oky) - sy * az
    bz = (paz + e1[p, kz]) - okz
    bx = ((pax + e1[p, kx]) - okx) - sx * bz
    by = ((pay + e1[p, ky]) - oky) - sy * bz
    cz = (paz + e2[p, kz]) - okz
    cx = ((pax + e2[p, kx]) - okx) - sx * cz
    cy = ((pay + e2[p, ky]) - oky) - sy * cz
    u = cx * by - cy * bx
    v = ax * cy - ay * cx
    w = bx * ay - by * ax
    if (u < 0.0 or v < 0.0 or w < 0.0) and (u > 0.0 or v > 0.0 or w > 0.0):
        return np.inf, 0.0, 0.0
    det = u + v + w
    if det == 0.0:
        return np.inf, 0.0, 0.0
    t = sz * (u * az + v * bz + w * cz) / det
    if not (t > tmin and t < tmax):
        return np.inf, 0.0, 0.0
    return t, v / det, w / det



@inline
def _inv(d):
    if d == 0.0:
        return 1e300
    return 1.0 / d


@inline
def closest_hit(ox, oy, oz, dx, dy, dz, tmin, tmax, bmin, bmax, child, count, axis, v0, e1, e2, stack):
    """Closest triangle hit in (tmin, tmax). Returns (t, prim, u, v); prim = -1 on a miss.

    Front-to-back: of two children hit, the nearer is visited first and the other pushed;
    a popped node is skipped when its box now starts beyond the best hit.
    """
    ix = _inv(dx); iy = _inv(dy); iz = _inv(dz)
    kx, ky, kz, sx, sy, sz = ray_setup(dx, dy, dz)
    okx = _pick(ox, oy, oz, kx); oky = _pick(ox, oy, oz, ky); okz = _pick(ox, oy, oz, kz)
    best_t = tmax
    best_p = -1
    best_u = 0.0
    best_v = 0.0
    if v0.shape[0] == 0 or _slab(ox, oy, oz, ix, iy, iz, bmin, bmax, 0, best_t) == np.inf:
        return np.inf, -1, 0.0, 0.0
    sp = 0
    node = 0
    while True:
        c = count[node]
        if c > 0:
            first = child[node]
            for k in range(first, first + c):
                t, u, v = intersect_triangle(okx, oky, okz, kx, ky, kz, sx, sy, sz, v0, e1, e2, k, tmin, best_t)
                if t < best_t:
                    best_t = t
                    best_p = k
                    best_u = u
                    best_v = v
        else:
            left = child[node]
            right = left + 1
            tl = _slab(ox, oy, oz, ix, iy, iz, bmin, bmax, left, best_t)
            tr = _slab(ox, oy, oz, ix, iy, iz, bmin, bmax, right, best_t)
            if tl < np.inf and tr < np.inf:
                if tr < tl:
                    stack[sp] = left
                    node = right
                else:
                    stack[sp] = right
                    node = left
                sp += 1
                continue
            elif tl < np.inf:
                node = left
                continue
            elif tr < np.inf:
                node = right
                continue
        found = False
        while sp > 0:
            sp -= 1
            nd = stack[sp]
            if _slab(ox, oy, oz, ix, iy, iz, bmin, bmax, nd, best_t) < np.inf:
                node = nd
                found = True
                break
        if not found:
            break
    if best_p < 0:
        return np.inf, -1, 0.0, 0.0
    return best_t, best_p, best_u, best_v


@inline
def occluded(ox, oy, oz, dx, dy, dz, tmin, tmax, bmin, bmax, child, count, v0, e1, e2, stack):
    """True if any triangle is hit in (tmin, tmax). Nearer child first, any hit ends it."""
    if v0.shape[0] == 0:
        return False
    ix = _inv(dx); iy = _inv(dy); iz = _inv(dz)
    if _slab(ox, oy, oz, ix, iy, iz, bmin, bmax, 0, tmax) == np.inf:
        return False
    kx, ky, kz, sx, sy, sz = ray_setup(dx, dy, dz)
    okx = _pick(ox, oy, oz, kx); oky = _pick(ox, oy, oz, ky); okz = _pick(ox, oy, oz, kz)
    sp = 0
    node = 0
    while True:
        c = count[node]
        if c > 0:
            first = child[node]
            for k in range(first, first + c):
                t, u, v = intersect_triangle(okx, oky, okz, kx, ky, kz, sx, sy, sz, v0, e1, e2, k, tmin, tmax)
                if t < np.inf:
                    return True
        else:
            left = child[node]
            right = left + 1
            tl = _slab(ox, oy, oz, ix, iy, iz, bmin, bmax, left, tmax)
            tr = _slab(ox, oy, oz, ix, iy, iz, bmin, bmax, right, tmax)
            if tl < np.inf and tr < np.inf:
                if tr < tl:
                    stack[sp] = left
                    node = right
                else:
                    stack[sp] = right
                    node = left
                sp += 1
                continue
            elif tl < np.inf:
                node = left
                continue
            elif tr < np.inf:
                node = right
                continue
        if sp == 0:
            return False
        sp -= 1
        node = stack[sp]


@kernel(parallel=True)
def trace_closest_batch(orig, dirs, tmax, bmin, bmax, child, count, axis, v0, e1, e2):
    """Closest hits of a batch of rays. Returns t (inf on a miss) and prim (leaf order, -1)."""
    n = orig.shape[0]
    t_out = np.empty(n)
    p_out = np.empty(n, np.int32)
    for i in prange(n):
        stack = np.empty(STACK_SIZE, np.int32)
        t, p, u, v = closest_hit(orig[i, 0], orig[i, 1], orig[i, 2], dirs[i, 0], dirs[i, 1], dirs[i, 2],
                                 0.0, tmax[i], bmin, bmax, child, count, axis, v0, e1, e2, stack)
        t_out[i] = t
        p_out[i] = p
    return t_out, p_out


@kernel(parallel=True)
def trace_occluded_batch(orig, dirs, tmax, bmin, bmax, child, count, v0, e1, e2):
    """Any-hit queries of a batch of segments (origin, unit direction, length)."""
    n = orig.shape[0]
    out = np.empty(n, np.bool_)
    for i in prange(n):
        stack = np.empty(STACK_SIZE, np.int32)
        out[i] = occluded(orig[i, 0], orig[i, 1], orig[i, 2], dirs[i, 0], dirs[i, 1], dirs[i, 2],
                          0.0, tmax[i], bmin, bmax, child, count, v0, e1, e2, stack)
    return out
