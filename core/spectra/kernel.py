"""Evaluating Fourier-basis spectra inside kernels (Peters et al. 2019).

A spectrum is *prepared* once (NumPy, ``core.spectra.moments.prepare``): its
exponential moments and the solution of their Toeplitz system for a reflectance, or
the solution of the Toeplitz system of its trigonometric moments for an emission
spectrum. Evaluating it at a wavelength then costs O(m) complex multiply-adds.
Prepared row layout, float64[4m]: re(a), im(a), re(q), im(q) for a bounded spectrum;
q in the first m entries for an unbounded one.
"""
import math

import numpy as np
from numba import prange

from .. import constants as C
from ..jit import inline, kernel

LMIN = C.LAMBDA_MIN
LSTEP = C.LAMBDA_STEP
NL = C.N_LAMBDA


@inline
def lookup(table, row, lam):
    """Row ``row`` of a (rows, N_LAMBDA) table on the 1 nm grid, linearly interpolated at
    ``lam`` (clamped to the ends): how the path tracer and the media read spectra."""
    x = (lam - LMIN) / LSTEP
    i = int(x)
    if i < 0:
        return table[row, 0]
    if i >= NL - 1:
        return table[row, NL - 1]
    f = x - i
    return table[row, i] * (1.0 - f) + table[row, i + 1] * f


@inline
def warped_phase(warp, lam):
    x = (lam - LMIN) / LSTEP
    if x <= 0.0:
        return warp[0]
    i = int(x)
    if i >= NL - 1:
        return warp[NL - 1]
    f = x - i
    return warp[i] * (1.0 - f) + warp[i + 1] * f


@inline
def eval_bounded(prep, row, m, phi):
    """Bounded MESE at phase phi: the Herglotz transform of the exponential moments' MESE."""
    zr = math.cos(phi)  # conj(e^{i phi})
    zi = -math.sin(phi)
    # poly_k = q_k + poly_{k-1} * conj(z), poly_0 = Re q_0; acc = Σ_{j=1}^{m-1} poly_{m-1-j} a_j
    pr = prep[row, 2 * m]
    pi = 0.0
    acc_r = 0.0
    acc_i = 0.0
    for k in range(m - 1):
        j = m - 1 - k
        ar = prep[row, j]
        ai = prep[row, m + j]
        acc_r += pr * ar - pi * ai
        acc_i += pr * ai + pi * ar
        nr = prep[row, 2 * m + k + 1] + pr * zr - pi * zi
        ni = prep[row, 3 * m + k + 1] + pr * zi + pi * zr
        pr = nr
        pi = ni
    den = pr * pr + pi * pi
    if den == 0.0:
        return 0.0
    # h = a_0 + 2 acc / poly_{m-1}
    hr = prep[row, 0] + 2.0 * (acc_r * pr + acc_i * pi) / den
    hi = prep[row, m] + 2.0 * (acc_i * pr - acc_r * pi) / den
    v = math.atan2(hi, hr) / math.pi + 0.5
    return min(max(v, 0.0), 1.0)


@inline
def eval_unbounded(prep, row, m, phi):
    """Burg's maximum-entropy estimate q_0 / |Σ q_k e^{-ik phi}|² at phase phi."""
    if prep[row, 0] <= 0.0:
        return 0.0
    cr = math.cos(phi)
    ci = -math.sin(phi)
    er = 1.0
    ei = 0.0
    sr = 0.0
    si = 0.0
    for k in range(m):
        q = prep[row, k]
        sr += q * er
        si += q * ei
        tr = er * cr - ei * ci
        ei = er * ci + ei * cr
        er = tr
    den = sr * sr + si * si
    if den == 0.0:
        return 0.0
    return prep[row, 0] / den


@inline
def eval_spectrum(prep, kinds, m, warp, row, lam):
    phi = warped_phase(warp, lam)
    if kinds[row] == C.SPECTRUM_BOUNDED:
        return eval_bounded(prep, row, m, phi)
    return eval_unbounded(prep, row, m, phi)


@kernel(parallel=True)
def eval_spectrum_batch(prep, kinds, m, warp, rows, lams):
    """Evaluate spectrum ``rows[i]`` at wavelength ``lams[i]`` (tests, benchmarks, tools)."""
    out = np.empty(lams.shape[0])
    for i in prange(lams.shape[0]):
        out[i] = eval_spectrum(prep, kinds, m, warp, rows[i], lams[i])
    return out
