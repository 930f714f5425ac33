"""The stratified sampler: Sobol (0, 2) pixel positions with a per-pixel digital shift."""
import numpy as np
import pytest

from spectral_gi import core
from spectral_gi.core import constants as C
from spectral_gi.core.kernels.rng import shift_32, sobol_02

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
