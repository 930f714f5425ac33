"""Wavelengths, colour matching and spectra of the reference.

* Colour matching: the CIE 1931 2° functions as colour-science tabulates them (360–830 nm,
  1 nm), linear in between. Luminance is K_m ∫ L ȳ dλ with K_m = 683 lm/W, so an
  emitter of luminance ℓ seen directly measures ℓ cd/m².
* Wavelengths: a density p(λ) piecewise constant on the 1 nm cells, a mixture of the
  normalised ȳ, x̄, z̄ and the uniform density with the weights ``MIXTURE``: mostly ȳ, as
  luminance is the quantity the tests compare, with enough of x̄ and z̄ that X and Z keep
  a moderate variance, and a uniform floor. A set of K wavelengths is stratified in p's
  primary space with one shared uniform offset: λ_k = P⁻¹((k + u) / K); each carries the
  weight 1 / (K p(λ_k)). With K = 8 the relative standard deviation of one set's
  estimate of ∫ x̄, ∫ ȳ, ∫ z̄ under a flat spectrum is about 9 %, 1.4 %, 18 %.
* Spectra: the scene's Fourier-basis rows decoded exactly at the wavelengths in use
  (``core.spectra.moments.reconstruct``); an emitter's shape is scaled to radiance in
  W/(m² sr nm) by its luminance over K_m ∫ shape · ȳ dλ (trapezoid rule on a 0.25 nm grid).
"""
import functools

import numpy as np

from spectral_gi.core import constants as C
from spectral_gi.core.spectra import moments

MIXTURE = {"y": 0.6, "x": 0.15, "z": 0.15, "uniform": 0.1}


@functools.lru_cache(maxsize=1)
def cie_1931():
    """(wavelengths (471,), x̄ ȳ z̄ (471, 3)) from colour-science."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import colour
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    wl = np.asarray(cmfs.wavelengths, dtype=np.float64)
    xyz = np.asarray(cmfs.values, dtype=np.float64)
    keep = (wl >= C.LAMBDA_MIN) & (wl <= C.LAMBDA_MAX)
    return wl[keep], xyz[keep]


def cmf(lam):
    """x̄, ȳ, z̄ at wavelengths ``lam`` (any shape): (..., 3)."""
    wl, xyz = cie_1931()
    return np.stack([np.interp(lam, wl, xyz[:, j], left=0.0, right=0.0) for j in range(3)], axis=-1)


class WavelengthSampler:
    """The density p(λ) of the module docstring and its inverse cdf."""

    def __init__(self):
        wl, xyz = cie_1931()
        self.edges = wl
        width = np.diff(wl)
        cell = 0.5 * (xyz[1:] + xyz[:-1]) * width[:, None]  # each cell's share of ∫ x̄, ∫ ȳ, ∫ z̄
        cell /= cell.sum(axis=0)
        mass = (MIXTURE["x"] * cell[:, 0] + MIXTURE["y"] * cell[:, 1] + MIXTURE["z"] * cell[:, 2]
                + MIXTURE["uniform"] * width / width.sum())
        self.density = mass / width
        self.cdf = np.concatenate([[0.0], np.cumsum(mass)])
        self.cdf /= self.cdf[-1]

    def pdf(self, lam):
        i = np.clip(np.searchsorted(self.edges, lam, side="right") - 1, 0, self.density.size - 1)
        return self.density[i]

    def stratified(self, k, u):
        """k wavelengths stratified with the offset u ∈ [0, 1): (λ (k,), weight 1/(k p(λ)) (k,))."""
        v = (np.arange(k) + u) / k
        lam = np.interp(v, self.cdf, self.edges)
        return lam, 1.0 / (k * self.pdf(lam))


def decode(table, row, lam):
    """Row ``row`` of a scene's SpectrumTable at wavelengths ``lam``."""
    return moments.reconstruct(table.coeffs[row], int(table.kind[row]), np.asarray(lam, dtype=np.float64))


def radiance_scale(table, row, luminance):
    """The factor turning emission shape ``row`` into spectral radiance of ``luminance`` cd/m²."""
    if luminance == 0.0:
        return 0.0
    g = np.linspace(C.LAMBDA_MIN, C.LAMBDA_MAX, 4 * int(C.LAMBDA_MAX - C.LAMBDA_MIN) + 1)
    f = decode(table, row, g) * cmf(g)[:, 1]
    y = float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(g)))
    if not y > 0.0:
        raise ValueError("reference: an emission spectrum without visible power")
    return luminance / (C.K_M * y)
