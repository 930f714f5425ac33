"""The film: per-pixel sums of CIE XYZ, and its development into images.

The kernel adds, per sample, X, Y, Z (∫ L x̄ dλ etc., with L in W/(m² sr nm), so Y
times K_m is luminance in cd/m²), the sample count, and Y² for the variance estimate.
Development is NumPy, not kernels.
"""
from dataclasses import dataclass

import numpy as np

from . import constants as C
from .colour import XYZ_to_sRGB_linear


class Film:
    """Per-pixel sums. ``spectral_bins`` > 0 also keeps the spectral radiance in that many
    equal bins of [LAMBDA_MIN, LAMBDA_MAX] (for spectral OpenEXR output)."""

    def __init__(self, width, height, spectral_bins=0):
        self.width = int(width)
        self.height = int(height)
        self.sums = np.zeros((self.height, self.width, C.FILM_CHANNELS), dtype=np.float64)
        n = int(spectral_bins)
        self.spectral = np.zeros((self.height, self.width, n) if n > 0 else (1, 1, 0), dtype=np.float64)
        self.spp = 0

    @property
    def spectral_bins(self):
        return self.spectral.shape[2]

    def bin_centres(self):
        """Centre wavelength (nm) of each spectral bin."""
        n = self.spectral_bins
        w = (C.LAMBDA_MAX - C.LAMBDA_MIN) / max(n, 1)
        return C.LAMBDA_MIN + w * (np.arange(n) + 0.5)

    def spectral_radiance(self):
        """(H, W, B) mean spectral radiance per bin, W/(m² sr nm)."""
        n = np.maximum(self.sums[..., 3], 1.0)
        return self.spectral / n[..., None]

    def copy(self):
        f = Film(self.width, self.height)
        f.sums = self.sums.copy()
        f.spectral = self.spectral.copy()
        f.spp = self.spp
        return f

    def develop(self):
        return develop(self.sums)


@dataclass
class Developed:
    XYZ: np.ndarray  # (H, W, 3) mean CIE XYZ per pixel; Y = 1 is 683 cd/m²
    rgb: np.ndarray  # (H, W, 3) linear Rec.709 (Blender's scene-linear), same scale as XYZ
    luminance: np.ndarray  # (H, W) cd/m²
    variance: np.ndarray  # (H, W) variance of the pixel's mean luminance, (cd/m²)²
    count: np.ndarray  # (H, W) samples per pixel


def develop(sums):
    n = sums[..., 3]
    safe = np.maximum(n, 1.0)
    XYZ = sums[..., :3] / safe[..., None]
    XYZ[n == 0] = 0.0
    mean_y = XYZ[..., 1]
    mean_y2 = sums[..., 4] / safe
    var_sample = np.maximum(mean_y2 - mean_y * mean_y, 0.0) * safe / np.maximum(safe - 1.0, 1.0)
    variance = (C.K_M ** 2) * var_sample / safe
    variance[n < 2] = np.inf
    return Developed(XYZ=XYZ, rgb=XYZ_to_sRGB_linear(XYZ), luminance=C.K_M * mean_y,
                     variance=variance, count=n.copy())
