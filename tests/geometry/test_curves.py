"""Hair curves tessellated into triangles: counts, Cycles' radius taper, the tube's projected
area against the cylinder's closed form 2·r·L, ribbons facing the eye."""
import math

import numpy as np
import pytest

from spectral_gi.core.geometry import accel
from spectral_gi.core.geometry import curves as G


def _straight(n_keys=5, length=2.0, radius=0.1, n_curves=1, spacing=1.0):
    z = np.linspace(0.0, length, n_keys)
    pts = [np.stack([np.full(n_keys, i * spacing), np.zeros(n_keys), z], 1) for i in range(n_curves)]
    return np.concatenate(pts), np.full(n_keys * n_curves, radius), np.full(n_curves, n_keys)


@pytest.mark.parametrize("sides", [3, 6, 8])
def test_round_tube_counts_and_radius(sides):
    p, r, c = _straight(n_keys=5, n_curves=3)
    pos, tri, nrm, curve = G.tessellate(p, r, c, shape=G.ROUND, sides=sides)
    assert tri.shape == (3 * 4 * sides * 2, 3) == (G.triangle_count(c, G.ROUND, sides), 3)
    assert pos.shape == nrm.shape == (3 * 5 * sides, 3)
    assert np.bincount(curve).tolist() == [4 * sides * 2] * 3
    # ring vertices at the area-preserving circumradius, normals radial and of unit length
    axis = np.repeat(p, sides, axis=0)
    off = pos.astype(np.float64) - axis
    np.testing.assert_allclose(np.linalg.norm(off, axis=1), G.area_preserving_radius(0.1, sides), rtol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(nrm, axis=1), 1.0, rtol=1e-6)
    np.testing.assert_allclose(np.einsum("ij,ij->i", off / np.linalg.norm(off, axis=1)[:, None], nrm), 1.0,
                               rtol=1e-5)
    # the faces wind outwards: their geometric normals agree with the shading normals
    v0, v1, v2 = (pos[tri[:, k]].astype(np.float64) for k in range(3))
    ng = np.cross(v1 - v0, v2 - v0)
    assert np.all(np.einsum("ij,ij->i", ng, nrm[tri[:, 0]]) > 0.0)


@pytest.mark.parametrize("sides", [3, 4, 6, 8, 16])
def test_tube_projected_area_averages_the_cylinder_closed_form(sides):
    """Silhouette width × length over view directions across the axis: mean 2·r·L (Cauchy's
    mean width of the polygon with the area-preserving radius), and within cos(π/N) per view."""
    r, length = 0.05, 3.0
    p, rr, c = _straight(n_keys=4, length=length, radius=r)
    pos, _, _, _ = G.tessellate(p, rr, c, shape=G.ROUND, sides=sides)
    phi = np.linspace(0.0, 2.0 * math.pi, 7200, endpoint=False)
    across = np.stack([np.cos(phi), np.sin(phi)], 1)  # directions in the plane perpendicular to Z
    proj = pos[:, :2].astype(np.float64) @ across.T
    width = proj.max(axis=0) - proj.min(axis=0)
    area = width * length
    assert area.mean() == pytest.approx(2.0 * r * length, rel=1e-4)
    lo, hi = G.silhouette_range(sides)
    assert area.min() >= 2.0 * r * length * lo * (1 - 1e-6)
    assert area.max() <= 2.0 * r * length * hi * (1 + 1e-6)


