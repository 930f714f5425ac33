"""Fourier-basis spectra: trigonometric moments of a phase-warped wavelength.

After Peters, Merzbach, Hanika and Dachsbacher, "Using Moments to Represent Bounded
Signals for Spectral Rendering", ACM TOG 38(4), 2019.

A spectrum g(λ) on [LAMBDA_MIN, LAMBDA_MAX] is mapped to a phase φ(λ) ∈ [-π, 0]
(a monotonic warp of the wavelength, see ``warp_table``) and mirrored to an even
function on [-π, π]. Its m real trigonometric moments are

    c_j = (1/π) ∫_{-π}^{0} g(φ) cos(j φ) dφ,   j = 0 .. m-1,

i.e. the Fourier coefficients of the mirrored signal (c_0 is the mean of g). Three
reconstructions are offered:

* ``reconstruct_fourier``: the truncated Fourier series (the compendium's item 65,
  extended to m terms). Exact moments, but it rings and can leave [0, 1].
* ``reconstruct_bounded``: the bounded maximum-entropy spectral estimate (MESE) of
  Peters et al.: stays in [0, 1] and reproduces the moments exactly. Reflectances.
* ``reconstruct_unbounded``: Burg's maximum-entropy estimate: positive, reproduces the
  moments exactly, any scale. Emission spectra.

These are NumPy functions used when a scene is prepared: each spectrum is evaluated
once on the renderer's 1 nm grid and the kernels interpolate that table.
"""
from __future__ import annotations

import functools

import numpy as np

from .. import constants as C
from ..io import presets



# The phase warp. Moments of a linearly mapped wavelength spend as many coefficients on
# 360–400 nm and 700–830 nm, where the eye sees almost nothing, as on the middle of the
# range. The warp instead advances the phase in proportion to
#     w(λ) = sqrt(s(λ) / max s) + WARP_FLOOR,   s = x̄ + ȳ + z̄ (CIE 1931),
# so more of [-π, 0] goes where colour is decided. Measured on the 24 ColorChecker
# spectra under D65, A and F11 (benchmarks/spectra_bench.py), this warp with 12
# coefficients gives a mean ΔE00 of 0.35 and a maximum of 0.83 where the linear map
# gives 0.73 and 2.1. The warp is part of the scene format: changing it changes every
# stored coefficient (bump SCENE_FORMAT_VERSION).
WARP_POWER = 0.5
WARP_FLOOR = 0.02


def _grid():
    return C.LAMBDA_MIN + C.LAMBDA_STEP * np.arange(C.N_LAMBDA)


@functools.lru_cache(maxsize=1)
def warp_table():
    """φ at every wavelength of the 1 nm grid (float64[N_LAMBDA]); linear in between."""
    wl, xyz = presets.cmfs("1931")
    g = _grid()
    s = np.interp(g, wl, xyz.sum(axis=1), left=0.0, right=0.0)
    w = np.sqrt(s / s.max()) + WARP_FLOOR
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]))])
    return np.pi * cum / cum[-1] - np.pi


def phase(wavelengths):
    """Warped phase φ ∈ [-π, 0] of wavelengths in nm (clamped outside the range)."""
    return np.interp(np.asarray(wavelengths, dtype=np.float64), _grid(), warp_table())


def grid():
    """The renderer's wavelength grid (nm)."""
    return _grid()


