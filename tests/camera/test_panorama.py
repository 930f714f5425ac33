"""Panoramic cameras (Cycles' equirectangular, equidistant and equisolid fisheye): the ray of
each image position against the projection's defining formula, the solid angle each pixel
sees against its closed form, and renders of a uniform world."""
import math

import numpy as np
import pytest
from helpers import flat_emission, look_at

from spectral_gi.core import constants as C
from spectral_gi.core.camera.kernel import camera_ray, filter_table
from spectral_gi.core.camera.record import camera_vector
from spectral_gi.core.film import develop
from spectral_gi.core.integrators import render as R
from spectral_gi.core.scene import Camera, RenderSettings, Scene, SceneError, SpectrumTable, World, validate

BOX = filter_table(C.FILTER_BOX, 1.0)  # a sample u of the box filter of 1 px lands at offset u − ½


def turned_camera(projection, width, height, **kw):
    """A panoramic camera at (1, 2, 3) looking along (1, 0.3, −0.2) with a tilted up vector."""
    return Camera(look_at((1.0, 2.0, 3.0), (2.0, 2.3, 2.8), up=(0.1, 0.2, 1.0)), width=width, height=height,
                  projection=projection, **kw)


def rays(cam, fx, fy):
    """Directions (N, 3) through the image positions (fx, fy) (pixels from the top left)."""
    v = camera_vector(cam)
    out = np.empty((len(fx), 3))
    for k, (a, b) in enumerate(zip(fx, fy)):
        x, y = int(math.floor(a)), int(math.floor(b))
        r = camera_ray(v, BOX, x, y, cam.width, cam.height, a - x, b - y, 0.5, 0.5)
        assert r[:3] == pytest.approx(tuple(cam.to_world[:3, 3]))
        out[k] = r[3:]
    return out


def to_camera(cam, d):
    """World directions → camera space (x right, y up, z towards the viewer)."""
    return d @ cam.to_world[:3, :3]


def image_positions(width, height, n=400, seed=1):
    rng = np.random.default_rng(seed)
    return rng.uniform(0.02, width - 0.02, n), rng.uniform(0.02, height - 0.02, n)


def jacobian(cam, fx, fy, h=1e-4):
    """Solid angle per unit of image area (sr per pixel²) at (fx, fy), by central differences."""
    dx = (rays(cam, fx + h, fy) - rays(cam, fx - h, fy)) / (2 * h)
    dy = (rays(cam, fx, fy + h) - rays(cam, fx, fy - h)) / (2 * h)
    return np.linalg.norm(np.cross(dx, dy), axis=1)


@pytest.mark.parametrize("ranges", [(-0.5 * math.pi, 0.5 * math.pi, -math.pi, math.pi), (-0.3, 1.1, -0.4, 2.0)])
def test_equirectangular_rays_have_the_pixels_latitude_and_longitude(ranges):
    """Latitude runs linearly from latitude_min at the bottom to latitude_max at the top and
    longitude from longitude_min at the left to longitude_max at the right (0: the view axis,
    positive towards the camera's +X); each pixel sees Δlon Δlat cos(lat) / (W H) sr."""
    lat0, lat1, lon0, lon1 = ranges
    cam = turned_camera(C.CAM_EQUIRECTANGULAR, 40, 20, latitude_min=lat0, latitude_max=lat1, longitude_min=lon0,
                        longitude_max=lon1)
    fx, fy = image_positions(40, 20)
    c = to_camera(cam, rays(cam, fx, fy))
    lat = lat0 + (1.0 - fy / 20) * (lat1 - lat0)
    lon = lon0 + fx / 40 * (lon1 - lon0)
    np.testing.assert_allclose(np.arcsin(np.clip(c[:, 1], -1, 1)), lat, atol=1e-9)
    np.testing.assert_allclose(np.cos(np.arctan2(c[:, 0], -c[:, 2]) - lon), 1.0, atol=1e-12)
    sa = jacobian(cam, fx[:50], fy[:50])
    np.testing.assert_allclose(sa, abs(lon1 - lon0) * abs(lat1 - lat0) * np.cos(lat[:50]) / (40 * 20), rtol=1e-5)


