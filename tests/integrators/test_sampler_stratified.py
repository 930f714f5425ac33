"""The stratified sampler: Sobol (0, 2) pixel positions with a per-pixel digital shift, and every
other pair of dimensions from its own Owen-scrambled, index-shuffled copy of the sequence."""
import numpy as np
import pytest

from spectral_gi import core
from spectral_gi.core import constants as C
from spectral_gi.core.sampling.rng import (
    mix64, nested_index, owen32, pascal32, rev32, shift_32, sobol_02, sobol_bits, sobol_pair)

# Sobol's first two dimensions, points 0..7 in index order (not Gray-code order): dimension
# 0 is the van der Corput sequence, dimension 1 XORs the direction numbers 1/2, 3/4, 5/8
# of the primitive polynomial x + 1 selected by the bits of the index
SOBOL_D0 = [0.0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875]
SOBOL_D1 = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875]


def test_unshifted_points_are_sobols():
    assert [sobol_02(i, 0, 0) for i in range(8)] == SOBOL_D0
    assert [sobol_02(i, 1, 0) for i in range(8)] == SOBOL_D1


@pytest.mark.parametrize("pseed", [0, 12345, 2**40 + 7])
def test_shifted_points_form_a_0_m_2_net(pseed):
    """Every block of 2^m points has exactly one point in each elementary interval of area 2^-m."""
    m = 8
    s0, s1 = shift_32(pseed, 1), shift_32(pseed, 2)
    assert s0 != s1
    for start in (0, 256):
        pts = np.array([[sobol_02(i, 0, s0), sobol_02(i, 1, s1)] for i in range(start, start + 2 ** m)])
        assert np.all((pts >= 0) & (pts < 1))
        for k in range(m + 1):
            ix = np.floor(pts[:, 0] * 2 ** k).astype(int)
            iy = np.floor(pts[:, 1] * 2 ** (m - k)).astype(int)
            cells = np.unique(ix * 2 ** (m - k) + iy)
            assert cells.size == 2 ** m, (start, k)


def _cornell(sampler, spp, seed):
    sc = core.cornell_box(24, 24, spp=spp, max_depth=2, seed=seed)
    sc.settings.sampler = sampler
    return sc


def test_stratified_is_unbiased_and_less_noisy_at_the_lamps_edge():
    ref, _ = core.render(_cornell(C.SAMPLER_INDEPENDENT, 1024, 9), threads=2)
    r = ref.develop()
    errs = {}
    for sampler in (C.SAMPLER_INDEPENDENT, C.SAMPLER_STRATIFIED):
        film, _ = core.render(_cornell(sampler, 64, 1), threads=2)
        d = film.develop()
        errs[sampler] = np.sqrt(np.mean((d.luminance - r.luminance) ** 2)) / r.luminance.mean()
        # the image mean agrees with the reference within its standard error
        n = d.luminance.size
        se = np.sqrt(d.variance.sum() + r.variance.sum()) / n
        if sampler == C.SAMPLER_INDEPENDENT:
            assert abs(d.luminance.mean() - r.luminance.mean()) < 4 * se
    # stratification cannot be judged by the film's variance estimate (it assumes
    # independent samples); against the reference, the error is clearly lower
    assert errs[C.SAMPLER_STRATIFIED] < 0.8 * errs[C.SAMPLER_INDEPENDENT], errs


def test_thread_count_does_not_change_the_image():
    a, _ = core.render(_cornell(C.SAMPLER_STRATIFIED, 8, 3), threads=1)
    b, _ = core.render(_cornell(C.SAMPLER_STRATIFIED, 8, 3), threads=2)
    assert np.array_equal(a.sums, b.sums)


def test_bit_reversal():
    assert rev32(1) == 2 ** 31 and rev32(2 ** 31) == 1 and rev32(0b1011) == 0b1101 << 28
    x = np.random.default_rng(0).integers(0, 2 ** 32, 200)
    assert all(rev32(rev32(int(v))) == v for v in x)
    # only the low 32 bits count, as a string reversal of them
    y = np.random.default_rng(1).integers(0, 2 ** 63, 500, dtype=np.int64).astype(np.uint64) * np.uint64(3)
    assert all(rev32(v) == int(format(int(v) & 0xFFFFFFFF, "032b")[::-1], 2) for v in y)


def _sobol_second_oracle(i):
    """Sobol's second dimension from its direction numbers: d_0 = 1/2, d_(k+1) = d_k ^ (d_k >> 1)
    (the primitive polynomial x + 1), XORed where the index has a bit."""
    i &= 0xFFFFFFFF
    v, d = 0, 1 << 31
    while i:
        if i & 1:
            v ^= d
        i >>= 1
        d ^= d >> 1
    return v


def test_second_dimension_is_pascals_matrix():
    """The shift-and-mask form (pascal32, reversed) gives the direction numbers' XOR."""
    rng = np.random.default_rng(2)
    idx = [int(v) for v in rng.integers(0, 2 ** 63, 3000, dtype=np.int64)] + list(range(260)) + [2 ** 32 - 1]
    for i in idx:
        assert sobol_bits(np.uint64(i), 1) == _sobol_second_oracle(i), i
        assert pascal32(np.uint64(i)) == rev32(_sobol_second_oracle(i)), i


