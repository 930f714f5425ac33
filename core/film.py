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


AOV_CHANNELS = 9  # albedo XYZ, normal xyz, depth sum, number of samples that hit, transparent samples
FILM_FORMAT = "spectral-gi-film"
FILM_VERSION = 2  # 2: the AOVs gained the transparent-sample count (version 1 films load as opaque)


class Film:
    """Per-pixel sums. ``spectral_bins`` > 0 also keeps the spectral radiance in that many
    equal bins of [LAMBDA_MIN, LAMBDA_MAX] (for spectral OpenEXR output). ``aov`` holds
    the sums of the albedo, normal and depth passes (see :func:`develop`)."""

    def __init__(self, width, height, spectral_bins=0):
        self.width = int(width)
        self.height = int(height)
        self.sums = np.zeros((self.height, self.width, C.FILM_CHANNELS), dtype=np.float64)
        n = int(spectral_bins)
        self.spectral = np.zeros((self.height, self.width, n) if n > 0 else (1, 1, 0), dtype=np.float64)
        self.aov = np.zeros((self.height, self.width, AOV_CHANNELS), dtype=np.float64)
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
        f.aov = self.aov.copy()
        f.spp = self.spp
        return f

    def develop(self, white_luminance=C.K_M, white_balance=None):
        return develop(self.sums, white_luminance, white_balance, aov=self.aov)

    def save(self, path):
        """Write the film (a checkpoint to resume from) as one .npz, atomically."""
        import io
        from pathlib import Path

        from .io.atomic import write_bytes

        buf = io.BytesIO()
        np.savez_compressed(buf, format=np.array(FILM_FORMAT), version=np.array(FILM_VERSION),
                            spp=np.array(self.spp, np.int64), sums=self.sums, spectral=self.spectral, aov=self.aov)
        write_bytes(Path(path), buf.getvalue())
        return Path(path)

    @classmethod
    def load(cls, path):
        """Read a film written by :meth:`save`; ValueError naming the problem otherwise."""
        try:
            with np.load(path, allow_pickle=False) as z:
                data = {k: z[k] for k in z.files}
        except Exception as e:  # OSError, zipfile.BadZipFile, ValueError
            raise ValueError(f"film {path}: cannot read ({e})") from None
        version = int(data.get("version", -1))
        if str(data.get("format", "")) != FILM_FORMAT or version not in (1, FILM_VERSION):
            raise ValueError(f"film {path}: not a spectral-gi film of version 1 or {FILM_VERSION}")
        sums, spectral, aov = data["sums"], data["spectral"], data["aov"]
        if version == 1 and aov.ndim == 3 and aov.shape[2] == AOV_CHANNELS - 1:
            aov = np.concatenate([aov, np.zeros(aov.shape[:2] + (1,))], axis=2)  # no transparent samples
        if sums.ndim != 3 or sums.shape[2] != C.FILM_CHANNELS or aov.shape != sums.shape[:2] + (AOV_CHANNELS,):
            raise ValueError(f"film {path}: unexpected array shapes {sums.shape}, {aov.shape}")
        f = cls(sums.shape[1], sums.shape[0])
        f.sums = np.ascontiguousarray(sums, np.float64)
        f.spectral = np.ascontiguousarray(spectral, np.float64)
        f.aov = np.ascontiguousarray(aov, np.float64)
        f.spp = int(data["spp"])
        return f


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
    albedo: np.ndarray = None  # (H, W, 3) linear Rec.709 reflectance of the first non-delta hit (under D65)
    normal: np.ndarray = None  # (H, W, 3) mean world shading normal of the first hit, facing the camera
    depth: np.ndarray = None  # (H, W) mean camera-ray distance to the first hit (m), inf where nothing was hit
    alpha: np.ndarray = None  # (H, W) film alpha: the fraction of samples not left transparent (holdout, transparent film)


def develop(sums, white_luminance=C.K_M, white_balance=None, aov=None):
    """Turn film sums into images.

    white_luminance: luminance (cd/m²) of the white that L* = 100 refers to; the default
    683 cd/m² is Blender's RGB (1, 1, 1). The reference white's chromaticity is D65.
    white_balance: None, or the xy chromaticity of the scene's light: then ``rgb`` (and
    only ``rgb``) is adapted from that white to D65 with Bradford's transform, as a
    camera's white balance would; XYZ, xyY, Lab and Luv stay unadapted.
    aov: the film's AOV sums (Film.aov); then ``albedo``, ``normal`` (sums over the sample
    count), ``depth`` (over the samples that hit; inf if none did) and ``alpha`` (1 minus
    the fraction of samples that saw a holdout or, with a transparent film, nothing; 0
    where the pixel has no samples) are filled in. ``XYZ``/``rgb`` are then premultiplied
    by alpha, as Blender's Combined pass: transparent samples carry no radiance.
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
    albedo = normal = depth = alpha = None
    if aov is not None:
        albedo = XYZ_to_sRGB_linear(aov[..., 0:3] / safe[..., None])
        albedo[n == 0] = 0.0
        normal = aov[..., 3:6] / safe[..., None]
        hits = aov[..., 7]
        depth = np.full(hits.shape, np.inf)
        np.divide(aov[..., 6], hits, out=depth, where=hits > 0)
        if aov.shape[2] > 8:
            alpha = np.where(n > 0, 1.0 - aov[..., 8] / safe, 0.0)
    return Developed(XYZ=XYZ, rgb=XYZ_to_sRGB_linear(rgb_xyz), luminance=C.K_M * mean_y,
                     variance=variance, count=n.copy(), xyY=xyY,
                     Lab=XYZ_to_Lab(XYZ * scale, np.array(D65_XY)), Luv=XYZ_to_Luv(XYZ * scale, np.array(D65_XY)),
                     white_luminance=float(white_luminance), white_xy=D65_XY, albedo=albedo, normal=normal,
                     depth=depth, alpha=alpha)