@pytest.mark.slow
def test_tube_blocks_the_rays_of_its_projected_area():
    """Parallel rays through a square window across a tube (through the BVH): the fraction
    blocked is the projected area 2·r_eff·L over the window's, r_eff the tessellation's width."""
    rng = np.random.default_rng(3)
    r, length, sides = 0.1, 2.0, 6
    p, rr, c = _straight(n_keys=3, length=length, radius=r)
    pos, tri, _, _ = G.tessellate(p, rr, c, shape=G.ROUND, sides=sides)
    bvh = accel.build(*(pos[tri[:, k]].astype(np.float64) for k in range(3)))
    n = 200_000
    for phi in (0.0, math.pi / 6, 0.4):  # across a vertex, across a face, between
        d = np.array([math.cos(phi), math.sin(phi), 0.0])
        side = np.array([-math.sin(phi), math.cos(phi), 0.0])
        u, z = rng.uniform(-0.5, 0.5, n), rng.uniform(0.0, length, n)
        o = -2.0 * d + u[:, None] * side + z[:, None] * np.array([0.0, 0.0, 1.0])
        blocked = accel.occluded(bvh, o, np.tile(d, (n, 1)), np.full(n, 4.0)).mean()
        proj = pos[:, :2].astype(np.float64) @ side[:2]
        expected = (proj.max() - proj.min())  # window 1 wide: the blocked fraction is the width
        assert blocked == pytest.approx(expected, abs=4.0 * math.sqrt(expected / n))
        lo, hi = G.silhouette_range(sides)
        assert 2 * r * lo - 1e-3 <= blocked <= 2 * r * hi + 1e-3


