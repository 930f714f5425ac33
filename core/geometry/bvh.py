"""Bounding volume hierarchy over triangles: binned SAH build, 4-wide packed records, ordered stack traversal.

The builder makes a binary tree by binned SAH and then collapses it into a tree of
arity four (``_collapse``): each record holds up to four children, so a ray's chain of
record visits is about half as long, and the four boxes are tested at once
(``simd.slab4``, 4-wide float64). Records are packed for traversal, 128 bytes (two
cache lines) each: ``nodes`` float32 (R, 32), record 0 the root's; columns

* ``[0:24]`` the children's boxes plane by plane: min x of children 0-3, then min y,
  min z, max x, max y, max z (float32, rounded outwards); an absent child's box is
  min +inf, max -inf, which no ray enters
* ``[C_REF:C_REF + 4]`` (24-27) the children's references and ``[C_CNT:C_CNT + 4]``
  (28-31) their triangle counts, int32 bit patterns (read through ``nodes.view(np.int32)``):
  ``cnt == 0`` → ``ref`` is the child's record (-1: absent); ``cnt > 0`` → a leaf of
  ``cnt`` triangles whose first block is ``ref`` (below)

A tree that is a single leaf gets one record with that leaf as its only child.
``accel.build`` gives the array 64-byte alignment so a record is exactly two lines.

Triangles for traversal are ``tris`` float32 (B, 40), in blocks of four (``simd.py``): a
leaf of ``cnt`` triangles owns ceil(cnt / 4) consecutive blocks, and its reference in the
record above is its first block. A block row holds the float32-rounded corners of its
four lanes coordinate by coordinate (column ``4 * (3 * corner + axis) + lane``: v0 x of
the four lanes, then v0 y, ...), then four int32 bit patterns (columns 36-39, read through
``tris.view(np.int32)``): each lane's triangle index in leaf order, -1 for a padding lane
(three equal corners, never hit). A leaf's triangles fill its lanes in leaf order. The
traversal tests the four lanes of a block at once (``simd.hit4``, 4-wide float64, edge
functions and distance; ``simd.hit4_nearest`` also picks the nearest lane hit), and
repeats the scalar watertight test (the same operations) on the final closest hit only,
for its barycentrics. Both read the corners themselves, so neighbouring triangles see
the very same corner. Shading keeps ``v0`` (float32 (T, 3)) and the exact
edges ``e1 = v1 - v0``, ``e2 = v2 - v0`` (float64 (T, 3), differences of the float32
corners, exact unless a corner's coordinates differ by more than 2^29 in magnitude),
also in leaf order.

The tree depth is at most ``MAX_DEPTH``: below ``FALLBACK_DEPTH`` the builder splits by
SAH, deeper it halves the triangle range, which needs at most 31 more levels for fewer
than 2^31 triangles; collapsing never deepens it. Traversal leaves at most three
children per record level on the stack (3 int32 slots each: reference, count, entry
distance), so ``STACK_SIZE`` slots always suffice.

Memory latency: beyond a few million triangles the records and rows no longer fit the
caches and a ray's node visits form a chain of memory round trips. A pushed child is
prefetched when it is pushed (``prefetch.py``), so it has arrived when it is popped. The
batch kernels go further: each thread keeps ``LANES`` rays in flight and advances them
in turn, one node or leaf each, prefetching what each ray reads next, so the round trips
of different rays overlap (one step function serves both, so the rays' paths and hits
are exactly those of the one-ray functions the path kernel calls).
"""
import numpy as np
from numba import prange

from ..jit import function, inline, kernel
from .prefetch import prefetch_lines
from .simd import BLOCK, PRIM_COL, f32_below, hit4, hit4_nearest, slab4

N_BINS = 16
MAX_LEAF = 8  # ranges this small always become leaves (fewer nodes, same ray speed as 4)
MAX_LEAF_SAH = 16  # SAH may keep ranges up to this size as leaves
FALLBACK_DEPTH = 32
MAX_DEPTH = FALLBACK_DEPTH + 32
STACK_SIZE = 3 * 3 * MAX_DEPTH  # int32 slots: 3 per pushed child, at most 3 left per record level
TRAVERSAL_COST = 1.0  # relative to one triangle test
EDGE_DTYPE = np.float64
NODE_WIDTH = 32  # float32 slots per record: 128 bytes, two cache lines
C_BOX = 0  # columns 0-23: the four children's boxes, plane by plane (module docstring)
C_REF = 24  # columns 24-27: the children's references (int32)
C_CNT = 28  # columns 28-31: the children's triangle counts (int32; 0: a record)
_U0 = np.uint64(0)  # unsigned stack offsets (see uidx)
_U1 = np.uint64(1)
_U2 = np.uint64(2)
_U3 = np.uint64(3)
_B2_WIDTH = 16  # the builder's binary records: two boxes (0-5, 6-11), then int32
_L_REF = 12  # left reference, count, right reference, count (as in the 4-wide records)
_L_CNT = 13
_R_REF = 14
_R_CNT = 15


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
def _set_child_box(nodes, rec, side, l0, l1, l2, h0, h1, h2):
    o = 6 * side
    nodes[rec, o] = _down(l0); nodes[rec, o + 1] = _down(l1); nodes[rec, o + 2] = _down(l2)
    nodes[rec, o + 3] = _up(h0); nodes[rec, o + 4] = _up(h1); nodes[rec, o + 5] = _up(h2)


