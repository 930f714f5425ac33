"""Illuminance, luminance and cylindrical illuminance at points (core/integrators/illuminance.py)
against closed forms.

Statistical checks use fixed seeds: |estimate − exact| < 5 standard errors (the estimator's
own, or over points) plus a small relative allowance for the exact references' spectral
round trip; each test also asserts that its standard error is small enough to catch a
few per cent.
"""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from spectral_gi.core import constants as C
from spectral_gi.core.integrators.illuminance import (
    batches, cylindrical_illuminance, illuminance, luminance, semicylindrical_illuminance, vertical_illuminance)
from spectral_gi.core.scene import Light, Material, Mesh, RenderSettings, Scene, SceneError, SpectrumTable, World

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from helpers import box_mesh, flat_emission, flat_reflectance  # noqa: E402

pytestmark = pytest.mark.statistical


def close(got, se, want, rel=2e-3, k=5.0):
    got, se, want = (np.atleast_1d(np.asarray(x, float)) for x in (got, se, want))
    ok = np.abs(got - want) <= k * se + rel * np.abs(want) + 1e-9
    assert np.all(ok), (got, se, want)


def spectra():
    sp = SpectrumTable.empty()
    e = sp.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    return sp, e


def quad(name, half, z, material, flip=False):
    p = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]], np.float32)
    idx = np.array([[0, 2, 1], [0, 3, 2]] if flip else [[0, 1, 2], [0, 2, 3]], np.int32)
    return Mesh(name, p, idx, np.full(2, material, np.int32))


def floor_scene(lights, sp, rho=0.0, world=None, half=50.0, seed=3):
    """A floor (z = 0, ±half m) of reflectance rho (0: black) under ``lights``."""
    mats = [Material("floor", reflectance=sp.add("floor", flat_reflectance(rho), C.SPECTRUM_BOUNDED)
                     if rho > 0 else -1)]
    return Scene(meshes=[quad("floor", half, 0.0, 0)], spectra=sp, materials=mats, lights=lights,
                 world=world or World(), settings=RenderSettings(seed=seed))


def point_light(e, pos, intensity):
    return Light("point", C.LIGHT_POINT, pos, (0, 0, 0), (0, 0, 0), e, 0.0, intensity=intensity)


# ------------------------------------------------------------------------------ direct light

I_CD = 100.0
H = 2.0


def test_point_light_inverse_square_cosine():
    sp, e = spectra()
    sc = floor_scene([point_light(e, (0.0, 0.0, H), I_CD)], sp)
    s5 = 1 / math.sqrt(5)
    pts = [[0, 0, 0], [1, 0, 0], [1, 0, 0], [1, 0, 0], [1, 0, 0], [0.5, 0.3, 1.2], [1, 0, 0]]
    nrm = [[0, 0, 1], [0, 0, 1], [-1, 0, 0], [-s5, 0, 2 * s5], [0, 0, 2.5], [0, 0, 1], [1, 0, 0]]
    d_free = np.array([-0.5, -0.3, H - 1.2])
    want = [I_CD / H ** 2,
            I_CD * H / 5 ** 1.5,  # on the floor, facing up
            I_CD * 1 / 5 ** 1.5,  # at floor level, vertical plane facing the light (the camera route: 50 % low)
            I_CD / 5,  # normal at the light
            I_CD * H / 5 ** 1.5,  # an unnormalised normal
            I_CD * d_free[2] / np.linalg.norm(d_free) ** 3,  # in free space, 1.2 m above the floor
            0.0]  # facing away
    lux, se, n = illuminance(sc, pts, nrm, spp=64, threads=2)
    assert np.all(n == 64)
    close(lux, se, want)
    assert lux[-1] == 0.0 and np.all(se[:-1] < 0.01 * np.asarray(want[:-1]))


def test_point_in_free_space_without_geometry():
    sp, e = spectra()
    sc = Scene(spectra=sp, lights=[point_light(e, (0.0, 0.0, H), I_CD)], settings=RenderSettings(seed=4))
    lux, se, _ = illuminance(sc, [[0, 0, 0], [0, 0, 4]], [[0, 0, 1], [0, 0, -1]], spp=32, threads=1)
    close(lux, se, [I_CD / H ** 2, I_CD / H ** 2])


