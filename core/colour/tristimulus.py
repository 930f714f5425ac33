"""Spectral data → CIE XYZ tristimulus values (compendium item 63).

X = k Σ_λ φ(λ) x̄(λ) Δλ (and Y, Z with ȳ, z̄), CIE 015:2018, summed on the
colour-matching functions' own grid (the tables shipped in ``presets/cie``:
360–830 nm, Δλ = 1 nm). The input spectra are first brought onto that grid the
way colour-science's ``sd_to_XYZ(..., method="Integration")`` does (its
``SpectralDistribution.align``), so the results agree with it to rounding:

* inside the input's wavelength range, interpolation by the Sprague (1880)
  fifth-order polynomial for uniformly spaced data (≥ 6 samples), the method
  CIE 167:2005 recommends, or a not-a-knot cubic spline for non-uniform data
  (≥ 4 samples); linear for 2–3 samples (colour-science refuses those);
* outside it, constant extrapolation of the first / last value (the usual
  practice when nothing better is known).

colour-science's ``sd_to_XYZ`` defaults to ``method="ASTM E308"``, which for
inputs at 5, 10 or 20 nm sums with the ASTM E308-15 tables of weighting
factors (or the ASTM E2022 ones it computes) rather than interpolating to 1 nm.
That is a different approximation of the same integral: for the "dark skin"
patch of the ColorChecker (5 nm, 380–780 nm) under D65, the two methods differ
by about 4e-4 in X (relative 4e-5). We implement "Integration" only.
colour-science also trims its default CMFs to 360–780 nm
(``SPECTRAL_SHAPE_DEFAULT``); we sum over the full 360–830 nm tables, which
equals colour-science when its full CMFs are passed explicitly
(``cmfs=colour.MSDS_CMFS[...]``); the tail adds ~1e-5 relative.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..io import presets
from ._common import as_float

# --------------------------------------------------------------------------- interpolation

# Sprague (1880) boundary coefficients: two extra points at each end from the first / last
# six samples (CIE 167:2005; Westland, Ripamonti & Cheung, Computational Colour Science
# Using MATLAB, 2nd ed., 2012).
_SPRAGUE_BOUNDARY = np.array(
    [
        [884.0, -1960.0, 3033.0, -2648.0, 1080.0, -180.0],
        [508.0, -540.0, 488.0, -367.0, 144.0, -24.0],
        [-24.0, 144.0, -367.0, 488.0, -540.0, 508.0],
        [-180.0, 1080.0, -2648.0, 3033.0, -1960.0, 884.0],
    ]
) / 209.0

# Coefficients a_1..a_5 of the fifth-degree polynomial on [x_i, x_{i+1}] in terms of
# p_{i-2}..p_{i+3} (a_0 = p_i), times 1/24.
_SPRAGUE_POLY = np.array(
    [
        [2.0, -16.0, 0.0, 16.0, -2.0, 0.0],
        [-1.0, 16.0, -30.0, 16.0, -1.0, 0.0],
        [-9.0, 39.0, -70.0, 66.0, -33.0, 7.0],
        [13.0, -64.0, 126.0, -124.0, 61.0, -12.0],
        [-5.0, 25.0, -50.0, 50.0, -25.0, 5.0],
    ]
) / 24.0


def is_uniform(x) -> bool:
    """True if the samples ``x`` (1-D, increasing) are evenly spaced (to 1e-10 relative)."""
    d = np.diff(as_float(x))
    return d.size > 0 and bool(np.all(np.abs(d - d[0]) <= 1e-10 * abs(d[0])))


def _check_xy(x, y):
    x = as_float(x)
    y = as_float(y)
    if x.ndim != 1 or x.size < 2:
        raise ValueError(f"wavelengths must be a 1-D array of at least 2 samples, got shape {x.shape}")
    if y.ndim == 0 or y.shape[-1] != x.size:
        raise ValueError(f"values must have shape (..., {x.size}), got {y.shape}")
    if not np.all(np.diff(x) > 0):
        raise ValueError("wavelengths must be strictly increasing")
    return x, y


def interpolate_sprague(x, y, x_new):
    """Sprague (1880) interpolation of uniformly spaced samples.

    Domain: ``x`` uniform, increasing, ≥ 6 samples; ``y`` shape ``(..., N)``; ``x_new`` inside
    [x_0, x_{N-1}]. Range: ``(..., M)``, exact at the knots.

    References: T. B. Sprague, "Explanation of a new formula for interpolation", J. Inst.
    Actuaries 22:270–285, 1880; CIE 167:2005 "Recommended practice for tabulating spectral
    data for use in colour computations"; Westland et al. 2012.
    """
    x, y = _check_xy(x, y)
    if x.size < 6 or not is_uniform(x):
        raise ValueError("Sprague interpolation needs at least 6 uniformly spaced samples")
    x_new = as_float(x_new)
    h = x[1] - x[0]
    with np.errstate(all="ignore"):
        head = np.einsum("kj,...j->...k", _SPRAGUE_BOUNDARY[:2], y[..., :6])
        tail = np.einsum("kj,...j->...k", _SPRAGUE_BOUNDARY[2:], y[..., -6:])
        p = np.concatenate([head, y, tail], axis=-1)  # p[..., i + 2] = y_i
        s = (x_new - x[0]) / h
        i = np.clip(np.floor(s), 0, x.size - 2).astype(np.intp)
        t = s - i
        # p_{i-2}..p_{i+3} are p[..., i + 0 .. i + 5] in the padded array.
        P = np.stack([p[..., i + k] for k in range(6)], axis=-1)  # (..., M, 6)
        a = np.einsum("kj,...mj->...mk", _SPRAGUE_POLY, P)  # a_1..a_5, (..., M, 5)
        out = a[..., 4]
        for k in (3, 2, 1, 0):
            out = out * t + a[..., k]
        # Exact at the knots, including the last one (t = 1 in the last interval).
        return np.where(t == 1.0, P[..., 3], P[..., 2] + t * out)


def interpolate_cubic_spline(x, y, x_new):
    """Not-a-knot cubic spline interpolation (the default of ``scipy.interpolate.interp1d``).

    Domain: ``x`` increasing, ≥ 4 samples; ``y`` shape ``(..., N)``; ``x_new`` inside the range.
    Range: ``(..., M)``. Solves for the second derivatives M_i with continuity of the third
    derivative at x_1 and x_{N−2} (C. de Boor, A Practical Guide to Splines, 1978, ch. IV).
    """
    x, y = _check_xy(x, y)
    n = x.size
    if n < 4:
        raise ValueError("cubic spline interpolation needs at least 4 samples")
    x_new = as_float(x_new)
    h = np.diff(x)
    A = np.zeros((n, n))
    for i in range(1, n - 1):
        A[i, i - 1] = h[i - 1]
        A[i, i] = 2.0 * (h[i - 1] + h[i])
        A[i, i + 1] = h[i]
    A[0, 0], A[0, 1], A[0, 2] = h[1], -(h[0] + h[1]), h[0]
    A[-1, -3], A[-1, -2], A[-1, -1] = h[-1], -(h[-2] + h[-1]), h[-2]
    with np.errstate(all="ignore"):
        slopes = np.diff(y, axis=-1) / h
        rhs = np.zeros(y.shape)
        rhs[..., 1:-1] = 6.0 * np.diff(slopes, axis=-1)
        flat = rhs.reshape(-1, n).T
        M = np.linalg.solve(A, flat).T.reshape(y.shape)
        i = np.clip(np.searchsorted(x, x_new, side="right") - 1, 0, n - 2)
        hi = h[i]
        dl = x_new - x[i]
        dr = x[i + 1] - x_new
        Mi, Mj = M[..., i], M[..., i + 1]
        yi, yj = y[..., i], y[..., i + 1]
        return (Mi * dr**3 + Mj * dl**3) / (6.0 * hi) + (yi / hi - Mi * hi / 6.0) * dr + (yj / hi - Mj * hi / 6.0) * dl


def _interp_linear(x, y, x_new):
    i = np.clip(np.searchsorted(x, x_new, side="right") - 1, 0, x.size - 2)
    with np.errstate(all="ignore"):
        t = (x_new - x[i]) / (x[i + 1] - x[i])
        return y[..., i] * (1.0 - t) + y[..., i + 1] * t


def align_spectrum(wavelengths, values, target, interpolation="auto"):
    """Resample spectral ``values`` sampled at ``wavelengths`` onto the grid ``target``.

    As colour-science's ``SpectralDistribution.align``: with ``interpolation="auto"`` (its
    default for measured data) Sprague for uniform data (≥ 6 samples), not-a-knot cubic
    spline otherwise (≥ 4 samples), linear for 2–3 samples; with ``"linear"``, piecewise
    linear (what colour-science's CIE illuminant datasets use, following CIE 015's advice
    to interpolate illuminant tables linearly). Inside the input's range only, then
    constant extrapolation of the first / last interpolated value outside it.

    Domain: ``wavelengths`` 1-D increasing (nm); ``values`` shape ``(..., N)``; ``target``
    1-D increasing. Range: ``(..., len(target))``.
    """
    x, y = _check_xy(wavelengths, values)
    target = as_float(target)
    inside = (target >= x[0]) & (target <= x[-1])
    if not inside.any():
        raise ValueError(
            f"spectral data {x[0]:g}–{x[-1]:g} nm does not overlap the grid {target[0]:g}–{target[-1]:g} nm"
        )
    t_in = target[inside]
    if interpolation not in ("auto", "linear"):
        raise ValueError(f"interpolation must be 'auto' or 'linear', got {interpolation!r}")
    if x.size == t_in.size and np.array_equal(x, t_in):
        v_in = y.copy()
    elif interpolation == "linear":
        v_in = _interp_linear(x, y, t_in)
    elif x.size >= 6 and is_uniform(x):
        v_in = interpolate_sprague(x, y, t_in)
    elif x.size >= 4:
        v_in = interpolate_cubic_spline(x, y, t_in)
    else:
        v_in = _interp_linear(x, y, t_in)
    idx = np.cumsum(inside) - 1  # index into t_in of the last inside point at or before each target
    first = int(np.argmax(inside))
    idx = np.where(np.arange(target.size) < first, 0, idx)
    return v_in[..., idx]


# --------------------------------------------------------------------------- tables


@lru_cache(maxsize=None)
def _illuminant_cached(name: str):
    wl, values = presets.illuminant(name)
    wl.setflags(write=False)
    values.setflags(write=False)
    return wl, values


@lru_cache(maxsize=None)
def _cmfs_cached(observer: str):
    wl, xyz = presets.cmfs(observer)
    wl.setflags(write=False)
    xyz.setflags(write=False)
    return wl, xyz


def cmfs(observer="1931"):
    """CIE colour-matching functions from ``presets/cie``: ``(wl[471], xyz_bar[471, 3])`` (read-only).

    ``observer``: "1931" / "2" / "CIE 1931 2 Degree Standard Observer" (default), or
    "1964" / "10" / "CIE 1964 10 Degree Standard Observer". 360–830 nm, 1 nm.
    """
    return _cmfs_cached(str(observer))


def _spectrum(spec, what):
    """``spec`` as ``(wl, values)``: a preset illuminant name or a pair of arrays."""
    if isinstance(spec, str):
        return _illuminant_cached(spec)
    try:
        wl, values = spec
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be a preset name or a (wavelengths, values) pair") from None
    return as_float(wl), as_float(values)


# --------------------------------------------------------------------------- sd_to_XYZ


def sd_to_XYZ(wavelengths, values, illuminant=None, observer="1931", k=None, scale=None,
              interpolation="auto", illuminant_interpolation=None):
    """Spectral distribution(s) → CIE XYZ tristimulus values (CIE 015:2018).

    X = k Σ φ(λ) x̄(λ) Δλ, Y, Z likewise, on the CMFs' 1 nm grid (360–830 nm), after the
    input is aligned to that grid as described in the module docstring.

    Parameters
    ----------
    wavelengths
        1-D increasing wavelengths in nm (in air, as the CIE tables), shape ``(N,)``.
    values
        Spectral values, shape ``(..., N)``: reflectance/transmittance factors if an
        ``illuminant`` is given, otherwise a spectral concentration of a radiometric
        quantity (e.g. W m⁻² sr⁻¹ nm⁻¹).
    illuminant
        ``None`` for self-luminous spectra (emitters), or the illuminant's relative SPD,
        either a preset name (``"D65"``, ``"A"``, ...; see ``presets/illuminants``) or a
        ``(wavelengths, values)`` pair.
    observer
        "1931" (CIE 1931 2°, default) or "1964" (CIE 1964 10°), or the colour-science names.
    k
        Normalisation constant. If given, XYZ = k Σ S R x̄ Δλ (reflectance) or k Σ Φ x̄ Δλ
        (emitter) exactly as CIE 015 writes it. ``k = K_M`` (683 lm/W) on an emitter gives Y
        in photometric units (lm, cd, lx, cd/m² for W, W/sr, W/m², W/(m² sr) per nm).
    scale
        Used when ``k`` is None. Reflectance: k = scale / Σ S ȳ Δλ, so the perfect reflecting
        diffuser has Y = ``scale`` (default 100, as colour-science; 1 gives Y in [0, 1]).
        Emitter: ``None`` (default) means k = 1, absolute XYZ in the units of ``values`` × nm;
        a number means k = scale / Σ ȳ Δλ, i.e. the equal-energy spectrum of value 1 gets
        Y = scale (colour-science's relative convention is ``scale=100``).
    interpolation
        How ``values`` are brought to the 1 nm grid: ``"auto"`` (Sprague / cubic spline,
        colour-science's default) or ``"linear"``.
    illuminant_interpolation
        The same for the illuminant. ``None`` means ``"linear"`` for a preset name (as
        colour-science's ``SDS_ILLUMINANTS``, which carry a linear interpolator) and
        ``"auto"`` for a ``(wavelengths, values)`` pair (as a new colour-science
        ``SpectralDistribution``).

    Returns
    -------
    XYZ, shape ``(..., 3)``. Domain/Range: reflectances in [0, 1] give Y in [0, scale].

    Differences from colour-science 0.4.6 ``sd_to_XYZ(..., method="Integration")``: none in
    the arithmetic when the full 360–830 nm CMFs are passed to it, except that with an
    explicit ``k`` *and* an illuminant it divides the result by 100 (its "as percentage"
    convention; without an illuminant it uses illuminant E = 100, which cancels it). We
    follow CIE 015: no hidden factor. Its default ``method="ASTM E308"`` and its 360–780 nm
    default CMFs differ slightly (module docstring).

    References: CIE 015:2018 *Colorimetry*, 4th ed.; CIE 167:2005; ASTM E308-15.
    """
    wl_c, xyz_bar = cmfs(observer)
    dw = float(wl_c[1] - wl_c[0])
    R = align_spectrum(wavelengths, values, wl_c, interpolation)
    with np.errstate(all="ignore"):
        if illuminant is None:
            if k is None:
                k = 1.0 if scale is None else float(scale) / (np.sum(xyz_bar[:, 1]) * dw)
            phi = R
        else:
            if illuminant_interpolation is None:
                illuminant_interpolation = "linear" if isinstance(illuminant, str) else "auto"
            wl_s, S = _spectrum(illuminant, "illuminant")
            S = align_spectrum(wl_s, S, wl_c, illuminant_interpolation)
            if S.ndim != 1:
                raise ValueError("illuminant must be a single spectrum")
            if k is None:
                k = (100.0 if scale is None else float(scale)) / (np.sum(S * xyz_bar[:, 1]) * dw)
            phi = R * S
        return as_float(k) * np.einsum("...n,nc->...c", phi, xyz_bar) * dw