@function
def _collapse(n2, l2, nodes, st, c_ref, c_cnt, c_box):
    """Fill ``nodes`` with the 4-wide records of the binary tree (``n2`` records, ``l2``
    their int32 view): each 4-wide record takes a binary record's two children and, while
    it has fewer than four and one of them is a record, replaces the record child of
    largest surface area by its two children, so it spans up to three binary levels.
    Records are numbered in depth-first order, the root's 0. Returns their number. The
    other arguments are scratch (``build_bvh``); a function of its own, as the builder
    compiles faster in two parts than in one."""
    links = nodes.view(np.int32)
    st[0, 0] = 0
    st[0, 1] = -1
    sp = 1
    n4 = 0
    while sp > 0:
        sp -= 1
        r2 = st[sp, 0]
        slot = st[sp, 1]
        rec = n4
        n4 += 1
        if slot >= 0:
            links[slot >> 2, C_REF + (slot & 3)] = rec
            links[slot >> 2, C_CNT + (slot & 3)] = 0
        nc = 0
        for side in range(2):
            if l2[r2, _L_REF + 2 * side] >= 0:  # present (absent only in a single-leaf or empty tree)
                c_ref[nc] = l2[r2, _L_REF + 2 * side]
                c_cnt[nc] = l2[r2, _L_CNT + 2 * side]
                for q in range(6):
                    c_box[nc, q] = n2[r2, 6 * side + q]
                nc += 1
        while nc < 4:
            best = -1
            best_a = -1.0
            for i in range(nc):
                if c_cnt[i] == 0:
                    a = _area(np.float64(c_box[i, 3]) - c_box[i, 0], np.float64(c_box[i, 4]) - c_box[i, 1],
                              np.float64(c_box[i, 5]) - c_box[i, 2])
                    if a > best_a:
                        best_a = a
                        best = i
            if best < 0:
                break
            r = c_ref[best]
            c_ref[best] = l2[r, _L_REF]; c_cnt[best] = l2[r, _L_CNT]
            c_ref[nc] = l2[r, _R_REF]; c_cnt[nc] = l2[r, _R_CNT]
            for q in range(6):
                c_box[best, q] = n2[r, q]
                c_box[nc, q] = n2[r, 6 + q]
            nc += 1
        for c in range(4):
            if c < nc:
                for q in range(6):
                    nodes[rec, C_BOX + 4 * q + c] = c_box[c, q]
                links[rec, C_REF + c] = c_ref[c]
                links[rec, C_CNT + c] = c_cnt[c]
            else:  # absent: a box no ray enters
                for q in range(3):
                    nodes[rec, C_BOX + 4 * q + c] = np.inf
                    nodes[rec, C_BOX + 4 * (3 + q) + c] = -np.inf
                links[rec, C_REF + c] = -1
                links[rec, C_CNT + c] = 0
        for c in range(nc - 1, -1, -1):  # the first child's subtree is numbered first
            if c_cnt[c] == 0:
                st[sp, 0] = c_ref[c]
                st[sp, 1] = 4 * rec + c
                sp += 1
    return n4


@function
def _corner_bounds(v0, v1, v2, lo, hi, prims):
    """Per-triangle bounds of the float32 corners, and prims = 0..T-1. Returns the index of
    the first triangle with a non-finite coordinate, or -1."""
    bad = -1
    n_tri = v0.shape[0]
    for i in range(n_tri):
        for q in range(3):
            a = np.float32(v0[i, q]); b = np.float32(v1[i, q]); c = np.float32(v2[i, q])
            lo[i, q] = min(a, min(b, c))
            hi[i, q] = max(a, max(b, c))
            if bad < 0 and not (np.isfinite(a) and np.isfinite(b) and np.isfinite(c)):
                bad = i
        prims[i] = i
    return bad


@function
def _bin_centroids(lo, hi, s, e, cb, c_min, c_scale, b_cnt, b_lo, b_hi):
    """One binning pass of triangles [s, e) along the three axes of the centroid bounds
    ``cb``: counts and boxes per bin. Returns False if every axis has zero extent."""
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
    return any_axis


@function
def _best_split(st_c, sp, c_scale, b_cnt, b_lo, b_hi, r_area, r_cnt):
    """The cheapest SAH split over the binned axes of the range on stack slot ``sp``:
    (axis or -1, first bin of the right child, cost)."""
    best_axis = -1
    best_split = 0
    best_cost = np.inf
    node_area = max(_area(np.float64(np.float32(st_c[sp, 9])) - np.float32(st_c[sp, 6]),
                          np.float64(np.float32(st_c[sp, 10])) - np.float32(st_c[sp, 7]),
                          np.float64(np.float32(st_c[sp, 11])) - np.float32(st_c[sp, 8])), 1e-300)
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
    return best_axis, best_split, best_cost


@function
def _partition(lo, hi, prims, s, e, a, cmin, scale, best_split):
    """Partition triangles [s, e) in place by bin along axis ``a``: those in bins below
    ``best_split`` first. Returns (mid, the left child's doubled-centroid bounds (6), the
    right child's (6))."""
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
    return i, pl0, pl1, pl2, ph0, ph1, ph2, ql0, ql1, ql2, qh0, qh1, qh2


@inline
def _bins_box(b_lo, b_hi, a, b0, b1):
    """The union of the boxes of bins [b0, b1) along axis ``a``."""
    l0 = np.inf; l1 = np.inf; l2 = np.inf; h0 = -np.inf; h1 = -np.inf; h2 = -np.inf
    for b in range(b0, b1):
        l0 = min(l0, b_lo[a, b, 0]); l1 = min(l1, b_lo[a, b, 1]); l2 = min(l2, b_lo[a, b, 2])
        h0 = max(h0, b_hi[a, b, 0]); h1 = max(h1, b_hi[a, b, 1]); h2 = max(h2, b_hi[a, b, 2])
    return l0, l1, l2, h0, h1, h2


@function
def _leaf_order_shading(v0, v1, v2, prims, tv0, te1, te2):
    """The triangles in leaf order for shading: the first corner and the exact edges."""
    for k in range(prims.shape[0]):
        p = prims[k]
        for q in range(3):
            a32 = np.float32(v0[p, q]); b32 = np.float32(v1[p, q]); c32 = np.float32(v2[p, q])
            tv0[k, q] = a32
            te1[k, q] = np.float64(b32) - np.float64(a32)
            te2[k, q] = np.float64(c32) - np.float64(a32)


