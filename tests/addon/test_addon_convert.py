"""The add-on's unit and axis conversions (pure functions: no Blender needed)."""
import math

import numpy as np
import pytest

from spectral_gi.addon.export import convert


def rot_z(deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def rot_x(deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])


def matrix(rot=np.eye(3), scale=(1, 1, 1), loc=(0, 0, 0)):
    m = np.eye(4)
    m[:3, :3] = rot @ np.diag(scale)
    m[:3, 3] = loc
    return m


def test_matrix_to_array_is_row_major():
    rows = [[1, 2, 3, 4], [5, 6, 7, 8], [9, 10, 11, 12], [0, 0, 0, 1]]
    a = convert.matrix_to_array(rows)
    assert a.dtype == np.float64 and a[0, 3] == 4 and a[2, 0] == 9


def test_points_to_world_metres():
    m = matrix(rot_z(90), (2, 2, 2), (1, 0, 0))
    p = convert.points_to_world_metres(m, [[1, 0, 0], [0, 0, 1]], 0.5)
    assert p.dtype == np.float32 and p.shape == (2, 3)
    np.testing.assert_allclose(p, [[0.5, 1.0, 0.0], [0.5, 0.0, 1.0]], atol=1e-6)


def test_camera_to_world_removes_scale_and_converts_translation():
    m = matrix(rot_x(75) @ rot_z(30), (3, 0.5, 2), (10, -20, 5))
    out = convert.camera_to_world_metres(m, 0.01)
    np.testing.assert_allclose(out[:3, :3].T @ out[:3, :3], np.eye(3), atol=1e-12)
    np.testing.assert_allclose(out[:3, :3], rot_x(75) @ rot_z(30), atol=1e-12)
    np.testing.assert_allclose(out[:3, 3], [0.1, -0.2, 0.05])
    np.testing.assert_array_equal(out[3], [0, 0, 0, 1])


@pytest.mark.parametrize("x, y, pct, expect", [(1920, 1080, 100, (1920, 1080)), (1920, 1080, 50, (960, 540)),
                                               (33, 25, 33, (10, 8)), (10, 10, 1, (1, 1))])
def test_render_resolution(x, y, pct, expect):
    assert convert.render_resolution(x, y, pct) == expect


def test_area_light_axes_identity_rectangle():
    pos, u, v, ellipse, area = convert.area_light_geometry(np.eye(4), "RECTANGLE", 2.0, 1.0, 1.0)
    assert not ellipse
    np.testing.assert_allclose(np.abs(u), [1, 0, 0])
    np.testing.assert_allclose(np.abs(v), [0, 0.5, 0])
    n = np.cross(u, v)
    np.testing.assert_allclose(n / np.linalg.norm(n), [0, 0, -1])  # Blender area lights emit along -Z
    assert area == pytest.approx(2.0)


@pytest.mark.parametrize("mirror", [False, True])
def test_area_light_axes_follow_rotation_scale_and_mirroring(mirror):
    rot = rot_x(30) @ rot_z(40)
    scale = (-1.5 if mirror else 1.5, 2.0, 0.7)
    m = matrix(rot, scale, (1, 2, 3))
    pos, u, v, ellipse, area = convert.area_light_geometry(m, "RECTANGLE", 2.0, 0.5, 0.1)
    np.testing.assert_allclose(pos, [0.1, 0.2, 0.3])
    n = np.cross(u, v)
    emit = -(rot @ np.diag(scale))[:, 2]
    np.testing.assert_allclose(n / np.linalg.norm(n), emit / np.linalg.norm(emit), atol=1e-12)
    assert np.linalg.norm(u) == pytest.approx(0.5 * 2.0 * 1.5 * 0.1)
    assert np.linalg.norm(v) == pytest.approx(0.5 * 0.5 * 2.0 * 0.1)
    assert area == pytest.approx((2.0 * 1.5 * 0.1) * (0.5 * 2.0 * 0.1))


def test_area_light_square_and_disk():
    _, u, v, ellipse, area = convert.area_light_geometry(np.eye(4), "SQUARE", 3.0, 99.0, 1.0)
    assert not ellipse and area == pytest.approx(9.0)
    _, u, v, ellipse, area = convert.area_light_geometry(np.eye(4), "DISK", 2.0, 99.0, 1.0)
    assert ellipse and area == pytest.approx(math.pi)  # diameter 2 → radius 1
    _, u, v, ellipse, area = convert.area_light_geometry(np.eye(4), "ELLIPSE", 2.0, 1.0, 1.0)
    assert ellipse and area == pytest.approx(math.pi * 1.0 * 0.5)
    with pytest.raises(ValueError):
        convert.area_light_geometry(np.eye(4), "TRIANGLE", 1.0, 1.0, 1.0)


def test_normalising_area():
    assert convert.area_light_normalising_area(3.0, True, 0.01) == 3.0
    assert convert.area_light_normalising_area(3.0, False, 0.01) == pytest.approx(1e-4)


def test_light_power_and_colour():
    assert convert.light_power_watts(100.0, 0.0) == 100.0
    assert convert.light_power_watts(100.0, 1.0) == 200.0
    assert convert.light_power_watts(100.0, -2.0) == 25.0
    assert convert.light_rgb((1, 0.5, 0.25)) == (1.0, 0.5, 0.25)
    assert convert.light_rgb((1, 0.5, 0.25), True, (0.5, 1.0, 2.0)) == (0.5, 0.5, 0.5)
    assert convert.light_rgb((1, 0.5, 0.25), False, (0.5, 1.0, 2.0)) == (1.0, 0.5, 0.25)


def test_rgb_of_drops_alpha():
    assert convert.rgb_of((0.1, 0.2, 0.3, 0.4)) == (0.1, 0.2, 0.3)


def test_rgba_rows_bottom_up():
    rgb = np.arange(2 * 3 * 3, dtype=np.float64).reshape(2, 3, 3)
    flat = convert.rgba_rows_bottom_up(rgb)
    assert flat.dtype == np.float32 and flat.shape == (2 * 3 * 4,)
    px = flat.reshape(2, 3, 4)
    np.testing.assert_array_equal(px[0, :, :3], rgb[1])  # Blender's first row is the bottom one
    np.testing.assert_array_equal(px[1, :, :3], rgb[0])
    assert np.all(px[..., 3] == 1.0)
    with pytest.raises(ValueError):
        convert.rgba_rows_bottom_up(np.zeros((2, 3)))