def moments_from_samples(wavelengths, values, n_coeffs=C.N_COEFFS_DEFAULT):
    """Moments of a tabulated spectrum (any sampling, linear between samples).

    Outside the tabulated range the end values are held, as colour-science's default
    extrapolation does. ``values`` may be (N,) or (N, K) for K spectra at once; the
    result is (n_coeffs,) or (K, n_coeffs).
    """
    wl = np.asarray(wavelengths, dtype=np.float64)
    v = np.asarray(values, dtype=np.float64)
    if wl.ndim != 1 or wl.size < 1 or v.shape[0] != wl.size:
        raise ValueError(f"moments_from_samples: {wl.size} wavelengths but values of shape {v.shape}")
    if not (np.all(np.isfinite(wl)) and np.all(np.isfinite(v))):
        raise ValueError("moments_from_samples: wavelengths and values must be finite")
    if wl.size > 1 and np.any(np.diff(wl) <= 0):
        raise ValueError("moments_from_samples: wavelengths must be strictly increasing")
    # g is linear in λ between samples and φ is linear in λ between grid points, so g is
    # linear in φ between the union of both: integrate each piece exactly.
    inside = wl[(wl > C.LAMBDA_MIN) & (wl < C.LAMBDA_MAX)]
    knots = np.union1d(_grid(), inside)
    single = v.ndim == 1
    cols = v.reshape(wl.size, -1)
    g = np.stack([np.interp(knots, wl, cols[:, k]) for k in range(cols.shape[1])], axis=1)  # (P, K)
    phi = phase(knots)
    pa, pb = phi[:-1], phi[1:]
    ga, gb = g[:-1], g[1:]
    d = pb - pa
    keep = d > 0
    pa, pb, ga, gb, d = pa[keep], pb[keep], ga[keep], gb[keep], d[keep]
    slope = (gb - ga) / d[:, None]  # (P-1, K)
    icpt = ga - slope * pa[:, None]
    c = np.empty((cols.shape[1], n_coeffs))
    c[:, 0] = np.sum(icpt * d[:, None] + slope * 0.5 * ((pb * pb - pa * pa)[:, None]), axis=0)
    for j in range(1, n_coeffs):
        sa, sb = np.sin(j * pa), np.sin(j * pb)
        ca, cb = np.cos(j * pa), np.cos(j * pb)
        int_cos = (sb - sa) / j
        int_phi_cos = (pb * sb - pa * sa) / j + (cb - ca) / (j * j)
        c[:, j] = np.sum(icpt * int_cos[:, None] + slope * int_phi_cos[:, None], axis=0)
    c /= np.pi
    return c[0] if single else c


def reconstruct_fourier(coeffs, wavelengths):
    """Truncated Fourier series g(φ) = c_0 + 2 Σ c_j cos(jφ) (may leave [0, 1])."""
    c = np.asarray(coeffs, dtype=np.float64)
    phi = phase(wavelengths)
    j = np.arange(1, c.size)
    return c[0] + 2.0 * np.cos(np.multiply.outer(phi, j)) @ c[1:]


def _toeplitz_hermitian(first_col):
    n = first_col.size
    idx = np.arange(n)[:, None] - np.arange(n)[None, :]
    t = np.where(idx >= 0, first_col[np.abs(idx)], np.conj(first_col[np.abs(idx)]))
    return t


def solve_toeplitz_e0(first_col):
    """x with T x = e_0, T the Hermitian positive definite Toeplitz matrix of first column
    ``first_col`` (``_toeplitz_hermitian``), by Levinson's recursion: the solution of each
    leading block extended by one row with the error of the last row cancelled by the mirrored
    (conjugated, reversed) solution. O(m²) in a few small NumPy operations and no LAPACK
    call: the export fits spectra on Blender's main thread while the render's threads hold
    the cores, and a LAPACK solve there waited for BLAS threads (25 ms for a 12 × 12 system,
    against 20 µs)."""
    r = np.asarray(first_col)
    m = r.size
    f = np.zeros(m, dtype=np.result_type(r.dtype, np.float64))
    f[0] = 1.0 / r[0]
    for n in range(1, m):
        eps = np.dot(r[n:0:-1], f[:n])  # the last row of the (n+1) block times (f, 0)
        mirrored = np.conj(f[n - 1::-1])
        f[1:n + 1] -= eps * mirrored
        f[:n + 1] /= 1.0 - abs(eps) ** 2
    return f