def corner_factor(a, b, h):
    """The configuration factor from a point to a parallel rectangle a × b at height h, the
    point on the normal through one of its corners."""
    A, B = a / h, b / h
    return (A / math.sqrt(1 + A * A) * math.atan(B / math.sqrt(1 + A * A))
            + B / math.sqrt(1 + B * B) * math.atan(A / math.sqrt(1 + B * B))) / (2 * math.pi)


def test_rectangle_light_configuration_factor():
    sp, e = spectra()
    a, b, h, L = 1.0, 2.0, 1.5, 1000.0
    rect = Light("rect", C.LIGHT_RECT, (a / 2, b / 2, h), (a / 2, 0, 0), (0, -b / 2, 0), e, L)  # emits down
    sc = floor_scene([rect], sp)
    lux, se, _ = illuminance(sc, [[0, 0, 0], [a / 2, b / 2, 0], [a / 2, b / 2, 0.5]],
                             [[0, 0, 1], [0, 0, 1], [0, 0, 1]], spp=4096, threads=2)
    want = [L * math.pi * corner_factor(a, b, h), L * math.pi * 4 * corner_factor(a / 2, b / 2, h),
            L * math.pi * 4 * corner_factor(a / 2, b / 2, h - 0.5)]
    close(lux, se, want)
    assert np.all(se < 0.01 * np.asarray(want))


@pytest.mark.parametrize("angle", [0.0, 0.02])
def test_sun_cosine(angle):
    sp, e = spectra()
    e_sun = 50000.0
    s = np.array([math.sin(math.radians(30)), 0.0, math.cos(math.radians(30))])  # towards the sun
    sun = Light("sun", C.LIGHT_SUN, (0, 0, 0), (0, 0, 0), (0, 0, 0), e, 0.0, direction=tuple(-s),
                illuminance=e_sun, angle=angle)
    sc = floor_scene([sun], sp)
    lux, se, _ = illuminance(sc, [[0, 0, 0], [0, 0, 0], [0, 0, 1], [0, 0, 0]],
                             [[0, 0, 1], s, [1, 0, 0], [-1, 0, 0]], spp=32, threads=2)
    close(lux, se, [e_sun * s[2], e_sun, e_sun * s[0], 0.0])


def test_emissive_mesh_and_constant_sky():
    sp, e = spectra()
    L = 100.0
    # inside a closed box whose walls emit L towards the inside (and reflect nothing): E = π L
    box = box_mesh("box", (-1, -1, -1), (1, 1, 1), 0)
    sc = Scene(meshes=[box], spectra=sp, materials=[Material("glow", emission=e, emission_luminance=L)],
               settings=RenderSettings(seed=5))
    lux, se, _ = illuminance(sc, [[0, 0, 0], [0.5, -0.3, 0.2], [0.9, 0.9, -0.99]],
                             [[0, 0, 1], [1, 2, 3], [0, 0, 1]], spp=1024, threads=2)
    close(lux, se, [math.pi * L] * 3)
    assert np.all(se < 0.015 * math.pi * L)
    # the world: a constant sky over a black floor
    sky = floor_scene([], sp, world=World(background=e, luminance=L))
    lux, se, _ = illuminance(sky, [[0, 0, 0], [0, 0, 1], [0, 0, 1]], [[0, 0, 1], [0, 0, -1], [1, 0, 0]],
                             spp=256, threads=2)
    close(lux, se, [math.pi * L, 0.0, math.pi * L / 2], rel=5e-3)


# ----------------------------------------------------------------------- interreflection

PHI = 10000.0  # lm
SIDE = 4.0


def cube(rho, seed=11):
    sp, e = spectra()
    r = sp.add("wall", flat_reflectance(rho), C.SPECTRUM_BOUNDED)
    h = SIDE / 2
    return Scene(meshes=[box_mesh("walls", (-h, -h, -h), (h, h, h), 0)], spectra=sp,
                 materials=[Material("wall", reflectance=r)],
                 lights=[point_light(e, (0.0, 0.0, 0.0), PHI / (4 * math.pi))],
                 settings=RenderSettings(seed=seed))


