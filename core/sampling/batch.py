"""The package's two entry kernels: every warp behind one integer tag, so tests and tools
compile once whatever the number of samplers.

``sample_batch(tag, params, u)``: u (N, 2 or 3) → points (N, 3), pdf (N,), flag (N,)
``pdf_batch(tag, params, w)``:    w (N, 3)      → pdf (N,), inverse u (N, 2) (-1 where
the warp has no inverse)

Tags and the layout of ``params`` are in tags.py. The Python wrappers ``sample``,
``pdf_and_inverse`` and ``qmc_points`` coerce dtypes and contiguity (one signature per
kernel).

Compile time: the if/elif over every warp lives in ``_sample_one`` / ``_pdf_one``,
compiled once with jit's ``function`` (the inline helpers are inlined into them) and
called from the prange loops. Inlining the whole dispatch into the parallel loops made
numba's parfor analysis, which grows faster than linearly with a loop body, take
~150 s; this layout compiles both kernels in ~25 s, cached afterwards.
"""
import math

import numpy as np
from numba import prange

from ..jit import inline, kernel
from . import tags as T
from .distrib import (
    distribution_1d_pdf, distribution_2d_pdf, invert_distribution_1d, invert_distribution_2d,
    sample_distribution_1d, sample_distribution_2d)
from .lobes import offnormal_cosn_pdf, sample_offnormal_cosn
from .qmc import qmc_sample
from .sphtri import invert_spherical_triangle, sample_spherical_triangle, spherical_triangle_pdf
from .warps import (
    cosine_cone_pdf, cosine_hemisphere_pdf, cosn_cone_pdf, cosn_pdf, disk_pdf, invert_cosine_cone,
    invert_cosine_hemisphere, invert_cosn, invert_cosn_cone, invert_disk_concentric, invert_disk_polar,
    invert_triangle_area, invert_uniform_cone, invert_uniform_hemisphere, invert_uniform_sphere,
    sample_cosine_cone, sample_cosine_hemisphere, sample_cosn, sample_cosn_cone, sample_disk_concentric,
    sample_disk_polar, sample_triangle_area, sample_uniform_cone, sample_uniform_hemisphere,
    sample_uniform_sphere, uniform_cone_pdf, uniform_hemisphere_pdf, uniform_sphere_pdf)

try:  # the per-sample dispatchers are compiled once as functions of their own (core/jit.py)
    from ..jit import function
except ImportError:  # pragma: no cover - a jit policy without ``function``: inline them
    function = inline


@inline
def _store(out, pdf, flag, k, x, y, z, pd):
    """Write one sample; non-finite output becomes an invalid sample at the origin."""
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)) or math.isnan(pd):
        x = 0.0
        y = 0.0
        z = 0.0
        pd = 0.0
    out[k, 0] = x
    out[k, 1] = y
    out[k, 2] = z
    pdf[k] = pd
    if pd == math.inf:
        flag[k] = T.FLAG_DELTA
    elif pd > 0.0:
        flag[k] = T.FLAG_VALID
    else:
        flag[k] = T.FLAG_INVALID


@inline
def _store_pdf(pdf, uinv, k, pd, a, b):
    pdf[k] = pd if not math.isnan(pd) else 0.0
    uinv[k, 0] = a
    uinv[k, 1] = b


