"""Point, spot and sun lights: photometric units, Blender's spot mask, sphere and sun discs
(sampled by their cones and hit by BSDF rays under MIS), power-proportional selection, validation."""
import math

import numpy as np
import pytest
from helpers import (
    RHO, blender_spot_mask, check_luminance, disk_over_plane_scene, ground_points, look_at, plane_scene, render_lum)

from spectral_gi.core import constants as C
from spectral_gi.core.film import develop
from spectral_gi.core.integrators import render as R
from spectral_gi.core.scene import (
    Light, SceneError, load, save, validate)

def point_expected(sc, pos, intensity, mask=None):
    """ρ/π · I · mask · cos θ / d² averaged over each pixel."""
    p = ground_points(sc)
    v = np.asarray(pos) - p
    d2 = (v ** 2).sum(-1)
    cos = v[..., 2] / np.sqrt(d2)
    m = 1.0 if mask is None else mask(-v / np.sqrt(d2)[..., None])
    return (RHO / np.pi * intensity * m * cos / d2).mean(-1)


def _check_mean(d, expected):
    """Only the wavelength sampling varies: the mean is within noise and 1 % of ``expected``."""
    se = np.sqrt(d.variance.mean() / d.luminance.size)
    assert abs(d.luminance.mean() - expected) < 4.5 * se and abs(d.luminance.mean() / expected - 1) < 0.01, \
        (d.luminance.mean(), expected, se)


def _point(pos, intensity, radius=0.0):
    return Light("point", C.LIGHT_POINT, pos, (0, 0, 0), (0, 0, 0), 0, 0.0, radius=radius, intensity=intensity)


@pytest.mark.statistical
@pytest.mark.parametrize("radius", [0.0, 0.3])
def test_point_and_sphere_light_give_I_cos_over_d2(radius):
    """A point light of I cd gives E = I cos θ / d² lux, so a white Lambert plane shows ρE/π.
    A uniformly radiant sphere of radius r (radiance I/(πr²)) gives exactly the same
    irradiance wherever it is fully above the horizon (E = L π sin²α cos θ)."""
    pos, inten = (0.2, -0.1, 1.0), 50.0
    sc = plane_scene([_point(pos, inten, radius)], spp=64 if radius else 8)
    d = render_lum(sc)
    check_luminance(d, point_expected(sc, pos, inten), 0.02)
    assert abs(d.luminance.mean() / point_expected(sc, pos, inten).mean() - 1) < 0.01


@pytest.mark.statistical
def test_spot_with_hard_edge_is_a_point_light_inside_and_dark_outside():
    pos, inten, size = (0.0, 0.0, 1.0), 40.0, math.radians(60)
    spot = Light("spot", C.LIGHT_SPOT, pos, (0, 0, 0), (0, 0, 0), 0, 0.0, intensity=inten,
                 direction=(0, 0, -2.0), spot_angle=size, spot_blend=0.0)
    sc = plane_scene([spot], res=16, spp=16)
    d = render_lum(sc)
    p = ground_points(sc)
    rad = np.hypot(p[..., 0], p[..., 1])
    edge = math.tan(size / 2)
    # the sub-points stop 1/12 px short of a pixel's border: keep a margin so that no pixel
    # counted as inside reaches past the cone's edge
    inside = np.all(rad < edge * 0.97, axis=-1)
    outside = np.all(rad > edge * 1.03, axis=-1)
    assert inside.sum() > 20 and outside.sum() > 20
    exp = point_expected(sc, pos, inten)
    np.testing.assert_allclose(d.luminance[inside], exp[inside], rtol=0.03)
    assert np.all(d.luminance[outside] == 0.0)


@pytest.mark.statistical
@pytest.mark.parametrize("radius", [0.0, 0.05])
def test_spot_blend_profile_follows_blenders_smoothstep(radius):
    pos, inten, size, blend = (0.1, 0.0, 1.0), 40.0, math.radians(70), 0.6
    axis = np.array([0.2, 0.1, -1.0])
    spot = Light("spot", C.LIGHT_SPOT, pos, (0, 0, 0), (0, 0, 0), 0, 0.0, intensity=inten, radius=radius,
                 direction=tuple(axis), spot_angle=size, spot_blend=blend)
    sc = plane_scene([spot], res=16, spp=64 if radius else 16)
    d = render_lum(sc)
    a = axis / np.linalg.norm(axis)
    exp = point_expected(sc, pos, inten, mask=lambda q: blender_spot_mask(q @ a, size, blend))
    # the profile really varies across the view: dark corners, a ramp, a lit core
    assert exp.max() > 0 and (exp == 0).sum() > 10 and ((exp > 0.1 * exp.max()) & (exp < 0.9 * exp.max())).sum() > 20
    check_luminance(d, exp, 0.03)