def test_a_full_equirectangular_image_sees_the_whole_sphere():
    cam = turned_camera(C.CAM_EQUIRECTANGULAR, 64, 32)
    fx, fy = np.meshgrid(np.arange(64) + 0.5, np.arange(32) + 0.5)
    total = jacobian(cam, fx.ravel(), fy.ravel()).sum()
    assert total == pytest.approx(4 * math.pi, rel=1e-3)  # midpoint rule over the rows
    # the image's centre looks down the camera's −Z, its top row towards +Y
    c = to_camera(cam, rays(cam, [32.0, 32.0], [16.0, 0.01]))
    np.testing.assert_allclose(c[0], (0, 0, -1), atol=1e-12)
    assert c[1, 1] > 0.9999


@pytest.mark.parametrize("fov_deg, w, h", [(180.0, 30, 30), (230.0, 40, 24)])
def test_equidistant_fisheye_angle_grows_linearly_with_the_image_radius(fov_deg, w, h):
    """θ = r · fov / 2 with r the distance from the centre in units of half the image (on each
    axis); outside r = 1 no ray; dω per pixel = (fov/2) sin θ / r · 4 / (W H)."""
    fov = math.radians(fov_deg)
    cam = turned_camera(C.CAM_FISHEYE_EQUIDISTANT, w, h, fisheye_fov=fov)
    fx, fy = image_positions(w, h)
    a, b = 2 * fx / w - 1, 1 - 2 * fy / h
    r = np.hypot(a, b)
    d = rays(cam, fx, fy)
    inside = r < 1.0
    assert np.all(d[~inside] == 0.0) and (~inside).sum() > 20
    c = to_camera(cam, d[inside])
    np.testing.assert_allclose(np.arccos(np.clip(-c[:, 2], -1, 1)), r[inside] * fov / 2, atol=1e-9)
    # the direction's azimuth about the view axis is the image position's
    np.testing.assert_allclose(np.cos(np.arctan2(c[:, 1], c[:, 0]) - np.arctan2(b[inside], a[inside])), 1.0,
                               atol=1e-9)
    sel = np.flatnonzero(inside & (r > 0.05) & (r < 0.95))[:40]
    theta = r[sel] * fov / 2
    np.testing.assert_allclose(jacobian(cam, fx[sel], fy[sel]), fov / 2 * np.sin(theta) / r[sel] * 4 / (w * h),
                               rtol=1e-5)


@pytest.mark.parametrize("fit, w, h", [(C.FIT_AUTO, 48, 32), (C.FIT_VERTICAL, 32, 48)])
def test_equisolid_fisheye_sees_equal_solid_angles_in_equal_image_areas(fit, w, h):
    """r = 2 f sin(θ/2) on the sensor (the fitted axis keeps its size, the other follows the
    image's aspect), so a pixel of sensor area A sees A / f² sr wherever it is; no ray past
    the field of view."""
    lens, fov = 8.0, math.radians(200.0)
    cam = turned_camera(C.CAM_FISHEYE_EQUISOLID, w, h, fisheye_lens_mm=lens, fisheye_fov=fov, sensor_fit=fit,
                        sensor_width_mm=36.0, sensor_height_mm=24.0)
    size = 36.0 if fit == C.FIT_AUTO else 24.0
    sw, sh = (size, size * h / w) if w > h else (size * w / h, size)
    fx, fy = image_positions(w, h)
    a, b = (fx / w - 0.5) * sw, (0.5 - fy / h) * sh
    r = np.hypot(a, b)
    d = rays(cam, fx, fy)
    inside = r <= 2 * lens * math.sin(fov / 4)
    assert np.all(d[~inside] == 0.0) and (~inside).sum() > 10 and inside.sum() > 100
    c = to_camera(cam, d[inside])
    theta = np.arccos(np.clip(-c[:, 2], -1, 1))
    np.testing.assert_allclose(2 * lens * np.sin(theta / 2), r[inside], rtol=1e-9, atol=1e-9)
    sel = np.flatnonzero(inside & (r > 0.5) & (r < 0.95 * 2 * lens * math.sin(fov / 4)))[:40]
    np.testing.assert_allclose(jacobian(cam, fx[sel], fy[sel]), (sw / w) * (sh / h) / lens ** 2, rtol=1e-5)


