"""Quasi-Monte Carlo points (compendium item 30) and their randomisations."""
import math

import numpy as np
import pytest
from chi2 import chi2_interval, seed_for, ztest

from spectral_gi.core import sampling
from oracles import sampling as O
from spectral_gi.core.sampling import qmc
from spectral_gi.core.sampling.batch import qmc_points
from spectral_gi.core.sampling.tags import (
    RANDOMIZE_CP, RANDOMIZE_NONE, RANDOMIZE_OWEN, SAMPLER_HALTON, SAMPLER_HAMMERSLEY, SAMPLER_INDEPENDENT)

RANDOMIZED = [(SAMPLER_HALTON, RANDOMIZE_OWEN), (SAMPLER_HALTON, RANDOMIZE_CP),
              (SAMPLER_HAMMERSLEY, RANDOMIZE_OWEN), (SAMPLER_HAMMERSLEY, RANDOMIZE_CP)]
RANDOMIZED_IDS = ["halton-owen", "halton-cp", "hammersley-owen", "hammersley-cp"]


def test_sampler_tags():
    assert (sampling.SAMPLER_INDEPENDENT, sampling.SAMPLER_HALTON, sampling.SAMPLER_HAMMERSLEY) == (0, 1, 2)
    assert len(qmc.PRIMES) >= 64 and list(qmc.PRIMES[:8]) == [2, 3, 5, 7, 11, 13, 17, 19]
    assert list(qmc.PRIMES) == O.first_primes(len(qmc.PRIMES))


@pytest.mark.slow
def test_exact_low_index_values():
    vdc = qmc_points(8, 1, SAMPLER_HALTON, RANDOMIZE_NONE)[:, 0]
    assert list(vdc) == [0.0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875]
    h3 = qmc_points(9, 2, SAMPLER_HALTON, RANDOMIZE_NONE)[:, 1]
    # correctly rounded: exactly the nearest doubles to k/9
    assert list(h3) == [0, 1 / 3, 2 / 3, 1 / 9, 4 / 9, 7 / 9, 2 / 9, 5 / 9, 8 / 9]
    h5 = qmc_points(6, 3, SAMPLER_HALTON, RANDOMIZE_NONE)[:, 2]
    assert list(h5) == [0, 0.2, 0.4, 0.6, 0.8, 0.04]
    ham = qmc_points(4, 3, SAMPLER_HAMMERSLEY, RANDOMIZE_NONE, n_total=4)
    np.testing.assert_array_equal(ham[:, 0], [0.0, 0.25, 0.5, 0.75])
    np.testing.assert_array_equal(ham[:, 1], [0.0, 0.5, 0.25, 0.75])
    assert list(ham[:, 2]) == [0, 1 / 3, 2 / 3, 1 / 9]


def test_halton_and_hammersley_against_exact_arithmetic():
    dims = 70
    got = qmc_points(300, dims, SAMPLER_HALTON, RANDOMIZE_NONE)
    np.testing.assert_array_equal(got, O.halton_exact(300, dims))  # float(Fraction) rounds correctly
    got = qmc_points(128, 9, SAMPLER_HAMMERSLEY, RANDOMIZE_NONE)
    np.testing.assert_array_equal(got, O.hammersley_exact(128, 9))
    # large indices: digit by digit in exact arithmetic
    start = 2 ** 40 + 12345
    got = qmc_points(4, 5, SAMPLER_HALTON, RANDOMIZE_NONE, start=start)
    ref = [[float(O.radical_inverse_exact(p, i)) for p in (2, 3, 5, 7, 11)] for i in range(start, start + 4)]
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-15)


def test_radical_inverse_any_base():
    for b in (2, 3, 4, 10, 16, 97, 1619):
        for i in (0, 1, 5, 12345, 10 ** 9 + 7):
            assert abs(qmc.radical_inverse(b, i) - float(O.radical_inverse_exact(b, i))) < 1e-15, (b, i)
    assert qmc.van_der_corput(6) == 0.375
    assert qmc.radical_inverse(1, 5) == 0.0  # not a base: no endless loop