@pytest.mark.statistical
@pytest.mark.parametrize("angle_deg", [0.0, 10.0])
def test_sun_gives_its_illuminance_times_cos(angle_deg):
    """A sun of E lux at θ = 30° from the normal: L = ρ E cos θ / π, for a delta sun and for a
    sun disc of 10° (sampled in its cone and hit by BSDF rays, combined by MIS)."""
    e, th = 1000.0, math.radians(30)
    sun = Light("sun", C.LIGHT_SUN, (0, 0, 0), (0, 0, 0), (0, 0, 0), 0, 0.0, illuminance=e,
                direction=(math.sin(th), 0.0, -math.cos(th)), angle=math.radians(angle_deg))
    sc = plane_scene([sun], res=6, spp=64)
    d = render_lum(sc)
    expected = RHO * e * math.cos(th) / math.pi
    assert abs(d.luminance.mean() / expected - 1) < 0.01, (d.luminance.mean(), expected)
    if angle_deg == 0:
        np.testing.assert_allclose(d.luminance, expected, rtol=0.02)


@pytest.mark.statistical
def test_visible_sphere_and_sun_show_their_radiance():
    """Seen directly: a sphere light of I cd and radius r has L = I/(πr²); a sun disc of E lux
    and angular diameter 2α has L = E/(π sin²α)."""
    inten, r = 10.0, 0.25
    sc = plane_scene([_point((0, 0, 1.5), inten, r)], res=4, half_view=0.01, spp=4)
    sc.meshes = []  # lights do not occlude (as in Cycles): the camera would also see the plane behind
    sc.lights[0].visible = True
    d = render_lum(sc)
    _check_mean(d, inten / (np.pi * r * r))
    sc.lights[0].visible = False
    assert render_lum(sc).luminance.max() == 0.0
    e, ang = 1000.0, math.radians(8)
    sun = Light("sun", C.LIGHT_SUN, (0, 0, 0), (0, 0, 0), (0, 0, 0), 0, 0.0, illuminance=e,
                direction=(0, 0, 1.0), angle=ang, visible=True)
    sc = plane_scene([sun], res=4, spp=4)
    sc.meshes = []
    sc.camera.to_world = look_at((0, 0, 0), (0, 0, -1), up=(0, 1, 0))
    sc.camera.lens_mm = 5000.0
    d = render_lum(sc)
    _check_mean(d, e / (np.pi * math.sin(ang / 2) ** 2))


def test_light_selection_follows_luminous_flux():
    """Point: 4πI lm; spot: 2πI(1 − cos½)(1 − blend/2); area: πLA; sun: E · π R² over the
    scene's bounding sphere (its flux through the scene's cross-section)."""
    spot_size, blend = math.radians(50), 0.4
    lights = [_point((0, 0, 1), 10.0),
              Light("spot", C.LIGHT_SPOT, (0, 0, 1), (0, 0, 0), (0, 0, 0), 0, 0.0, intensity=20.0,
                    direction=(0, 0, -1), spot_angle=spot_size, spot_blend=blend),
              Light("area", C.LIGHT_RECT, (0, 0, 1), (0.5, 0, 0), (0, 0.25, 0), 0, 30.0),
              Light("sun", C.LIGHT_SUN, (0, 0, 0), (0, 0, 0), (0, 0, 0), 0, 0.0, illuminance=2.0,
                    direction=(0, 0, -1))]
    sc = plane_scene(lights)
    prep = R.prepare(sc)
    radius = 0.5 * np.linalg.norm([100.0, 100.0, 0.0])
    flux = np.array([4 * np.pi * 10, 2 * np.pi * 20 * (1 - math.cos(spot_size / 2)) * (1 - blend / 2),
                     np.pi * 30 * 0.5, 2.0 * np.pi * radius ** 2])
    np.testing.assert_allclose(prep.emitters.emit_prob, flux / flux.sum(), rtol=1e-9)
    # the spot's flux formula is the integral of its mask over the sphere
    t = np.linspace(-1, 1, 2_000_001)
    integral = 2 * np.pi * np.trapz(blender_spot_mask(t, spot_size, blend), t)
    assert integral == pytest.approx(2 * np.pi * (1 - math.cos(spot_size / 2)) * (1 - blend / 2), rel=1e-5)