def wall_points(per_face, seed=1):
    """Uniform random points on the six inner faces of the cube, normals inwards."""
    rng = np.random.default_rng(seed)
    h = SIDE / 2
    pts, nrm = [], []
    for axis in range(3):
        for sgn in (-1.0, 1.0):
            uv = rng.uniform(-h, h, (per_face, 2))
            p = np.zeros((per_face, 3))
            others = [k for k in range(3) if k != axis]
            p[:, others[0]] = uv[:, 0]
            p[:, others[1]] = uv[:, 1]
            p[:, axis] = sgn * h
            n = np.zeros((per_face, 3))
            n[:, axis] = -sgn
            pts.append(p)
            nrm.append(n)
    return np.concatenate(pts), np.concatenate(nrm)


def direct(pts, nrm):
    d = -pts  # towards the light at the centre
    dist = np.linalg.norm(d, axis=1)
    return PHI / (4 * math.pi) * np.sum(nrm * d, axis=1) / dist ** 3


@pytest.mark.parametrize("rho", [0.5, 0.95])
def test_closed_cube_interreflection_is_unbiased(rho):
    """CIE 171:2006 case 5.8: the mean indirect illuminance on the walls is Φρ/(A(1 − ρ))
    (1979 lx at ρ = 0.95); Russian roulette alone ends the paths, so nothing is cut off."""
    pts, nrm = wall_points(16)
    lux, se, _ = illuminance(cube(rho), pts, nrm, spp=128, threads=2)
    ind = lux - direct(pts, nrm)
    want = PHI * rho / (6 * SIDE ** 2 * (1 - rho))
    se_mean = ind.std(ddof=1) / math.sqrt(ind.size)
    assert se_mean < 0.01 * want
    assert abs(ind.mean() - want) < 5 * se_mean + 0.005 * want, (ind.mean(), want, se_mean)
    if rho == 0.95:
        # a bounce limit loses ρ^k of it: what a program that truncates reads
        cut, _, _ = illuminance(cube(rho), pts[::8], nrm[::8], spp=32, threads=2, max_depth=8)
        assert np.mean(cut - direct(pts[::8], nrm[::8])) < 0.75 * want


# ----------------------------------------------------------------- determinism, stopping

def test_bit_identical_for_threads_and_chunks():
    pts, nrm = wall_points(1, seed=2)
    sc = cube(0.5)
    a = illuminance(sc, pts, nrm, spp=48, threads=1)
    b = illuminance(sc, pts, nrm, spp=48, threads=2)
    c = illuminance(sc, pts, nrm, spp=48, threads=2, _chunk=5)
    for x in (b, c):
        for u, v in zip(a, x):
            assert np.array_equal(u, v)
    # one point on every core: its samples split into chunks of one
    one = [illuminance(sc, pts[2:3], nrm[2:3], spp=48, threads=t, _chunk=k) for t, k in ((1, None), (2, 1))]
    assert np.array_equal(one[0][0], one[1][0]) and np.array_equal(one[0][1], one[1][1])
    d = illuminance(sc, pts, nrm, spp=48, threads=1, seed=99)
    assert not np.array_equal(a[0], d[0])


def test_rel_error_stops_bright_points_first():
    h = SIDE / 2
    pts = np.array([[0, 0, -h], [1.9, 1.9, -h], [0, 0, h]])
    nrm = np.array([[0, 0, 1], [0, 0, 1], [0, 0, -1]])
    target = 0.02
    lux, se, n = illuminance(cube(0.5), pts, nrm, spp=2048, rel_error=target, threads=2)
    assert np.all(n < 2048) and np.all(n >= 32)
    assert np.all(se <= target * lux)
    assert n[0] < n[1] and n[2] < n[1]  # the face centres (bright, mostly direct light) stop first
    # the samples used are a whole number of batches
    ends = {b1 for _, b1 in batches(2048)}
    assert set(n.tolist()) <= ends


