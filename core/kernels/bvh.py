"""Bounding volume hierarchy over triangles: binned SAH build, flattened nodes, stack traversal.

Node layout (struct of arrays, index 0 is the root):

* ``bmin``, ``bmax``  float32 (N, 3) node bounds
* ``child``  int32: internal node → index of its left child (the right child is
  ``child + 1``); leaf → index of its first primitive in ``prims``
* ``count``  int32: 0 for an internal node, the number of primitives for a leaf
* ``axis``   int32: split axis of an internal node (used to visit the nearer child first)

Triangles are stored reordered into leaf order as ``v0``, ``e1 = v1 - v0``,
``e2 = v2 - v0`` (float32, (T, 3)) so a leaf reads contiguous memory.
"""
import numpy as np
from numba import prange

from ..jit import inline, kernel

N_BINS = 16
MAX_LEAF = 4
STACK_SIZE = 128
TRAVERSAL_COST = 1.0  # relative to one triangle test


@inline
def _area(ex, ey, ez):
    if ex < 0.0 or ey < 0.0 or ez < 0.0:
        return 0.0
    return 2.0 * (ex * ey + ey * ez + ez * ex)


@kernel
def build_bvh(tri_min, tri_max, centroid):
    """Binned-SAH build. Inputs float64 (T, 3). Returns (bmin, bmax, child, count, axis, prims)."""
    n_tri = tri_min.shape[0]
    max_nodes = max(1, 2 * n_tri - 1)
    bmin = np.empty((max_nodes, 3), np.float32)
    bmax = np.empty((max_nodes, 3), np.float32)
    child = np.zeros(max_nodes, np.int32)
    count = np.zeros(max_nodes, np.int32)
    axis = np.zeros(max_nodes, np.int32)
    prims = np.arange(n_tri).astype(np.int32)
    bin_key = np.empty(n_tri, np.int32)

    st_node = np.empty(max_nodes + 1, np.int64)
    st_s = np.empty(max_nodes + 1, np.int64)
    st_e = np.empty(max_nodes + 1, np.int64)
    sp = 0
    st_node[0] = 0
    st_s[0] = 0
    st_e[0] = n_tri
    sp = 1
    n_nodes = 1

    b_cnt = np.zeros(N_BINS, np.int64)
    b_lo = np.empty((N_BINS, 3))
    b_hi = np.empty((N_BINS, 3))
    r_area = np.empty(N_BINS)
    r_cnt = np.empty(N_BINS, np.int64)

    if n_tri == 0:
        bmin[0, :] = 0.0
        bmax[0, :] = -1.0
        child[0] = 0
        count[0] = 0
        return bmin[:1], bmax[:1], child[:1], count[:1], axis[:1], prims

    while sp > 0:
        sp -= 1
        node = st_node[sp]
        s = st_s[sp]
        e = st_e[sp]
        n = e - s
        lo0 = np.inf; lo1 = np.inf; lo2 = np.inf
        hi0 = -np.inf; hi1 = -np.inf; hi2 = -np.inf
        c_lo0 = np.inf; c_lo1 = np.inf; c_lo2 = np.inf
        c_hi0 = -np.inf; c_hi1 = -np.inf; c_hi2 = -np.inf
        for k in range(s, e):
            p = prims[k]
            lo0 = min(lo0, tri_min[p, 0]); lo1 = min(lo1, tri_min[p, 1]); lo2 = min(lo2, tri_min[p, 2])
            hi0 = max(hi0, tri_max[p, 0]); hi1 = max(hi1, tri_max[p, 1]); hi2 = max(hi2, tri_max[p, 2])
            c_lo0 = min(c_lo0, centroid[p, 0]); c_lo1 = min(c_lo1, centroid[p, 1]); c_lo2 = min(c_lo2, centroid[p, 2])
            c_hi0 = max(c_hi0, centroid[p, 0]); c_hi1 = max(c_hi1, centroid[p, 1]); c_hi2 = max(c_hi2, centroid[p, 2])
        bmin[node, 0] = lo0; bmin[node, 1] = lo1; bmin[node, 2] = lo2
        bmax[node, 0] = hi0; bmax[node, 1] = hi1; bmax[node, 2] = hi2
        # Round bounds outwards so float32 storage never shrinks a box.
        for a in range(3):
            bmin[node, a] = np.nextafter(bmin[node, a], np.float32(-np.inf))
            bmax[node, a] = np.nextafter(bmax[node, a], np.float32(np.inf))

        if n <= MAX_LEAF:
            child[node] = s
            count[node] = n
            continue

        node_area = _area(hi0 - lo0, hi1 - lo1, hi2 - lo2)
        best_cost = np.inf
        best_axis = -1
        best_split = 0
        for a in range(3):
            if a == 0:
                cmin = c_lo0; ext = c_hi0 - c_lo0
            elif a == 1:
                cmin = c_lo1; ext = c_hi1 - c_lo1
            else:
                cmin = c_lo2; ext = c_hi2 - c_lo2
            if not ext > 0.0:
                continue
            scale = N_BINS / ext
            for b in range(N_BINS):
                b_cnt[b] = 0
                for q in range(3):
                    b_lo[b, q] = np.inf
                    b_hi[b, q] = -np.inf
            for k in range(s, e):
                p = prims[k]
                b = int((centroid[p, a] - cmin) * scale)
                if b >= N_BINS:
                    b = N_BINS - 1
                if b < 0:
                    b = 0
                b_cnt[b] += 1
                for q in range(3):
                    b_lo[b, q] = min(b_lo[b, q], tri_min[p, q])
                    b_hi[b, q] = max(b_hi[b, q], tri_max[p, q])
            # suffix sweep
            rl0 = np.inf; rl1 = np.inf; rl2 = np.inf
            rh0 = -np.inf; rh1 = -np.inf; rh2 = -np.inf
            rc = 0
            for b in range(N_BINS - 1, 0, -1):
                rc += b_cnt[b]
                rl0 = min(rl0, b_lo[b, 0]); rl1 = min(rl1, b_lo[b, 1]); rl2 = min(rl2, b_lo[b, 2])
                rh0 = max(rh0, b_hi[b, 0]); rh1 = max(rh1, b_hi[b, 1]); rh2 = max(rh2, b_hi[b, 2])
                r_cnt[b] = rc
                r_area[b] = _area(rh0 - rl0, rh1 - rl1, rh2 - rl2) if rc > 0 else 0.0
            ll0 = np.inf; ll1 = np.inf; ll2 = np.inf
            lh0 = -np.inf; lh1 = -np.inf; lh2 = -np.inf
            lc = 0
            for b in range(0, N_BINS - 1):
                lc += b_cnt[b]
                ll0 = min(ll0, b_lo[b, 0]); ll1 = min(ll1, b_lo[b, 1]); ll2 = min(ll2, b_lo[b, 2])
                lh0 = max(lh0, b_hi[b, 0]); lh1 = max(lh1, b_hi[b, 1]); lh2 = max(lh2, b_hi[b, 2])
                if lc == 0 or r_cnt[b + 1] == 0:
                    continue
                la = _area(lh0 - ll0, lh1 - ll1, lh2 - ll2)
                cost = TRAVERSAL_COST + (la * lc + r_area[b + 1] * r_cnt[b + 1]) / max(node_area, 1e-300)
                if cost < best_cost:
                    best_cost = cost
                    best_axis = a
                    best_split = b + 1

        mid = s
        if best_axis >= 0 and (best_cost < n or n > 16):
            if best_axis == 0:
                cmin = c_lo0; ext = c_hi0 - c_lo0
            elif best_axis == 1:
                cmin = c_lo1; ext = c_hi1 - c_lo1
            else:
                cmin = c_lo2; ext = c_hi2 - c_lo2
            scale = N_BINS / ext
            i = s
            j = e - 1
            while i <= j:
                b = int((centroid[prims[i], best_axis] - cmin) * scale)
                if b >= N_BINS:
                    b = N_BINS - 1
                if b < best_split:
                    i += 1
                else:
                    tmp = prims[i]
                    prims[i] = prims[j]
                    prims[j] = tmp
                    j -= 1
            mid = i
        elif best_axis < 0 and n > 16:
            # All centroids coincide: split the range in half so leaves stay small.
            mid = s + n // 2
            best_axis = 0
        if mid <= s or mid >= e:
            if n <= 16:
                child[node] = s
                count[node] = n
                continue
            mid = s + n // 2
        left = n_nodes
        n_nodes += 2
        child[node] = left
        count[node] = 0
        axis[node] = best_axis
        st_node[sp] = left + 1; st_s[sp] = mid; st_e[sp] = e
        sp += 1
        st_node[sp] = left; st_s[sp] = s; st_e[sp] = mid
        sp += 1
    return bmin[:n_nodes].copy(), bmax[:n_nodes].copy(), child[:n_nodes].copy(), \
        count[:n_nodes].copy(), axis[:n_nodes].copy(), prims


