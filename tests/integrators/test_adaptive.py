"""Adaptive sampling under a noise target: per-pixel allocation as Cycles' (core/integrators/render.py
``adaptive_mask``): converged pixels stop, noisy ones go on, the film counts each pixel's samples,
and the image does not depend on the thread count."""
import numpy as np
import pytest

from spectral_gi.core.film import CHUNK_SPP, Film
from spectral_gi.core.integrators import render as R
from spectral_gi.core.scene.builtin import cornell_box


def _cornell(target, spp=256, size=24, seed=5):
    sc = cornell_box(size, size, spp=spp, max_depth=4, seed=seed)
    sc.settings.noise_target = target
    return sc


def test_the_mask_keeps_noisy_pixels_and_their_neighbours():
    """A pixel above the target stays, with its eight neighbours; a pixel within it whose
    neighbours are all within it stops; a pixel that stopped before stays stopped."""
    f = Film(7, 5)
    n = 64
    y = np.ones((5, 7))
    sd = np.full((5, 7), 0.01 * np.sqrt(n))  # relative standard error 0.01
    sd[2, 3] = 0.5 * np.sqrt(n)  # 0.5
    f.sums[..., 1] = n * y
    f.sums[..., 3] = n
    f.sums[..., 4] = n * (y ** 2 + sd ** 2 * (n - 1) / n)
    m = R.adaptive_mask(f, 0.05)
    expect = np.zeros((5, 7), np.uint8)
    expect[1:4, 2:5] = 1
    np.testing.assert_array_equal(m, expect)
    prev = np.ones((5, 7), np.uint8)
    prev[2, 3] = 0  # stopped at an earlier check: not judged again
    assert not R.adaptive_mask(f, 0.05, prev).any()
    assert R.adaptive_check_at(f, 0.05) == 48  # Cycles' minimum 40, on the next multiple of 16
    f.spp = 48
    assert R.adaptive_check_at(f, 0.05) == 64 and R.ADAPTIVE_STEP == CHUNK_SPP


@pytest.mark.slow
def test_converged_pixels_stop_and_noisy_ones_go_on():
    """In the Cornell box at a 5 % target: every pixel that stopped early is within the target
    (its last samples were judged), the pixels still above it took every sample, some stopped and
    some went on; the film's per-pixel counts add up with the skipped samples."""
    target = 0.05
    sc = _cornell(target)
    film, stats = R.render(sc, threads=2)
    n = film.sums[..., 3]
    err = R.pixel_relative_errors(film)
    first = R.adaptive_check_at(Film(1, 1), target)
    assert n.min() >= first and n.max() == stats.spp > n.min()
    assert (n % R.ADAPTIVE_STEP == 0).all()  # a pixel stops only where the mask is judged
    stopped = n < stats.spp
    assert stopped.any() and (~stopped).any()
    assert (err[stopped] <= target).all()
    assert (n[err > target] == stats.spp).all()
    total = stats.spp * film.width * film.height
    assert stats.skipped_samples == film.skipped_samples == total - int(n.sum()) > 0
    assert film.dropped_samples() == 0
    # the skipped samples survive a checkpoint
    assert film.skipped_samples == film.copy().skipped_samples


@pytest.mark.slow
def test_the_adaptive_image_does_not_depend_on_the_thread_count():
    sc = _cornell(0.05, spp=128, size=20)
    a, sa = R.render(sc, threads=1)
    b, sb = R.render(sc, threads=2)
    assert sa.spp == sb.spp and sa.skipped_samples == sb.skipped_samples > 0
    assert np.array_equal(a.sums, b.sums) and np.array_equal(a.aov, b.aov)


@pytest.mark.slow
@pytest.mark.statistical
def test_the_adaptive_image_agrees_with_a_fixed_sample_reference():
    """The adaptive image's mean luminance against a render of every pixel at 512 spp (another
    seed): within four standard errors of their difference, each from its pixels' variances."""
    ad, st = R.render(_cornell(0.05, spp=512, seed=5), threads=2)
    assert st.skipped_samples > 0
    ref, _ = R.render(_cornell(0.0, spp=512, seed=9), threads=2)

    def mean_and_se(film):
        d = film.develop()
        n = film.sums[..., 3]
        return float(d.luminance.mean()), float(np.sqrt(d.variance.sum()) / n.size), n

    ma, sa, _ = mean_and_se(ad)
    mb, sb, _ = mean_and_se(ref)
    assert abs(ma - mb) < 4.0 * np.hypot(sa, sb), (ma, mb, sa, sb)


@pytest.mark.slow
def test_whole_image_stopping_is_still_available():
    """adaptive=False stops the whole image once 95 % of its pixels are within the target; the
    adaptive render of the same scene takes fewer samples in all (some pixels never get within
    the target: those go on to the sample count)."""
    sc = _cornell(0.1, spp=2048, size=16)
    film, stats = R.render(sc, threads=2, adaptive=False)
    assert stats.skipped_samples == 0 and (film.sums[..., 3] == stats.spp).all()
    assert stats.stop_reason == "noise_target" and stats.relative_error <= 0.1 and stats.spp < 2048
    ad, sa = R.render(sc, threads=2)
    assert float(ad.sums[..., 3].sum()) < float(film.sums[..., 3].sum())
