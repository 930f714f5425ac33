"""Patches: subdivision to a target size, both sides, refinement, the display mesh."""
import numpy as np
import pytest

from spectral_gi.core.integrators.radiosity import meshing


def test_subdivide_keeps_area_orientation_and_bounds_the_edges():
    rng = np.random.default_rng(2)
    tri = rng.normal(size=(6, 3, 3))
    sub, parent = meshing.subdivide(tri, 0.3)
    edge = np.linalg.norm(sub - np.roll(sub, 1, axis=1), axis=2)
    assert edge.max() <= 0.3 + 1e-12
    cross = np.cross(sub[:, 1] - sub[:, 0], sub[:, 2] - sub[:, 0])
    area = np.bincount(parent, weights=0.5 * np.linalg.norm(cross, axis=1))
    big = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    np.testing.assert_allclose(area, 0.5 * np.linalg.norm(big, axis=1), rtol=1e-12)
    # every piece faces as its parent
    assert np.all(np.einsum("ij,ij->i", cross, big[parent]) > 0)


def test_split4_and_the_display_mesh_weld_shared_corners():
    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0], [0, 1, 0]]], float)
    kids = meshing.split4(tri)
    assert kids.shape == (8, 3, 3)
    p = meshing._assemble(kids, np.zeros(8, np.int32), np.zeros(8, np.int32), "both")
    assert p.n == 16 and np.all(p.normal[:8, 2] == 1) and np.all(p.normal[8:, 2] == -1)
    assert p.area.sum() == pytest.approx(2.0)
    mesh = meshing.display_mesh(p)
    assert mesh.positions.shape[0] == 2 * 9  # a 3 × 3 grid of corners on each side
    v = meshing.to_vertices(mesh, p, np.arange(16.0))
    assert v.shape == (18,)
    pairs = meshing.neighbours(p)
    assert np.all(p.side[pairs[:, 0]] == p.side[pairs[:, 1]])


def test_the_display_mesh_does_not_weld_across_a_crease():
    """A floor and a wall sharing an edge keep their own vertices there, so a bright floor
    does not bleed into the wall's vertex values."""
    floor = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    wall = [[0, 0, 0], [0, 1, 0], [0, 0, 1]]
    p = meshing._assemble(np.array([floor, wall], float), np.zeros(2, np.int32), np.zeros(2, np.int32), "front")
    mesh = meshing.display_mesh(p)
    assert mesh.positions.shape[0] == 6
    np.testing.assert_array_equal(np.sort(np.unique(meshing.to_vertices(mesh, p, np.array([1.0, 5.0])))), [1, 5])