def exponential_moments(coeffs):
    """Exponential moments of the bounded signal (Peters et al. 2019, Herglotz transform)."""
    c = np.asarray(coeffs, dtype=np.float64)
    m = c.size
    a = np.zeros(m, dtype=np.complex128)
    a[0] = np.exp(1j * np.pi * (c[0] - 0.5)) / (4.0 * np.pi)
    for i in range(1, m):
        k = np.arange(i)
        a[i] = np.sum(c[i - k] * a[k] * (2j * np.pi * (i - k) / i))
    a[0] *= 2.0
    return a


def _bounded_prepare(c):
    a = exponential_moments(c)
    # The positive density behind the exponential moments has moments Re(a_0), a_1, ...
    # (the imaginary part of a_0 is the additive constant of the Carathéodory function).
    q = solve_toeplitz_e0(np.concatenate([[a[0].real], a[1:]])) * (2.0 * np.pi)
    return a, q


_EDGE = 1e-6  # c_0 this close to 0 or 1 means the constant spectrum 0 or 1


def reconstruct_bounded(coeffs, wavelengths):
    """Bounded MESE: a signal in [0, 1] whose moments equal ``coeffs``."""
    c = np.asarray(coeffs, dtype=np.float64)
    wl = np.asarray(wavelengths, dtype=np.float64)
    if c[0] <= _EDGE:
        return np.zeros(wl.shape)
    if c[0] >= 1.0 - _EDGE:
        return np.ones(wl.shape)
    a, q = _bounded_prepare(c)
    m = c.size
    z_conj = np.exp(-1j * phase(wl))
    # Evaluate the Herglotz transform of the MESE of the exponential moments with a
    # Horner-like recursion over the polynomial's coefficients.
    poly = np.empty((m,) + wl.shape, dtype=np.complex128)
    poly[0] = q[0].real
    for j in range(1, m):
        poly[j] = q[j] + poly[j - 1] * z_conj
    acc = np.zeros(wl.shape, dtype=np.complex128)
    for j in range(1, m):
        acc += poly[m - 1 - j] * a[j]
    h = a[0] + 2.0 * acc / poly[m - 1]
    return np.clip(np.arctan2(h.imag, h.real) / np.pi + 0.5, 0.0, 1.0)


def reconstruct_unbounded(coeffs, wavelengths):
    """Burg's maximum-entropy estimate: a positive signal whose moments equal ``coeffs``."""
    c = np.asarray(coeffs, dtype=np.float64)
    wl = np.asarray(wavelengths, dtype=np.float64)
    if c[0] <= 0.0:
        return np.zeros(wl.shape)
    q = solve_toeplitz_e0(c)
    z = np.exp(-1j * np.multiply.outer(phase(wl), np.arange(c.size)))
    denom = np.abs(z @ q) ** 2
    return q[0] / denom


def reconstruct(coeffs, kind, wavelengths):
    if kind == C.SPECTRUM_BOUNDED:
        return reconstruct_bounded(coeffs, wavelengths)
    if kind == C.SPECTRUM_UNBOUNDED:
        return reconstruct_unbounded(coeffs, wavelengths)
    raise ValueError(f"unknown spectrum kind {kind}")


