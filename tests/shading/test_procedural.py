"""Blender's procedural textures (``core.shading.procedural``): the hashes bit for bit
against a pure-Python lookup3 and PCG, Perlin noise against a corner-sum oracle, and
closed forms and distributions of every texture. The comparison with Cycles' own renders
is ``test_procedural_cycles.py``."""
import math

import numpy as np
import pytest

from chi2 import chi2_interval
from oracles import procedural as O
from spectral_gi.core.shading import procedural as P

RNG = np.random.default_rng(20251202)


def test_lookup3_hashes_match_hashword_with_initval_13():
    words = RNG.integers(0, 2 ** 32, size=(200, 4))
    words[:4] = [[0, 0, 0, 0], [1, 2, 3, 4], [2 ** 32 - 1] * 4, [0x80000000, 7, 0xDEADBEEF, 12345]]
    for a, b, c, d in words.tolist():
        assert P.hash_uint(a) == O.hashword([a], 13)
        assert P.hash_uint2(a, b) == O.hashword([a, b], 13)
        assert P.hash_uint3(a, b, c) == O.hashword([a, b, c], 13)
        assert P.hash_uint4(a, b, c, d) == O.hashword([a, b, c, d], 13)
    # negative ints are their two's complement, as Cycles' int-to-uint conversion
    assert P.hash_uint(-1) == O.hashword([2 ** 32 - 1], 13)
    assert P.hash_uint3(-5, 3, -7) == O.hashword([-5, 3, -7], 13)


def test_known_hash_values():
    # lookup3 words, and White Noise at integer points as Cycles 5.0 renders it (these points lie
    # on the grid of test_procedural_cycles' white-noise cases, which match Cycles bit for bit)
    assert (P.hash_uint(0), P.hash_uint2(1, 2), P.hash_uint3(1, 2, 3), P.hash_uint4(1, 2, 3, 4)) == \
        (2501500005, 272092061, 3100736010, 92593857)
    assert P.white_noise_texture(1.0, 2.0, 2.0, 0.0, 3) == \
        (0.7316466569900513, 0.7316466569900513, 0.9990622997283936, 0.8975786566734314)
    assert P.white_noise_texture(-4.0, 7.0, 0.0, 0.0, 2) == \
        (0.14437919855117798, 0.14437919855117798, 0.12836939096450806, 0.17659448087215424)


def test_hashword_of_no_words_is_its_seed():
    # lookup3: with no words left there is no final mixing, c = 0xdeadbeef + initval
    assert O.hashword([], 13) == 0xDEADBEEF + 13


def test_float_hashes_use_the_single_precision_bits():
    pts = RNG.normal(0.0, 50.0, size=(200, 4))
    pts[0] = [0.1, 1.0 / 3.0, -2.5, 1e7]
    for x, y, z, w in pts.tolist():
        assert P.hash_float_to_float(x) == O.hash_floats(x)
        assert P.hash_float2_to_float(x, y) == O.hash_floats(x, y)
        assert P.hash_float3_to_float(x, y, z) == O.hash_floats(x, y, z)
        assert P.hash_float4_to_float(x, y, z, w) == O.hash_floats(x, y, z, w)
    # 0.1 and its float32 neighbour hash apart; the double 0.1 hashes as float32(0.1)
    assert P.hash_float_to_float(0.1) == P.hash_float_to_float(float(np.float32(0.1)))
    assert P.hash_float_to_float(0.1) != P.hash_float_to_float(float(np.nextafter(np.float32(0.1), np.float32(1.0))))
    assert P.hash_float_to_float(0.0) != P.hash_float_to_float(-0.0)


def test_voronoi_cell_hashes_are_pcg_of_the_integer_cell():
    cells = RNG.integers(-10 ** 6, 10 ** 6, size=(200, 4))
    for a, b, c, d in cells.tolist():
        h2, h3, h4 = O.pcg(a, b), O.pcg(a, b, c), O.pcg(a, b, c, d)
        assert P.hash_int_to_point(a, b, c, d, 2)[:2] == tuple(O.f32(float(h)) * 2.0 ** -31 for h in h2)
        assert P.hash_int_to_point(a, b, c, d, 3)[:3] == tuple(O.f32(float(h)) * 2.0 ** -31 for h in h3)
        assert P.hash_int_to_point(a, b, c, d, 4) == tuple(O.f32(float(h)) * 2.0 ** -31 for h in h4)
        assert P.hash_int_to_color(a, b, c, d, 2) == tuple(O.f32(float(h)) * 2.0 ** -31 for h in O.pcg(a, b, 0))
        assert P.hash_int_to_point(a, b, c, d, 1)[0] == O.hash_floats(a)