@function
def _fill_blocks(v0, v1, v2, prims, leaf_s, leaf_n, n_leaf, tris, tri_ids):
    """The corners for traversal: each leaf's blocks, lane by lane; padding lanes are a
    triangle with three equal corners (determinant 0: never hit) and index -1."""
    b = 0
    for f in range(n_leaf):
        s = leaf_s[f]
        n = leaf_n[f]
        for j in range(n_blocks(n) * BLOCK):
            ln = j % BLOCK
            if j < n:
                p = prims[s + j]
                tri_ids[b, PRIM_COL + ln] = s + j
                for q in range(3):
                    tris[b, q * BLOCK + ln] = np.float32(v0[p, q])
                    tris[b, (3 + q) * BLOCK + ln] = np.float32(v1[p, q])
                    tris[b, (6 + q) * BLOCK + ln] = np.float32(v2[p, q])
            else:
                tri_ids[b, PRIM_COL + ln] = -1
                for q in range(9):
                    tris[b, q * BLOCK + ln] = 0.0
            if ln == BLOCK - 1:
                b += 1


@kernel
def build_bvh(v0, v1, v2, tris, tv0, te1, te2):
    """Binned-SAH build over corners (T, 3) (float32 or float64; rounded to float32).

    Fills the caller's arrays (so the caller chooses their memory, e.g. huge pages):
    ``tris`` float32 (T, BLOCK_COLS) the leaf blocks for traversal (a leaf of n
    triangles takes ceil(n / 4) <= n blocks, so T rows always suffice; the first
    ``n_blk`` are used), ``tv0`` float32 (T, 3), ``te1``, ``te2`` float64 (T, 3) the
    leaf-order shading arrays. Returns (nodes, prims, bad, n_blk): ``nodes`` the packed
    records (module docstring; a view of a larger, mostly untouched buffer: copy it),
    ``prims`` maps leaf order to input order, ``bad`` the index of the first triangle with
    a non-finite coordinate, or -1 (the tree is then not valid), ``n_blk`` the blocks used.
    """
    n_tri = v0.shape[0]
    max_rec = max(1, n_tri - 1)  # inner nodes of a tree whose leaves are never empty
    # np.empty: the pages of records never written are never touched, so never resident
    nodes = np.empty((max_rec, _B2_WIDTH), np.float32)
    links = nodes.view(np.int32)
    prims = np.empty(n_tri, np.int32)
    bad = -1
    n_rec = 0
    n_blk = 0
    tri_ids = tris.view(np.int32)
    leaf_s = np.empty(n_tri, np.int64)  # each leaf's first triangle (leaf order) and count,
    leaf_n = np.empty(n_tri, np.int64)  # in the order the leaves are made (= leaf order)
    n_leaf = 0
    if n_tri == 0:
        for q in range(12):
            nodes[0, q] = np.inf
        links[0, _L_REF] = -1; links[0, _L_CNT] = 0; links[0, _R_REF] = -1; links[0, _R_CNT] = 0
        n_rec = 1
    else:
        # per-triangle bounds of the float32 corners; partitioned in place with prims
        lo = np.empty((n_tri, 3), np.float32)
        hi = np.empty((n_tri, 3), np.float32)
        bad = _corner_bounds(v0, v1, v2, lo, hi, prims)
        if bad >= 0:
            return nodes[:1], prims, bad, 0  # a placeholder: the tree is not valid

        b_cnt = np.zeros((3, N_BINS), np.int64)
        b_lo = np.empty((3, N_BINS, 3), np.float32)
        b_hi = np.empty((3, N_BINS, 3), np.float32)
        r_area = np.empty(N_BINS)
        r_cnt = np.empty(N_BINS, np.int64)
        c_min = np.empty(3)
        c_scale = np.empty(3)
        cb = np.empty(6)  # centroid bounds of the node being processed
        # stack of pending ranges: slot (2 * parent record + side, -1 for the root), start,
        # end, depth; their doubled-centroid bounds and their (rounded) boxes
        st_i = np.empty((2 * MAX_DEPTH + 4, 4), np.int64)
        st_c = np.empty((2 * MAX_DEPTH + 4, 12))

        l0, l1, l2, h0, h1, h2, cl0, cl1, cl2, ch0, ch1, ch2 = _range_bounds(lo, hi, 0, n_tri)
        st_i[0, 0] = -1; st_i[0, 1] = 0; st_i[0, 2] = n_tri; st_i[0, 3] = 1
        st_c[0, 0] = cl0; st_c[0, 1] = cl1; st_c[0, 2] = cl2
        st_c[0, 3] = ch0; st_c[0, 4] = ch1; st_c[0, 5] = ch2
        st_c[0, 6] = _down(l0); st_c[0, 7] = _down(l1); st_c[0, 8] = _down(l2)
        st_c[0, 9] = _up(h0); st_c[0, 10] = _up(h1); st_c[0, 11] = _up(h2)
        sp = 1
        while sp > 0:
            sp -= 1
            slot = st_i[sp, 0]; s = st_i[sp, 1]; e = st_i[sp, 2]; depth = st_i[sp, 3]
            for q in range(6):
                cb[q] = st_c[sp, q]
            n = e - s
            is_leaf = n <= MAX_LEAF

            best_axis = -1
            best_split = 0
            best_cost = np.inf
            if not is_leaf and depth < FALLBACK_DEPTH:
                # one binning pass for the three axes
                if _bin_centroids(lo, hi, s, e, cb, c_min, c_scale, b_cnt, b_lo, b_hi):
                    best_axis, best_split, best_cost = _best_split(st_c, sp, c_scale, b_cnt, b_lo, b_hi, r_area,
                                                                   r_cnt)
                if best_axis >= 0 and best_cost >= n and n <= MAX_LEAF_SAH:
                    is_leaf = True
                if best_axis < 0 and n <= MAX_LEAF_SAH:
                    is_leaf = True

            if is_leaf:
                blk = n_blk
                n_blk += n_blocks(n)
                leaf_s[n_leaf] = s
                leaf_n[n_leaf] = n
                n_leaf += 1
                if slot < 0:
                    # the whole tree is one leaf: record 0 holds it and a box no ray meets
                    for q in range(6):
                        nodes[0, q] = st_c[sp, 6 + q]
                    for q in range(6, 12):
                        nodes[0, q] = np.inf  # not rounded: nextafter(inf, -inf) is finite
                    links[0, _L_REF] = blk; links[0, _L_CNT] = n; links[0, _R_REF] = -1; links[0, _R_CNT] = 0
                    n_rec = 1
                else:
                    links[slot >> 1, _L_REF + 2 * (slot & 1)] = blk
                    links[slot >> 1, _L_CNT + 2 * (slot & 1)] = n
                continue

            rec = n_rec
            n_rec += 1
            if slot >= 0:
                links[slot >> 1, _L_REF + 2 * (slot & 1)] = rec
                links[slot >> 1, _L_CNT + 2 * (slot & 1)] = 0
            if best_axis >= 0:
                # partition by bin; the children's boxes are the unions of their bins
                a = best_axis
                mid, pl0, pl1, pl2, ph0, ph1, ph2, ql0, ql1, ql2, qh0, qh1, qh2 = _partition(
                    lo, hi, prims, s, e, a, c_min[a], c_scale[a], best_split)
                l0, l1, l2, h0, h1, h2 = _bins_box(b_lo, b_hi, a, 0, best_split)
                _set_child_box(nodes, rec, 0, l0, l1, l2, h0, h1, h2)
                l0, l1, l2, h0, h1, h2 = _bins_box(b_lo, b_hi, a, best_split, N_BINS)
                _set_child_box(nodes, rec, 1, l0, l1, l2, h0, h1, h2)
            else:
                # deep (or all centroids equal): halve the range, which bounds the depth
                mid = s + n // 2
                l0, l1, l2, h0, h1, h2, pl0, pl1, pl2, ph0, ph1, ph2 = _range_bounds(lo, hi, s, mid)
                _set_child_box(nodes, rec, 0, l0, l1, l2, h0, h1, h2)
                l0, l1, l2, h0, h1, h2, ql0, ql1, ql2, qh0, qh1, qh2 = _range_bounds(lo, hi, mid, e)
                _set_child_box(nodes, rec, 1, l0, l1, l2, h0, h1, h2)
            # push right, then left (processed next)
            st_i[sp, 0] = 2 * rec + 1; st_i[sp, 1] = mid; st_i[sp, 2] = e; st_i[sp, 3] = depth + 1
            st_c[sp, 0] = ql0; st_c[sp, 1] = ql1; st_c[sp, 2] = ql2
            st_c[sp, 3] = qh0; st_c[sp, 4] = qh1; st_c[sp, 5] = qh2
            for q in range(6):
                st_c[sp, 6 + q] = nodes[rec, 6 + q]
            sp += 1
            st_i[sp, 0] = 2 * rec; st_i[sp, 1] = s; st_i[sp, 2] = mid; st_i[sp, 3] = depth + 1
            st_c[sp, 0] = pl0; st_c[sp, 1] = pl1; st_c[sp, 2] = pl2
            st_c[sp, 3] = ph0; st_c[sp, 4] = ph1; st_c[sp, 5] = ph2
            for q in range(6):
                st_c[sp, 6 + q] = nodes[rec, q]
            sp += 1

    # triangles in leaf order (lo and hi are no longer needed), then their traversal blocks
    _leaf_order_shading(v0, v1, v2, prims, tv0, te1, te2)
    _fill_blocks(v0, v1, v2, prims, leaf_s, leaf_n, n_leaf, tris, tri_ids)
    nodes4 = np.empty((max(1, n_rec), NODE_WIDTH), np.float32)
    n4 = _collapse(nodes, links, nodes4, np.empty((3 * MAX_DEPTH + 8, 2), np.int64), np.empty(4, np.int64),
                   np.empty(4, np.int64), np.empty((4, 6), np.float32))
    return nodes4[:n4], prims, bad, n_blk


