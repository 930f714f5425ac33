"""RGB colourspaces from their primaries and white point (compendium item 66).

A normalised primary matrix (NPM, SMPTE RP 177-1993) maps linear RGB to
CIE XYZ so that RGB = (1, 1, 1) gives the white point with Y = 1. Colourspaces:

* ``"ITU-R BT.709"`` / ``"sRGB"`` (ITU-R BT.709-6, IEC 61966-2-1:1999): primaries
  R (0.64, 0.33), G (0.30, 0.60), B (0.15, 0.06), white D65 (0.3127, 0.3290). This is
  Blender's scene-linear space. Both names use the NPM computed from the primaries
  in float64, which is colour-science's "ITU-R BT.709" matrix. colour-science's
  "sRGB" colourspace instead uses the 4-decimal matrices printed in IEC 61966-2-1
  (0.4124, 0.3576, ...; 3.2406, −1.5372, ...), which differ from ours by up to
  about 1e-4 and are not exact inverses of each other.
* ``"NTSC (1953)"`` (FCC 1953, ITU-R BT.470): primaries R (0.67, 0.33), G (0.21, 0.71),
  B (0.14, 0.08), white CIE illuminant C (0.31006, 0.31616).
  The compendium's item 66 matrix ("NTSC standard RGB based on standard CIE
  phosphors and D6500 white point", X = 0.5893 R + 0.1789 G + 0.1831 B, ...) is the
  NPM of the NTSC primaries with the white (0.313, 0.329), i.e. D65, not C: it is
  not the NTSC 1953 matrix (entries differ by up to 0.096) but an "NTSC primaries
  with a D65 white" space, rounded to 4 decimals (it agrees with
  ``normalised_primary_matrix(PRIMARIES_NTSC1953, (0.313, 0.329))`` to 2.4e-4, and
  its printed inverse inverts it to 1.1e-4). ``MATRIX_NTSC_D6500_TO_XYZ_COMPENDIUM``
  keeps it for reference; use ``"NTSC (1953)"``.
* ``"ACEScg"`` (ACES S-2014-004): AP1 primaries R (0.713, 0.293), G (0.165, 0.830),
  B (0.128, 0.044), ACES white (0.32168, 0.33767) ("≈ D60", not the CIE daylight
  D60). Scene XYZ under D65 is converted with Bradford adaptation D65 → ACES white
  by passing ``illuminant=CCS_D65``.

``XYZ`` is on any linear scale (Y = 1 for the white of the space); RGB is linear.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._common import as_float, matvec, tsplit
from .adaptation import matrix_chromatic_adaptation_Bradford
from .illuminants import CCS_ACES, CCS_C, CCS_D65
from .models import xy_to_XYZ

REC709_PRIMARIES = np.array([[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]])
D65_XY = np.array([0.3127, 0.3290])
PRIMARIES_BT709 = REC709_PRIMARIES
PRIMARIES_NTSC1953 = np.array([[0.67, 0.33], [0.21, 0.71], [0.14, 0.08]])
PRIMARIES_AP1 = np.array([[0.713, 0.293], [0.165, 0.830], [0.128, 0.044]])
for _a in (REC709_PRIMARIES, D65_XY, PRIMARIES_NTSC1953, PRIMARIES_AP1):
    _a.setflags(write=False)


def normalised_primary_matrix(primaries, whitepoint):
    """Normalised primary matrix (SMPTE RP 177): RGB (1, 1, 1) maps to the white with Y = 1.

    Domain: ``primaries`` xy of R, G, B, shape (3, 2) (or 6 values); ``whitepoint`` xy (or
    xyY, Y ignored). Range: the (3, 3) matrix taking linear RGB to CIE XYZ.

    Columns are the XYZ of the primaries with Y = 1, P = [x/y, 1, (1−x−y)/y]ᵀ, scaled
    by S = P⁻¹ W where W = [x_w/y_w, 1, (1−x_w−y_w)/y_w]ᵀ.

    References: SMPTE RP 177-1993 "Derivation of Basic Television Color Equations";
    Lindbloom, "RGB/XYZ Matrices".
    """
    p = as_float(primaries).reshape(3, 2)
    w = as_float(whitepoint)[:2]
    xyz = np.stack([p[:, 0] / p[:, 1], np.ones(3), (1 - p[:, 0] - p[:, 1]) / p[:, 1]])  # columns
    white = np.array([w[0] / w[1], 1.0, (1 - w[0] - w[1]) / w[1]])
    s = np.linalg.solve(xyz, white)
    return xyz * s[None, :]


RGB_to_XYZ_matrix = normalised_primary_matrix
"""Former name of :func:`normalised_primary_matrix` (kept for existing callers)."""


def _ro(a):
    a = np.array(a, dtype=np.float64)
    a.setflags(write=False)
    return a


MATRIX_REC709_TO_XYZ = _ro(normalised_primary_matrix(REC709_PRIMARIES, D65_XY))
MATRIX_XYZ_TO_REC709 = _ro(np.linalg.inv(MATRIX_REC709_TO_XYZ))
MATRIX_NTSC1953_TO_XYZ = _ro(normalised_primary_matrix(PRIMARIES_NTSC1953, CCS_C))
MATRIX_XYZ_TO_NTSC1953 = _ro(np.linalg.inv(MATRIX_NTSC1953_TO_XYZ))
MATRIX_ACESCG_TO_XYZ = _ro(normalised_primary_matrix(PRIMARIES_AP1, CCS_ACES))
MATRIX_XYZ_TO_ACESCG = _ro(np.linalg.inv(MATRIX_ACESCG_TO_XYZ))

# The compendium's item 66 matrices, exactly as printed (see the module docstring).
MATRIX_NTSC_D6500_TO_XYZ_COMPENDIUM = _ro(
    [[0.5893, 0.1789, 0.1831], [0.2904, 0.6051, 0.1045], [0.0000, 0.0684, 1.0202]]
)
MATRIX_XYZ_TO_NTSC_D6500_COMPENDIUM = _ro(
    [[1.967, -0.548, -0.297], [-0.955, 1.938, -0.027], [0.064, -0.130, 0.982]]
)


@dataclass(frozen=True)
class RGB_Colourspace:
    """A linear RGB colourspace: name, primaries (3, 2), white point xy, and its matrices."""

    name: str
    primaries: np.ndarray
    whitepoint: np.ndarray
    whitepoint_name: str
    matrix_RGB_to_XYZ: np.ndarray
    matrix_XYZ_to_RGB: np.ndarray


def _space(name, primaries, white, white_name, M, M_inv):
    return RGB_Colourspace(name, primaries, white, white_name, M, M_inv)


RGB_COLOURSPACES: dict[str, RGB_Colourspace] = {
    "ITU-R BT.709": _space("ITU-R BT.709", REC709_PRIMARIES, CCS_D65, "D65",
                           MATRIX_REC709_TO_XYZ, MATRIX_XYZ_TO_REC709),
    "sRGB": _space("sRGB", REC709_PRIMARIES, CCS_D65, "D65", MATRIX_REC709_TO_XYZ, MATRIX_XYZ_TO_REC709),
    "NTSC (1953)": _space("NTSC (1953)", PRIMARIES_NTSC1953, CCS_C, "C",
                          MATRIX_NTSC1953_TO_XYZ, MATRIX_XYZ_TO_NTSC1953),
    "ACEScg": _space("ACEScg", PRIMARIES_AP1, CCS_ACES, "ACES", MATRIX_ACESCG_TO_XYZ, MATRIX_XYZ_TO_ACESCG),
}


def _colourspace(colourspace) -> RGB_Colourspace:
    if isinstance(colourspace, RGB_Colourspace):
        return colourspace
    try:
        return RGB_COLOURSPACES[colourspace]
    except KeyError:
        raise ValueError(
            f"unknown RGB colourspace {colourspace!r}; expected one of {sorted(RGB_COLOURSPACES)}"
        ) from None


def _cat(illuminant_from, illuminant_to, transform):
    if transform is None:
        return None
    if str(transform).lower() != "bradford":
        raise ValueError(f"unsupported chromatic adaptation transform {transform!r}; use 'Bradford' or None")
    return matrix_chromatic_adaptation_Bradford(xy_to_XYZ(as_float(illuminant_from)[:2]),
                                                xy_to_XYZ(as_float(illuminant_to)[:2]))


def XYZ_to_RGB(XYZ, colourspace="ITU-R BT.709", illuminant=None, chromatic_adaptation_transform="Bradford"):
    """CIE XYZ → linear RGB of ``colourspace``.

    ``illuminant`` is the xy white point of the XYZ data. If it is given and
    ``chromatic_adaptation_transform`` is ``"Bradford"`` (default), XYZ is first adapted
    from that white to the colourspace's white; with ``illuminant=None`` (default) or
    ``chromatic_adaptation_transform=None``, no adaptation is made. (colour-science's
    ``XYZ_to_RGB`` has the same arguments but defaults to CAT02.)

    Domain: XYZ any linear scale, shape ``(..., 3)``. Range: linear RGB, same scale
    (the colourspace's white with Y = 1 gives RGB (1, 1, 1)); out-of-gamut colours give
    negative components; no clipping.

    References: SMPTE RP 177-1993; ITU-R BT.709-6; IEC 61966-2-1; FCC 1953 / ITU-R BT.470;
    ACES S-2014-004; Lindbloom, "Chromatic Adaptation".
    """
    cs = _colourspace(colourspace)
    M = cs.matrix_XYZ_to_RGB
    if illuminant is not None:
        M_cat = _cat(illuminant, cs.whitepoint, chromatic_adaptation_transform)
        if M_cat is not None:
            M = M @ M_cat
    tsplit(XYZ)
    return matvec(M, XYZ)


def RGB_to_XYZ(RGB, colourspace="ITU-R BT.709", illuminant=None, chromatic_adaptation_transform="Bradford"):
    """Linear RGB of ``colourspace`` → CIE XYZ (inverse of :func:`XYZ_to_RGB`).

    With ``illuminant`` (xy) given and Bradford adaptation, the XYZ returned is adapted
    from the colourspace's white to ``illuminant``.

    Domain: linear RGB, shape ``(..., 3)``. Range: XYZ, same scale (RGB (1, 1, 1) gives the
    white with Y = 1).
    """
    cs = _colourspace(colourspace)
    M = cs.matrix_RGB_to_XYZ
    if illuminant is not None:
        M_cat = _cat(cs.whitepoint, illuminant, chromatic_adaptation_transform)
        if M_cat is not None:
            M = M_cat @ M
    tsplit(RGB)
    return matvec(M, RGB)


def XYZ_to_sRGB_linear(XYZ):
    """CIE XYZ → linear Rec.709 (no chromatic adaptation: the film's white is D65).

    Domain: XYZ, shape ``(..., 3)`` (Y = 1 for the D65 white). Range: linear Rec.709 RGB.
    """
    return matvec(MATRIX_XYZ_TO_REC709, XYZ)


def sRGB_linear_to_XYZ(RGB):
    """Linear Rec.709 / sRGB → CIE XYZ (D65 white, no adaptation). Inverse of :func:`XYZ_to_sRGB_linear`.

    Domain: linear Rec.709, shape (..., 3). Range: XYZ (Y = 1 for RGB (1, 1, 1)).
    References: ITU-R BT.709-6, IEC 61966-2-1.
    """
    return matvec(MATRIX_REC709_TO_XYZ, RGB)


def XYZ_to_NTSC1953(XYZ, illuminant=None, chromatic_adaptation_transform="Bradford"):
    """CIE XYZ → linear NTSC (1953) RGB (white C); see :func:`XYZ_to_RGB` for ``illuminant``.

    Domain: XYZ, shape (..., 3). Range: linear NTSC RGB. References: FCC 1953; ITU-R BT.470.
    """
    return XYZ_to_RGB(XYZ, "NTSC (1953)", illuminant, chromatic_adaptation_transform)


def NTSC1953_to_XYZ(RGB, illuminant=None, chromatic_adaptation_transform="Bradford"):
    """Linear NTSC (1953) RGB → CIE XYZ; see :func:`RGB_to_XYZ` for ``illuminant``.

    Domain: linear NTSC RGB, shape (..., 3). Range: XYZ. References: FCC 1953; ITU-R BT.470.
    """
    return RGB_to_XYZ(RGB, "NTSC (1953)", illuminant, chromatic_adaptation_transform)


def XYZ_to_ACEScg(XYZ, illuminant=None, chromatic_adaptation_transform="Bradford"):
    """CIE XYZ → ACEScg (AP1, linear). Pass ``illuminant=CCS_D65`` for D65-referred XYZ.

    Domain: XYZ, shape (..., 3). Range: linear ACEScg (AP1). References: ACES S-2014-004.
    """
    return XYZ_to_RGB(XYZ, "ACEScg", illuminant, chromatic_adaptation_transform)


def ACEScg_to_XYZ(RGB, illuminant=None, chromatic_adaptation_transform="Bradford"):
    """ACEScg (AP1, linear) → CIE XYZ. Pass ``illuminant=CCS_D65`` to get D65-referred XYZ.

    Domain: linear ACEScg, shape (..., 3). Range: XYZ. References: ACES S-2014-004.
    """
    return RGB_to_XYZ(RGB, "ACEScg", illuminant, chromatic_adaptation_transform)


def luminance_rec709(rgb):
    """Relative luminance Y of linear Rec.709 values (the middle row of the RGB→XYZ matrix).

    Domain: linear Rec.709, shape ``(..., 3)``. Range: Y, shape ``(...)``.
    """
    with np.errstate(all="ignore"):
        return np.asarray(rgb, dtype=np.float64) @ MATRIX_REC709_TO_XYZ[1]


def sRGB_encode(linear):
    """IEC 61966-2-1 transfer function (linear → non-linear sRGB), NaN-safe, no clipping.

    V = 12.92 L for L ≤ 0.0031308, else 1.055 L^(1/2.4) − 0.055. Domain: L any real
    (negative values are mirrored: V(−L) = −V(L)). Range: V, [0, 1] for L in [0, 1].
    colour-science's ``eotf_inverse_sRGB`` agrees for L ≥ 0 (and for −0.0031308 ≤ L < 0)
    but uses the linear segment 12.92 L for every negative L.

    References: IEC 61966-2-1:1999
    """
    x = np.asarray(linear, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        a = np.abs(x)
        out = np.where(a <= 0.0031308, 12.92 * a, 1.055 * np.power(a, 1 / 2.4) - 0.055)
    return np.copysign(out, x)


def sRGB_decode(encoded):
    """Inverse of :func:`sRGB_encode` (non-linear sRGB → linear), NaN-safe, no clipping.

    L = V/12.92 for V ≤ 12.92 · 0.0031308 ≈ 0.04045, else ((V + 0.055)/1.055)^2.4.
    The switch is placed at the image of the encoding's threshold (as colour-science's
    ``eotf_sRGB`` does), so decode(encode(L)) = L to rounding on both sides; the standard
    prints 0.04045, and the two pieces differ there by 2.3e-9 (7e-7 relative).
    Domain: V any real (negative values mirrored). Range: L, [0, 1] for V in [0, 1].
    colour-science's ``eotf_sRGB`` agrees for V ≥ 0 but is linear for every negative V.

    References: IEC 61966-2-1:1999
    """
    x = np.asarray(encoded, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        a = np.abs(x)
        out = np.where(a <= 12.92 * 0.0031308, a / 12.92, np.power((a + 0.055) / 1.055, 2.4))
    return np.copysign(out, x)
