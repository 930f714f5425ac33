"""Calculation surfaces: EN 12464-1:2021 spacing and point counts, bands, polygons, meshes, records."""
import json
import math

import numpy as np
import pytest

from spectral_gi.core.lux import grids as G
from spectral_gi.core.lux import LuxError


@pytest.mark.parametrize("d, p", [(1.0, 0.2), (5.0, 0.2 * 5 ** math.log10(5)), (10.0, 1.0), (100.0, 5.0),
                                  (1000.0, 10.0), (1e5, 10.0)])
def test_en12464_spacing(d, p):
    assert G.en12464_spacing(d) == pytest.approx(p, rel=1e-12)


def test_en12464_spacing_table_values():
    """The standard's table: 1 m → 0.2 m, 5 m → 0.6 m, 10 m → 1 m (rounded to 0.1 m)."""
    assert [round(G.en12464_spacing(d), 1) for d in (1, 5, 10)] == [0.2, 0.6, 1.0]
    with pytest.raises(LuxError, match="positive"):
        G.en12464_spacing(0.0)


def test_points_per_side_rounds_up():
    """n = ceil(L / p): the real spacing L / n never exceeds p; exact multiples are not rounded up."""
    assert G.points_per_side(1.0, 0.2) == 5
    assert G.points_per_side(5.0, G.en12464_spacing(5.0)) == 9  # 5 / 0.616 = 8.11
    assert G.points_per_side(10.0, 1.0) == 10
    assert G.points_per_side(1.1, 0.1) == 11  # 1.1 / 0.1 = 11.000000000000002 in floating point
    assert G.points_per_side(1.01, 0.2) == 6
    assert G.points_per_side(0.05, 0.2) == 1
    for L in np.linspace(0.3, 37.0, 50):
        p = G.en12464_spacing(L)
        n = G.points_per_side(L, p)
        assert L / n <= p * (1 + 1e-12) and L / (n - 1 if n > 1 else 0.5) > p


@pytest.mark.parametrize("d, n, spacing", [(1.0, 5, 0.2), (5.0, 9, 5.0 / 9), (10.0, 10, 1.0)])
def test_square_grid_counts_and_cell_centres(d, n, spacing):
    s = G.rectangle_grid((0, 0, 0), (d, 0, 0), (0, d, 0))
    assert s.grid_shape == (n, n) and s.n_points == n * n
    assert s.spacing == pytest.approx((spacing, spacing))
    xs = np.unique(np.round(s.points[:, 0], 9))
    np.testing.assert_allclose(xs, (np.arange(n) + 0.5) * spacing, atol=1e-9)
    np.testing.assert_allclose(s.normals, np.tile([0, 0, 1.0], (n * n, 1)))
    assert s.weights.sum() == pytest.approx(d * d)


def test_rectangle_longer_side_sets_the_spacing():
    s = G.rectangle_grid((0, 0, 0), (10, 0, 0), (0, 6, 0))  # d = 10 m → p = 1 m
    assert s.grid_shape == (6, 10)
    assert s.spacing == pytest.approx((1.0, 1.0))


def test_long_area_takes_its_shorter_side():
    """A side at least twice the other: d is the shorter side (10 × 2 m: d = 2 m, p = 0.2 · 5^log10 2)."""
    assert G.grid_size(10.0, 2.0) == 2.0 and G.grid_size(2.0, 10.0) == 2.0
    assert G.grid_size(10.0, 6.0) == 10.0 and G.grid_size(4.0, 2.0) == 2.0
    s = G.rectangle_grid((0, 0, 0), (10, 0, 0), (0, 2, 0))
    p = G.en12464_spacing(2.0)  # 0.324 m
    assert s.grid_shape == (G.points_per_side(2.0, p), G.points_per_side(10.0, p)) == (7, 31)


def test_band_is_left_out_and_the_spacing_fits_the_inner_area():
    s = G.rectangle_grid((0, 0, 0), (6, 0, 0), (0, 6, 0), band=0.5)  # inner 5 × 5 m
    assert s.grid_shape == (9, 9) and s.band == 0.5
    assert s.points[:, :2].min() == pytest.approx(0.5 + 5 / 18)
    assert s.points[:, :2].max() == pytest.approx(5.5 - 5 / 18)
    with pytest.raises(LuxError, match="leaves no area"):
        G.rectangle_grid((0, 0, 0), (1, 0, 0), (0, 1, 0), band=0.5)