def test_cancel_and_progress():
    pts, nrm = wall_points(1, seed=3)
    seen = []
    lux, se, n = illuminance(cube(0.5), pts, nrm, spp=64, threads=1, progress=lambda d, t: seen.append((d, t)),
                             should_cancel=lambda: len(seen) >= 1)
    assert np.all(n == 16) and np.all(np.isfinite(lux))
    assert seen == [(16 * 6, 64 * 6)]
    assert batches(64) == [(0, 16), (16, 32), (32, 64)] and batches(600)[-1] == (512, 600)


def test_bad_input():
    sc = cube(0.5)
    with pytest.raises(SceneError, match=r"points\[1\]: contains NaN"):
        illuminance(sc, [[0, 0, 0], [np.nan, 0, 0]], [[0, 0, 1], [0, 0, 1]], spp=4)
    with pytest.raises(SceneError, match=r"normals\[1\]: a zero vector"):
        illuminance(sc, [[0, 0, 0], [0, 0, 0]], [[0, 0, 1], [0, 0, 0]], spp=4)
    with pytest.raises(SceneError, match=r"points: expected shape \(N, 3\)"):
        illuminance(sc, [[0, 0]], [[0, 0, 1]], spp=4)
    with pytest.raises(SceneError, match="normals: 1 normals for 2 points"):
        illuminance(sc, [[0, 0, 0], [0, 0, 0]], [[0, 0, 1]], spp=4)
    with pytest.raises(SceneError, match="spp"):
        illuminance(sc, [[0, 0, 0]], [[0, 0, 1]], spp=0)
    with pytest.raises(SceneError, match="rel_error"):
        illuminance(sc, [[0, 0, 0]], [[0, 0, 1]], rel_error=-1)


# ------------------------------------------------------------------ luminance, cylindrical

def test_luminance():
    sp, e = spectra()
    L = 200.0
    sky = Scene(spectra=sp, world=World(background=e, luminance=L), settings=RenderSettings(seed=6))
    lum, se, _ = luminance(sky, [[0, 0, 0], [3, 1, 2]], [[0, 0, 1], [1, -1, 0]], spp=32, threads=1)
    close(lum, se, [L, L], rel=5e-3)
    # a Lambertian floor of reflectance ρ under a sun at the zenith: L = ρ E / π from any direction
    e_sun, rho = 10000.0, 0.5
    sun = Light("sun", C.LIGHT_SUN, (0, 0, 0), (0, 0, 0), (0, 0, 0), e, 0.0, direction=(0, 0, -1),
                illuminance=e_sun)
    sc = floor_scene([sun], sp, rho=rho)
    lum, se, _ = luminance(sc, [[0, 0, 1], [0, 0, 1]], [[0, 0, -1], [1, 0, -1]], spp=64, threads=1)
    close(lum, se, [rho * e_sun / math.pi] * 2, rel=5e-3)


def test_cylindrical_and_semicylindrical():
    sp, e = spectra()
    sc = Scene(spectra=sp, lights=[point_light(e, (0.0, 0.0, H), I_CD)], settings=RenderSettings(seed=8))
    r = 1.5
    d2 = r * r + H * H
    sin_g = r / math.sqrt(d2)  # the light's angle from the vertical
    pts = [[r, 0, 0]]
    towards = [[-1, 0, 0.3]]
    lux, se, _ = vertical_illuminance(sc, pts, towards, spp=64, threads=1)
    close(lux, se, [I_CD / d2 * sin_g])
    lux, se, _ = cylindrical_illuminance(sc, pts, spp=1024, threads=2)
    close(lux, se, [I_CD / d2 * sin_g / math.pi], rel=5e-3)
    assert se[0] < 0.05 * lux[0]
    lux, se, _ = semicylindrical_illuminance(sc, pts + pts, towards + [[1, 0, 0]], spp=1024, threads=2)
    close(lux, se, [I_CD / d2 * sin_g * 2 / math.pi, 0.0], rel=5e-3)