@inline
def _planes4(ix, iy, iz):
    """First columns of the near and far planes of a record's boxes along x, y, z for a
    ray with inverse direction (ix, iy, iz): the low plane is the near one along a
    positive component (then (lo - o) / d <= (hi - o) / d), the high plane along a
    negative one. Chosen once per ray, so the slab test needs no per-axis min/max."""
    if ix >= 0.0:
        nx = uidx(C_BOX); fx = uidx(C_BOX + 12)
    else:
        nx = uidx(C_BOX + 12); fx = uidx(C_BOX)
    if iy >= 0.0:
        ny = uidx(C_BOX + 4); fy = uidx(C_BOX + 16)
    else:
        ny = uidx(C_BOX + 16); fy = uidx(C_BOX + 4)
    if iz >= 0.0:
        nz = uidx(C_BOX + 8); fz = uidx(C_BOX + 20)
    else:
        nz = uidx(C_BOX + 20); fz = uidx(C_BOX + 8)
    return nx, ny, nz, fx, fy, fz


@inline
def uidx(i):
    """An index as unsigned: numba then emits no negative-index wraparound for it (the
    traversal's indices are never negative)."""
    return np.uint64(i)


@inline
def _pick(x, y, z, k):
    if k == 0:
        return x
    if k == 1:
        return y
    return z


@inline
def ray_setup(dx, dy, dz, ix, iy, iz):
    """Watertight-test constants of a ray: the axes (kx, ky, kz), kz the dominant one, and
    the shear (sx, sy, sz) mapping the direction to +z (Woop, Benthin, Wald 2013).
    ``ix, iy, iz`` are the inverse direction (``_inv``): sz = 1 / d_kz is the dominant
    axis's, the same division (d_kz is never 0 for a direction)."""
    ax = abs(dx); ay = abs(dy); az = abs(dz)
    kz = 0  # the first axis of largest |d|
    if ay > ax:
        kz = 1
        ax = ay
    if az > ax:
        kz = 2
    kx = kz + 1 if kz < 2 else 0
    ky = kx + 1 if kx < 2 else 0
    if _pick(dx, dy, dz, kz) < 0.0:
        t = kx; kx = ky; ky = t  # keep the winding
    sz = _pick(ix, iy, iz, kz)
    sx = _pick(dx, dy, dz, kx) * sz
    sy = _pick(dx, dy, dz, ky) * sz
    return kx, ky, kz, sx, sy, sz