@pytest.mark.parametrize("n", [256, 1024])
def test_discrepancy_lower_than_random(n):
    """L2 star discrepancy (Warnock's formula) of 2D Halton and Hammersley points, plain and
    scrambled, is below the mean of 8 independent random sets, and the exact star
    discrepancy of the plain sets is below the random sets' too."""
    rng = np.random.default_rng(seed_for(f"disc{n}"))
    rand_l2 = np.mean([O.l2_star_discrepancy(rng.random((n, 2))) for _ in range(8)])
    rand_star = np.mean([O.star_discrepancy_2d(rng.random((n, 2))) for _ in range(3)])
    sets = {
        "halton": qmc_points(n, 2, SAMPLER_HALTON, RANDOMIZE_NONE),
        "hammersley": qmc_points(n, 2, SAMPLER_HAMMERSLEY, RANDOMIZE_NONE),
        "halton-owen": qmc_points(n, 2, SAMPLER_HALTON, RANDOMIZE_OWEN, seed=3),
        "hammersley-owen": qmc_points(n, 2, SAMPLER_HAMMERSLEY, RANDOMIZE_OWEN, seed=3),
        "independent": qmc_points(n, 2, SAMPLER_INDEPENDENT, RANDOMIZE_NONE, seed=3),
    }
    l2 = {k: O.l2_star_discrepancy(v) for k, v in sets.items()}
    for k in ("halton", "hammersley", "halton-owen", "hammersley-owen"):
        assert l2[k] < 0.5 * rand_l2, (k, l2[k], rand_l2)
    assert l2["independent"] > 0.3 * rand_l2  # the pseudo-random reference is not a QMC set
    for k in ("halton", "hammersley"):
        assert O.star_discrepancy_2d(sets[k]) < 0.5 * rand_star


def test_warnock_formula_against_brute_force():
    pts = np.random.default_rng(1).random((40, 2))
    # the L2 star discrepancy as ∫ (count(box)/N - vol(box))² over the anchors, by a grid
    g = (np.arange(400) + 0.5) / 400
    X, Y = np.meshgrid(g, g)
    cnt = ((pts[:, 0][None, None] < X[..., None]) & (pts[:, 1][None, None] < Y[..., None])).mean(-1)
    brute = math.sqrt(((cnt - X * Y) ** 2).mean())
    assert abs(O.l2_star_discrepancy(pts) - brute) < 2e-3


@pytest.mark.statistical
@pytest.mark.parametrize("sampler,rand", RANDOMIZED, ids=RANDOMIZED_IDS)
def test_randomized_estimates_are_unbiased(sampler, rand, alpha):
    """The mean over 64 seeds of a randomised estimate of ∫ e^x (1 + sin 2πy) cos(z/2) w² over
    [0,1)^4 is within the z-test's reach of the exact value ((e-1) · 1 · 2 sin ½ · 1/3)."""
    exact = (math.e - 1.0) * 1.0 * 2.0 * math.sin(0.5) / 3.0
    n = 128
    est = []
    for s in range(64):
        x = qmc_points(n, 4, sampler, rand, seed=1000 + s)
        f = np.exp(x[:, 0]) * (1 + np.sin(2 * np.pi * x[:, 1])) * np.cos(x[:, 2] / 2) * x[:, 3] ** 2
        est.append(f.mean())
    est = np.array(est)
    se = est.std(ddof=1) / math.sqrt(len(est))
    assert se > 0
    res = ztest(est.mean(), se, exact, alpha, f"{sampler}-{rand}")
    assert res.passed, res.message
    assert abs(est.mean() - exact) < 4 * se


@pytest.mark.statistical
def test_scrambling_is_uniform_over_seeds(alpha):
    """For a fixed index and dimension, the scrambled value is uniform over seeds."""
    vals = np.concatenate([qmc_points(1, 3, SAMPLER_HALTON, RANDOMIZE_OWEN, seed=s, start=5)[0]
                           for s in range(4000)])
    res = chi2_interval(vals, lambda x: np.ones_like(x), alpha, "owen-seeds", bins=40)
    assert res.passed, res.message


@pytest.mark.parametrize("sampler,rand", RANDOMIZED + [(SAMPLER_INDEPENDENT, RANDOMIZE_NONE)],
                         ids=RANDOMIZED_IDS + ["independent"])