def check_coefficients(coeffs, kind):
    """Return a sentence describing why ``coeffs`` is not a valid spectrum, or None."""
    c = np.asarray(coeffs, dtype=np.float64)
    if not np.all(np.isfinite(c)):
        return "coefficients contain NaN or Inf"
    # a non-negative g has |c_j| <= c_0 (|cos| <= 1): larger moments describe no spectrum
    # (and would only reach the eigenvalue test below as numbers it cannot take)
    tol = 1e-6 * max(abs(float(c[0])), 1.0)
    if c.size > 1 and np.abs(c[1:]).max() > abs(float(c[0])) + tol:
        return ("coefficients describe no reflectance within [0, 1]" if kind == C.SPECTRUM_BOUNDED
                else "coefficients describe no non-negative emission spectrum")
    try:
        if kind == C.SPECTRUM_BOUNDED:
            if c[0] < -1e-9:
                return f"negative reflectance (mean {c[0]:.6g} < 0)"
            if c[0] > 1.0 + 1e-9:
                return f"reflectance above 1 (mean {c[0]:.6g} > 1)"
            if _EDGE < c[0] < 1.0 - _EDGE:
                a = exponential_moments(c)
                a[0] = a[0].real
                if np.linalg.eigvalsh(_toeplitz_hermitian(a)).min() <= 0.0:
                    return "coefficients describe no reflectance within [0, 1]"
            return None
        if c[0] < 0.0:
            return f"negative emission (mean {c[0]:.6g} < 0)"
        if c[0] > MAX_EMISSION_MEAN:
            return f"emission mean {c[0]:.6g} above {MAX_EMISSION_MEAN:g} (the shape's scale; luminance sets power)"
        if c[0] > 0.0 and np.linalg.eigvalsh(_toeplitz_hermitian((c / c[0]).astype(np.complex128)).real).min() <= 0.0:
            return "coefficients describe no non-negative emission spectrum"
    except np.linalg.LinAlgError:
        return "coefficients describe no spectrum (their moment matrix cannot be decomposed)"
    return None


MAX_EMISSION_MEAN = 1e12  # an emission shape's c_0 (any scale is the same shape; this keeps it representable)


def prepare(coeffs, kind):
    """The float64[4m] row that ``core.kernels.spectrum`` evaluates (see its layout)."""
    c = np.asarray(coeffs, dtype=np.float64)
    m = c.size
    row = np.zeros(4 * m)
    if kind == C.SPECTRUM_BOUNDED:
        if c[0] <= _EDGE or c[0] >= 1.0 - _EDGE:
            # constant 0 or 1: h = a_0 with arg(a_0) = π (v - 1/2), poly = 1
            v = 0.0 if c[0] <= _EDGE else 1.0
            row[0] = np.cos(np.pi * (v - 0.5))
            row[m] = np.sin(np.pi * (v - 0.5))
            row[2 * m] = 1.0
            return row
        a, q = _bounded_prepare(c)
        row[:m], row[m:2 * m], row[2 * m:3 * m], row[3 * m:] = a.real, a.imag, q.real, q.imag
        return row
    if kind == C.SPECTRUM_UNBOUNDED:
        if c[0] <= 0.0:
            return row
        row[:m] = solve_toeplitz_e0(c)
        return row
    raise ValueError(f"unknown spectrum kind {kind}")


def prepare_table(coeffs, kinds):
    """Prepared rows of S spectra: float64 (S, 4m)."""
    coeffs = np.asarray(coeffs, dtype=np.float64)
    out = np.zeros((coeffs.shape[0], 4 * coeffs.shape[1]))
    for i, (c, k) in enumerate(zip(coeffs, kinds)):
        out[i] = prepare(c, int(k))
    return out


_TABULATED = {}  # (coefficients, kind) → one spectrum on the grid; a scene's spectra change rarely
_TABULATED_MAX = 4096


def tabulate(coeffs, kinds):
    """Reconstruct S spectra on the renderer's grid: float32 (S, N_LAMBDA).

    Each spectrum is reconstructed once a process for the same coefficients and kind (the
    viewport and repeated point calculations prepare the same scene again and again)."""
    wl = grid()
    out = np.zeros((len(kinds), wl.size), dtype=np.float32)
    for i, (c, k) in enumerate(zip(coeffs, kinds)):
        c = np.ascontiguousarray(c, dtype=np.float64)
        key = (c.tobytes(), int(k))
        row = _TABULATED.get(key)
        if row is None:
            row = reconstruct(c, int(k), wl).astype(np.float32)
            if len(_TABULATED) >= _TABULATED_MAX:
                _TABULATED.clear()
            _TABULATED[key] = row
        out[i] = row
    return out
