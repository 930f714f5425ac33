"""Bradford chromatic adaptation (a von Kries transform in the Bradford cone space).

M_CAT = M_BFD⁻¹ · diag(ρ_wr/ρ_w, γ_wr/γ_w, β_wr/β_w) · M_BFD, with
(ρ, γ, β) = M_BFD · XYZ of the source white (w) and of the destination white (wr).
This is the linearised Bradford transform (no non-linear blue correction), as
given by Lindbloom ("Chromatic Adaptation", brucelindbloom.com) and recommended
by the ICC for v4 profiles, with the matrix of Lam (1985) as quoted by Lindbloom:

    [ 0.8951  0.2664 -0.1614]
    [-0.7502  1.7135  0.0367]
    [ 0.0389 -0.0685  1.0296]

colour-science's ``chromatic_adaptation_VonKries(..., transform="Bradford")``
computes the same thing (it is the oracle of the tests).
"""
from __future__ import annotations

import numpy as np

from ._common import as_float, matvec, sdiv

CAT_BRADFORD = np.array(
    [
        [0.8951, 0.2664, -0.1614],
        [-0.7502, 1.7135, 0.0367],
        [0.0389, -0.0685, 1.0296],
    ]
)
CAT_BRADFORD.setflags(write=False)
CAT_INVERSE_BRADFORD = np.linalg.inv(CAT_BRADFORD)
CAT_INVERSE_BRADFORD.setflags(write=False)


def matrix_chromatic_adaptation_Bradford(XYZ_w, XYZ_wr):
    """Bradford adaptation matrix from white ``XYZ_w`` (source) to ``XYZ_wr`` (destination).

    Domain: XYZ_w, XYZ_wr tristimulus values of the two whites, shape ``(..., 3)``, any
    common scale (only their ratios matter). Range: matrices of shape ``(..., 3, 3)``.

    References: Lindbloom, "Chromatic Adaptation"; K. M. Lam, "Metamerism and colour
    constancy", PhD thesis, University of Bradford, 1985.
    """
    w = matvec(CAT_BRADFORD, XYZ_w)
    wr = matvec(CAT_BRADFORD, XYZ_wr)
    gain = sdiv(wr, w)  # (..., 3)
    with np.errstate(all="ignore"):
        # M⁻¹ · diag(g) · M  ==  (M⁻¹ * g[None, :]) @ M
        return np.einsum("ij,...j,jk->...ik", CAT_INVERSE_BRADFORD, gain, CAT_BRADFORD)


def chromatic_adaptation_Bradford(XYZ, XYZ_w, XYZ_wr):
    """Adapt ``XYZ`` seen under white ``XYZ_w`` to its corresponding colour under ``XYZ_wr``.

    Domain: XYZ any scale, shape ``(..., 3)``; XYZ_w, XYZ_wr ``(3,)`` or broadcastable.
    Range: XYZ on the scale of the input; ``XYZ = XYZ_w`` maps exactly to ``XYZ_wr``.

    References: Lindbloom, "Chromatic Adaptation".
    """
    M = matrix_chromatic_adaptation_Bradford(XYZ_w, XYZ_wr)
    return matvec(M, as_float(XYZ))