@pytest.mark.parametrize("dims", [1, 2, 3, 4])
def test_perlin_noise_matches_the_corner_sum_oracle(dims):
    pts = np.concatenate([RNG.uniform(-20, 20, size=(100, 4)), RNG.uniform(-3e6, 3e6, size=(20, 4)),
                          RNG.uniform(99990, 100010, size=(20, 4))])
    for p in pts.tolist():
        ours = P.perlin_signed(*p, dims)
        assert ours == pytest.approx(O.snoise(*p[:dims]), abs=1e-12)


@pytest.mark.parametrize("dims", [1, 2, 3, 4])
def test_perlin_noise_vanishes_on_the_lattice_and_stays_in_range(dims):
    cells = RNG.integers(-1000, 1000, size=(50, 4)).astype(float)
    assert all(P.perlin_signed(*c, dims) == 0.0 for c in cells.tolist())
    vals = np.array([P.perlin_signed(*p, dims) for p in RNG.uniform(-50, 50, size=(4000, 4)).tolist()])
    assert np.abs(vals).max() <= 1.05 and np.abs(vals).max() > 0.5
    assert abs(vals.mean()) < 0.03


def test_noise_far_away_repeats_with_the_half_cell_shift():
    # Cycles wraps each axis every 100000 and shifts coordinates of magnitude 1e6 and more by
    # half a cell: far from the origin the noise is that of the wrapped, shifted point
    for x, y in RNG.uniform(1e6, 4e6, size=(20, 2)).tolist():
        xf, yf = float(np.float32(x)), float(np.float32(y))
        near = (math.fmod(xf, 100000.0) + 0.5, math.fmod(yf, 100000.0) + 0.5)
        assert P.perlin_signed(x, y, 0.0, 0.0, 2) == P.perlin_signed(*near, 0.0, 0.0, 2)


@pytest.mark.statistical
@pytest.mark.parametrize("dims", [1, 2, 3, 4])
def test_white_noise_is_uniform(dims, alpha):
    pts = RNG.uniform(-100, 100, size=(20000, 4)).tolist()
    out = np.array([P.white_noise_texture(*p, dims) for p in pts])
    assert out.min() >= 0.0 and out.max() <= 1.0
    for ch in range(4):
        res = chi2_interval(out[:, ch], lambda x: np.ones_like(x), alpha, f"white-{dims}d-{ch}", bins=40)
        assert res.passed, res.message
    assert abs(np.corrcoef(out[:, 1], out[:, 2])[0, 1]) < 0.05


def test_normalized_fbm_is_centred_in_the_unit_interval():
    vals = np.array([P.noise_texture(*p, 3, P.NOISE_FBM, 1.0, 4.0, 0.5, 2.0, 0.0, 1.0, 0.0, 1, 0)[0]
                     for p in RNG.uniform(-50, 50, size=(3000, 4)).tolist()])
    assert vals.min() >= 0.0 and vals.max() <= 1.0
    assert abs(vals.mean() - 0.5) < 0.02
    # detail 0 is one octave: fBM = (snoise + 1) / 2
    for p in RNG.uniform(-5, 5, size=(20, 4)).tolist():
        f = P.noise_texture(*p, 3, P.NOISE_FBM, 2.0, 0.0, 0.5, 2.0, 0.0, 1.0, 0.0, 1, 0)[0]
        assert f == pytest.approx(0.5 * P.perlin_signed(2 * p[0], 2 * p[1], 2 * p[2], 0.0, 3) + 0.5, abs=1e-6)


