"""Colour differences ΔE*ab (CIE 1976) and ΔE00 (CIEDE2000).

ΔE maps between this renderer and Cycles (compendium item 68) use these.
"""
from __future__ import annotations

import numpy as np

from ._common import as_float, tsplit


def delta_E_CIE1976(Lab_1, Lab_2):
    """CIE 1976 colour difference ΔE*ab: the Euclidean distance in CIE L*a*b*.

    Domain: Lab_1, Lab_2 (L* in [0, 100]), shapes ``(..., 3)`` broadcastable.
    Range: ΔE*ab ≥ 0, shape ``(...)``.

    References: CIE 015:2018
    """
    with np.errstate(all="ignore"):
        d = as_float(Lab_1) - as_float(Lab_2)
        tsplit(d)
        return np.sqrt(np.sum(d * d, axis=-1))


_25_POW_7 = 25.0**7


def delta_E_CIE2000(Lab_1, Lab_2, textiles=False):
    """CIEDE2000 colour difference ΔE00 (CIE 142-2001, ISO/CIE 11664-6:2014).

    Implements equations (1)–(22) of G. Sharma, W. Wu and E. N. Dalal, "The CIEDE2000
    color-difference formula: Implementation notes, supplementary test data, and
    mathematical observations", Color Research & Application 30(1):21–30, 2005,
    with k_L = k_C = k_H = 1, or k_L = 2 for ``textiles=True``. Hue angles are in
    degrees; a hue of a neutral (C' = 0) is 0, and Δh' = 0, h̄' = h'_1 + h'_2 when
    either chroma is 0, as the paper prescribes.

    The hue difference is computed as ``atan2`` of the cross and dot products of the
    (a', b') vectors, which is exact when the hues are opposite (|h'_1 − h'_2| = 180°):
    then Δh' = h'_2 − h'_1 = ±180° and h̄' = (h'_1 + h'_2)/2, the paper's branch, so all
    34 pairs of the paper's test data are reproduced. colour-science subtracts hue
    angles instead, and for the paper's pair 14 ((50, −0.001, 2.49) vs (50, 0.001, −2.49))
    floating-point rounding puts it in the other branch on some platforms (4.7461
    instead of the published 4.8045); its own test skips that pair.

    Domain: Lab_1, Lab_2 (L* in [0, 100]), shapes ``(..., 3)`` broadcastable.
    Range: ΔE00 ≥ 0, shape ``(...)``.
    """
    L1, a1, b1 = tsplit(Lab_1)
    L2, a2, b2 = tsplit(Lab_2)
    k_L = 2.0 if textiles else 1.0
    k_C = k_H = 1.0
    with np.errstate(all="ignore"):
        # (2)-(7): a' scaled by G, C', h'.
        C1 = np.hypot(a1, b1)
        C2 = np.hypot(a2, b2)
        C_bar7 = ((C1 + C2) / 2.0) ** 7
        G = 0.5 * (1.0 - np.sqrt(C_bar7 / (C_bar7 + _25_POW_7)))
        a1p = (1.0 + G) * a1
        a2p = (1.0 + G) * a2
        C1p = np.hypot(a1p, b1)
        C2p = np.hypot(a2p, b2)
        h1p = np.where(C1p == 0, 0.0, np.degrees(np.arctan2(b1, a1p)) % 360.0)
        h2p = np.where(C2p == 0, 0.0, np.degrees(np.arctan2(b2, a2p)) % 360.0)

        # (8)-(10): differences.
        dLp = L2 - L1
        dCp = C2p - C1p
        CC = C1p * C2p
        # Signed hue difference in (-180, 180]; exactly ±180 for opposite hues.
        dh = np.degrees(np.arctan2(a1p * b2 - b1 * a2p, a1p * a2p + b1 * b2))
        opposite = np.abs(dh) == 180.0
        dh = np.where(opposite, np.where(h2p >= h1p, 180.0, -180.0), dh)
        dhp = np.where(CC == 0, 0.0, dh)
        dHp = 2.0 * np.sqrt(CC) * np.sin(np.radians(dhp / 2.0))

        # (11)-(14): means.
        L_bar = (L1 + L2) / 2.0
        C_barp = (C1p + C2p) / 2.0
        h_mean = np.where(opposite, (h1p + h2p) / 2.0, (h1p + dh / 2.0) % 360.0)
        h_barp = np.where(CC == 0, h1p + h2p, h_mean)

        # (15)-(22): weights and rotation term.
        T = (
            1.0
            - 0.17 * np.cos(np.radians(h_barp - 30.0))
            + 0.24 * np.cos(np.radians(2.0 * h_barp))
            + 0.32 * np.cos(np.radians(3.0 * h_barp + 6.0))
            - 0.20 * np.cos(np.radians(4.0 * h_barp - 63.0))
        )
        d_theta = 30.0 * np.exp(-(((h_barp - 275.0) / 25.0) ** 2))
        C_barp7 = C_barp**7
        R_C = 2.0 * np.sqrt(C_barp7 / (C_barp7 + _25_POW_7))
        L50 = (L_bar - 50.0) ** 2
        S_L = 1.0 + 0.015 * L50 / np.sqrt(20.0 + L50)
        S_C = 1.0 + 0.045 * C_barp
        S_H = 1.0 + 0.015 * C_barp * T
        R_T = -np.sin(np.radians(2.0 * d_theta)) * R_C

        tL = dLp / (k_L * S_L)
        tC = dCp / (k_C * S_C)
        tH = dHp / (k_H * S_H)
        return np.sqrt(tL * tL + tC * tC + tH * tH + R_T * tC * tH)
