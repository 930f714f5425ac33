"""Spectra from RGB colours (uplifting) and from tabulated data, as Fourier coefficients.

Reflectances: the Mallett–Yuksel (2019) sRGB basis, r·B_r + g·B_g + b·B_b, which stays
within [0, 1] for colours in the unit cube and sums to a flat 1 for white; its moments
are linear in the colour. Emission colours: the same reflectance times CIE D65, so a
white emitter has D65's shape and renders as RGB (1, 1, 1).
"""
import numpy as np

from .. import constants as C
from ..colour import XYZ_to_sRGB_linear, luminance_rec709
from . import basis, fit, moments


def reflectance_from_rgb(rgb, n_coeffs=C.N_COEFFS_DEFAULT, exact=True):
    """Bounded spectrum coefficients for a linear Rec.709 reflectance (clipped to [0, 1]).

    exact=True (materials): the moments are corrected so that the colour under D65 is
    reproduced (round trip ΔE00 < 0.01; about 30 ms). exact=False (textures): the
    projection of the Mallett–Yuksel spectrum alone (ΔE00 ≈ 0.06 on average).
    """
    if exact:
        return fit.reflectance_from_rgb_exact(np.clip(basis.rgb_triple(rgb), 0.0, 1.0), n_coeffs)
    return basis.reflectance(rgb, n_coeffs)


def emission_from_rgb(rgb, n_coeffs=C.N_COEFFS_DEFAULT, exact=True):
    """Unbounded spectrum coefficients for the *shape* of an emitter's linear Rec.709 colour.

    exact=True corrects the moments so the chromaticity is reproduced exactly.
    """
    if exact:
        return fit.emission_shape_from_rgb_exact(np.maximum(basis.rgb_triple(rgb), 0.0), n_coeffs)
    return basis.emission_shape(rgb, n_coeffs)


def reflectance_from_samples(wavelengths, values, n_coeffs=C.N_COEFFS_DEFAULT):
    v = np.asarray(values, dtype=np.float64)
    if np.any(v < 0.0) or np.any(v > 1.0):
        raise ValueError("a reflectance spectrum must lie within [0, 1]")
    return moments.moments_from_samples(wavelengths, v, n_coeffs)


def emission_from_samples(wavelengths, values, n_coeffs=C.N_COEFFS_DEFAULT):
    v = np.asarray(values, dtype=np.float64)
    if np.any(v < 0.0):
        raise ValueError("an emission spectrum must be non-negative")
    return moments.moments_from_samples(wavelengths, v, n_coeffs)


# ----------------------------------------------------------------- back to RGB (for Cycles)


def reflectance_to_rgb(coeffs):
    """Linear Rec.709 colour of a reflectance spectrum under CIE D65 (white → (1, 1, 1)).

    The colour a Cycles material needs to look like this spectrum under a white light.
    """
    return XYZ_to_sRGB_linear(fit.reflectance_XYZ(np.asarray(coeffs, np.float64)))


def emission_to_rgb(coeffs, luminance):
    """Blender colour and strength of an emitter: ``(rgb, strength)``.

    ``rgb`` is the linear Rec.709 colour of the emission spectrum with luminance weight
    Y(rgb) = 1 (negative components, outside the Rec.709 gamut, are clipped);
    ``strength`` = luminance / 683, so strength · rgb is Blender's radiance for it.
    """
    XYZ = fit.emission_XYZ(np.asarray(coeffs, np.float64))
    if not XYZ[1] > 0:
        return np.ones(3), 0.0
    rgb = np.maximum(XYZ_to_sRGB_linear(XYZ / XYZ[1]), 0.0)
    rgb = rgb / luminance_rec709(rgb)
    return rgb, float(luminance) / C.K_M


def reflectance_from_rgb_array(rgb, n_coeffs=C.N_COEFFS_DEFAULT):
    """Coefficients for every texel of a linear Rec.709 texture (..., 3) → (..., n_coeffs).

    The fast, linear uplift (the moments of the Mallett–Yuksel spectrum), done once at
    export; every texel's spectrum stays within [0, 1]. Non-finite texels become black.
    """
    a = np.asarray(rgb, dtype=np.float64)
    if a.shape[-1] != 3:
        raise ValueError(f"expected an (..., 3) RGB array, got shape {a.shape}")
    a = np.clip(np.nan_to_num(a, nan=0.0, posinf=1.0, neginf=0.0), 0.0, 1.0)
    return a @ basis.basis_moments(n_coeffs, False).T
