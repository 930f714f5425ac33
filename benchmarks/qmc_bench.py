"""Independent vs randomised quasi-Monte Carlo samples on a smooth rendering integral.

    python benchmarks/qmc_bench.py [--reps 200]

The integrand is the irradiance of a surface under a smooth sky (compendium items
24–25, 30): E = ∫ L(ω) cos θ dω with L(ω) = 1 + 0.5 ω_x + 3 exp(8 (ω·s - 1)), a soft sun
s at 40° elevation. Each estimate draws N points of a 2D sequence, maps them through the
cosine-weighted hemisphere warp (item 20) and averages π L(ω_i). For every N = 16 ...
4096 and every sampler (the counter-based independent sampler; Halton and Hammersley,
Owen-scrambled and Cranley–Patterson rotated), it repeats the estimate with ``reps``
seeds and prints

* the variance of one N-sample estimate and its ratio to the independent sampler's,
* the mean time of one estimate T (points + warp + integrand, this machine),
* the efficiency 1/(T σ²) (item 29) and its ratio to the independent sampler's,
* the bias |mean - E| in standard errors (every randomised sampler is unbiased).

No thresholds: the figures are for reading. The exact E comes from adaptive quadrature.
"""
import argparse
import math
import time

import results  # benchmarks/results.py: the JSON record of this run

import numpy as np
from scipy import integrate

from spectral_gi.core.sampling import batch, stats
from spectral_gi.core.sampling.tags import (
    RANDOMIZE_CP, RANDOMIZE_NONE, RANDOMIZE_OWEN, SAMPLER_HALTON, SAMPLER_HAMMERSLEY, SAMPLER_INDEPENDENT,
    WARP_COSINE_HEMISPHERE)

SUN = np.array([math.cos(math.radians(40.0)) * math.cos(0.3), math.cos(math.radians(40.0)) * math.sin(0.3),
                math.sin(math.radians(40.0))])
NS = (16, 64, 256, 1024, 4096)
SAMPLERS = (
    ("independent", SAMPLER_INDEPENDENT, RANDOMIZE_NONE),
    ("Halton, Owen", SAMPLER_HALTON, RANDOMIZE_OWEN),
    ("Halton, CP rotation", SAMPLER_HALTON, RANDOMIZE_CP),
    ("Hammersley, Owen", SAMPLER_HAMMERSLEY, RANDOMIZE_OWEN),
    ("Hammersley, CP rotation", SAMPLER_HAMMERSLEY, RANDOMIZE_CP),
)


def radiance(w):
    return 1.0 + 0.5 * w[:, 0] + 3.0 * np.exp(8.0 * (w @ SUN - 1.0))


def exact_irradiance():
    def f(theta, phi):
        st = math.sin(theta)
        w = np.array([[st * math.cos(phi), st * math.sin(phi), math.cos(theta)]])
        return radiance(w)[0] * math.cos(theta) * st

    val, _ = integrate.dblquad(f, 0.0, 2.0 * math.pi, 0.0, 0.5 * math.pi, epsabs=1e-12, epsrel=1e-12)
    return val


def estimate(n, sampler, randomize, seed):
    u = batch.qmc_points(n, 2, sampler, randomize, seed=seed, n_total=n)
    w, _, _ = batch.sample(WARP_COSINE_HEMISPHERE, [], u)
    return math.pi * radiance(w).mean()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=200, help="independent randomisations per (sampler, N)")
    args = ap.parse_args()
    exact = exact_irradiance()
    estimate(16, SAMPLER_HALTON, RANDOMIZE_OWEN, 0)  # compile / load the kernels
    print(f"E = {exact:.10f} (quadrature); {args.reps} randomisations per cell\n")
    head = (f"{'N':>5}  {'sampler':<24}{'variance':>11}{'var ratio':>11}{'T (ms)':>9}"
            f"{'1/(T σ²)':>12}{'eff ratio':>11}{'|bias|/se':>10}")
    print(head)
    print("-" * len(head))
    rows = []
    for n in NS:
        ref = None
        for name, sampler, randomize in SAMPLERS:
            for r in range(3):  # warm caches before timing
                estimate(n, sampler, randomize, 10 ** 6 + r)
            t0 = time.perf_counter()
            est = [estimate(n, sampler, randomize, 1 + 7919 * r) for r in range(args.reps)]
            secs = time.perf_counter() - t0
            s = stats.estimator_stats(est, seconds=secs)
            if ref is None:
                ref = s
            bias = abs(s.mean - exact) / s.std_error if s.std_error > 0 else 0.0
            print(f"{n:>5}  {name:<24}{s.variance:>11.3e}{ref.variance / s.variance:>11.1f}"
                  f"{1e3 * s.time_per_sample:>9.3f}{s.efficiency:>12.3e}{s.efficiency / ref.efficiency:>11.1f}"
                  f"{bias:>10.2f}")
            rows.append([n, name, s.variance, ref.variance / s.variance, 1e3 * s.time_per_sample, s.efficiency,
                         s.efficiency / ref.efficiency, bias])
        print()
    print("var ratio: independent variance / this sampler's (higher is better); T is one N-sample estimate.")
    results.write("qmc_bench", [results.table(
        f"Irradiance under a smooth sky, E = {exact:.10f}: variance of one N-sample estimate, {args.reps} "
        "randomisations per cell; ratios against the independent sampler (higher is better)",
        ["N", "sampler", "variance", "var ratio", "T (ms)", "1/(T σ²)", "eff ratio", "|bias|/se"], rows)],
        conditions={"reps": args.reps})


if __name__ == "__main__":
    main()