def test_user_spacing_overrides():
    s = G.rectangle_grid((0, 0, 0), (3, 0, 0), (0, 2, 0), spacing=0.25)
    assert s.grid_shape == (8, 12)
    s = G.rectangle_grid((0, 0, 0), (3, 0, 0), (0, 2, 0), spacing=(1.0, 0.3))
    assert s.grid_shape == (7, 3)
    assert s.spacing == pytest.approx((1.0, 2 / 7))


def test_tilted_and_vertical_rectangles():
    # a wall x = 2 facing -X, 4 m wide (Y) and 3 m high
    s = G.rectangle_grid((2, 0, 0), (0, 4, 0), (0, 0, 3), normal=(-1, 0, 0))
    assert s.grid_shape == (6, 8)  # p(4 m) = 0.2 · 5^0.602 = 0.527 m: 3 / p = 5.7 → 6, 4 / p = 7.6 → 8
    np.testing.assert_allclose(s.points[:, 0], 2.0)
    np.testing.assert_allclose(s.normals, np.tile([-1.0, 0, 0], (s.n_points, 1)))
    # a roof slope at 30°
    c, si = math.cos(math.radians(30)), math.sin(math.radians(30))
    s = G.rectangle_grid((0, 0, 0), (2, 0, 0), (0, 2 * c, 2 * si))
    np.testing.assert_allclose(s.normals[0], [0, -si, c], atol=1e-12)
    np.testing.assert_allclose((s.points - s.points[0]) @ s.normals[0], 0.0, atol=1e-12)
    with pytest.raises(LuxError, match="perpendicular"):
        G.rectangle_grid((0, 0, 0), (1, 0, 0), (1, 1, 0))
    with pytest.raises(LuxError, match="perpendicular to the rectangle"):
        G.rectangle_grid((0, 0, 0), (1, 0, 0), (0, 1, 0), normal=(0, 1, 1))


L_ROOM = [(0, 0), (6, 0), (6, 3), (3, 3), (3, 6), (0, 6)]


def test_l_shaped_work_plane():
    """6 × 6 m with a 3 × 3 m notch, band 0.5 m: inner 5 × 5 m → 9 × 9 cells of 5/9 m starting at
    0.5 + 5/18; the 5 × 5 cells with x ≥ 3 and y ≥ 3 (the notch or on its wall) are dropped: 56."""
    w = G.workplane(L_ROOM)
    assert w.kind == "workplane" and w.band == 0.5
    assert w.grid_shape == (9, 9) and w.n_points == 81 - 25
    np.testing.assert_allclose(w.points[:, 2], 0.75)
    np.testing.assert_allclose(w.normals, np.tile([0, 0, 1.0], (56, 1)))
    c = 0.5 + (np.arange(9) + 0.5) * 5 / 9
    grid = {(round(x, 9), round(y, 9)) for x in c for y in c if not (x >= 3 - 1e-9 and y >= 3 - 1e-9)}
    assert {(round(x, 9), round(y, 9)) for x, y in w.points[:, :2]} == grid
    assert w.weights == pytest.approx(np.full(56, (5 / 9) ** 2))
    # every kept point is at least the band from every wall, and inside
    x, y = w.points[:, 0], w.points[:, 1]
    assert (np.minimum.reduce([x, y, 6 - x, 6 - y]) >= 0.5).all()


def test_l_shaped_polygon_without_band_and_face_set_agree():
    poly = G.polygon_grid(L_ROOM, spacing=0.5)
    assert poly.grid_shape == (12, 12) and poly.n_points == 144 - 36
    verts = np.array([[0, 0, 0], [6, 0, 0], [6, 3, 0], [3, 3, 0], [3, 6, 0], [0, 6, 0], [0, 3, 0]], float)
    tris = [[0, 1, 2], [0, 2, 3], [0, 3, 6], [6, 3, 4], [6, 4, 5]]
    for band in (0.0, 0.5):
        a = G.polygon_grid(L_ROOM, spacing=0.5, band=band)
        b = G.face_set_grid(verts, tris, spacing=0.5, band=band)
        np.testing.assert_allclose(a.points, b.points)
        np.testing.assert_array_equal(a.grid_index, b.grid_index)


def test_face_set_with_a_hole_applies_the_band_at_the_hole():
    """A 4 × 4 m square face set with a 1 × 1 m hole in the middle (8 triangles around it)."""
    outer = [(0, 0), (4, 0), (4, 4), (0, 4)]
    inner = [(1.5, 1.5), (2.5, 1.5), (2.5, 2.5), (1.5, 2.5)]
    v = np.array([(*p, 0.0) for p in outer + inner])
    tris = [[0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]]
    s = G.face_set_grid(v, tris, spacing=0.5)
    assert s.n_points == 64 - 4
    s = G.face_set_grid(v, tris, spacing=0.5, band=0.3)
    x, y = s.points[:, 0], s.points[:, 1]
    dx = np.maximum(np.abs(x - 2) - 0.5, 0)
    dy = np.maximum(np.abs(y - 2) - 0.5, 0)
    assert (np.hypot(dx, dy) >= 0.3).all()
    assert (np.minimum.reduce([x, y, 4 - x, 4 - y]) >= 0.3).all()