@inline
def _slab(ox, oy, oz, ix, iy, iz, bmin, bmax, node, tmax):
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
def intersect_triangle(ox, oy, oz, dx, dy, dz, v0, e1, e2, p, tmin, tmax):
    """Möller–Trumbore. Returns (t, u, v); t = inf on a miss."""
    ax = e1[p, 0]; ay = e1[p, 1]; az = e1[p, 2]
    bx = e2[p, 0]; by = e2[p, 1]; bz = e2[p, 2]
    px = dy * bz - dz * by
    py = dz * bx - dx * bz
    pz = dx * by - dy * bx
    det = ax * px + ay * py + az * pz
    if det == 0.0:
        return np.inf, 0.0, 0.0
    inv = 1.0 / det
    tx = ox - v0[p, 0]; ty = oy - v0[p, 1]; tz = oz - v0[p, 2]
    u = (tx * px + ty * py + tz * pz) * inv
    if u < 0.0 or u > 1.0:
        return np.inf, 0.0, 0.0
    qx = ty * az - tz * ay
    qy = tz * ax - tx * az
    qz = tx * ay - ty * ax
    v = (dx * qx + dy * qy + dz * qz) * inv
    if v < 0.0 or u + v > 1.0:
        return np.inf, 0.0, 0.0
    t = (bx * qx + by * qy + bz * qz) * inv
    if t <= tmin or t >= tmax:
        return np.inf, 0.0, 0.0
    return t, u, v


