"""Monte Carlo toolkit (compendium items 5–30): warps, distributions, MIS, QMC, statistics.

Kernels import the ``@inline`` functions from the submodules directly:

* ``warps``    sphere, hemisphere, cone, cosine and cosⁿ lobes, disk, triangle (items 18–21)
* ``sphtri``   Arvo's spherical-triangle sampling and the solid angle (items 5, 22)
* ``lobes``    off-normal cosⁿ lobes on the digon and Arvo's double-axis moments (10, 23)
* ``distrib``  piecewise-constant 1D/2D distributions (11–16)
* ``frame``    (θ, φ) ↔ direction, shading frames, dA ↔ dω (6–8)
* ``mis``      balance / power heuristics with any β, one- and multi-sample combination (27–28)
* ``qmc``      radical inverse, van der Corput, Halton, Hammersley, Owen / Cranley–Patterson (30)
* ``stats``    mean, variance, standard error, efficiency 1/(T σ²) (11–15, 29)
* ``batch``    the entry kernels ``sample_batch`` / ``pdf_batch`` for tests and tools
* ``oracle``   slow NumPy references for the tests

The pdf convention (0: no sample; inf: Dirac event) is described in ``warps``.
"""
from .tags import (
    FLAG_DELTA, FLAG_INVALID, FLAG_VALID, N_WARPS, RANDOMIZE_CP, RANDOMIZE_NONE, RANDOMIZE_OWEN,
    SAMPLER_HALTON, SAMPLER_HAMMERSLEY, SAMPLER_INDEPENDENT, WARP_COSINE_CONE, WARP_COSINE_HEMISPHERE,
    WARP_COSN, WARP_COSN_CONE, WARP_DISK_CONCENTRIC, WARP_DISK_POLAR, WARP_DISTRIBUTION_1D,
    WARP_DISTRIBUTION_2D, WARP_OFFNORMAL_COSN, WARP_QMC, WARP_SPHERICAL_TRIANGLE, WARP_TRIANGLE_AREA,
    WARP_UNIFORM_CONE, WARP_UNIFORM_HEMISPHERE, WARP_UNIFORM_SPHERE)

# The renderer's sampler setting: SAMPLER_INDEPENDENT = 0, SAMPLER_HALTON = 1,
# SAMPLER_HAMMERSLEY = 2 (defined in tags.py so kernels can import them without this
# package's submodules; never renumber).

from .distrib import build_distribution_1d, build_distribution_2d  # noqa: E402
from .mis import combine_multi_sample, combine_one_sample, mis_weights  # noqa: E402
from .stats import EstimatorStats, efficiency, estimator_stats  # noqa: E402

__all__ = [
    "SAMPLER_INDEPENDENT", "SAMPLER_HALTON", "SAMPLER_HAMMERSLEY",
    "RANDOMIZE_NONE", "RANDOMIZE_OWEN", "RANDOMIZE_CP",
    "FLAG_INVALID", "FLAG_VALID", "FLAG_DELTA", "N_WARPS",
    "WARP_UNIFORM_SPHERE", "WARP_UNIFORM_HEMISPHERE", "WARP_UNIFORM_CONE", "WARP_COSINE_HEMISPHERE",
    "WARP_COSINE_CONE", "WARP_COSN", "WARP_COSN_CONE", "WARP_SPHERICAL_TRIANGLE", "WARP_OFFNORMAL_COSN",
    "WARP_DISTRIBUTION_1D", "WARP_DISTRIBUTION_2D", "WARP_DISK_CONCENTRIC", "WARP_DISK_POLAR",
    "WARP_TRIANGLE_AREA", "WARP_QMC",
    "build_distribution_1d", "build_distribution_2d", "mis_weights", "combine_multi_sample",
    "combine_one_sample", "estimator_stats", "efficiency", "EstimatorStats",
]