@pytest.mark.parametrize("field, value, match", [
    ("kind", 7, "kind"), ("intensity", -1.0, "intensity"), ("intensity", float("nan"), "intensity"),
    ("radius", -0.1, "radius"), ("direction", (0, 0, 0), "direction"), ("direction", (0, float("nan"), 1), "direction"),
    ("spot_angle", 0.0, "spot_angle"), ("spot_angle", 4.0, "spot_angle"), ("spot_blend", 1.5, "spot_blend"),
    ("position", (0, 0, float("inf")), "position"), ("spectrum", -1, "spectrum")])
def test_point_and_spot_fields_are_validated(field, value, match):
    spot = Light("s", C.LIGHT_SPOT, (0, 0, 1), (0, 0, 0), (0, 0, 0), 0, 0.0, intensity=1.0, direction=(0, 0, -1),
                 spot_angle=1.0)
    sc = plane_scene([spot])
    validate(sc)
    setattr(sc.lights[0], field, value)
    with pytest.raises(SceneError, match=rf"lights\[0\] \('s'\)\.{match}"):
        validate(sc)


@pytest.mark.parametrize("field, value", [("illuminance", -1.0), ("angle", -0.1), ("angle", 3.5),
                                          ("direction", (0.0, 0.0, 0.0)), ("illuminance", float("inf"))])
def test_sun_fields_are_validated(field, value):
    sun = Light("sun", C.LIGHT_SUN, (0, 0, 0), (0, 0, 0), (0, 0, 0), 0, 0.0, illuminance=1.0, direction=(0, 0, -1))
    sc = plane_scene([sun])
    validate(sc)
    setattr(sc.lights[0], field, value)
    with pytest.raises(SceneError, match=rf"lights\[0\] \('sun'\)\.{field}"):
        validate(sc)


def test_new_light_fields_survive_save_and_load(tmp_path):
    lights = [_point((0, 0, 1), 3.0, 0.1),
              Light("spot", C.LIGHT_SPOT, (1, 0, 1), (0, 0, 0), (0, 0, 0), 0, 0.0, intensity=2.0, radius=0.05,
                    direction=(0, 0.6, -0.8), spot_angle=0.7, spot_blend=0.3, visible=True),
              Light("sun", C.LIGHT_SUN, (0, 0, 0), (0, 0, 0), (0, 0, 0), 0, 0.0, illuminance=5.0,
                    direction=(0.0, 0.0, -1.0), angle=0.01)]
    sc = plane_scene(lights)
    back = load(save(sc, tmp_path / "s.json"))
    for a, b in zip(sc.lights, back.lights):
        for f in ("kind", "radius", "intensity", "spot_angle", "spot_blend", "illuminance", "angle", "visible"):
            assert getattr(a, f) == getattr(b, f), f
        np.testing.assert_array_equal(a.direction, b.direction)


@pytest.mark.statistical
@pytest.mark.parametrize("kind", [C.LIGHT_RECT, C.LIGHT_ELLIPSE])
def test_area_light_with_skewed_axes_is_hit_where_it_is_sampled(kind):
    """A parallelogram (or the affine image of a disc) spanned by two axes that are not at right
    angles, as an area light under a sheared parent has: the light that BSDF sampling hits is the
    light that next-event estimation samples, so both estimators agree on the lit plane."""
    means = []
    for nee in (True, False):
        sc = disk_over_plane_scene(radius=0.3, height=1.0, kind=kind, spp=512, res=5)
        sc.lights[0].axis_u = (0.3, 0.3, 0.0)  # with axis_v (0.3, 0, 0): skewed by 45°
        sc.settings.next_event = nee
        d = develop(R.render(sc, threads=2)[0].sums)
        means.append((d.luminance.mean(), np.sqrt(d.variance.sum()) / d.luminance.size))
    (a, sa), (b, sb) = means
    assert abs(a - b) < 4.0 * np.hypot(sa, sb), means