def test_voronoi_with_zero_randomness_is_the_integer_lattice():
    # every feature point sits on its cell's corner, so the cells are unit squares/cubes about
    # the integer points: F1 is the distance to the nearest one, F2 to the second nearest,
    # the edge distance is 0.5 minus the largest axis offset, the n-sphere radius is 0.5
    for p in RNG.uniform(-20, 20, size=(100, 3)).astype(np.float32).astype(float).tolist():
        f = np.array(p) - np.round(p)
        f1 = P.voronoi_texture(*p, 0.0, 3, P.VORONOI_F1, P.VORONOI_EUCLIDEAN, 1.0, 0.0, 0.5, 2.0, 1.0, 1.0, 0.0, 0)
        assert f1[0] == pytest.approx(np.linalg.norm(f), abs=1e-9)
        assert f1[4:7] == pytest.approx(tuple(np.round(p)), abs=1e-9)
        f2 = P.voronoi_texture(*p, 0.0, 3, P.VORONOI_F2, P.VORONOI_MANHATTAN, 1.0, 0.0, 0.5, 2.0, 1.0, 1.0, 0.0, 0)
        a = np.sort(np.abs(f))
        assert f2[0] == pytest.approx(a[0] + a[1] + 1.0 - a[2], abs=1e-9)
        edge = P.voronoi_texture(p[0], p[1], 0.0, 0.0, 2, P.VORONOI_DISTANCE_TO_EDGE, 0, 1.0, 0.0, 0.5, 2.0,
                                 1.0, 1.0, 0.0, 0)
        assert edge[0] == pytest.approx(0.5 - np.abs(f[:2]).max(), abs=1e-9)
        rad = P.voronoi_texture(*p, 0.0, 3, P.VORONOI_N_SPHERE_RADIUS, 0, 1.0, 0.0, 0.5, 2.0, 1.0, 1.0, 0.0, 0)
        assert rad[8] == pytest.approx(0.5, abs=1e-12)


def test_smooth_f1_lies_below_f1_and_tends_to_it():
    for p in RNG.uniform(-20, 20, size=(100, 3)).tolist():
        f1 = P.voronoi_texture(*p, 0.0, 3, P.VORONOI_F1, 0, 1.0, 0.0, 0.5, 2.0, 1.0, 1.0, 1.0, 0)[0]
        smooth = P.voronoi_texture(*p, 0.0, 3, P.VORONOI_SMOOTH_F1, 0, 1.0, 0.0, 0.5, 2.0, 1.0, 1.0, 1.0, 0)[0]
        sharp = P.voronoi_texture(*p, 0.0, 3, P.VORONOI_SMOOTH_F1, 0, 1.0, 0.0, 0.5, 2.0, 1e-4, 1.0, 1.0, 0)[0]
        assert smooth <= f1 + 1e-12
        assert sharp == pytest.approx(f1, abs=1e-3)


def test_checker_alternates_per_unit_cell():
    for p in RNG.uniform(-10, 10, size=(200, 3)).tolist():
        cell = [math.floor(v * 3.0) for v in p]
        if min(abs(v * 3.0 - round(v * 3.0)) for v in p) < 1e-4:
            continue
        parity = (abs(cell[0]) % 2 == abs(cell[1]) % 2) == (abs(cell[2]) % 2 == 1)
        r, g, b, fac = P.checker_texture(*p, 3.0, 1.0, 0.5, 0.25, 0.0, 0.1, 0.2)
        assert fac == (1.0 if parity else 0.0)
        assert (r, g, b) == ((1.0, 0.5, 0.25) if parity else (0.0, 0.1, 0.2))


@pytest.mark.parametrize("name,closed", [
    ("LINEAR", lambda x, y, z: x),
    ("QUADRATIC", lambda x, y, z: max(x, 0.0) ** 2),
    ("EASING", lambda x, y, z: 3 * min(max(x, 0), 1) ** 2 - 2 * min(max(x, 0), 1) ** 3),
    ("DIAGONAL", lambda x, y, z: (x + y) / 2),
    ("RADIAL", lambda x, y, z: math.atan2(y, x) / (2 * math.pi) + 0.5),
    ("QUADRATIC_SPHERE", lambda x, y, z: max(0.999999 - math.sqrt(x * x + y * y + z * z), 0.0) ** 2),
    ("SPHERICAL", lambda x, y, z: max(0.999999 - math.sqrt(x * x + y * y + z * z), 0.0)),
])
def test_gradient_closed_forms(name, closed):
    for p in RNG.uniform(-1.5, 1.5, size=(200, 3)).tolist():
        expect = min(max(closed(*p), 0.0), 1.0)
        assert P.gradient_texture(*p, P.GRADIENT_TYPES[name]) == pytest.approx(expect, abs=1e-6)


