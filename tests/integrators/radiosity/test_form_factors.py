"""Form factors (compendium items 55, 57, 58, 59, 60) against closed forms and published values.

Reference values: J. R. Howell, "A Catalog of Radiation Heat Transfer Configuration
Factors" (3rd ed., University of Texas at Austin, configurations C-11, directly opposed
parallel rectangles, and C-14, perpendicular rectangles with a common edge); the same
closed forms are in Siegel & Howell, *Thermal Radiation Heat Transfer*, appendix C. Two
unit squares a unit apart: 0.1998; two unit squares at right angles sharing an edge: 0.2000.
"""
import math

import numpy as np
import pytest

from spectral_gi import core
from spectral_gi.core.integrators.radiosity import form_factors as ff
from oracles.radiosity import form_factor_rows


def parallel_rectangles(a, b, c):
    """Howell C-11: rectangles a × b directly opposed at distance c."""
    x, y = a / c, b / c
    return 2.0 / (math.pi * x * y) * (
        math.log(math.sqrt((1 + x * x) * (1 + y * y) / (1 + x * x + y * y)))
        + x * math.sqrt(1 + y * y) * math.atan(x / math.sqrt(1 + y * y))
        + y * math.sqrt(1 + x * x) * math.atan(y / math.sqrt(1 + x * x))
        - x * math.atan(x) - y * math.atan(y))


def perpendicular_rectangles(l, w, h):
    """Howell C-14: from a rectangle w × l to a perpendicular h × l sharing the edge of length l."""
    W, H = w / l, h / l
    s = H * H + W * W
    t = (1 + W * W) * (1 + H * H) / (1 + s)
    t *= (W * W * (1 + s) / ((1 + W * W) * s)) ** (W * W)
    t *= (H * H * (1 + s) / ((1 + H * H) * s)) ** (H * H)
    return (W * math.atan(1 / W) + H * math.atan(1 / H) - math.sqrt(s) * math.atan(1 / math.sqrt(s))
            + 0.25 * math.log(t)) / (math.pi * W)


def floor(a, b):
    return np.array([[0, 0, 0], [a, 0, 0], [a, b, 0], [0, b, 0]], float)  # faces +z


def ceiling(a, b, c):
    return np.array([[0, 0, c], [0, b, c], [a, b, c], [a, 0, c]], float)  # faces -z


def wall(a, h):
    return np.array([[0, 0, 0], [0, 0, h], [a, 0, h], [a, 0, 0]], float)  # the plane y = 0, faces +y


def test_published_values_items_59():
    assert ff.form_factor_polygon_polygon(floor(1, 1), ceiling(1, 1, 1)) == pytest.approx(0.1998, abs=5e-5)
    assert ff.form_factor_polygon_polygon(floor(1, 1), wall(1, 1)) == pytest.approx(0.2000, abs=5e-5)
    assert core.form_factor_polygon_polygon is ff.form_factor_polygon_polygon


@pytest.mark.parametrize("a, b, c", [(1, 1, 1), (2, 0.5, 1.5), (0.3, 4, 0.7), (5, 5, 0.2)])
def test_parallel_rectangles_closed_form(a, b, c):
    assert ff.form_factor_polygon_polygon(floor(a, b), ceiling(a, b, c)) == pytest.approx(
        parallel_rectangles(a, b, c), rel=1e-8)


@pytest.mark.parametrize("l, w, h", [(1, 1, 1), (2, 0.5, 1.5), (0.3, 4, 0.7), (1, 0.05, 3)])
def test_perpendicular_rectangles_sharing_an_edge(l, w, h):
    """Item 59 is exact for polygons that touch along an edge (the log singularity)."""
    # floor w (along y) × l (along x), wall h × l in the plane y = 0
    fl = np.array([[0, 0, 0], [l, 0, 0], [l, w, 0], [0, w, 0]], float)
    wl = wall(l, h)
    assert ff.form_factor_polygon_polygon(fl, wl) == pytest.approx(perpendicular_rectangles(l, w, h), rel=1e-7)


def test_reciprocity_and_zero_cases_item_60():
    rng = np.random.default_rng(3)
    for _ in range(10):
        # two random triangles facing each other
        p = rng.normal(size=(3, 3))
        q = rng.normal(size=(3, 3)) + np.array([0, 0, 3.0])
        if ff.polygon_normal(p)[2] < 0:
            p = p[::-1]
        if ff.polygon_normal(q)[2] > 0:
            q = q[::-1]
        fpq = ff.form_factor_polygon_polygon(p, q)
        fqp = ff.form_factor_polygon_polygon(q, p)
        assert ff.polygon_area(p) * fpq == pytest.approx(ff.polygon_area(q) * fqp, rel=1e-9, abs=1e-14)
    # coplanar, back to back, facing away
    assert ff.form_factor_polygon_polygon(floor(1, 1), floor(1, 1) + [2, 0, 0]) == 0.0
    assert ff.form_factor_polygon_polygon(floor(1, 1), ceiling(1, 1, 1)[::-1]) == 0.0
    assert ff.form_factor_polygon_polygon(floor(1, 1), ceiling(1, 1, -1)) == 0.0


def _cube_faces():
    """The six faces of the unit cube, each facing inwards."""
    z0 = floor(1, 1)
    z1 = ceiling(1, 1, 1)
    y0 = wall(1, 1)
    y1 = y0[::-1] + [0, 1, 0]
    x0 = np.array([[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]], float)  # faces +x
    x1 = x0[::-1] + [1, 0, 0]
    return [z0, z1, y0, y1, x0, x1]


