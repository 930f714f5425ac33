"""Colour: spectra → CIE XYZ, CIE colour models, RGB colourspaces, adaptation, ΔE.

Names and conventions follow colour-science (which is only the tests' oracle: nothing
here imports it, since Blender's Python does not ship it). numpy only; every function
is vectorised over any leading shape. Compendium items 63, 64, 66, 67, 68.

Photometric integrals (K_m ∫ V Φ dλ, items 31–36) live in ``core.photometry``.
"""
from .adaptation import CAT_BRADFORD, chromatic_adaptation_Bradford, matrix_chromatic_adaptation_Bradford
from .difference import delta_E_CIE1976, delta_E_CIE2000  # noqa: F401
from .illuminants import CCS_ACES, CCS_C, CCS_D65, CCS_ILLUMINANTS  # noqa: F401
from .models import (
    CIE_E, CIE_K, Lab_to_LCHab, Lab_to_XYZ, Luv_to_uv, Luv_to_XYZ, Luv_uv_to_xy, UCS_to_uv, UCS_to_XYZ,
    UCS_uv_to_xy, XYZ_to_Lab, XYZ_to_Luv, XYZ_to_Luv_uv, XYZ_to_UCS, XYZ_to_xy, XYZ_to_xyY,
    intermediate_lightness_function_CIE1976, intermediate_luminance_function_CIE1976, lightness_CIE1976,
    luminance_CIE1976, uv_to_Luv, xy_to_Luv_uv, xy_to_UCS_uv, xy_to_XYZ, xy_to_xyY, xyY_to_xy, xyY_to_XYZ)
from .rgb import (
    MATRIX_ACESCG_TO_XYZ, MATRIX_NTSC1953_TO_XYZ, MATRIX_NTSC_D6500_TO_XYZ_COMPENDIUM, MATRIX_REC709_TO_XYZ,
    MATRIX_XYZ_TO_ACESCG, MATRIX_XYZ_TO_NTSC1953, MATRIX_XYZ_TO_NTSC_D6500_COMPENDIUM, MATRIX_XYZ_TO_REC709,
    PRIMARIES_AP1, PRIMARIES_BT709, PRIMARIES_NTSC1953, RGB_COLOURSPACES, RGB_Colourspace, ACEScg_to_XYZ,
    NTSC1953_to_XYZ, RGB_to_XYZ, RGB_to_XYZ_matrix, XYZ_to_ACEScg, XYZ_to_NTSC1953, XYZ_to_RGB,
    XYZ_to_sRGB_linear, luminance_rec709, normalised_primary_matrix, sRGB_decode, sRGB_encode,
    sRGB_linear_to_XYZ)
from .tristimulus import align_spectrum, cmfs, interpolate_cubic_spline, interpolate_sprague, sd_to_XYZ

__all__ = [
    # tristimulus values (item 63)
    "sd_to_XYZ", "cmfs", "align_spectrum", "interpolate_sprague", "interpolate_cubic_spline",
    # white points
    "CCS_ILLUMINANTS", "CCS_D65", "CCS_C", "CCS_ACES",
    # xyY (items 63, 64)
    "XYZ_to_xyY", "xyY_to_XYZ", "XYZ_to_xy", "xy_to_XYZ", "xy_to_xyY", "xyY_to_xy",
    # CIELAB / CIELUV / UCS (items 67, 68)
    "CIE_E", "CIE_K",
    "intermediate_lightness_function_CIE1976", "intermediate_luminance_function_CIE1976",
    "lightness_CIE1976", "luminance_CIE1976",
    "XYZ_to_Lab", "Lab_to_XYZ", "Lab_to_LCHab",
    "XYZ_to_Luv", "Luv_to_XYZ", "Luv_to_uv", "uv_to_Luv", "xy_to_Luv_uv", "Luv_uv_to_xy", "XYZ_to_Luv_uv",
    "XYZ_to_UCS", "UCS_to_XYZ", "UCS_to_uv", "xy_to_UCS_uv", "UCS_uv_to_xy",
    # RGB (item 66)
    "normalised_primary_matrix", "RGB_to_XYZ_matrix", "RGB_Colourspace", "RGB_COLOURSPACES",
    "PRIMARIES_BT709", "PRIMARIES_NTSC1953", "PRIMARIES_AP1",
    "MATRIX_REC709_TO_XYZ", "MATRIX_XYZ_TO_REC709",
    "MATRIX_NTSC1953_TO_XYZ", "MATRIX_XYZ_TO_NTSC1953",
    "MATRIX_ACESCG_TO_XYZ", "MATRIX_XYZ_TO_ACESCG",
    "MATRIX_NTSC_D6500_TO_XYZ_COMPENDIUM", "MATRIX_XYZ_TO_NTSC_D6500_COMPENDIUM",
    "XYZ_to_RGB", "RGB_to_XYZ", "XYZ_to_sRGB_linear", "sRGB_linear_to_XYZ",
    "XYZ_to_NTSC1953", "NTSC1953_to_XYZ", "XYZ_to_ACEScg", "ACEScg_to_XYZ",
    "luminance_rec709", "sRGB_encode", "sRGB_decode",
    # chromatic adaptation
    "CAT_BRADFORD", "matrix_chromatic_adaptation_Bradford", "chromatic_adaptation_Bradford",
    # colour differences
    "delta_E_CIE1976", "delta_E_CIE2000",
]
