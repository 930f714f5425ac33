"""Integer tags of the sampling package (stored nowhere on disk, but never reorder them:
kernels compare against these numbers)."""

# Sample generators for qmc.qmc_sample (the renderer's sampler setting).
SAMPLER_INDEPENDENT = 0
SAMPLER_HALTON = 1
SAMPLER_HAMMERSLEY = 2

# Randomisation of the low-discrepancy generators.
RANDOMIZE_NONE = 0  # deterministic points (biased estimates: tests and plots only)
RANDOMIZE_OWEN = 1  # nested uniform (Owen) scrambling: unbiased, keeps stratification
RANDOMIZE_CP = 2  # Cranley–Patterson rotation: unbiased

# Status of a sample in batch outputs (the inline samplers encode it in the pdf:
# 0 → invalid, inf → Dirac; see warps.py).
FLAG_INVALID = 0
FLAG_VALID = 1
FLAG_DELTA = 2

# Warps understood by batch.sample_batch / batch.pdf_batch, with their params layout.
WARP_UNIFORM_SPHERE = 0  # []
WARP_UNIFORM_HEMISPHERE = 1  # []
WARP_UNIFORM_CONE = 2  # [theta_max]
WARP_COSINE_HEMISPHERE = 3  # []
WARP_COSINE_CONE = 4  # [theta_max]
WARP_COSN = 5  # [n]
WARP_COSN_CONE = 6  # [n, theta_max]
WARP_SPHERICAL_TRIANGLE = 7  # [ax, ay, az, bx, by, bz, cx, cy, cz]
WARP_OFFNORMAL_COSN = 8  # [n, mx, my, mz]; u may have a third column for the retry stream
WARP_DISTRIBUTION_1D = 9  # the flat array of distrib.build_distribution_1d; out (x, 0, 0)
WARP_DISTRIBUTION_2D = 10  # the flat array of distrib.build_distribution_2d; out (x, y, 0)
WARP_DISK_CONCENTRIC = 11  # []; out (x, y, 0)
WARP_DISK_POLAR = 12  # []; out (x, y, 0)
WARP_TRIANGLE_AREA = 13  # []; out barycentrics (b0, b1, b2), pdf 2 on the reference triangle
WARP_QMC = 14  # [sampler, randomize, seed, n, dim0]; u[:, 0] = index; out dims dim0..dim0+2
N_WARPS = 15
