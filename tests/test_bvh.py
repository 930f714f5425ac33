"""Ray casting (compendium items 2-4): the BVH against brute force."""
import numpy as np
import pytest

from spectral_gi.core import accel


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
    tb, trib = accel.brute_force_closest(v0, v1, v2, o, d)
    hit = np.isfinite(tb)
    assert hit.sum() > 30
    assert np.array_equal(np.isfinite(t), hit)
    np.testing.assert_allclose(t[hit], tb[hit], rtol=1e-4, atol=1e-6)
    assert np.mean(tri[hit] == trib[hit]) > 0.999  # ties on shared edges may differ


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
    tb, _ = accel.brute_force_closest(v0, v1, v2, o, d)
    assert np.array_equal(np.isfinite(t), np.isfinite(tb))
    np.testing.assert_allclose(t[np.isfinite(t)], tb[np.isfinite(tb)], rtol=1e-4, atol=1e-6)


def test_identical_centroids_build_bounded_leaves():
    v0 = np.zeros((100, 3)) + [0, 0, 0]
    v1 = np.tile([1.0, 0, 0], (100, 1))
    v2 = np.tile([0, 1.0, 0], (100, 1))
    bvh = accel.build(v0, v1, v2)
    assert bvh.count.max() <= 16
    t, tri = accel.closest(bvh, np.array([[0.2, 0.2, 1.0]]), np.array([[0, 0, -1.0]]))
    assert t[0] == pytest.approx(1.0) and 0 <= tri[0] < 100


def test_empty_scene():
    bvh = accel.build(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)))
    t, tri = accel.closest(bvh, np.zeros((4, 3)), np.tile([0, 0, 1.0], (4, 1)))
    assert np.all(np.isinf(t)) and np.all(tri == -1)


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
    assert bvh.count.max() <= 16
    # every primitive appears exactly once in the leaves
    leaves = bvh.count > 0
    assert bvh.count[leaves].sum() == 20000
    assert np.array_equal(np.sort(bvh.prims), np.arange(20000))