@function
def _sample_one(tag, p, a, b, c):
    """One sample of warp ``tag``: (x, y, z, pdf). Compiled once as a function of its own
    (not inlined into the parallel loop, where numba's parfor analysis of a large body is
    slow to compile)."""
    if tag == T.WARP_UNIFORM_SPHERE:
        return sample_uniform_sphere(a, b)
    elif tag == T.WARP_UNIFORM_HEMISPHERE:
        return sample_uniform_hemisphere(a, b)
    elif tag == T.WARP_UNIFORM_CONE:
        return sample_uniform_cone(p[0], a, b)
    elif tag == T.WARP_COSINE_HEMISPHERE:
        return sample_cosine_hemisphere(a, b)
    elif tag == T.WARP_COSINE_CONE:
        return sample_cosine_cone(p[0], a, b)
    elif tag == T.WARP_COSN:
        return sample_cosn(p[0], a, b)
    elif tag == T.WARP_COSN_CONE:
        return sample_cosn_cone(p[0], p[1], a, b)
    elif tag == T.WARP_SPHERICAL_TRIANGLE:
        return sample_spherical_triangle(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], a, b)
    elif tag == T.WARP_OFFNORMAL_COSN:
        return sample_offnormal_cosn(p[0], p[1], p[2], p[3], a, b, c)
    elif tag == T.WARP_DISTRIBUTION_1D:
        x, pd, _ = sample_distribution_1d(p, a)
        return x, 0.0, 0.0, pd
    elif tag == T.WARP_DISTRIBUTION_2D:
        x, y, pd = sample_distribution_2d(p, a, b)
        return x, y, 0.0, pd
    elif tag == T.WARP_DISK_CONCENTRIC:
        x, y, pd = sample_disk_concentric(a, b)
        return x, y, 0.0, pd
    elif tag == T.WARP_DISK_POLAR:
        x, y, pd = sample_disk_polar(a, b)
        return x, y, 0.0, pd
    elif tag == T.WARP_TRIANGLE_AREA:
        b0, b1, b2 = sample_triangle_area(a, b)
        return b0, b1, b2, 2.0
    return 0.0, 0.0, 0.0, 0.0


@function
def _qmc_one(p, index, dim):
    return qmc_sample(int(p[0]), int(p[1]), index, int(p[4]) + dim, np.uint64(p[2]), int(p[3]))


@function
def _pdf_one(tag, p, x, y, z):
    """(pdf, u1, u2) of warp ``tag`` at (x, y, z); u = -1 where the warp has no inverse."""
    if tag == T.WARP_UNIFORM_SPHERE:
        a, b = invert_uniform_sphere(x, y, z)
        return uniform_sphere_pdf(), a, b
    elif tag == T.WARP_UNIFORM_HEMISPHERE:
        a, b = invert_uniform_hemisphere(x, y, z)
        return uniform_hemisphere_pdf(x, y, z), a, b
    elif tag == T.WARP_UNIFORM_CONE:
        a, b = invert_uniform_cone(p[0], x, y, z)
        return uniform_cone_pdf(p[0], x, y, z), a, b
    elif tag == T.WARP_COSINE_HEMISPHERE:
        a, b = invert_cosine_hemisphere(x, y, z)
        return cosine_hemisphere_pdf(x, y, z), a, b
    elif tag == T.WARP_COSINE_CONE:
        a, b = invert_cosine_cone(p[0], x, y, z)
        return cosine_cone_pdf(p[0], x, y, z), a, b
    elif tag == T.WARP_COSN:
        a, b = invert_cosn(p[0], x, y, z)
        return cosn_pdf(p[0], x, y, z), a, b
    elif tag == T.WARP_COSN_CONE:
        a, b = invert_cosn_cone(p[0], p[1], x, y, z)
        return cosn_cone_pdf(p[0], p[1], x, y, z), a, b
    elif tag == T.WARP_SPHERICAL_TRIANGLE:
        a, b = invert_spherical_triangle(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], x, y, z)
        return spherical_triangle_pdf(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], x, y, z), a, b
    elif tag == T.WARP_OFFNORMAL_COSN:
        return offnormal_cosn_pdf(p[0], p[1], p[2], p[3], x, y, z), -1.0, -1.0
    elif tag == T.WARP_DISTRIBUTION_1D:
        return distribution_1d_pdf(p, x), invert_distribution_1d(p, x), -1.0
    elif tag == T.WARP_DISTRIBUTION_2D:
        a, b = invert_distribution_2d(p, x, y)
        return distribution_2d_pdf(p, x, y), a, b
    elif tag == T.WARP_DISK_CONCENTRIC:
        a, b = invert_disk_concentric(x, y)
        return disk_pdf(x, y), a, b
    elif tag == T.WARP_DISK_POLAR:
        a, b = invert_disk_polar(x, y)
        return disk_pdf(x, y), a, b
    elif tag == T.WARP_TRIANGLE_AREA:
        a, b = invert_triangle_area(x, y)
        inside = x >= 0.0 and y >= 0.0 and z >= 0.0 and abs(x + y + z - 1.0) <= 1e-12
        return (2.0 if inside else 0.0), a, b
    elif tag == T.WARP_QMC:
        return 1.0, -1.0, -1.0
    return 0.0, -1.0, -1.0


