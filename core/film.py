"""The film: per-pixel sums of CIE XYZ, and its development into images.

The kernel adds, per sample, X, Y, Z (∫ L x̄ dλ etc., with L in W/(m² sr nm), so Y
times K_m is luminance in cd/m²), the sample count, and Y² for the variance estimate.
Development is NumPy, not kernels.
"""
from dataclasses import dataclass

import numpy as np

from . import constants as C
from .colour import XYZ_to_Lab, XYZ_to_Luv, XYZ_to_sRGB_linear, XYZ_to_xyY, chromatic_adaptation_Bradford

D65_XY = (0.3127, 0.3290)


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
    xyY: np.ndarray = None  # (H, W, 3) chromaticity x, y and luminance Y in cd/m²
    Lab: np.ndarray = None  # (H, W, 3) CIE L*a*b* against the reference white below
    Luv: np.ndarray = None  # (H, W, 3) CIE L*u*v* against the reference white below
    white_luminance: float = C.K_M  # cd/m² of the reference white (L* = 100)
    white_xy: tuple = D65_XY  # chromaticity of the reference white


def develop(sums, white_luminance=C.K_M, white_balance=None):
    """Turn film sums into images.

    white_luminance: luminance (cd/m²) of the white that L* = 100 refers to; the default
    683 cd/m² is Blender's RGB (1, 1, 1). The reference white's chromaticity is D65.
    white_balance: None, or the xy chromaticity of the scene's light: then ``rgb`` (and
    only ``rgb``) is adapted from that white to D65 with Bradford's transform, as a
    camera's white balance would; XYZ, xyY, Lab and Luv stay unadapted.
    """
    n = sums[..., 3]
    safe = np.maximum(n, 1.0)
    XYZ = sums[..., :3] / safe[..., None]
    XYZ[n == 0] = 0.0
    mean_y = XYZ[..., 1]
    mean_y2 = sums[..., 4] / safe
    var_sample = np.maximum(mean_y2 - mean_y * mean_y, 0.0) * safe / np.maximum(safe - 1.0, 1.0)
    variance = (C.K_M ** 2) * var_sample / safe
    variance[n < 2] = np.inf
    rgb_xyz = XYZ
    d65 = np.array([D65_XY[0] / D65_XY[1], 1.0, (1 - D65_XY[0] - D65_XY[1]) / D65_XY[1]])
    if white_balance is not None:
        wx, wy = float(white_balance[0]), float(white_balance[1])
        src = np.array([wx / wy, 1.0, (1 - wx - wy) / wy])
        rgb_xyz = chromatic_adaptation_Bradford(XYZ, src, d65)
    scale = C.K_M / float(white_luminance)  # film units → units of the reference white
    xyY = XYZ_to_xyY(XYZ, illuminant=np.array(D65_XY))
    xyY[..., 2] *= C.K_M
    return Developed(XYZ=XYZ, rgb=XYZ_to_sRGB_linear(rgb_xyz), luminance=C.K_M * mean_y,
                     variance=variance, count=n.copy(), xyY=xyY,
                     Lab=XYZ_to_Lab(XYZ * scale, np.array(D65_XY)), Luv=XYZ_to_Luv(XYZ * scale, np.array(D65_XY)),
                     white_luminance=float(white_luminance), white_xy=D65_XY)
