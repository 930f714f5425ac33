"""Estimator statistics (compendium items 11–15, 24–26, 29), in NumPy.

For N independent samples Y_i of an estimator (each an unbiased estimate of I):
mean Ȳ, sample variance s² = Σ (Y_i - Ȳ)² / (N - 1) (the unbiased σ² of item 15),
standard error s / sqrt(N), and efficiency ε = 1 / (T σ²) (item 29) where T is the
time for one sample and σ² the variance of one sample; equivalently 1 / (T_total σ̂²)
with T_total the time of the whole N-sample estimate and σ̂² = σ²/N its variance.
"""
from dataclasses import dataclass
import math

import numpy as np


@dataclass(frozen=True)
class EstimatorStats:
    n: int
    mean: float
    variance: float  # of one sample (unbiased, ddof = 1)
    std_error: float  # of the mean
    time_per_sample: float  # seconds (nan if unknown)
    efficiency: float  # 1 / (T σ²) (nan if the time is unknown, inf for zero variance)

    @property
    def relative_error(self):
        return self.std_error / abs(self.mean) if self.mean != 0 else math.inf


def estimator_stats(samples, seconds=None):
    """Statistics of the samples Y_i (any shape, flattened); ``seconds`` is the total time
    taken to produce them (for the efficiency)."""
    y = np.asarray(samples, dtype=np.float64).ravel()
    n = y.size
    if n == 0:
        raise ValueError("no samples")
    mean = float(np.mean(y))
    var = float(np.var(y, ddof=1)) if n > 1 else math.nan
    se = math.sqrt(var / n) if n > 1 else math.nan
    t = math.nan if seconds is None else float(seconds) / n
    return EstimatorStats(n, mean, var, se, t, efficiency(var, t))


def efficiency(variance, seconds):
    """ε = 1 / (T σ²) (item 29)."""
    if seconds is None or not np.isfinite(seconds) or not np.isfinite(variance):
        return math.nan
    d = seconds * variance
    return math.inf if d == 0 else 1.0 / d


def running_mean_variance(samples, axis=0):
    """Welford's one-pass mean and unbiased variance along ``axis`` (stable for large means)."""
    y = np.moveaxis(np.asarray(samples, dtype=np.float64), axis, 0)
    mean = np.zeros(y.shape[1:])
    m2 = np.zeros(y.shape[1:])
    for k, v in enumerate(y, start=1):
        d = v - mean
        mean = mean + d / k
        m2 = m2 + d * (v - mean)
    n = y.shape[0]
    return mean, (m2 / (n - 1) if n > 1 else np.full_like(mean, np.nan))


def variance_of_estimates(estimates):
    """Mean, variance and standard error of R independent estimates (e.g. one per seed)."""
    s = estimator_stats(estimates)
    return s.mean, s.variance, s.std_error