@pytest.mark.parametrize("h", [1, 2 ** 40 + 3, 0xDEADBEEFCAFEF00D])
def test_index_shuffle_maps_every_power_of_two_block_onto_itself(h):
    """What keeps a time-limited render stratified: the first 2^m samples of every pair are
    the whole first 2^m points, in another order."""
    for m in range(0, 11):
        idx = sorted(int(nested_index(i, np.uint64(h))) for i in range(2 ** m))
        assert idx == list(range(2 ** m)), m
    # and it does shuffle
    assert [int(nested_index(i, np.uint64(h))) for i in range(16)] != list(range(16))


def test_owen_scrambling_is_a_nested_bijection():
    """Owen scrambling maps each elementary interval [k 2^-j, (k+1) 2^-j) onto another one:
    values sharing their first j binary digits still share them after scrambling."""
    rng = np.random.default_rng(1)
    for seed in (0, 77, 2 ** 31 + 5):
        v = rng.integers(0, 2 ** 32, 64, dtype=np.uint64)
        for j in (1, 3, 8):
            w = (v >> np.uint64(32 - j)) << np.uint64(32 - j) | (rng.integers(0, 2 ** (32 - j), 64, dtype=np.uint64))
            a = [int(owen32(int(x), seed)) >> (32 - j) for x in v]
            b = [int(owen32(int(x), seed)) >> (32 - j) for x in w]
            assert a == b
        out = sorted(int(owen32(i << 24, seed)) >> 24 for i in range(256))
        assert out == list(range(256))


@pytest.mark.parametrize("pair", [1, 3, 10])
@pytest.mark.parametrize("pseed", [0, 987654321])
def test_every_pair_is_a_0_m_2_net_from_the_first_sample(pair, pseed):
    m = 7
    pts = np.array([[sobol_pair(i, c, pseed, pair) for c in (0, 1)] for i in range(2 ** m)])
    assert np.all((pts >= 0) & (pts < 1))
    for k in range(m + 1):
        ix = np.floor(pts[:, 0] * 2 ** k).astype(int)
        iy = np.floor(pts[:, 1] * 2 ** (m - k)).astype(int)
        assert np.unique(ix * 2 ** (m - k) + iy).size == 2 ** m, k


def test_pairs_are_uniform_and_uncorrelated_across_pixels():
    """Over many pixel seeds each sample of a pair is uniform, and two pairs of the same
    sample are independent: E[x_a] = 1/2, E[x_a x_b] = 1/4, E[x_a y_a] = 1/4, within 4 sd."""
    n_pix, spp = 4000, 4
    seeds = [np.uint64(mix64(np.uint64(p))) for p in range(n_pix)]
    a = np.array([[sobol_pair(s, 0, ps, 3) for s in range(spp)] for ps in seeds])
    ay = np.array([[sobol_pair(s, 1, ps, 3) for s in range(spp)] for ps in seeds])
    b = np.array([[sobol_pair(s, 0, ps, 4) for s in range(spp)] for ps in seeds])
    n = a.size
    assert abs(a.mean() - 0.5) < 4 * np.sqrt(1 / 12 / n)
    for prod in (a * b, a * ay):
        assert abs(prod.mean() - 0.25) < 4 * prod.std() / np.sqrt(n)
    # a chi-square over 16 bins of the pair (x_a, x_b) for sample 1
    counts, _, _ = np.histogram2d(a[:, 1], b[:, 1], bins=4, range=[[0, 1], [0, 1]])
    chi2 = ((counts - n_pix / 16) ** 2 / (n_pix / 16)).sum()
    assert chi2 < 37.7  # 15 degrees of freedom, p = 0.001


def test_stratified_mean_is_unbiased_over_seeds():
    """The scrambled sampler's image mean, over independent seeds, matches the independent
    sampler's converged mean (the film's variance estimate does not hold for QMC)."""
    ref, _ = core.render(_cornell(C.SAMPLER_INDEPENDENT, 512, 11), threads=2)
    r = ref.develop().luminance.mean()
    means = [core.render(_cornell(C.SAMPLER_STRATIFIED, 16, sd), threads=2)[0].develop().luminance.mean()
             for sd in range(6)]
    se = np.std(means, ddof=1) / np.sqrt(len(means))
    assert abs(np.mean(means) - r) < 4 * np.hypot(se, np.sqrt(ref.develop().variance.sum()) / ref.sums[..., 0].size)


@pytest.mark.slow
def test_pair_draws_equal_two_single_draws():
    """The path kernel's paired draw (light sample, BSDF sample) gives exactly the two values
    of two single draws, for every sampler, aligned or not, across the stratified sampler's
    last Sobol dimension and into its hashed ones."""
    from spectral_gi.core.integrators import path as P
    from spectral_gi.core.sampling.rng import path_key, sobol_pair, sobol_pair_both

    for pair in range(3, 12):
        for i in range(64):
            assert sobol_pair_both(i, 12345, pair) == (sobol_pair(i, 0, 12345, pair), sobol_pair(i, 1, 12345, pair))
    for sampler in (C.SAMPLER_INDEPENDENT, C.SAMPLER_HALTON, C.SAMPLER_HAMMERSLEY, C.SAMPLER_STRATIFIED):
        for index in (0, 1, 5, 37):
            key = np.uint64(path_key(3, 77, index))
            for dim in range(5, 24):
                got = P.rnd2(sampler, key, 991, np.int64(index), np.int64(dim), np.int64(64))
                want = (P.rnd(sampler, key, 991, np.int64(index), np.int64(dim), np.int64(64)),
                        P.rnd(sampler, key, 991, np.int64(index), np.int64(dim + 1), np.int64(64)))
                assert got == want, (sampler, index, dim, got, want)