COURTYARD = [(2.0, 2.0), (4.0, 2.0), (4.0, 3.0), (2.0, 3.0)]  # m, a 2 × 1 m hole in a 6 × 5 m floor
FLOOR_6X5 = [(0, 0), (6, 0), (6, 5), (0, 5)]


def _distance_to_box(x, y, x0, x1, y0, y1):
    """Distance from points to the rectangle [x0, x1] × [y0, y1] (0 inside)."""
    return np.hypot(np.maximum.reduce([x0 - x, x - x1, 0 * x]), np.maximum.reduce([y0 - y, y - y1, 0 * y]))


def test_work_plane_over_a_floor_with_a_hole():
    """A 6 × 5 m floor with a 2 × 1 m courtyard: the grid is the floor's (the band shrinks the box the
    spacing is chosen for: 5 × 4 m inside 0.5 m, d = 5 m → p = 0.62 m → 9 × 7 cells), the points in the
    courtyard are dropped, and so are those closer than the band to its edge; hole_band=0 keeps them."""
    no_hole = G.workplane(FLOOR_6X5)
    w = G.workplane(FLOOR_6X5, holes=[COURTYARD])
    assert w.grid_shape == no_hole.grid_shape == (7, 9)
    x, y = w.points[:, 0], w.points[:, 1]
    d_hole = _distance_to_box(x, y, 2, 4, 2, 3)
    assert (d_hole >= 0.5 - 1e-12).all() and (np.minimum.reduce([x, y, 6 - x, 5 - y]) >= 0.5 - 1e-12).all()
    xa, ya = no_hole.points[:, 0], no_hole.points[:, 1]
    dropped = _distance_to_box(xa, ya, 2, 4, 2, 3) < 0.5
    assert 0 < dropped.sum() and w.n_points == no_hole.n_points - dropped.sum()
    np.testing.assert_array_equal(w.grid_index, no_hole.grid_index[~dropped])
    assert w.area == pytest.approx(w.n_points * w.spacing[0] * w.spacing[1])
    tight = G.workplane(FLOOR_6X5, holes=[COURTYARD], hole_band=0.0)
    inside = (xa > 2) & (xa < 4) & (ya > 2) & (ya < 3)
    assert tight.n_points == no_hole.n_points - inside.sum() and inside.sum() > 0
    # the plan's outline: the four walls and the courtyard's four edges, in the grid's frame
    assert w.outline.shape == (8, 2, 2)
    assert np.allclose(w.outline.min(axis=(0, 1)), [-0.5, -0.5]) and np.allclose(w.outline.max(axis=(0, 1)), [5.5, 4.5])


def test_a_hole_either_way_round_and_the_face_set_with_the_same_hole_agree():
    """The hole's winding does not matter, and the floor triangulated around the hole (the add-on's
    work plane) gives the same points with the same band."""
    a = G.workplane(FLOOR_6X5, holes=[COURTYARD], spacing=0.5)
    b = G.workplane(FLOOR_6X5, holes=[COURTYARD[::-1]], spacing=0.5)
    np.testing.assert_array_equal(a.grid_index, b.grid_index)
    v = np.array([(*p, 0.75) for p in FLOOR_6X5 + COURTYARD])
    tris = [[0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]]
    f = G.face_set_grid(v, tris, spacing=0.5, band=0.5)
    np.testing.assert_allclose(np.sort(f.points, axis=0), np.sort(a.points, axis=0))


def test_hole_errors():
    with pytest.raises(LuxError, match="hole 0 is not inside"):
        G.workplane(FLOOR_6X5, holes=[[(5, 4), (7, 4), (7, 6), (5, 6)]])
    with pytest.raises(LuxError, match="floor's level"):
        G.workplane(FLOOR_6X5, holes=[[(*p, 0.3) for p in COURTYARD]])
    with pytest.raises(LuxError, match="hole 0 needs at least 3"):
        G.workplane(FLOOR_6X5, holes=[[(1, 1), (2, 2)]])
    with pytest.raises(LuxError, match="band at the holes"):
        G.workplane(FLOOR_6X5, holes=[COURTYARD], hole_band=-1.0)