def test_points_stay_in_unit_interval(sampler, rand):
    for seed in (0, 1, 2 ** 52 + 1):
        x = qmc_points(2048, 300, sampler, rand, seed=seed, start=2 ** 33 - 1000, n_total=2 ** 34)
        assert np.all(x >= 0.0) and np.all(x < 1.0)
    x = qmc_points(64, 3, sampler, rand, seed=5, n_total=64)
    assert np.all(x >= 0.0) and np.all(x < 1.0)


def test_scrambling_keeps_stratification():
    """Owen scrambling keeps elementary intervals: the first b^k points of a base-b
    dimension fall one per interval [j b^-k, (j+1) b^-k)."""
    for seed in (1, 77, 123456789):
        x = qmc_points(3 ** 7, 3, SAMPLER_HALTON, RANDOMIZE_OWEN, seed=seed)
        for k in range(1, 12):
            cells = np.floor(x[:2 ** k, 0] * 2 ** k).astype(int)
            assert np.array_equal(np.sort(cells), np.arange(2 ** k)), (seed, k)
        for k in range(1, 8):
            cells = np.floor(x[:3 ** k, 1] * 3 ** k).astype(int)
            assert np.array_equal(np.sort(cells), np.arange(3 ** k)), (seed, k)
        for k in range(1, 5):
            cells = np.floor(x[:5 ** k, 2] * 5 ** k).astype(int)
            assert np.array_equal(np.sort(cells), np.arange(5 ** k)), (seed, k)
        # and the scrambled values differ from the plain ones
        plain = qmc_points(64, 3, SAMPLER_HALTON, RANDOMIZE_NONE)
        assert np.mean(np.abs(x[:64] - plain) > 1e-9) > 0.9


@pytest.mark.parametrize("m", [4, 7, 10])
def test_scrambled_hammersley_is_a_net(m):
    """Owen-scrambled 2D Hammersley with n = 2^m is a (0, m, 2)-net in base 2: every
    elementary interval of area 2^-m holds exactly one point."""
    n = 2 ** m
    for seed in (3, 4):
        x = qmc_points(n, 2, SAMPLER_HAMMERSLEY, RANDOMIZE_OWEN, seed=seed, n_total=n)
        for a in range(m + 1):
            ix = np.floor(x[:, 0] * 2 ** a).astype(int)
            iy = np.floor(x[:, 1] * 2 ** (m - a)).astype(int)
            assert len(np.unique(ix * 2 ** (m - a) + iy)) == n, (m, a, seed)


def test_deterministic_and_seed_dependent():
    a = qmc_points(100, 10, SAMPLER_HALTON, RANDOMIZE_OWEN, seed=9)
    b = qmc_points(100, 10, SAMPLER_HALTON, RANDOMIZE_OWEN, seed=9)
    c = qmc_points(100, 10, SAMPLER_HALTON, RANDOMIZE_OWEN, seed=10)
    np.testing.assert_array_equal(a, b)
    assert np.mean(a != c) > 0.99
    # a point is a function of its index alone: computing a sub-range gives the same values
    np.testing.assert_array_equal(qmc_points(10, 10, SAMPLER_HALTON, RANDOMIZE_OWEN, seed=9, start=50), a[50:60])
    # Cranley–Patterson: the same shift for every point of a dimension
    plain = qmc_points(50, 4, SAMPLER_HALTON, RANDOMIZE_NONE)
    cp = qmc_points(50, 4, SAMPLER_HALTON, RANDOMIZE_CP, seed=4)
    shift = np.mod(cp - plain, 1.0)
    np.testing.assert_allclose(shift, np.broadcast_to(shift[0], shift.shape), atol=1e-12)


@pytest.mark.statistical
def test_independent_sampler_is_uniform(alpha):
    x = qmc_points(200_000, 2, SAMPLER_INDEPENDENT, RANDOMIZE_NONE, seed=seed_for("indep"))
    for d in range(2):
        res = chi2_interval(x[:, d], lambda t: np.ones_like(t), alpha, f"independent-{d}", bins=100)
        assert res.passed, res.message
    assert abs(np.corrcoef(x[:, 0], x[:, 1])[0, 1]) < 0.02


def test_pixel_seeds_decorrelate():
    s = [int(qmc.pixel_seed(7, p)) for p in range(1000)]
    assert len(set(s)) == 1000