@inline
def ray_constants(ox, oy, oz, dx, dy, dz):
    """What every traversal derives once per ray: the inverse direction (ix, iy, iz) for
    the slab tests, and for the watertight triangle test the axes and shear of
    ``ray_setup`` and the origin's coordinates on those axes (okx, oky, okz)."""
    ix = _inv(dx); iy = _inv(dy); iz = _inv(dz)
    kx, ky, kz, sx, sy, sz = ray_setup(dx, dy, dz, ix, iy, iz)
    return (ix, iy, iz, kx, ky, kz, sx, sy, sz,
            _pick(ox, oy, oz, kx), _pick(ox, oy, oz, ky), _pick(ox, oy, oz, kz))


@inline
def intersect_lane(okx, oky, okz, ukx, uky, ukz, sx, sy, sz, tris, blk, lane, tmin, tmax):
    """Watertight ray/triangle test (Woop, Benthin, Wald, JCGT 2(1), 2013) in float64.

    ``okx, oky, okz`` are the ray origin's coordinates on the axes of ``ray_setup``
    (``ukx, uky, ukz``, unsigned); the triangle is lane ``lane`` of block ``blk`` of
    ``tris`` (float32 corners, see the module docstring). The corners, exact in float64,
    are moved to the ray origin and sheared so the ray runs along +z; the signs of the
    three edge functions decide the hit, and a shared edge gets the same edge function
    (negated) in both its triangles, so no ray slips between them. Returns (t, u, v)
    with u, v the weights of v1, v2; t = inf on a miss. ``simd.hit4`` computes the same
    edge functions and distance for the four lanes of a block at once, so the traversal
    calls this only for its final closest hit, for the barycentrics.
    """
    q = uidx(blk)
    ln = uidx(lane)
    c4 = uidx(BLOCK)
    ox_ = ukx * c4 + ln; oy_ = uky * c4 + ln; oz_ = ukz * c4 + ln
    c12 = uidx(3 * BLOCK)
    c24 = uidx(6 * BLOCK)
    az = np.float64(tris[q, oz_]) - okz
    ax = (np.float64(tris[q, ox_]) - okx) - sx * az
    ay = (np.float64(tris[q, oy_]) - oky) - sy * az
    bz = np.float64(tris[q, c12 + oz_]) - okz
    bx = (np.float64(tris[q, c12 + ox_]) - okx) - sx * bz
    by = (np.float64(tris[q, c12 + oy_]) - oky) - sy * bz
    cz = np.float64(tris[q, c24 + oz_]) - okz
    cx = (np.float64(tris[q, c24 + ox_]) - okx) - sx * cz
    cy = (np.float64(tris[q, c24 + oy_]) - oky) - sy * cz
    u = cx * by - cy * bx
    v = ax * cy - ay * cx
    w = bx * ay - by * ax
    # a miss when the edge functions have mixed signs; min/max instead of six branches
    if min(u, min(v, w)) < 0.0 and max(u, max(v, w)) > 0.0:
        return np.inf, 0.0, 0.0
    det = u + v + w
    if det == 0.0:
        return np.inf, 0.0, 0.0
    t = sz * (u * az + v * bz + w * cz) / det
    if not (t > tmin and t < tmax):
        return np.inf, 0.0, 0.0
    return t, v / det, w / det


@inline
def n_blocks(cnt):
    """Blocks of a leaf of ``cnt`` triangles (BLOCK = 4)."""
    return (cnt + 3) >> 2


@inline
def leaf_closest(rf, ru, tris, tri_ids, ref, cnt, tmin, best):
    """The closest hit so far ``best`` = (t, prim, q) after testing the leaf whose blocks
    start at ``ref`` (``cnt`` triangles) with the ray's constants ``rf``, ``ru``
    (``_ray_tuples``): each block's nearest lane hit before the closest so far
    (``hit4_nearest``; ties go to the first triangle, as one by one). q = 4 block + lane
    locates the hit in ``tris`` for its barycentrics, which ``closest_hit`` computes once,
    for the final hit only."""
    _ox, _oy, _oz, _ix, _iy, _iz, sx, sy, sz, okx, oky, okz = rf
    ukx, uky, ukz = ru[0], ru[1], ru[2]
    best_t, best_p, best_q = best
    for b in range(ref, ref + n_blocks(cnt)):
        ub = uidx(b)
        ln, t = hit4_nearest(tris, ub, ukx, uky, ukz, okx, oky, okz, sx, sy, sz, tmin, best_t)
        if ln >= 0:
            best_t = t
            best_p = tri_ids[ub, uidx(PRIM_COL + ln)]
            best_q = b * BLOCK + ln
    return best_t, best_p, best_q


@inline
def leaf_any(okx, oky, okz, ukx, uky, ukz, sx, sy, sz, tris, ref, cnt, tmin, tmax):
    """True if a triangle of the leaf at blocks ``ref`` (``cnt`` triangles) is hit in
    (tmin, tmax): a lane ``hit4`` sets is exactly a lane the scalar test would report, so
    an any-hit query needs no scalar test."""
    for b in range(ref, ref + n_blocks(cnt)):
        if hit4(tris, uidx(b), ukx, uky, ukz, okx, oky, okz, sx, sy, sz, tmin, tmax) != 0:
            return True
    return False


@inline
def triangle_normal(e1, e2, p):
    """e1 × e2 of leaf triangle ``p``: its geometric normal, of length twice its area (the
    one place the renderer derives it, for shading, emitter sampling and media)."""
    return (e1[p, 1] * e2[p, 2] - e1[p, 2] * e2[p, 1],
            e1[p, 2] * e2[p, 0] - e1[p, 0] * e2[p, 2],
            e1[p, 0] * e2[p, 1] - e1[p, 1] * e2[p, 0])


@inline
def _inv(d):
    if d == 0.0:
        return 1e300
    return 1.0 / d