def test_public_names():
    from spectral_gi import core
    from spectral_gi.core.integrators import illuminance as M

    assert core.point_illuminance is M.illuminance and core.point_luminance is M.luminance
    assert core.cylindrical_illuminance is M.cylindrical_illuminance
    assert {"point_illuminance", "point_luminance", "semicylindrical_illuminance"} <= set(core.__all__)


@pytest.mark.parametrize("sampler", [C.SAMPLER_INDEPENDENT, C.SAMPLER_HALTON, C.SAMPLER_HAMMERSLEY])
def test_other_samplers(sampler):
    sp, e = spectra()
    a, b, h, L = 1.0, 2.0, 1.5, 1000.0
    rect = Light("rect", C.LIGHT_RECT, (a / 2, b / 2, h), (a / 2, 0, 0), (0, -b / 2, 0), e, L)
    sc = floor_scene([rect, point_light(e, (0.0, 0.0, H), I_CD)], sp, rho=0.0)
    sc.settings.sampler = sampler
    lux, se, _ = illuminance(sc, [[0, 0, 0]], [[0, 0, 1]], spp=1024, threads=2)
    close(lux, se, [L * math.pi * corner_factor(a, b, h) + I_CD / H ** 2])


def test_spot_and_profiled_lights_are_counted():
    """Delta lights with a direction-dependent intensity: a spot's cone, and an IES-style
    profile I(θ) = I0 (1 − θ/π) (linear in θ, so its bilinear table is exact)."""
    from spectral_gi.core.scene import Profile

    sp, e = spectra()
    spot = Light("spot", C.LIGHT_SPOT, (0.0, 0.0, H), (0, 0, 0), (0, 0, 0), e, 0.0, intensity=I_CD,
                 direction=(0, 0, -1), spot_angle=math.radians(60))
    lux, se, _ = illuminance(floor_scene([spot], sp), [[0, 0, 0], [0.5, 0, 0], [2, 0, 0]], [[0, 0, 1]] * 3,
                             spp=32, threads=1)
    close(lux, se, [I_CD / H ** 2, I_CD * H / (0.25 + H * H) ** 1.5, 0.0])
    prof = Profile("linear", np.array([0.0, 180.0]), np.array([0.0, 360.0]), np.array([[I_CD, 0.0], [I_CD, 0.0]]))
    lamp = Light("ies", C.LIGHT_POINT, (0.0, 0.0, H), (1, 0, 0), (0, 0, 0), e, 0.0, direction=(0, 0, -1),
                 profile=0, profile_mode="file")
    sc = Scene(spectra=sp, lights=[lamp], profiles=[prof], settings=RenderSettings(seed=9))
    s2 = 1 / math.sqrt(2)
    lux, se, _ = illuminance(sc, [[0, 0, 0], [2, 0, 0], [0, 0, 4]], [[0, 0, 1], [-s2, 0, s2], [0, 0, -1]],
                             spp=32, threads=1)
    close(lux, se, [I_CD / H ** 2, I_CD * 0.75 / 8.0, 0.0])
    assert lux[1] > 0.0


def test_shadow_ray_through_an_absorbing_medium():
    """A slab of absorbing medium (σa = 0.7 /m, 1 m thick, bounded by a null surface)
    between a point light and the point: E = I / d² · exp(−σa · 1 m)."""
    from spectral_gi.core.scene import Medium

    sp, e = spectra()
    sigma = 0.7
    slab = box_mesh("slab", (-5, -5, 0.5), (5, 5, 1.5), 1)
    sc = Scene(meshes=[quad("floor", 50.0, 0.0, 0), slab], spectra=sp,
               materials=[Material("black"), Material("volume", model=C.MAT_NULL, interior=0)],
               media=[Medium("absorber", absorption_density=sigma)],
               lights=[point_light(e, (0.0, 0.0, H), I_CD)], settings=RenderSettings(seed=10))
    lux, se, _ = illuminance(sc, [[0, 0, 0], [0, 0, 1.8]], [[0, 0, 1], [0, 0, 1]], spp=32, threads=1)
    close(lux, se, [I_CD / H ** 2 * math.exp(-sigma), I_CD / 0.2 ** 2])
