"""Spectra from colours: the compendium's item 65 and a moment fit that keeps colour exactly.

* ``glassner1989``: the compendium's item 65 (after Glassner, "How to Derive a Spectrum
  from an RGB Triplet", IEEE CG&A 9(4), 1989): C(λ) = a F1 + b F2 + c F3 with three
  fixed basis functions, (a, b, c) solved from a 3×3 system so that C has the given
  XYZ. With the Fourier basis F1 = 1, F2 = ½(1 + sin 2π(λ−380)/400),
  F3 = ½(1 + cos 2π(λ−380)/400) on [380, 780] nm, or with three Dirac impulses.
  Exact XYZ, but the spectrum can leave [0, 1] (it is not a reflectance).
* ``reflectance_from_XYZ`` (method "Peters 2019"): the bounded-moment spectrum whose
  colour under CIE D65 equals the target. It starts from the Mallett–Yuksel uplift and
  corrects the moments by Gauss–Newton steps of minimum norm, so it stays a valid
  bounded spectrum (in [0, 1]) while the reconstruction's XYZ converges to the target.
"""
from __future__ import annotations

import functools

import numpy as np

from .. import constants as C
from ..io import presets
from ..colour import MATRIX_REC709_TO_XYZ, MATRIX_XYZ_TO_REC709
from . import basis, moments

GLASSNER_RANGE = (380.0, 780.0)


def glassner1989_basis(wavelengths, basis="fourier"):
    """The three Fourier basis functions of item 65 on [380, 780] nm (zero outside): (N, 3)."""
    wl = np.asarray(wavelengths, dtype=np.float64)
    if basis != "fourier":
        raise ValueError(f"unknown basis {basis!r}; tabulated bases: 'fourier'")
    x = 2.0 * np.pi * (wl - GLASSNER_RANGE[0]) / (GLASSNER_RANGE[1] - GLASSNER_RANGE[0])
    inside = (wl >= GLASSNER_RANGE[0]) & (wl <= GLASSNER_RANGE[1])
    f = np.stack([np.ones_like(wl), 0.5 * (1.0 + np.sin(x)), 0.5 * (1.0 + np.cos(x))], axis=-1)
    return f * inside[..., None]


@functools.lru_cache(maxsize=4)
def _cmf_grid(observer="1931"):
    g = moments.grid()
    wl, xyz = presets.cmfs(observer)
    return g, np.stack([np.interp(g, wl, xyz[:, k], left=0.0, right=0.0) for k in range(3)], axis=1)


def glassner1989(XYZ, basis="fourier", dirac_wavelengths=(450.0, 550.0, 610.0), observer="1931"):
    """Item 65: a spectrum with tristimulus values ``XYZ`` (∫ C x̄ dλ = X, …, 1 nm sums).

    Returns ``(wavelengths, values)``: for the Fourier basis the spectrum on the 1 nm
    grid; for ``basis="dirac"`` the three impulse wavelengths and their weights.
    """
    g, cmf = _cmf_grid(observer)
    target = np.asarray(XYZ, dtype=np.float64)
    if basis == "dirac":
        lw = np.asarray(dirac_wavelengths, dtype=np.float64)
        m = np.stack([np.interp(lw, g, cmf[:, k]) for k in range(3)])  # rows X, Y, Z; columns impulses
        return lw, np.linalg.solve(m, target)
    f = glassner1989_basis(g, basis)
    m = cmf.T @ f * C.LAMBDA_STEP  # m[i, j] = ∫ F_j cmf_i dλ
    abc = np.linalg.solve(m, target)
    return g, f @ abc


@functools.lru_cache(maxsize=4)
def _d65_weights(observer="1931"):
    """D65-weighted matching functions on the grid, normalised so that a perfect white
    reflector has exactly the XYZ of Rec.709's white (x, y) = (0.3127, 0.3290), Y = 1.

    The CIE D65 table summed with the 1 nm CMFs gives (0.31271, 0.32902); the 1e-5
    difference (ΔE00 ≈ 0.014 for white) is the rounding of the defined white point, and
    is removed here by scaling X and Z so that RGB (1, 1, 1) round-trips to white.
    """
    g, cmf = _cmf_grid(observer)
    dwl, d65 = presets.illuminant("D65")
    ill = np.interp(g, dwl, d65, left=0.0, right=0.0)
    w = ill[:, None] * cmf
    w = w / w[:, 1].sum()
    white = MATRIX_REC709_TO_XYZ.sum(axis=1)
    return w * (white / w.sum(axis=0))[None, :]


def reflectance_XYZ(coeffs, observer="1931"):
    """XYZ (Y of white = 1) of a bounded spectrum under CIE D65."""
    r = moments.reconstruct_bounded(coeffs, moments.grid())
    return r @ _d65_weights(observer)


