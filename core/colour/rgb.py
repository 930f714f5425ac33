"""RGB colourspaces from their primaries and white point.

Rec.709 / sRGB (IEC 61966-2-1): primaries R (0.64, 0.33), G (0.30, 0.60),
B (0.15, 0.06), white D65 (0.3127, 0.3290). This is Blender's scene-linear space.
"""
import numpy as np

REC709_PRIMARIES = np.array([[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]])
D65_XY = np.array([0.3127, 0.3290])


def RGB_to_XYZ_matrix(primaries, white_xy):
    """Normalised primary matrix (SMPTE RP 177): RGB (1,1,1) maps to the white with Y = 1."""
    p = np.asarray(primaries, dtype=np.float64)
    w = np.asarray(white_xy, dtype=np.float64)
    xyz = np.stack([p[:, 0] / p[:, 1], np.ones(3), (1 - p[:, 0] - p[:, 1]) / p[:, 1]])  # columns
    white = np.array([w[0] / w[1], 1.0, (1 - w[0] - w[1]) / w[1]])
    s = np.linalg.solve(xyz, white)
    return xyz * s[None, :]


MATRIX_REC709_TO_XYZ = RGB_to_XYZ_matrix(REC709_PRIMARIES, D65_XY)
MATRIX_XYZ_TO_REC709 = np.linalg.inv(MATRIX_REC709_TO_XYZ)


def XYZ_to_sRGB_linear(XYZ):
    """CIE XYZ → linear Rec.709 (no chromatic adaptation: the film's white is D65)."""
    return np.einsum("...j,ij->...i", np.asarray(XYZ, dtype=np.float64), MATRIX_XYZ_TO_REC709)


def luminance_rec709(rgb):
    """Relative luminance Y of linear Rec.709 values (the middle row of the RGB→XYZ matrix)."""
    return np.asarray(rgb, dtype=np.float64) @ MATRIX_REC709_TO_XYZ[1]


def sRGB_encode(linear):
    """IEC 61966-2-1 transfer function (linear → non-linear sRGB), NaN-safe, no clipping."""
    x = np.asarray(linear, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        a = np.abs(x)
        out = np.where(a <= 0.0031308, 12.92 * a, 1.055 * np.power(a, 1 / 2.4) - 0.055)
    return np.copysign(out, x)