def sky_scene(cam, spp=8, **world):
    spectra = SpectrumTable.empty()
    e = spectra.add("white", flat_emission(), C.SPECTRUM_UNBOUNDED)
    return Scene(spectra=spectra, camera=cam, world=World(background=e, luminance=250.0, **world),
                 settings=RenderSettings(spp=spp, max_depth=0, seed=3))


def test_a_uniform_world_seen_through_panoramic_cameras_is_uniform():
    """Every ray of an equirectangular camera sees the world's 250 cd/m²; a fisheye's pixels
    outside its image circle are black (transparent with Film > Transparent)."""
    img = develop(R.render(sky_scene(turned_camera(C.CAM_EQUIRECTANGULAR, 32, 16)))[0].sums).luminance
    np.testing.assert_allclose(img, 250.0, rtol=0.02)
    assert img.std() / img.mean() < 0.01
    cam = turned_camera(C.CAM_FISHEYE_EQUIDISTANT, 24, 24)
    sc = sky_scene(cam, spp=16)
    sc.settings.filter = C.FILTER_BOX
    sc.settings.filter_width = 1.0
    film, _ = R.render(sc)
    lum = develop(film.sums).luminance
    c = (np.arange(24) + 0.5) / 12 - 1
    r = np.hypot(c[None, :], c[:, None]) + np.zeros((24, 24))
    pix = 1 / 12 * math.sqrt(0.5)  # half a pixel's diagonal, in units of the radius
    np.testing.assert_allclose(lum[r < 1 - pix], 250.0, rtol=0.02)
    assert np.all(lum[r > 1 + pix] == 0.0)
    sc.settings.film_transparent = True
    sc.world.background, sc.world.luminance = -1, 0.0
    alpha = R.render(sc)[0].develop().alpha
    assert np.all(alpha[r > 1 + pix] == 0.0)


@pytest.mark.parametrize("field, value, match", [
    ("projection", 7, "camera.projection: unknown projection 7"),
    ("latitude_max", 2.0, "camera.latitude_max"),
    ("longitude_min", float("nan"), "camera.longitude_min"),
    ("fisheye_fov", 0.0, "camera.fisheye_fov"),
    ("fisheye_lens_mm", -1.0, "camera.fisheye_lens_mm")])
def test_bad_panoramic_parameters_are_named(field, value, match):
    sc = sky_scene(turned_camera(C.CAM_EQUIRECTANGULAR, 4, 4))
    setattr(sc.camera, field, value)
    with pytest.raises(SceneError, match=match):
        validate(sc)


def test_panoramic_camera_survives_save_and_load(tmp_path):
    from spectral_gi.core.scene import load, save

    sc = sky_scene(turned_camera(C.CAM_FISHEYE_EQUISOLID, 4, 4, fisheye_fov=3.0, fisheye_lens_mm=7.5))
    sc.camera.latitude_min = -0.2
    back = load(save(sc, tmp_path / "pano.json"))
    for f in ("projection", "fisheye_fov", "fisheye_lens_mm", "latitude_min", "longitude_max"):
        assert getattr(back.camera, f) == getattr(sc.camera, f), f


@pytest.mark.parametrize("projection, kw", [
    (C.CAM_EQUIRECTANGULAR, dict(latitude_min=-1.0, latitude_max=0.7, longitude_min=-2.5, longitude_max=1.0)),
    (C.CAM_FISHEYE_EQUIDISTANT, dict(fisheye_fov=4.0, shift_x=0.05)),
    (C.CAM_FISHEYE_EQUISOLID, dict(fisheye_fov=3.6, fisheye_lens_mm=9.0, sensor_fit=C.FIT_VERTICAL))])
def test_kernel_rays_match_the_reference_camera(projection, kw):
    """The kernel's rays and the reference's (tests/oracles/reference/camera.py, written from the
    contract) through the same film positions."""
    from oracles.reference.camera import CameraModel

    cam = turned_camera(projection, 36, 20, **kw)
    ref = CameraModel(cam, RenderSettings(filter=C.FILTER_BOX, filter_width=1.0))
    fx, fy = image_positions(36, 20, n=300, seed=4)
    d = rays(cam, fx, fy)
    want = ref.panorama(fx, fy) @ ref.rot.T
    np.testing.assert_allclose(d, want, atol=1e-9)
    assert (np.abs(d).sum(axis=1) == 0).any() == (projection != C.CAM_EQUIRECTANGULAR)