@inline
def _prefetch_child(nodes, tris, ref, cnt):
    """Start loading a child the traversal will visit later: its record (two lines) or
    every line of its leaf's blocks."""
    if cnt == 0:
        prefetch_lines(nodes, ref)
    else:
        for b in range(ref, ref + n_blocks(cnt)):
            prefetch_lines(tris, b)


@inline
def _push(stack, fstack, sp, links, rec, c, t):
    """Push child ``c`` of record ``rec`` (reference, count, entry distance rounded down to
    float32) if the ray enters its box (t < inf)."""
    if t < np.inf:
        stack[sp] = links[rec, uidx(C_REF + c)]
        stack[sp + _U1] = links[rec, uidx(C_CNT + c)]
        fstack[sp + _U2] = f32_below(t)
        return sp + _U3
    return sp


@inline
def _visit_record(nodes, links, tris, rec, rf, ru, tmax, stack, fstack, sp, nearest):
    """The children of record ``rec`` the ray (constants ``rf``, ``ru``: ``_ray_tuples``)
    enters before ``tmax`` (``simd.slab4``): pushed, and then, if ``nearest``, ordered so
    the nearest is on top (insertion sort of at most four entries), else left in child
    order. Children the ray is to visit later are prefetched. Returns the new stack
    pointer."""
    ox, oy, oz, ix, iy, iz = rf[0], rf[1], rf[2], rf[3], rf[4], rf[5]
    nx, ny, nz, fx, fy, fz = ru[3], ru[4], ru[5], ru[6], ru[7], ru[8]
    t0, t1, t2, t3 = slab4(nodes, rec, nx, ny, nz, fx, fy, fz, ox, oy, oz, ix, iy, iz, tmax)
    base = sp
    sp = _push(stack, fstack, sp, links, rec, 0, t0)
    sp = _push(stack, fstack, sp, links, rec, 1, t1)
    sp = _push(stack, fstack, sp, links, rec, 2, t2)
    sp = _push(stack, fstack, sp, links, rec, 3, t3)
    if nearest and sp > base + _U3:
        # far to near from the bottom up, so the nearest is popped first
        i = base + _U3
        while i < sp:
            r = stack[i]; c = stack[i + _U1]; d = fstack[i + _U2]
            j = i
            while j > base and fstack[j - _U1] < d:
                stack[j] = stack[j - _U3]; stack[j + _U1] = stack[j - _U2]; fstack[j + _U2] = fstack[j - _U1]
                j -= _U3
            stack[j] = r; stack[j + _U1] = c; fstack[j + _U2] = d
            i += _U3
    if sp > base + _U3:
        k = base
        while k < sp - _U3:
            _prefetch_child(nodes, tris, stack[k], stack[k + _U1])
            k += _U3
    return sp


@inline
def _closest_step(rf, ru, tmin, nodes, links, tris, tri_ids, stack, fstack, ref, cnt, sp, best_t, best_p, best_q):
    """One step of ``closest_hit``: visit the record or leaf (ref, cnt), then pop the next
    child whose box starts within the best hit so far. ``rf``, ``ru`` are the ray's
    constants (``_ray_tuples``; tuples keep the call under CPython's 30 arguments, beyond
    which it becomes a ``*args`` call numba cannot inline). Returns the new state (ref,
    cnt, sp, best_t, best_p, best_q) and whether there is a next child."""
    if cnt == 0:
        sp = _visit_record(nodes, links, tris, uidx(ref), rf, ru, best_t, stack, fstack, sp, True)
    else:
        best_t, best_p, best_q = leaf_closest(rf, ru, tris, tri_ids, ref, cnt, tmin, (best_t, best_p, best_q))
    while sp > _U0:
        sp -= _U3
        if fstack[sp + _U2] <= best_t:
            return stack[sp], stack[sp + _U1], sp, best_t, best_p, best_q, True
    return ref, cnt, sp, best_t, best_p, best_q, False


@inline
def _occluded_step(rf, ru, tmin, tmax, nodes, links, tris, stack, fstack, ref, cnt, sp):
    """One step of ``occluded``: visit the record or leaf (ref, cnt), then pop the next
    child. Returns (ref, cnt, sp, state): state 1 a hit (the answer is True), 0 no child
    left (False), 2 go on. ``rf``, ``ru`` as in ``_closest_step``."""
    _ox, _oy, _oz, _ix, _iy, _iz, sx, sy, sz, okx, oky, okz = rf
    ukx, uky, ukz = ru[0], ru[1], ru[2]
    if cnt == 0:
        sp = _visit_record(nodes, links, tris, uidx(ref), rf, ru, tmax, stack, fstack, sp, False)
    elif leaf_any(okx, oky, okz, ukx, uky, ukz, sx, sy, sz, tris, ref, cnt, tmin, tmax):
        return ref, cnt, sp, 1
    if sp == _U0:
        return ref, cnt, sp, 0
    sp -= _U3
    return stack[sp], stack[sp + _U1], sp, 2


@inline
def _ray_tuples(ox, oy, oz, dx, dy, dz):
    """A ray's traversal constants as two tuples: floats (origin, inverse direction,
    shear, origin on the shear axes) and unsigned integers (the shear axes, the near
    and far plane columns of ``_planes4``)."""
    ix, iy, iz, kx, ky, kz, sx, sy, sz, okx, oky, okz = ray_constants(ox, oy, oz, dx, dy, dz)
    nx, ny, nz, fx, fy, fz = _planes4(ix, iy, iz)
    return (ox, oy, oz, ix, iy, iz, sx, sy, sz, okx, oky, okz), (uidx(kx), uidx(ky), uidx(kz), nx, ny, nz, fx, fy, fz)