def test_brick_mortar_rows_and_offsets():
    # bricks 0.5 x 0.25, mortar 0.02; rows 0, 2, ... (row % offset frequency 2 == 0) shifted by
    # half a brick, so their joints are at x = 0.25 + k/2 and those of rows 1, 3, ... at x = k/2
    args = (1.0, 0.02, 0.0, 0.0, 0.5, 0.25, 0.5, 2, 1.0, 1)
    assert P.brick_texture(0.5, 0.125, 0.0, *args)[1] == 0.0  # the middle of a brick of row 0
    assert P.brick_texture(0.5, 0.01, 0.0, *args)[1] == 1.0  # in the mortar between rows -1 and 0
    assert P.brick_texture(0.26, 0.125, 0.0, *args)[1] == 1.0  # the joint at x = 0.25 in row 0 ...
    assert P.brick_texture(0.26, 0.375, 0.0, *args)[1] == 0.0  # ... is mid-brick in row 1
    assert P.brick_texture(0.49, 0.375, 0.0, *args)[1] == 1.0  # whose joint is at x = 0.5
    tints = [P.brick_texture(x, y, 0.0, *args)[0] for x, y in RNG.uniform(-20, 20, size=(500, 2)).tolist()]
    assert min(tints) >= 0.0 and max(tints) <= 1.0 and np.std(tints) > 0.1
    # within one brick the tint is one value
    assert P.brick_texture(0.35, 0.1, 0.0, *args)[0] == P.brick_texture(0.65, 0.2, 0.0, *args)[0]
    r, g, b = P.brick_color(0.25, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.5)
    assert (r, g, b) == (0.75, 0.75, 0.75)
    assert P.brick_color(0.25, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.5, 0.4, 0.3) == (0.5, 0.4, 0.3)


def test_wave_profiles_closed_forms():
    # bands along x, no distortion: n = 20 x (x scaled by Scale, nudged by Cycles' 1e-6) + phase
    for x in RNG.uniform(-2, 2, size=50).tolist():
        xs = float(np.float32(np.float32(np.float32(x * 2.0) + np.float32(1e-6)) * np.float32(0.999999)))
        n = xs * 20.0 + 0.3
        sin = P.wave_texture(x, 0.0, 0.0, 0, 0, 0, 0, 2.0, 0.0, 2.0, 1.0, 0.5, 0.3)
        saw = P.wave_texture(x, 0.0, 0.0, 0, 0, 0, 1, 2.0, 0.0, 2.0, 1.0, 0.5, 0.3)
        tri = P.wave_texture(x, 0.0, 0.0, 0, 0, 0, 2, 2.0, 0.0, 2.0, 1.0, 0.5, 0.3)
        t = n / (2 * math.pi)
        assert sin == pytest.approx(0.5 - 0.5 * math.cos(n), abs=1e-6)
        assert saw == pytest.approx(t - math.floor(t), abs=1e-6)
        assert tri == pytest.approx(2 * abs(t - math.floor(t + 0.5)), abs=1e-6)


def test_magic_depth_0_closed_form():
    for x, y, z in RNG.uniform(-3, 3, size=(50, 3)).tolist():
        r, g, b, fac = P.magic_texture(x, y, z, 0, 1.5, 1.0)
        px, py, pz = (math.fmod(v, 2 * math.pi) for v in (x, y, z))
        assert r == pytest.approx(0.5 - math.sin((px + py + pz) * 7.5) / 2, abs=1e-5)
        assert g == pytest.approx(0.5 - math.cos((-px + py - pz) * 7.5) / 2, abs=1e-5)
        assert b == pytest.approx(0.5 + math.cos((-px - py + pz) * 7.5) / 2, abs=1e-5)
        assert fac == pytest.approx((r + g + b) / 3, abs=1e-12)