def test_closure_in_a_cube_items_59_60():
    faces = _cube_faces()
    for i, f in enumerate(faces):
        s = sum(ff.form_factor_polygon_polygon(f, g) for j, g in enumerate(faces) if j != i)
        assert s == pytest.approx(1.0, abs=1e-7)


def test_point_polygon_closure_and_clipping_item_57():
    faces = _cube_faces()
    rng = np.random.default_rng(5)
    for _ in range(5):
        p = np.array([rng.random(), rng.random(), 0.0])
        s = sum(ff.form_factor_point_polygon(p, [0, 0, 1], g) for g in faces[1:])
        assert s == pytest.approx(1.0, abs=1e-12)
    # a tilted receiver sees part of a wall behind its horizon: clipped, and still closed
    n = np.array([0.3, -0.2, 1.0])
    p = np.array([0.4, 0.6, 0.5])
    assert sum(ff.form_factor_point_polygon(p, n, g) for g in faces) == pytest.approx(1.0, abs=1e-12)
    # a point under the corner of a unit square at unit height (Howell B-3): 0.1385
    sq = ceiling(1, 1, 1)
    a = 1 / math.sqrt(2)  # A / sqrt(1 + A²) with A = B = 1
    exact = 2 * a * math.atan(a) / (2 * math.pi)
    assert ff.form_factor_point_polygon([0, 0, 0], [0, 0, 1], sq) == pytest.approx(exact, rel=1e-12)
    assert ff.form_factor_point_polygon([0, 0, 2], [0, 0, 1], sq) == 0.0  # behind the square


def test_differential_form_factor_item_55():
    """Integrated over a polygon by quadrature it gives item 57's closed form."""
    m = 400
    u = (np.arange(m) + 0.5) / m
    y = np.stack(np.meshgrid(u, u, indexing="ij"), -1).reshape(-1, 2)
    y = np.concatenate([y, np.ones((y.shape[0], 1))], 1)
    f = ff.differential_form_factor([0.2, 0.3, 0], [0, 0, 1], y, [0, 0, -1]).sum() / m ** 2
    assert f == pytest.approx(ff.form_factor_point_polygon([0.2, 0.3, 0], [0, 0, 1], ceiling(1, 1, 1)), rel=1e-4)
    assert ff.differential_form_factor([0, 0, 0], [0, 0, 1], [0, 0, 1], [0, 0, -1], visible=False) == 0.0


def _triangles(poly):
    return np.array([poly[[0, 1, 2]], poly[[0, 2, 3]]])


def test_kernel_form_factors_against_the_oracle_item_57():
    """The kernel's Lambert formula for triangles equals the NumPy oracle, clipping included."""
    rng = np.random.default_rng(11)
    rec = rng.normal(size=(5, 3, 3))
    snd = rng.normal(size=(7, 3, 3)) + [0, 0, 1.0]
    got = core.element_form_factors(rec, snd, np.zeros((0, 3, 3)), n_points=4, n_vis=0)
    from spectral_gi.core.integrators.radiosity.solve import sample_points

    e = np.cross(rec[:, 1] - rec[:, 0], rec[:, 2] - rec[:, 0])
    want = form_factor_rows(sample_points(rec, 4), e / np.linalg.norm(e, axis=1, keepdims=True), snd)
    assert np.any(want > 0) and np.any(want == 0)
    np.testing.assert_allclose(got, want, rtol=2e-6, atol=1e-7)  # float32 out


def test_kernel_visibility_against_the_oracle_item_58():
    """A blocker that hides one of two senders wholly: that factor is 0, the other unchanged."""
    rec = _triangles(floor(1, 1))
    snd = np.concatenate([_triangles(ceiling(1, 1, 1)), _triangles(ceiling(1, 1, 1) + [3, 0, 0])])
    blocker = _triangles(np.array([[-1, -1, 0.5], [-1, 2, 0.5], [1.4, 2, 0.5], [1.4, -1, 0.5]], float))
    occ = np.concatenate([rec, snd, blocker])
    got = core.element_form_factors(rec, snd, occ, n_points=4, n_vis=16)
    from spectral_gi.core.integrators.radiosity.solve import sample_points

    want = form_factor_rows(sample_points(rec, 4), np.tile([0, 0, 1.0], (2, 1)), snd, occ)
    np.testing.assert_allclose(got, want, rtol=2e-6, atol=1e-9)
    assert np.all(got[:, :2] == 0) and np.all(got[:, 2:] > 0)


def test_element_form_factor_converges_to_stokes_item_58_59():
    """Item 58 (Lambert's formula averaged over points of the receiver) tends to item 59."""
    rec = _triangles(floor(1, 1))
    snd = _triangles(wall(1, 1))
    f64 = core.element_form_factors(rec, snd, np.zeros((0, 3, 3)), n_points=64, n_vis=0)
    total = (f64.sum(axis=1) * 0.5).sum()  # each receiver half the square's area
    assert total == pytest.approx(perpendicular_rectangles(1, 1, 1), rel=2e-3)
    f1 = core.element_form_factors(rec, snd, np.zeros((0, 3, 3)), n_points=1, n_vis=0)
    assert abs((f1.sum(axis=1) * 0.5).sum() - 0.2000438) > abs(total - 0.2000438)
