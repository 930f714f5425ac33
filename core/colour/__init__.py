"""Colour: CIE XYZ to RGB spaces, transfer functions, luminance.

Names follow colour-science. Issue #3 grows this into the full colour module.
"""
from .rgb import (  # noqa: F401
    MATRIX_REC709_TO_XYZ,
    MATRIX_XYZ_TO_REC709,
    RGB_to_XYZ_matrix,
    XYZ_to_sRGB_linear,
    luminance_rec709,
    sRGB_encode,
)
