"""CIE xy chromaticity coordinates of white points (illuminants).

Values as published in CIE 015:2018 *Colorimetry*, 4th ed. (chromaticities of
the CIE standard, daylight and fluorescent illuminants, 4-5 decimals) and, for
the ACES white, SMPTE ST 2065-1:2012 / ACES S-2014-004. They are the
same numbers as colour-science's ``CCS_ILLUMINANTS`` (the tests compare).

Note on D65: CIE 015 lists (0.31272, 0.32903) for the 2° observer; sRGB, BT.709
and colour-science use the rounded (0.3127, 0.3290), which is what we use too
(it is the white point of Blender's scene-linear Rec.709).

The ACES white point (0.32168, 0.33767) is "approximately D60": it is not the
CIE daylight locus at 6000 K (which gives about (0.32162, 0.33762)).
"""
from __future__ import annotations

import numpy as np

OBSERVER_1931 = "CIE 1931 2 Degree Standard Observer"
OBSERVER_1964 = "CIE 1964 10 Degree Standard Observer"


def _ro(a):
    a = np.array(a, dtype=np.float64)
    a.setflags(write=False)
    return a


CCS_ILLUMINANTS: dict[str, dict[str, np.ndarray]] = {
    OBSERVER_1931: {
        "A": _ro([0.44758, 0.40745]),
        "C": _ro([0.31006, 0.31616]),
        "D50": _ro([0.3457, 0.3585]),
        "D55": _ro([0.33243, 0.34744]),
        "D65": _ro([0.3127, 0.3290]),
        "D75": _ro([0.29903, 0.31488]),
        "E": _ro([1.0 / 3.0, 1.0 / 3.0]),
        "FL2": _ro([0.3721, 0.3751]),
        "FL11": _ro([0.3805, 0.3769]),
        "ACES": _ro([0.32168, 0.33767]),
    },
    OBSERVER_1964: {
        "A": _ro([0.45117, 0.40594]),
        "C": _ro([0.31039, 0.31905]),
        "D50": _ro([0.34773, 0.35952]),
        "D55": _ro([0.33412, 0.34877]),
        "D65": _ro([0.31382, 0.33100]),
        "D75": _ro([0.29968, 0.31740]),
        "E": _ro([1.0 / 3.0, 1.0 / 3.0]),
        "FL2": _ro([0.37925, 0.36733]),
        "FL11": _ro([0.38541, 0.37123]),
    },
}
"""``CCS_ILLUMINANTS[observer][name]`` → CIE xy, read-only float64 arrays of shape (2,)."""

CCS_ILLUMINANTS["1931"] = CCS_ILLUMINANTS[OBSERVER_1931]
CCS_ILLUMINANTS["1964"] = CCS_ILLUMINANTS[OBSERVER_1964]

CCS_D65 = CCS_ILLUMINANTS[OBSERVER_1931]["D65"]
"""Default white point of the colour functions: D65, CIE 1931 2° observer (0.3127, 0.3290)."""
CCS_C = CCS_ILLUMINANTS[OBSERVER_1931]["C"]
CCS_ACES = CCS_ILLUMINANTS[OBSERVER_1931]["ACES"]
