"""Ray casting (compendium items 2-4): the BVH against brute force."""
import numpy as np
import pytest

from spectral_gi.core.geometry import accel
from oracles.geometry import brute_force_closest
from spectral_gi.core.jit import set_threads
from spectral_gi.core.geometry import bvh as K


def _soup(rng, n, spread=1.0, size=0.1):
    c = rng.uniform(-spread, spread, (n, 3))
    return [c + rng.normal(0, size, (n, 3)) for _ in range(3)]


def _rays(rng, n, extent=2.0, tris=None):
    """Random rays; with ``tris``, half of them aimed at random points of random triangles."""
    o = rng.uniform(-extent, extent, (n, 3))
    d = rng.normal(size=(n, 3))
    if tris is not None:
        v0, v1, v2 = tris
        k = rng.integers(0, v0.shape[0], n // 2)
        a, b = rng.uniform(0, 1, (2, n // 2, 1))
        flip = (a + b) > 1
        a, b = np.where(flip, 1 - a, a), np.where(flip, 1 - b, b)
        d[: n // 2] = v0[k] + a * (v1[k] - v0[k]) + b * (v2[k] - v0[k]) - o[: n // 2]
    return o, d / np.linalg.norm(d, axis=1)[:, None]


@pytest.mark.parametrize("n_tri,seed", [(1, 0), (3, 1), (50, 2), (2000, 3)])
def test_closest_hit_matches_brute_force(n_tri, seed):
    rng = np.random.default_rng(seed)
    v0, v1, v2 = _soup(rng, n_tri)
    bvh = accel.build(v0, v1, v2)
    o, d = _rays(rng, 3000, tris=(v0, v1, v2))
    t, tri = accel.closest(bvh, o, d)
    tb, trib = brute_force_closest(v0, v1, v2, o, d)
    hit = np.isfinite(tb)
    assert hit.sum() > 30
    assert np.array_equal(np.isfinite(t), hit)
    same = tri == trib
    assert np.mean(same[hit]) > 0.999  # ties on shared edges may differ
    # the oracle repeats the kernel's arithmetic: same triangle, bit-identical distance
    assert np.array_equal(t[same & hit], tb[same & hit])
    np.testing.assert_allclose(t[hit], tb[hit], rtol=1e-6)


def test_axis_aligned_and_degenerate_input():
    """Flat layers (zero extent on an axis), repeated triangles and zero-area triangles."""
    rng = np.random.default_rng(5)
    n = 600
    v0 = rng.uniform(-1, 1, (n, 3))
    v0[:, 2] = np.round(v0[:, 2] * 2) / 2  # five flat layers
    v1 = v0 + [0.05, 0, 0]
    v2 = v0 + [0, 0.05, 0]
    v0 = np.concatenate([v0, v0[:10], v0[:5]])
    v1 = np.concatenate([v1, v1[:10], v0[:5]])  # last five are degenerate (zero area)
    v2 = np.concatenate([v2, v2[:10], v0[:5]])
    bvh = accel.build(v0, v1, v2)
    o, d = _rays(rng, 4000, tris=(v0, v1, v2))
    t, _ = accel.closest(bvh, o, d)
    tb, _ = brute_force_closest(v0, v1, v2, o, d)
    assert np.array_equal(np.isfinite(t), np.isfinite(tb))
    np.testing.assert_allclose(t[np.isfinite(t)], tb[np.isfinite(tb)], rtol=1e-4, atol=1e-6)


def test_identical_centroids_build_bounded_leaves():
    v0 = np.zeros((100, 3)) + [0, 0, 0]
    v1 = np.tile([1.0, 0, 0], (100, 1))
    v2 = np.tile([0, 1.0, 0], (100, 1))
    bvh = accel.build(v0, v1, v2)
    assert bvh.leaves()[1].max() <= 16
    t, tri = accel.closest(bvh, np.array([[0.2, 0.2, 1.0]]), np.array([[0, 0, -1.0]]))
    assert t[0] == pytest.approx(1.0) and 0 <= tri[0] < 100


def test_empty_scene():
    bvh = accel.build(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)))
    t, tri = accel.closest(bvh, np.zeros((4, 3)), np.tile([0, 0, 1.0], (4, 1)))
    assert np.all(np.isinf(t)) and np.all(tri == -1)


@pytest.mark.slow
def test_visibility_agrees_with_closest_hit_and_is_symmetric():
    """V(x, y) (item 4): any-hit agrees with closest-hit, and V(x, y) = V(y, x)."""
    rng = np.random.default_rng(7)
    v0, v1, v2 = _soup(rng, 500)
    bvh = accel.build(v0, v1, v2)
    x = rng.uniform(-1.5, 1.5, (4000, 3))
    y = rng.uniform(-1.5, 1.5, (4000, 3))
    d = y - x
    dist = np.linalg.norm(d, axis=1)
    d /= dist[:, None]
    occ_xy = accel.occluded(bvh, x, d, dist)
    occ_yx = accel.occluded(bvh, y, -d, dist)
    t, _ = accel.closest(bvh, x, d)
    assert 0.1 < occ_xy.mean() < 0.9
    assert np.array_equal(occ_xy, t < dist)
    assert np.mean(occ_xy == occ_yx) > 0.999  # may differ only for hits exactly at an end


def test_sah_tree_is_shallow_and_compact():
    rng = np.random.default_rng(9)
    v0, v1, v2 = _soup(rng, 20000, size=0.01)
    bvh = accel.build(v0, v1, v2)
    assert bvh.n_nodes < 2 * 20000
    first, count, _, _ = bvh.leaves()
    assert count.max() <= 16
    # every primitive appears exactly once in the leaves
    assert count.sum() == 20000
    assert np.array_equal(np.sort(bvh.prims), np.arange(20000))


@pytest.mark.parametrize("n_tri", [1, 5, 3000])
def test_packed_records_are_consistent(n_tri):
    """The packed layout: 64-byte aligned 4-wide records; leaf ranges tile [0, T) exactly;
    every leaf box holds its triangles' corners and every record child's box holds the
    boxes of that record's children; absent children have boxes no ray enters; a
    single-leaf tree is one record with one child; each leaf owns ceil(count / 4)
    consecutive blocks, in leaf order, whose lanes hold its triangles in order and then
    degenerate padding lanes of index -1; the blocks' corners are the float32 corners of
    ``prims`` and the shading edges their exact differences."""
    rng = np.random.default_rng(12)
    v0, v1, v2 = _soup(rng, n_tri, size=0.05)
    bvh = accel.build(v0, v1, v2)
    nodes, lk = bvh.nodes, bvh.links
    assert nodes.dtype == np.float32 and nodes.shape[1] == 32 and nodes.ctypes.data % 64 == 0
    first, count, block, boxes = bvh.leaves()
    n_blk = (count + 3) // 4
    assert bvh.tris.dtype == np.float32 and bvh.tris.shape == (n_blk.sum(), 40)
    order = np.argsort(first)
    assert first[order][0] == 0 and np.array_equal(first[order][1:], (first + count)[order][:-1])
    assert (first + count).max() == n_tri
    # blocks in leaf order, each leaf's consecutive, lanes in leaf order then padding
    assert block[order][0] == 0 and np.array_equal(block[order][1:], (block + n_blk)[order][:-1])
    ids = bvh.tris.view(np.int32)[:, 36:40].reshape(-1)
    for f, c, b in zip(first, count, block):
        lanes = ids[4 * b:4 * (b + (c + 3) // 4)]
        assert np.array_equal(lanes[:c], np.arange(f, f + c)) and np.all(lanes[c:] == -1)
    pad = bvh.tris[:, :36].reshape(-1, 9, 4).transpose(0, 2, 1).reshape(-1, 3, 3)[ids < 0]
    assert np.all(pad == pad[:, :1])  # three equal corners: determinant 0, never hit
    corners = bvh.corners().reshape(-1, 3, 3)
    for f, c, box in zip(first, count, boxes):
        pts = corners[f:f + c].reshape(-1, 3)
        assert np.all(box[:3] <= pts.min(0)) and np.all(pts.max(0) <= box[3:])
    seen = np.zeros(bvh.n_records, int)
    for c in range(4):
        ref, cnt, box = lk[:, 24 + c], lk[:, 28 + c], bvh.child_boxes(c)
        absent = ref < 0
        assert np.all(cnt[absent] == 0) and np.all(box[absent, :3] == np.inf) and np.all(box[absent, 3:] == -np.inf)
        inner = np.nonzero((cnt == 0) & ~absent)[0]
        kids = ref[inner]
        seen[kids] += 1
        for c2 in range(4):
            sub = bvh.child_boxes(c2)[kids]
            live = lk[kids, 24 + c2] >= 0
            assert np.all(box[inner][live, :3] <= sub[live, :3]) and np.all(sub[live, 3:] <= box[inner][live, 3:])
        assert np.all(kids > inner)  # depth-first numbering
    assert seen[0] == 0 and np.all(seen[1:] == 1)  # every record but the root's has one parent
    # the collapse fills records: every record but a single leaf's has two children or more,
    # and on average far more than a binary record's two
    present = np.count_nonzero(lk[:, 24:28] >= 0, axis=1)
    if n_tri > 100:
        assert present.min() >= 2 and present.mean() > 2.75
    if n_tri <= K.MAX_LEAF:
        assert bvh.n_records == 1 and lk[0, 24] == 0 and lk[0, 28] == n_tri and np.all(lk[0, 25:28] == -1)
        assert accel.tree_depth(bvh) == 1
    p = bvh.prims
    tri = bvh.corners()
    for k, v in enumerate((v0, v1, v2)):
        assert np.array_equal(tri[:, 3 * k:3 * k + 3], np.asarray(v, np.float32)[p])
    assert np.array_equal(bvh.v0, tri[:, :3])
    assert np.array_equal(bvh.e1, tri[:, 3:6].astype(np.float64) - tri[:, :3])
    assert np.array_equal(bvh.e2, tri[:, 6:9].astype(np.float64) - tri[:, :3])


def _icosphere(level):
    """Closed, consistently wound unit icosphere: (vertices, faces) with shared vertices."""
    t = (1 + 5 ** 0.5) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
             (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    verts = [np.array(v, float) / np.linalg.norm(v) for v in verts]
    for _ in range(level):
        mid = {}

        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                p = verts[a] + verts[b]
                verts.append(p / np.linalg.norm(p))
                mid[k] = len(verts) - 1
            return mid[k]

        new = []
        for a, b, c in faces:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new
    return np.array(verts), np.array(faces)


def test_watertight_at_shared_edges_and_vertices():
    """Rays aimed exactly at the vertices and at points of the shared edges of a closed mesh
    never slip through it: from inside every ray hits (closest and any-hit), from outside
    every ray aimed at the surface hits. (Möller–Trumbore on float32 edges let ~5 % of these
    rays through, the watertight test with float32 edges ~1 %.)"""
    rng = np.random.default_rng(3)
    verts, faces = _icosphere(3)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    centre = np.array([0.3, -2.1, 5.4])
    verts = (verts @ q.T * 1.7 + centre).astype(np.float32)  # irrational-looking float32 corners
    bvh = accel.build(verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]])
    edges = np.unique(np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), 1), axis=0)
    p = verts.astype(np.float64)
    targets = np.concatenate([p] + [p[edges[:, 0]] + s * (p[edges[:, 1]] - p[edges[:, 0]])
                                    for s in (0.5, 1 / 3, 0.9, 0.123)])
    for _ in range(3):
        o = np.tile(centre + rng.normal(0, 0.3, 3), (targets.shape[0], 1))
        d = targets - o
        d /= np.linalg.norm(d, axis=1)[:, None]
        t, tri = accel.closest(bvh, o, d)
        assert np.all(np.isfinite(t)) and np.all(tri >= 0)
        assert np.all(accel.occluded(bvh, o, d, 1e30))
        o = centre + (targets - centre) * 3.0 + rng.normal(0, 0.01, targets.shape)
        d = targets - o
        d /= np.linalg.norm(d, axis=1)[:, None]
        t, _ = accel.closest(bvh, o, d)
        assert np.all(np.isfinite(t))
    # random directions from inside, including axis-aligned ones
    o = np.tile(centre, (4006, 1))
    d = np.concatenate([rng.normal(size=(4000, 3)), np.eye(3), -np.eye(3)])
    d /= np.linalg.norm(d, axis=1)[:, None]
    assert np.all(accel.occluded(bvh, o, d, 1e30))


def test_edges_are_exact_and_float32_input_builds_the_same_tree():
    """v0 + e1 gives back the float32 corner exactly (what watertightness needs), and float32
    or float64 corners build the same tree; so does any thread count."""
    rng = np.random.default_rng(11)
    v0, v1, v2 = _soup(rng, 3000)
    b64 = accel.build(v0, v1, v2)
    b32 = accel.build(*(np.asarray(v, np.float32) for v in (v0, v1, v2)))
    for name in ("nodes", "prims", "tris", "v0", "e1", "e2"):  # bit for bit (int32 slots are NaN as float32)
        x, y = getattr(b64, name), getattr(b32, name)
        assert x.shape == y.shape and x.tobytes() == y.tobytes(), name
    p = b64.prims
    for e, v in ((b64.e1, v1), (b64.e2, v2)):
        assert e.dtype == np.float64
        assert np.array_equal(b64.v0.astype(np.float64) + e, np.asarray(v, np.float32)[p].astype(np.float64))
    try:
        set_threads(1)
        b1 = accel.build(v0, v1, v2)
    finally:
        set_threads(None)
    assert all(getattr(b1, n).tobytes() == getattr(b64, n).tobytes() for n in ("nodes", "prims", "tris"))


def test_depth_is_bounded_for_pathological_input():
    """Triangles shrinking geometrically towards one point (SAH peels off a few at a time,
    and below 1e-45 the float32 corners coincide) still give a tree no deeper than
    MAX_DEPTH, within the traversal stack, and correct hits."""
    n = 3000
    x = 1.05 ** -np.arange(n)
    v0 = np.stack([x, np.zeros(n), np.zeros(n)], 1)
    v1 = v0 + np.stack([np.zeros(n), 0.5 * x, np.zeros(n)], 1)
    v2 = v0 + np.stack([0.5 * x, np.zeros(n), 0.3 * x], 1)
    bvh = accel.build(v0, v1, v2)
    depth = accel.tree_depth(bvh)
    # a collapsed record spans up to three binary levels of this chain-like tree
    assert K.FALLBACK_DEPTH // 3 < depth <= K.MAX_DEPTH and 9 * (depth - 1) <= K.STACK_SIZE
    assert np.array_equal(np.sort(bvh.prims), np.arange(n))
    rng = np.random.default_rng(4)
    k = rng.integers(0, 400, 2000)
    target = v0[k] + 0.25 * (v1[k] - v0[k]) + 0.25 * (v2[k] - v0[k])
    o = target + rng.normal(size=(2000, 3)) * x[k, None] * 3
    d = target - o
    d /= np.linalg.norm(d, axis=1)[:, None]
    t, tri = accel.closest(bvh, o, d)
    tb, trib = brute_force_closest(v0, v1, v2, o, d)
    assert np.array_equal(np.isfinite(t), np.isfinite(tb)) and np.isfinite(t).mean() > 0.9
    # a few rays graze the 1e-20-sized triangles at the cluster point, far below the
    # origin's float64 resolution: there a box may miss what the triangle test grazes
    same = tri == trib
    assert same.mean() > 0.99
    assert np.array_equal(t[same], tb[same])


def test_bad_input_is_named():
    v = np.zeros((5, 3))
    w = np.eye(3)[[0, 1, 2, 0, 1]].astype(float)
    u = w[::-1].copy()
    u[3, 1] = np.nan
    with pytest.raises(ValueError, match="triangle 3"):
        accel.build(v, w, u)
    with pytest.raises(ValueError, match="shape"):
        accel.build(v, w, u[:4])


def test_batch_lanes_follow_the_one_ray_traversal():
    """The batch kernels trace ``LANES`` rays at once per thread, one step each in turn;
    every ray must end exactly where the one-ray traversal the path kernel calls ends:
    the same triangle at the bit-identical distance, the same visibility. Rays of mixed
    lengths, so lanes finish at different steps, over more than one chunk, the last one
    partial (lanes left idle)."""
    rng = np.random.default_rng(21)
    v0, v1, v2 = _soup(rng, 3000, size=0.05)
    bvh = accel.build(v0, v1, v2)
    n = K.CHUNK + 3 * K.LANES + 1
    o, d = _rays(rng, n, tris=(v0, v1, v2))
    tm = rng.uniform(0.2, 3.0, n)
    tm[::4] = np.inf
    t, p = K.trace_closest_batch(o, d, tm, bvh.nodes, bvh.tris)
    occ = K.trace_occluded_batch(o, d, tm, bvh.nodes, bvh.tris)
    assert 0.2 < np.isfinite(t).mean() < 0.9 and 0.2 < occ.mean() < 0.9
    stack = np.empty(K.STACK_SIZE, np.int32)
    for i in range(0, n, 5):
        ts, ps, _, _ = K.trace_closest(*o[i], *d[i], 0.0, tm[i], bvh.nodes, bvh.tris, stack)
        assert ps == p[i] and ts == t[i], i
        assert K.trace_occluded(*o[i], *d[i], 0.0, tm[i], bvh.nodes, bvh.tris, stack) == occ[i], i


def _nearest_lane_oracle(bvh, rf, ru, blk, tmin, tmax):
    """The scalar test of each lane in order, keeping a strictly nearer hit."""
    ox, oy, oz, ix, iy, iz, sx, sy, sz, okx, oky, okz = rf
    ukx, uky, ukz = ru[:3]
    lane, best = -1, tmax
    for ln in range(4):
        t, _, _ = K.intersect_lane(okx, oky, okz, ukx, uky, ukz, sx, sy, sz, bvh.tris, blk, ln, tmin, best)
        if t < best:
            lane, best = ln, t
    return lane, best


def test_nearest_lane_of_a_block_is_the_scalar_tests():
    """hit4_nearest (one vector test of a block's four triangles) reports the lane and the
    distance the scalar test finds lane by lane, ties to the first lane, for rays that
    hit, miss, start inside the interval's ends and pass through shared edges."""
    import numba

    from spectral_gi.core.geometry.simd import hit4_nearest

    @numba.njit
    def nearest(tris, blk, rf, ru, tmin, tmax):
        ox, oy, oz, ix, iy, iz, sx, sy, sz, okx, oky, okz = rf
        return hit4_nearest(tris, blk, ru[0], ru[1], ru[2], okx, oky, okz, sx, sy, sz, tmin, tmax)

    rng = np.random.default_rng(17)
    v0, v1, v2 = _soup(rng, 64, spread=0.3, size=0.3)
    # two triangles sharing an edge, twice (identical distances in two lanes: a tie)
    v0[:4] = [[0, 0, 0], [1, 1, 0], [0, 0, 0], [1, 1, 0]]
    v1[:4] = [[1, 0, 0], [0, 1, 0], [1, 0, 0], [0, 1, 0]]
    v2[:4] = [[0, 1, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0]]
    bvh = accel.build(v0, v1, v2)
    o, d = _rays(rng, 400, extent=1.5, tris=(v0, v1, v2))
    o[:50] = rng.uniform(0.0, 1.0, (50, 3)) * [1, 1, 0] + [0, 0, 2]
    o[:10, :2] = 0.5  # on the shared diagonal
    d[:50] = [0, 0, -1]
    seen = 0
    for i in range(o.shape[0]):
        rf, ru = K._ray_tuples(*o[i], *d[i])
        for blk in range(bvh.tris.shape[0]):
            for tmin, tmax in ((0.0, np.inf), (0.0, 1.0), (0.5, 3.0)):
                got = nearest(bvh.tris, blk, rf, ru, tmin, tmax)
                want = _nearest_lane_oracle(bvh, rf, ru, blk, tmin, tmax)
                assert got == want, (i, blk, tmin, tmax, got, want)
                seen += want[0] >= 0
    assert seen > 100


def test_entry_distances_round_down_to_float32():
    """simd.f32_below: the largest float32 not above t, as np.nextafter finds it."""
    import numba

    from spectral_gi.core.geometry.simd import f32_below

    @numba.njit
    def below(a):
        out = np.empty(a.size, np.float32)
        for i in range(a.size):
            out[i] = f32_below(a[i])
        return out

    rng = np.random.default_rng(5)
    t = np.concatenate([rng.random(20000) * 10.0 ** rng.integers(-46, 40, 20000),
                        [0.0, 1e-46, 2.0 ** -149, 2.0 ** -126, 1.0, 1.0 + 2.0 ** -30, 3.4028235e38, 1e39, np.inf]])
    with np.errstate(over="ignore"):
        f = t.astype(np.float32)
    want = np.where(f.astype(np.float64) > t, np.nextafter(f, np.float32(-np.inf)), f)
    got = below(t)
    assert np.array_equal(got.view(np.int32), want.view(np.int32))
    assert np.all(got.astype(np.float64) <= t)
    assert got[-1] == np.inf and got[-2] == np.finfo(np.float32).max