@inline
def closest_hit(ox, oy, oz, dx, dy, dz, tmin, tmax, nodes, tris, stack):
    """Closest triangle hit in (tmin, tmax). Returns (t, prim, u, v); prim = -1 on a miss.

    Front-to-back: of the children of a record the ray enters, all are pushed with their
    reference, count and entry distance (rounded down to float32), nearest on top, so a
    pop reads no record; a popped child is skipped when its box starts beyond the best
    hit by then.
    """
    if tris.shape[0] == 0:
        return np.inf, -1, 0.0, 0.0
    links = nodes.view(np.int32)
    tri_ids = tris.view(np.int32)
    fstack = stack.view(np.float32)
    rf, ru = _ray_tuples(ox, oy, oz, dx, dy, dz)
    best_t = tmax
    best_p = -1
    best_q = -1
    sp = _U0
    ref = 0  # the child being entered: a record (cnt == 0) or a leaf's blocks
    cnt = 0
    going = True
    while going:
        ref, cnt, sp, best_t, best_p, best_q, going = _closest_step(
            rf, ru, tmin, nodes, links, tris, tri_ids, stack, fstack, ref, cnt, sp, best_t, best_p, best_q)
    if best_p < 0:
        return np.inf, -1, 0.0, 0.0
    # the barycentrics of the hit: the scalar test of its lane, the same operations as
    # hit4's, so the same t
    ox, oy, oz, ix, iy, iz, sx, sy, sz, okx, oky, okz = rf
    ukx, uky, ukz, nx, ny, nz, fx, fy, fz = ru
    t, u, v = intersect_lane(okx, oky, okz, ukx, uky, ukz, sx, sy, sz, tris, best_q // BLOCK, best_q % BLOCK, tmin,
                             np.inf)
    return best_t, best_p, u, v


@inline
def occluded(ox, oy, oz, dx, dy, dz, tmin, tmax, nodes, tris, stack):
    """True if any triangle is hit in (tmin, tmax); any hit ends it. Children are visited
    in the order popped (the last of a record's children first); the answer does not
    depend on the order."""
    if tris.shape[0] == 0:
        return False
    links = nodes.view(np.int32)
    fstack = stack.view(np.float32)
    rf, ru = _ray_tuples(ox, oy, oz, dx, dy, dz)
    sp = _U0
    ref = 0
    cnt = 0
    state = 2
    while state == 2:
        ref, cnt, sp, state = _occluded_step(rf, ru, tmin, tmax, nodes, links, tris, stack, fstack, ref, cnt,
                                             sp)
    return state == 1


@function
def trace_closest(ox, oy, oz, dx, dy, dz, tmin, tmax, nodes, tris, stack):
    """``closest_hit`` compiled once as a function of its own, for the path kernel and the
    media: inlined at each of their call sites, the traversal's code was about a third of
    the path kernel's, and of its compile time (the call costs three array arguments)."""
    return closest_hit(ox, oy, oz, dx, dy, dz, tmin, tmax, nodes, tris, stack)


@function
def trace_occluded(ox, oy, oz, dx, dy, dz, tmin, tmax, nodes, tris, stack):
    """``occluded`` compiled once as a function of its own (see ``trace_closest``)."""
    return occluded(ox, oy, oz, dx, dy, dz, tmin, tmax, nodes, tris, stack)


LANES = 12  # rays a batch kernel's thread keeps in flight at once
CHUNK = 2048  # rays per parallel work item of the batch kernels
# rows of a batch kernel's int64 lane state (LANE_ROWS, LANES): each lane's ray (-1: retired),
# the child it enters next (reference, count) and, for closest hits, its best primitive so far
L_RAY = 0
L_REF = 1
L_CNT = 2
L_PRIM = 3
LANE_ROWS = 4


@inline
def _start_lane(orig, dirs, i, lane, lf, lk):
    """Load ray ``i``'s constants (``_ray_tuples``) into lane ``lane``: ``lf`` the floats,
    ``lk`` the unsigned integers."""
    rf, ru = _ray_tuples(orig[i, 0], orig[i, 1], orig[i, 2], dirs[i, 0], dirs[i, 1], dirs[i, 2])
    ox, oy, oz, ix, iy, iz, sx, sy, sz, okx, oky, okz = rf
    ukx, uky, ukz, nx, ny, nz, fx, fy, fz = ru
    lf[lane, 0] = ox; lf[lane, 1] = oy; lf[lane, 2] = oz; lf[lane, 3] = ix; lf[lane, 4] = iy; lf[lane, 5] = iz
    lf[lane, 6] = sx; lf[lane, 7] = sy; lf[lane, 8] = sz; lf[lane, 9] = okx; lf[lane, 10] = oky; lf[lane, 11] = okz
    lk[lane, 0] = ukx; lk[lane, 1] = uky; lk[lane, 2] = ukz
    lk[lane, 3] = nx; lk[lane, 4] = ny; lk[lane, 5] = nz; lk[lane, 6] = fx; lk[lane, 7] = fy; lk[lane, 8] = fz


@inline
def _lane_f(lf, j):
    """Lane ``j``'s float constants, the tuple ``_ray_tuples`` made."""
    return (lf[j, 0], lf[j, 1], lf[j, 2], lf[j, 3], lf[j, 4], lf[j, 5], lf[j, 6], lf[j, 7], lf[j, 8], lf[j, 9],
            lf[j, 10], lf[j, 11])


@inline
def _lane_u(lk, j):
    """Lane ``j``'s integer constants, the tuple ``_ray_tuples`` made."""
    return (lk[j, 0], lk[j, 1], lk[j, 2], lk[j, 3], lk[j, 4], lk[j, 5], lk[j, 6], lk[j, 7], lk[j, 8])


@inline
def _refill(orig, dirs, j, nxt, hi, lf, lk, ls, l_sp):
    """Start lane ``j`` on ray ``nxt`` at the root if ``nxt < hi`` (then return nxt + 1),
    else retire the lane (ray -1 in the lane state ``ls``; ``l_sp`` the stack pointers).
    Returns the next ray and whether it started."""
    ls[L_REF, j] = 0; ls[L_CNT, j] = 0; l_sp[j] = 0
    if nxt < hi:
        _start_lane(orig, dirs, nxt, j, lf, lk)
        ls[L_RAY, j] = nxt
        return nxt + 1, True
    ls[L_RAY, j] = -1
    return nxt, False