@kernel(parallel=True)
def sample_batch(tag, params, u):
    """u: (N, 2 or 3) float64 → (points (N, 3), pdf (N,), flag (N,) uint8).

    flag: FLAG_VALID for 0 < pdf < inf, FLAG_DELTA for a Dirac (pdf inf), FLAG_INVALID
    otherwise (the point is then the origin). A third column of u feeds the rejection
    retries of WARP_OFFNORMAL_COSN (0.5 if absent); a 1-column u is padded with 0.5.
    For WARP_QMC, u[:, 0] holds the sample index.
    """
    n = u.shape[0]
    ncol = u.shape[1]
    out = np.empty((n, 3))
    pdf = np.empty(n)
    flag = np.empty(n, np.uint8)
    for k in prange(n):
        a = u[k, 0]
        b = u[k, 1] if ncol > 1 else 0.5
        c = u[k, 2] if ncol > 2 else 0.5
        if tag == T.WARP_QMC:
            idx = int(a)
            x = _qmc_one(params, idx, 0)
            y = _qmc_one(params, idx, 1)
            z = _qmc_one(params, idx, 2)
            pd = 1.0
        else:
            x, y, z, pd = _sample_one(tag, params, a, b, c)
        _store(out, pdf, flag, k, x, y, z, pd)
    return out, pdf, flag


@kernel(parallel=True)
def pdf_batch(tag, params, w):
    """w: (N, 3) float64 → (pdf (N,), inverse u (N, 2)); u = -1 where there is no inverse."""
    n = w.shape[0]
    pdf = np.empty(n)
    uinv = np.empty((n, 2))
    for k in prange(n):
        pd, a, b = _pdf_one(tag, params, w[k, 0], w[k, 1], w[k, 2])
        _store_pdf(pdf, uinv, k, pd, a, b)
    return pdf, uinv


def _params(params):
    p = np.ascontiguousarray(np.atleast_1d(np.asarray(params, dtype=np.float64)))
    if p.size == 0:
        p = np.zeros(1)
    return p


def sample(tag, params, u):
    """Python wrapper of sample_batch: u is (N, 2 or 3) (or (N,) for 1D warps)."""
    u = np.asarray(u, dtype=np.float64)
    if u.ndim == 1:
        u = u[:, None]
    return sample_batch(int(tag), _params(params), np.ascontiguousarray(u))


def pdf_and_inverse(tag, params, w):
    """Python wrapper of pdf_batch: w is (N, k ≤ 3), padded with zeros to (N, 3)."""
    w = np.asarray(w, dtype=np.float64)
    if w.ndim == 1:
        w = w[:, None]
    if w.shape[1] < 3:
        w = np.concatenate([w, np.zeros((w.shape[0], 3 - w.shape[1]))], axis=1)
    return pdf_batch(int(tag), _params(params), np.ascontiguousarray(w))


def pdf(tag, params, w):
    return pdf_and_inverse(tag, params, w)[0]


def qmc_points(n, dims, sampler=T.SAMPLER_HALTON, randomize=T.RANDOMIZE_OWEN, seed=0, start=0, n_total=None):
    """(n, dims) array: points start .. start+n-1 of a sequence, computed by the kernel's
    ``qmc_sample`` (the function a render kernel calls). Hammersley uses n_total (default n)."""
    n_total = n if n_total is None else n_total
    idx = np.arange(start, start + n, dtype=np.float64)[:, None]
    out = np.empty((n, dims))
    for d0 in range(0, dims, 3):
        p = np.array([sampler, randomize, float(seed), float(n_total), float(d0)])
        pts, _, _ = sample_batch(T.WARP_QMC, p, idx)
        k = min(3, dims - d0)
        out[:, d0:d0 + k] = pts[:, :k]
    return out