def test_ribbon_faces_the_eye_with_cylinder_normals():
    p, r, c = _straight(n_keys=3, length=1.0, radius=0.02, n_curves=2, spacing=0.5)
    eye = np.array([0.25, -5.0, 0.5])
    pos, tri, nrm, _ = G.tessellate(p, r, c, shape=G.RIBBON, eye=eye)
    cols = G.DEFAULT_COLUMNS
    assert tri.shape[0] == 2 * 2 * cols * 2 == G.triangle_count(c, G.RIBBON, columns=cols)
    pos = pos.astype(np.float64).reshape(2, 3, cols + 1, 3)
    nrm = nrm.astype(np.float64).reshape(2, 3, cols + 1, 3)
    centre = pos[:, :, cols // 2]
    np.testing.assert_allclose(centre, p.reshape(2, 3, 3), atol=1e-6)
    half = np.linalg.norm(pos[:, :, -1] - centre, axis=2)
    np.testing.assert_allclose(half, 0.02, rtol=1e-5)  # width 2·r: the round curve's projected width
    to_eye = eye - centre
    to_eye[..., 2] = 0.0  # the part perpendicular to the (vertical) strand
    to_eye /= np.linalg.norm(to_eye, axis=2, keepdims=True)
    across = pos[:, :, -1] - pos[:, :, 0]
    np.testing.assert_allclose(np.einsum("ijk,ijk->ij", across, to_eye), 0.0, atol=1e-6)  # faces the eye
    np.testing.assert_allclose(np.einsum("ijk,ijk->ij", nrm[:, :, cols // 2], to_eye), 1.0, atol=1e-6)
    # at the edges the normal lies in the ribbon's plane, as a cylinder's silhouette normal
    edge = across / np.linalg.norm(across, axis=2, keepdims=True)
    np.testing.assert_allclose(np.abs(np.einsum("ijk,ijk->ij", nrm[:, :, -1], edge)), 1.0, atol=1e-6)


def test_ribbon_of_an_orthographic_view():
    p, r, c = _straight(n_keys=2, radius=0.01)
    pos, tri, nrm, _ = G.tessellate(p, r, c, shape=G.RIBBON, view_dir=(0.0, 1.0, 0.0))
    np.testing.assert_allclose(pos[:, 1], 0.0, atol=1e-7)  # the strip lies across the view
    np.testing.assert_allclose(nrm[2], (0.0, -1.0, 0.0), atol=1e-6)  # the centre faces the viewer


def test_frames_follow_a_bent_curve_without_twist():
    """A planar curve's rotation-minimising frame keeps its reference vector out of the plane."""
    s = np.linspace(0.0, math.pi, 33)
    p = np.stack([np.cos(s), np.sin(s), np.zeros_like(s)], 1)
    pos, _, nrm, _ = G.tessellate(p, np.full(33, 0.01), [33], shape=G.ROUND, sides=4)
    ring = nrm.reshape(33, 4, 3).astype(np.float64)
    t = G._tangents(p[None])[0]
    np.testing.assert_allclose(np.einsum("kj,ksj->ks", t, ring), 0.0, atol=1e-5)
    # the plane's normal (Z) makes the same angle with the ring's first normal at every key
    z = ring[:, :, 2]
    np.testing.assert_allclose(z, np.broadcast_to(z[0], z.shape), atol=1e-5)


def test_shape_radius_is_cycles_taper():
    t = np.array([0.0, 0.25, 0.5, 1.0])
    np.testing.assert_allclose(G.shape_radius(0.0, 2.0, 1.0, t), 2.0 - t)
    np.testing.assert_allclose(G.shape_radius(0.5, 1.0, 0.0, t), (1.0 - t) ** 2.0)
    np.testing.assert_allclose(G.shape_radius(-0.5, 1.0, 0.0, t), (1.0 - t) ** 0.5)


def test_bad_curves_are_refused_clearly():
    p, r, c = _straight()
    with pytest.raises(ValueError, match="do not agree"):
        G.tessellate(p, r[:-1], c)
    with pytest.raises(ValueError, match="sides"):
        G.tessellate(p, r, c, sides=2)
    with pytest.raises(ValueError, match="eye"):
        G.tessellate(p, r, c, shape=G.RIBBON)
    pos, tri, _, _ = G.tessellate(p[:1], r[:1], [1])  # one key: nothing to draw
    assert tri.shape == (0, 3)


def test_catmull_rom_refine_keeps_straight_strands_and_follows_the_spline():
    p, r, c = _straight(n_keys=5, n_curves=2)
    rp, rr, rc = G.catmull_rom_refine(p, r, c)
    assert rc.tolist() == [5, 5]
    np.testing.assert_allclose(rp, p)
    np.testing.assert_allclose(rr, r)
    # a half circle of 5 keys (and a one-key curve, kept): each segment turns by 45°
    a = np.linspace(0.0, math.pi, 5)
    arc = np.stack([np.cos(a), np.sin(a), np.zeros(5)], 1)
    pts = np.concatenate([arc, [[5.0, 5.0, 5.0]]])
    radii = np.concatenate([np.linspace(0.1, 0.0, 5), [0.3]])
    rp, rr, rc = G.catmull_rom_refine(pts, radii, [5, 1], max_angle=math.radians(10.0), max_pieces=8)
    assert rc[1] == 1 and np.allclose(rp[-1], (5.0, 5.0, 5.0)) and rr[-1] == pytest.approx(0.3)
    curve = rp[: rc[0]]
    for key in arc:  # the keys stay on the refined polyline
        assert np.min(np.linalg.norm(curve - key, axis=1)) < 1e-12
    # an inner segment: the spline's tangents at its ends differ by 45° → 5 pieces, points on the spline
    k = 1
    t = np.arange(6)[:, None] / 5.0
    want = 0.5 * ((-t**3 + 2 * t**2 - t) * arc[k - 1] + (3 * t**3 - 5 * t**2 + 2) * arc[k]
                  + (-3 * t**3 + 4 * t**2 + t) * arc[k + 1] + (t**3 - t**2) * arc[k + 2])
    for w in want:
        assert np.min(np.linalg.norm(curve - w, axis=1)) < 1e-12
    # the refined polyline turns by a few max_angle at most at each point (by 45° at the keys unrefined)
    d = np.diff(curve, axis=0)
    d /= np.linalg.norm(d, axis=1)[:, None]
    assert np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", d[1:], d[:-1]), -1, 1))).max() < 20.0  # 45° before
    angle = np.arctan2(curve[:, 1], curve[:, 0])
    inner = (angle >= math.pi / 4 - 1e-9) & (angle <= 3 * math.pi / 4 + 1e-9)  # the inner segments
    assert np.abs(np.linalg.norm(curve[inner, :2], axis=1) - 1.0).max() < 0.01
    assert np.all(rr[: rc[0]] >= 0.0)
