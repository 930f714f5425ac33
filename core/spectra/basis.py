"""The Mallett–Yuksel (2019) sRGB basis projected onto Fourier moments: the linear uplift.

r·B_r + g·B_g + b·B_b stays within [0, 1] for colours in the unit cube and sums to a flat
1 for white; its moments are linear in the colour. Emission shapes use the same basis
times CIE D65. :mod:`.uplift` and :mod:`.fit` both start from these projections.
"""
import functools

import numpy as np

from .. import constants as C
from ..io import presets
from . import moments


@functools.lru_cache(maxsize=None)
def basis_moments(n_coeffs, emission):
    wl, basis = presets.mallett2019_basis()
    if emission:
        dwl, d65 = presets.illuminant("D65")
        basis = basis * np.interp(wl, dwl, d65)[:, None] / 100.0
    return moments.moments_from_samples(wl, basis, n_coeffs).T.copy()  # (n, 3)


def rgb_triple(rgb):
    a = np.asarray(rgb, dtype=np.float64).reshape(-1)[:3]
    if a.size != 3 or not np.all(np.isfinite(a)):
        raise ValueError(f"expected a finite RGB triple, got {rgb!r}")
    return a


def reflectance(rgb, n_coeffs=C.N_COEFFS_DEFAULT):
    """Moments of the Mallett–Yuksel reflectance of linear Rec.709 ``rgb`` (clipped to [0, 1])."""
    return basis_moments(n_coeffs, False) @ np.clip(rgb_triple(rgb), 0.0, 1.0)


def emission_shape(rgb, n_coeffs=C.N_COEFFS_DEFAULT):
    """Moments of the D65-weighted basis for an emitter's colour, scaled so its peak channel is 1."""
    a = np.maximum(rgb_triple(rgb), 0.0)
    peak = a.max()
    if peak <= 0.0:
        a = np.ones(3)
        peak = 1.0
    return basis_moments(n_coeffs, True) @ (a / peak)