@inline
def _inv(d):
    if d == 0.0:
        return 1e300
    return 1.0 / d


@inline
def closest_hit(ox, oy, oz, dx, dy, dz, tmin, tmax, bmin, bmax, child, count, axis, v0, e1, e2, stack):
    """Closest triangle hit in (tmin, tmax). Returns (t, prim, u, v); prim = -1 on a miss."""
    ix = _inv(dx); iy = _inv(dy); iz = _inv(dz)
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
                t, u, v = intersect_triangle(ox, oy, oz, dx, dy, dz, v0, e1, e2, k, tmin, best_t)
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
        # pop, skipping nodes now farther than the best hit
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
    """True if any triangle is hit in (tmin, tmax)."""
    if v0.shape[0] == 0:
        return False
    ix = _inv(dx); iy = _inv(dy); iz = _inv(dz)
    sp = 0
    stack[0] = 0
    sp = 1
    while sp > 0:
        sp -= 1
        node = stack[sp]
        if _slab(ox, oy, oz, ix, iy, iz, bmin, bmax, node, tmax) == np.inf:
            continue
        c = count[node]
        if c > 0:
            first = child[node]
            for k in range(first, first + c):
                t, u, v = intersect_triangle(ox, oy, oz, dx, dy, dz, v0, e1, e2, k, tmin, tmax)
                if t < np.inf:
                    return True
        else:
            stack[sp] = child[node]
            stack[sp + 1] = child[node] + 1
            sp += 2
    return False


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
    n = orig.shape[0]
    out = np.empty(n, np.bool_)
    for i in prange(n):
        stack = np.empty(STACK_SIZE, np.int32)
        out[i] = occluded(orig[i, 0], orig[i, 1], orig[i, 2], dirs[i, 0], dirs[i, 1], dirs[i, 2],
                          0.0, tmax[i], bmin, bmax, child, count, v0, e1, e2, stack)
    return out