def test_polygon_errors():
    with pytest.raises(LuxError, match="not planar"):
        G.polygon_grid([(0, 0, 0), (1, 0, 0), (1, 1, 0.5), (0, 1, 0)])
    with pytest.raises(LuxError, match="at least 3"):
        G.polygon_grid([(0, 0), (1, 0)])
    with pytest.raises(LuxError, match="horizontal"):
        G.workplane([(0, 0, 0), (1, 0, 0), (1, 1, 0.2)])


def test_mesh_vertices_and_faces_with_weights():
    # a unit square of two triangles, tilted to face +X
    pos = np.array([[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1], [5, 5, 5]], float)  # the last vertex unused
    tri = np.array([[0, 1, 2], [0, 2, 3]])
    v = G.mesh_vertex_points(pos, tri)
    assert v.kind == "vertices" and v.n_points == 4
    np.testing.assert_allclose(v.normals, np.tile([1.0, 0, 0], (4, 1)))
    np.testing.assert_allclose(v.weights, [1 / 3, 1 / 6, 1 / 3, 1 / 6])
    assert v.area == pytest.approx(1.0)
    f = G.mesh_face_points(pos, tri)
    np.testing.assert_allclose(f.points, [[0, 2 / 3, 1 / 3], [0, 1 / 3, 2 / 3]])
    np.testing.assert_allclose(f.weights, [0.5, 0.5])
    np.testing.assert_allclose(f.normals, [[1.0, 0, 0], [1.0, 0, 0]])
    given = G.mesh_vertex_points(pos, tri, normals=np.tile([0, 0, 3.0], (5, 1)))
    np.testing.assert_allclose(given.normals, np.tile([0, 0, 1.0], (4, 1)))
    with pytest.raises(LuxError, match="degenerate"):
        G.mesh_face_points(pos, [[0, 1, 1]])


def test_maintenance_factor():
    assert G.maintenance_factor(0.9, 1.0, 0.9, 0.95) == pytest.approx(0.7695)
    assert G.maintenance_factor() == 1.0
    with pytest.raises(LuxError, match="LMF"):
        G.maintenance_factor(lmf=1.2)
    with pytest.raises(LuxError, match="maintenance factor"):
        G.rectangle_grid((0, 0, 0), (1, 0, 0), (0, 1, 0), maintenance_factor=0.0)


def test_surface_json_round_trip():
    w = G.workplane(L_ROOM, maintenance_factor=0.8, name="office")
    d = json.loads(json.dumps(w.to_dict()))
    assert d["version"] == G.SURFACE_FORMAT_VERSION
    back = G.CalculationSurface.from_dict(d)
    for key in ("points", "normals", "weights", "grid_index", "origin", "axis_u", "axis_v", "outline"):
        np.testing.assert_array_equal(getattr(back, key), getattr(w, key))
    assert (back.name, back.kind, back.grid_shape, back.spacing, back.band, back.maintenance_factor) == \
        (w.name, w.kind, w.grid_shape, w.spacing, w.band, w.maintenance_factor)
    v = G.mesh_vertex_points([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    back = G.CalculationSurface.from_dict(json.loads(json.dumps(v.to_dict())))
    assert back.grid_shape is None and back.kind == "vertices"
    with pytest.raises(LuxError, match="unknown calculation surface version"):
        G.CalculationSurface.from_dict({**d, "version": 99})
    with pytest.raises(LuxError, match="unknown fields"):
        G.CalculationSurface.from_dict({**d, "colour": 1})
    with pytest.raises(LuxError, match="unknown kind"):
        G.CalculationSurface.from_dict({**d, "kind": "sphere"})
    with pytest.raises(LuxError, match="grid_index"):
        G.CalculationSurface.from_dict({**d, "grid_index": [0] * w.n_points})
    with pytest.raises(LuxError, match="must be numbers"):
        G.CalculationSurface.from_dict({**d, "maintenance_factor": "high"})
    with pytest.raises(LuxError, match="missing field 'weights'"):
        G.CalculationSurface.from_dict({k: v for k, v in d.items() if k != "weights"})
    f = G.mesh_face_points([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    back = G.CalculationSurface.from_dict(json.loads(json.dumps(f.to_dict())))
    np.testing.assert_array_equal(back.points, f.points)
    assert back.kind == "faces" and back.weights[0] == pytest.approx(0.5)


def test_grid_image_places_values_in_their_cells():
    w = G.workplane(L_ROOM)
    img = w.grid_image(np.arange(w.n_points, dtype=float))
    assert img.shape == (9, 9)
    assert np.isnan(img).sum() == 25
    assert np.isnan(img[8, 8]) and img[0, 0] == 0.0 and img[0, 1] == 1.0  # row 0 is the lowest y