def _valid(c):
    return moments.check_coefficients(c, C.SPECTRUM_BOUNDED) is None


def reflectance_from_XYZ(XYZ, n_coeffs=C.N_COEFFS_DEFAULT, method="Peters 2019", tolerance=1e-7,
                         max_iterations=30):
    """Bounded coefficients of a reflectance whose colour under D65 is ``XYZ`` (white Y = 1).

    method "Peters 2019": moment fit (see module docstring), colour reproduced to
    ``tolerance`` in XYZ when the colour is reachable by a reflectance; otherwise the
    closest the iteration gets. method "Glassner 1989": item 65's Fourier spectrum,
    clipped to [0, 1] and projected onto the moments (colour then only approximate).
    """
    target = np.asarray(XYZ, dtype=np.float64)
    if target.shape != (3,) or not np.all(np.isfinite(target)):
        raise ValueError(f"expected a finite XYZ triple, got {XYZ!r}")
    if method == "Glassner 1989":
        d65 = _d65_weights()
        g, cmf = _cmf_grid()
        # Solve against the D65-weighted matching functions so the result is a reflectance.
        f = glassner1989_basis(g)
        abc = np.linalg.solve(d65.T @ f, target)
        spec = np.clip(f @ abc, 0.0, 1.0)
        return moments.moments_from_samples(g, spec, n_coeffs)
    if method != "Peters 2019":
        raise ValueError(f"unknown method {method!r}; use 'Peters 2019' or 'Glassner 1989'")
    rgb = np.clip(MATRIX_XYZ_TO_REC709 @ target, 0.0, 1.0)
    c = basis.reflectance(rgb, n_coeffs)
    if target[1] <= 0.0 or c[0] <= 1e-6:
        return c
    return _gauss_newton(c, target, reflectance_XYZ, lambda t: _valid(t) and 0.0 < t[0] < 1.0,
                         tolerance, max_iterations)


def _gauss_newton(c, target, xyz_of, valid, tolerance, max_iterations):
    """Minimum-norm Gauss–Newton corrections of the moments until xyz_of(c) = target."""
    eps = 1e-6
    for _ in range(max_iterations):
        cur = xyz_of(c)
        r = target - cur
        if np.max(np.abs(r)) < tolerance * max(1.0, abs(target[1])):
            break
        jac = np.empty((3, c.size))
        for j in range(c.size):
            dc = np.zeros_like(c)
            dc[j] = eps * max(1.0, abs(c[0]))
            jac[:, j] = (xyz_of(c + dc) - cur) / dc[j]
        step = np.linalg.lstsq(jac, r, rcond=None)[0]
        t = 1.0
        while t > 1e-4:
            trial = c + t * step
            if valid(trial) and np.max(np.abs(target - xyz_of(trial))) < np.max(np.abs(r)):
                c = trial
                break
            t *= 0.5
        else:
            break  # no step improves: the colour is at the edge of what the spectra reach
    return c


def emission_XYZ(coeffs, observer="1931"):
    """XYZ (1 nm sums of the reconstruction times x̄, ȳ, z̄) of an unbounded spectrum."""
    _, cmf = _cmf_grid(observer)
    return moments.reconstruct_unbounded(coeffs, moments.grid()) @ cmf * C.LAMBDA_STEP


def emission_shape_from_rgb_exact(rgb, n_coeffs=C.N_COEFFS_DEFAULT):
    """Unbounded coefficients of an emission shape whose chromaticity is that of linear
    Rec.709 ``rgb``: the D65-weighted uplift, corrected like ``reflectance_from_XYZ``."""
    c = basis.emission_shape(rgb, n_coeffs)
    a = np.maximum(np.asarray(rgb, dtype=np.float64).reshape(3), 0.0)
    if a.max() <= 0.0:
        a = np.ones(3)
    xyz = MATRIX_REC709_TO_XYZ @ a
    cur = emission_XYZ(c)
    target = xyz * (cur[1] / xyz[1]) if xyz[1] > 0 else cur
    return _gauss_newton(c, target, emission_XYZ,
                         lambda t: moments.check_coefficients(t, C.SPECTRUM_UNBOUNDED) is None and t[0] > 0,
                         1e-7, 30)


def reflectance_from_rgb_exact(rgb, n_coeffs=C.N_COEFFS_DEFAULT):
    """Bounded coefficients whose colour under D65 is the linear Rec.709 ``rgb`` (clipped to [0, 1])."""
    a = np.clip(np.asarray(rgb, dtype=np.float64).reshape(3), 0.0, 1.0)
    return reflectance_from_XYZ(MATRIX_REC709_TO_XYZ @ a, n_coeffs)
