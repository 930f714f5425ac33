"""Denoising of the beauty image with Intel Open Image Denoise (OIDN).

OIDN's ``RT`` filter is a neural network trained on path-traced images; it takes the noisy
colour and two guides the film records at the first non-specular hit, the albedo and the
shading normal, and returns an image that is smooth where the guides are (Áfra, *Intel
Open Image Denoise*, https://www.openimagedenoise.org/documentation.html). The result is a
plausible picture, not a measurement: the filter redistributes energy between pixels in
ways no estimator's variance accounts for, so only the display image (Blender's Combined
pass, the RGB of an output file) is ever denoised; luminance, illuminance, XYZ and the
colour-science outputs stay the unbiased Monte Carlo estimates.

The binding is the ``pyoidn`` package (PyPI), imported on first use; without it
:func:`denoise` raises :class:`DenoiseUnavailable`.
"""
from __future__ import annotations

import importlib.util

import numpy as np

PACKAGE = "pyoidn"


class DenoiseUnavailable(RuntimeError):
    """No OIDN binding is installed."""


def denoise_available():
    """True if the OIDN binding can be imported."""
    return importlib.util.find_spec(PACKAGE) is not None


def _guide(a, name, shape, lo, hi):
    if a is None:
        return None
    a = np.asarray(a, dtype=np.float64)
    if a.shape != shape:
        raise ValueError(f"denoise: the {name} guide is {a.shape}, the image {shape}")
    return np.ascontiguousarray(np.clip(np.nan_to_num(a, nan=0.0, posinf=hi, neginf=lo), lo, hi), np.float32)


def denoise(rgb, albedo=None, normal=None, quality="high"):
    """The denoised (H, W, 3) float32 of linear HDR ``rgb`` (negative and non-finite values read as 0).

    albedo: (H, W, 3) first-hit reflectance in [0, 1]; normal: (H, W, 3) shading normals in
    [-1, 1] (Developed.albedo and Developed.normal); both optional, both improve edges and
    texture detail. quality: 'high', 'balanced' or 'fast'.
    """
    if not denoise_available():
        raise DenoiseUnavailable(f"denoising needs Intel Open Image Denoise: pip install {PACKAGE}")
    import pyoidn

    colour = np.asarray(rgb, dtype=np.float64)
    if colour.ndim != 3 or colour.shape[2] != 3 or min(colour.shape[:2]) == 0:
        raise ValueError(f"denoise: the image must be (H, W, 3), got {colour.shape}")
    colour = np.ascontiguousarray(np.maximum(np.nan_to_num(colour, nan=0.0, posinf=0.0, neginf=0.0), 0.0),
                                  np.float32)
    a = _guide(albedo, "albedo", colour.shape, 0.0, 1.0)
    n = _guide(normal, "normal", colour.shape, -1.0, 1.0)
    if a is None and n is not None:
        raise ValueError("denoise: OIDN takes a normal guide only together with an albedo guide")
    return pyoidn.denoise(colour, albedo=a, normal=n, hdr=True, quality=quality)