@inline
def _start_lanes(orig, dirs, lo, hi, lf, lk, ls, l_sp):
    """Start every lane on the rays from ``lo`` (while any are left before ``hi``).
    Returns the next ray and the number of lanes started."""
    nxt = lo
    active = 0
    for j in range(LANES):
        nxt, started = _refill(orig, dirs, j, nxt, hi, lf, lk, ls, l_sp)
        active += started
    return nxt, active


@function
def _closest_lanes(orig, dirs, tmax, nodes, tris, lo, hi, t_out, p_out, stacks, lf, lk, ls, l_sp, l_t):
    """Closest hits of rays [lo, hi), ``LANES`` in flight (see ``trace_closest_batch``);
    the other arguments are the caller's scratch: the lanes' stacks, ray constants
    (``_start_lane``), int64 state (rows ``L_RAY`` ...), stack pointers and best distances.
    A function of its own: numba's parallel array analysis cannot follow the lanes' tuples
    inside a prange body."""
    links = nodes.view(np.int32)
    tri_ids = tris.view(np.int32)
    fstacks = stacks.view(np.float32)
    nxt, active = _start_lanes(orig, dirs, lo, hi, lf, lk, ls, l_sp)
    for j in range(active):  # lanes start in order, so the first ``active`` are running
        l_t[j] = tmax[ls[L_RAY, j]]; ls[L_PRIM, j] = -1
    j = 0
    while active > 0:
        if ls[L_RAY, j] >= 0:
            ref, cnt, sp, best_t, best_p, q, going = _closest_step(
                _lane_f(lf, j), _lane_u(lk, j), 0.0, nodes, links, tris, tri_ids, stacks[j], fstacks[j],
                ls[L_REF, j], ls[L_CNT, j], l_sp[j], l_t[j], ls[L_PRIM, j], np.int64(-1))
            if going:
                _prefetch_child(nodes, tris, ref, cnt)
                ls[L_REF, j] = ref; ls[L_CNT, j] = cnt; l_sp[j] = sp; l_t[j] = best_t; ls[L_PRIM, j] = best_p
            else:
                i = ls[L_RAY, j]
                if best_p < 0:
                    t_out[i] = np.inf
                    p_out[i] = -1
                else:
                    t_out[i] = best_t
                    p_out[i] = best_p
                nxt, started = _refill(orig, dirs, j, nxt, hi, lf, lk, ls, l_sp)
                if started:
                    l_t[j] = tmax[ls[L_RAY, j]]; ls[L_PRIM, j] = -1
                else:
                    active -= 1
        j += 1
        if j == LANES:
            j = 0


@function
def _occluded_lanes(orig, dirs, tmax, nodes, tris, lo, hi, out, stacks, lf, lk, ls, l_sp):
    """Any-hit answers of rays [lo, hi), ``LANES`` in flight (see ``_closest_lanes``)."""
    links = nodes.view(np.int32)
    fstacks = stacks.view(np.float32)
    nxt, active = _start_lanes(orig, dirs, lo, hi, lf, lk, ls, l_sp)
    j = 0
    while active > 0:
        i = ls[L_RAY, j]
        if i >= 0:
            ref, cnt, sp, state = _occluded_step(_lane_f(lf, j), _lane_u(lk, j), 0.0, tmax[i], nodes, links, tris,
                                                 stacks[j], fstacks[j], ls[L_REF, j], ls[L_CNT, j], l_sp[j])
            if state == 2:
                _prefetch_child(nodes, tris, ref, cnt)
                ls[L_REF, j] = ref; ls[L_CNT, j] = cnt; l_sp[j] = sp
            else:
                out[i] = state == 1
                nxt, started = _refill(orig, dirs, j, nxt, hi, lf, lk, ls, l_sp)
                if not started:
                    active -= 1
        j += 1
        if j == LANES:
            j = 0


@kernel(parallel=True)
def trace_closest_batch(orig, dirs, tmax, nodes, tris):
    """Closest hits of a batch of rays. Returns t (inf on a miss) and prim (leaf order, -1).

    Each ray takes the same path through the tree as ``closest_hit`` (the same step
    function, so the same hit), but a thread traces ``LANES`` rays at once, round robin,
    one step each (a record's children, or a leaf's blocks, then the next child): a step
    ends by prefetching what that ray reads next, and by the time its turn comes again
    the lines have arrived. On scenes far larger than the caches the memory latency of
    one ray's chain of record visits is then overlapped with the other rays' work.
    """
    n = orig.shape[0]
    t_out = np.empty(n)
    p_out = np.empty(n, np.int32)
    if tris.shape[0] == 0:
        for i in range(n):
            t_out[i] = np.inf
            p_out[i] = -1
        return t_out, p_out
    n_chunks = (n + CHUNK - 1) // CHUNK
    for c in prange(n_chunks):
        lo = c * CHUNK
        hi = min(n, lo + CHUNK)
        _closest_lanes(orig, dirs, tmax, nodes, tris, lo, hi, t_out, p_out, np.empty((LANES, STACK_SIZE), np.int32),
                       np.empty((LANES, 12)), np.empty((LANES, 9), np.uint64), np.empty((LANE_ROWS, LANES), np.int64),
                       np.empty(LANES, np.uint64), np.empty(LANES))
    return t_out, p_out


@kernel(parallel=True)
def trace_occluded_batch(orig, dirs, tmax, nodes, tris):
    """Any-hit queries of a batch of segments (origin, unit direction, length): each ray
    as in ``occluded`` (the same step function), ``LANES`` of them in flight per thread
    (see ``trace_closest_batch``)."""
    n = orig.shape[0]
    out = np.zeros(n, np.bool_)
    if tris.shape[0] == 0:
        return out
    n_chunks = (n + CHUNK - 1) // CHUNK
    for c in prange(n_chunks):
        lo = c * CHUNK
        hi = min(n, lo + CHUNK)
        _occluded_lanes(orig, dirs, tmax, nodes, tris, lo, hi, out, np.empty((LANES, STACK_SIZE), np.int32),
                        np.empty((LANES, 12)), np.empty((LANES, 9), np.uint64),
                        np.empty((LANE_ROWS, LANES), np.int64), np.empty(LANES, np.uint64))
    return out
