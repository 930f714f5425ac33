"""CIE colour models: xyY, L*a*b*, L*u*v*, u'v' and the CIE 1960 UCS.

Compendium items 63, 64, 67 and 68. Formulas from CIE 015:2018 *Colorimetry*,
4th ed. (CIE, Vienna, doi:10.25039/TR.015.2018), sections on CIELAB and
CIELUV, with the exact CIE constants ε = 216/24389 = (6/29)³ ≈ 0.008856 and
κ = 24389/27 ≈ 903.3; the compendium rounds them to 0.008856 and 903.3.

Scales, as colour-science's "reference" scale:

* ``XYZ`` and ``Y`` in [0, 1] for object colours (a perfect white has Y = 1
  when the white point is given as xy); any positive scale works when the
  white point is given as xyY with the same Y_n (e.g. ``(x, y, 100)``);
* ``L*`` in [0, 100]; a*, b*, u*, v* unbounded (about [-100, 100]);
* chromaticities x, y, u', v' in [0, 1].

``illuminant`` is the white point of the XYZ data: CIE xy (Y_n = 1) or xyY,
shape ``(2,)``/``(3,)`` or broadcastable to the data; default D65 for the
CIE 1931 2° observer, (0.3127, 0.3290), as colour-science's default.

Every function is vectorised over any leading shape ``(..., 3)``.
"""
from __future__ import annotations

import numpy as np

from ._common import as_float, sdiv, tsplit, tstack, white_XYZ
from .illuminants import CCS_D65

# CIE 015:2018 constants of the CIELAB / CIELUV lightness function.
CIE_E = 216.0 / 24389.0  # (6/29)^3 ≈ 0.008856
CIE_K = 24389.0 / 27.0  # (29/3)^3 ≈ 903.296


# --------------------------------------------------------------------------- xyY


def XYZ_to_xyY(XYZ, illuminant=None):
    """CIE XYZ → CIE xyY (compendium item 63: x = X/(X+Y+Z), y = Y/(X+Y+Z)).

    Domain: XYZ any real; Range: x, y in [0, 1] for physical colours, Y as given.

    Black (X + Y + Z = 0): with ``illuminant=None`` (default) x = y = 0, which is
    what colour-science 0.4.6 returns (its ``XYZ_to_xyY`` takes no illuminant);
    with an ``illuminant`` xy given, the chromaticity of that white point is
    returned instead (the convention of colour-science up to 0.3 and of
    Lindbloom), so that black sits at the white point in a chromaticity diagram.

    References: CIE 015:2018; Lindbloom, "XYZ to xyY".
    """
    X, Y, Z = tsplit(XYZ)
    with np.errstate(all="ignore"):
        s = X + Y + Z
        x = sdiv(X, s)
        y = sdiv(Y, s)
    if illuminant is not None:
        w = as_float(illuminant)
        black = s == 0
        x = np.where(black, w[..., 0], x)
        y = np.where(black, w[..., 1], y)
    return tstack([x, y, Y])


def xyY_to_XYZ(xyY):
    """CIE xyY → CIE XYZ (compendium item 64: X = xY/y, Z = (1 − x − y)Y/y).

    Domain: x, y in [0, 1], Y any; Range: XYZ. For y = 0 the result is X = Z = 0
    (black), as colour-science does.

    References: CIE 015:2018; Lindbloom, "xyY to XYZ".
    """
    x, y, Y = tsplit(xyY)
    Y_y = sdiv(Y, y)
    with np.errstate(all="ignore"):
        return tstack([x * Y_y, Y, (1.0 - x - y) * Y_y])


def XYZ_to_xy(XYZ, illuminant=None):
    """CIE XYZ → CIE xy chromaticity (see :func:`XYZ_to_xyY` for black).

    Domain: XYZ, shape (..., 3). Range: xy in [0, 1], shape (..., 2). References: CIE 015:2018.
    """
    return XYZ_to_xyY(XYZ, illuminant)[..., :2]


def xy_to_xyY(xy, Y=1.0):
    """CIE xy → CIE xyY with luminance ``Y`` (an xyY input is returned unchanged).

    Domain: xy in [0, 1], shape (..., 2) (or xyY). Range: xyY. References: CIE 015:2018.
    """
    xy = as_float(xy)
    if xy.ndim and xy.shape[-1] == 3:
        return xy
    x, y = tsplit(xy, 2)
    return tstack([x, y, Y])


def xyY_to_xy(xyY):
    """CIE xyY → CIE xy (an xy input is returned unchanged).

    Domain: xyY, shape (..., 3) (or xy). Range: xy in [0, 1]. References: CIE 015:2018.
    """
    xyY = as_float(xyY)
    if xyY.ndim and xyY.shape[-1] == 2:
        return xyY
    tsplit(xyY)
    return xyY[..., :2]


def xy_to_XYZ(xy):
    """CIE xy (or xyY) → CIE XYZ, with Y = 1 for xy input.

    Domain: xy in [0, 1] (or xyY). Range: XYZ with Y = 1 (or the given Y). References: CIE 015:2018.
    """
    return xyY_to_XYZ(xy_to_xyY(xy))


# --------------------------------------------------------------------------- lightness


def intermediate_lightness_function_CIE1976(Y, Y_n=1.0):
    """f(Y/Y_n) of CIE 015:2018: (Y/Y_n)^(1/3) above ε = (6/29)³, else (841/108)·Y/Y_n + 16/116.

    Domain: Y, Y_n on one scale. Range: f in [4/29, 1] for Y in [0, Y_n]. References: CIE 015:2018.
    """
    with np.errstate(all="ignore"):
        t = as_float(Y) / as_float(Y_n)
        return np.where(t > CIE_E, np.cbrt(t), (841.0 / 108.0) * t + 16.0 / 116.0)


def intermediate_luminance_function_CIE1976(f, Y_n=1.0):
    """Inverse of :func:`intermediate_lightness_function_CIE1976`: Y from f(Y/Y_n).

    Domain: f, typically [4/29, 1]. Range: Y on the scale of Y_n. References: CIE 015:2018.
    """
    f = as_float(f)
    Y_n = as_float(Y_n)
    with np.errstate(all="ignore"):
        return np.where(f > 24.0 / 116.0, Y_n * f**3, Y_n * (f - 16.0 / 116.0) * (108.0 / 841.0))


def lightness_CIE1976(Y, Y_n=100.0):
    """CIE 1976 lightness L* = 116 f(Y/Y_n) − 16 (= κ·Y/Y_n below ε). Domain Y, Y_n same scale; Range [0, 100]."""
    with np.errstate(all="ignore"):
        return 116.0 * intermediate_lightness_function_CIE1976(Y, Y_n) - 16.0


def luminance_CIE1976(L_star, Y_n=100.0):
    """Luminance Y from CIE 1976 lightness L* (inverse of :func:`lightness_CIE1976`), on the scale of Y_n.

    Domain: L* in [0, 100]. Range: Y in [0, Y_n]. References: CIE 015:2018.
    """
    with np.errstate(all="ignore"):
        return intermediate_luminance_function_CIE1976((as_float(L_star) + 16.0) / 116.0, Y_n)


# --------------------------------------------------------------------------- CIELAB


def XYZ_to_Lab(XYZ, illuminant=CCS_D65):
    """CIE XYZ → CIE 1976 L*a*b* (compendium item 68).

    L* = 116 f(Y/Y_n) − 16, a* = 500 (f(X/X_n) − f(Y/Y_n)), b* = 200 (f(Y/Y_n) − f(Z/Z_n)),
    with f(t) = t^(1/3) for t > (6/29)³ and (841/108) t + 16/116 otherwise.

    Domain: XYZ in [0, 1] (white point Y_n = 1 from an xy ``illuminant``; give xyY to
    use another Y_n). Range: L* in [0, 100], a*, b* in about [-100, 100].

    The compendium's flattened text reads "a = 500 L (f(X/X_n) − f(Y/Y_n))": there is
    no factor L* in a* or b* (CIE 015:2018).

    References: CIE 015:2018; Lindbloom, "XYZ to Lab".
    """
    X, Y, Z = tsplit(XYZ)
    X_n, Y_n, Z_n = tsplit(white_XYZ(illuminant))
    fx = intermediate_lightness_function_CIE1976(X, X_n)
    fy = intermediate_lightness_function_CIE1976(Y, Y_n)
    fz = intermediate_lightness_function_CIE1976(Z, Z_n)
    with np.errstate(all="ignore"):
        return tstack([116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)])


def Lab_to_XYZ(Lab, illuminant=CCS_D65):
    """CIE 1976 L*a*b* → CIE XYZ (compendium item 68, inverse).

    f_y = (L* + 16)/116, f_x = f_y + a*/500, f_z = f_y − b*/200; each t = f³ if
    f > 6/29, else 3 (6/29)² (f − 4/29); X = X_n t_x, and so on.

    Domain: L* in [0, 100], a*, b* any. Range: XYZ on the scale of the white point (Y_n = 1 for xy).
    The compendium's "X = X_n (Y/Y_n^(1/3) + a/(500 L))³" is garbled: a* is not divided by L*.

    References: CIE 015:2018 (inverse in its note); Lindbloom, "Lab to XYZ".
    """
    L, a, b = tsplit(Lab)
    X_n, Y_n, Z_n = tsplit(white_XYZ(illuminant))
    with np.errstate(all="ignore"):
        fy = (L + 16.0) / 116.0
        fx = fy + a / 500.0
        fz = fy - b / 200.0
    return tstack(
        [
            intermediate_luminance_function_CIE1976(fx, X_n),
            intermediate_luminance_function_CIE1976(fy, Y_n),
            intermediate_luminance_function_CIE1976(fz, Z_n),
        ]
    )


def Lab_to_LCHab(Lab):
    """CIE L*a*b* → L*, C*ab (chroma), h_ab (hue angle in degrees, [0, 360)).

    Domain: L*a*b*, shape (..., 3). Range: L* [0, 100], C*ab ≥ 0, h_ab [0, 360). References: CIE 015:2018.
    """
    L, a, b = tsplit(Lab)
    with np.errstate(all="ignore"):
        return tstack([L, np.hypot(a, b), np.degrees(np.arctan2(b, a)) % 360.0])


# --------------------------------------------------------------------------- CIELUV and UCS diagrams


def xy_to_Luv_uv(xy):
    """CIE xy → CIE 1976 UCS u'v': u' = 4x/(−2x + 12y + 3), v' = 9y/(−2x + 12y + 3). Domain/Range [0, 1]."""
    x, y = tsplit(xy, 2)
    with np.errstate(all="ignore"):
        d = -2.0 * x + 12.0 * y + 3.0
        return tstack([sdiv(4.0 * x, d), sdiv(9.0 * y, d)])


def Luv_uv_to_xy(uv):
    """CIE 1976 UCS u'v' → CIE xy: x = 9u'/(6u' − 16v' + 12), y = 4v'/(6u' − 16v' + 12).

    Domain: u'v' in [0, 1], shape (..., 2). Range: xy in [0, 1]. References: CIE 015:2018.
    """
    u, v = tsplit(uv, 2)
    with np.errstate(all="ignore"):
        d = 6.0 * u - 16.0 * v + 12.0
        return tstack([sdiv(9.0 * u, d), sdiv(4.0 * v, d)])


def XYZ_to_Luv_uv(XYZ):
    """CIE XYZ → u'v' = (4X, 9Y)/(X + 15Y + 3Z); (0, 0) for black.

    Domain: XYZ, shape (..., 3). Range: u'v' in [0, 1], shape (..., 2). References: CIE 015:2018.
    """
    X, Y, Z = tsplit(XYZ)
    with np.errstate(all="ignore"):
        d = X + 15.0 * Y + 3.0 * Z
        return tstack([4.0 * sdiv(X, d), 9.0 * sdiv(Y, d)])


def XYZ_to_Luv(XYZ, illuminant=CCS_D65):
    """CIE XYZ → CIE 1976 L*u*v* (compendium item 67).

    L* as CIELAB; u* = 13 L* (u' − u'_n), v* = 13 L* (v' − v'_n) with
    u' = 4X/(X + 15Y + 3Z), v' = 9Y/(X + 15Y + 3Z) (black: u' = v' = 0, so u* = v* = 0).

    Domain: XYZ in [0, 1] (Y_n = 1 for an xy ``illuminant``). Range: L* in [0, 100],
    u*, v* in about [-100, 100]. The compendium's flattened "u' = 4X / (X + 15Y + 3Z − 16)"
    is garbled: the "− 16" belongs to L* = 116 (Y/Y_n)^(1/3) − 16.

    References: CIE 015:2018; Lindbloom, "XYZ to Luv".
    """
    X, Y, Z = tsplit(XYZ)
    X_r, Y_r, Z_r = tsplit(white_XYZ(illuminant))
    L = lightness_CIE1976(Y, Y_r)
    with np.errstate(all="ignore"):
        d = X + 15.0 * Y + 3.0 * Z
        d_r = X_r + 15.0 * Y_r + 3.0 * Z_r
        u = 13.0 * L * (4.0 * sdiv(X, d) - 4.0 * sdiv(X_r, d_r))
        v = 13.0 * L * (9.0 * sdiv(Y, d) - 9.0 * sdiv(Y_r, d_r))
    return tstack([L, u, v])


def Luv_to_XYZ(Luv, illuminant=CCS_D65):
    """CIE 1976 L*u*v* → CIE XYZ (compendium item 67, inverse).

    Y from L* (CIE 1976 lightness inverse); u' = u*/(13 L*) + u'_n, v' = v*/(13 L*) + v'_n;
    X = Y · 9u'/(4v'), Z = Y · (12 − 3u' − 20v')/(4v'). L* = 0 gives black.
    Checked equal to the compendium's form with Q = u', R = v', A = 3Y(5R − 3):
    Z = ((Q − 4)A − 15QRY)/(12R), X = −(A/R + 3Z).

    Domain: L* in [0, 100], u*, v* any. Range: XYZ on the white point's scale.

    References: CIE 015:2018; Lindbloom, "Luv to XYZ".
    """
    L, u, v = tsplit(Luv)
    X_r, Y_r, Z_r = tsplit(white_XYZ(illuminant))
    Y = luminance_CIE1976(L, Y_r)
    with np.errstate(all="ignore"):
        d_r = X_r + 15.0 * Y_r + 3.0 * Z_r
        u_n = 4.0 * sdiv(X_r, d_r)
        v_n = 9.0 * sdiv(Y_r, d_r)
        L13 = 13.0 * L
        u_p = sdiv(u, L13) + u_n
        v_p = sdiv(v, L13) + v_n
        black = L13 == 0
        X = np.where(black, 0.0, Y * sdiv(9.0 * u_p, 4.0 * v_p))
        Z = np.where(black, 0.0, Y * sdiv(12.0 - 3.0 * u_p - 20.0 * v_p, 4.0 * v_p))
    return tstack([X, Y, Z])


def Luv_to_uv(Luv, illuminant=CCS_D65):
    """CIE L*u*v* → CIE 1976 UCS u'v' chromaticity (via XYZ, as colour-science). Range [0, 1].

    Domain: L*u*v*, shape (..., 3). References: CIE 015:2018.
    """
    return XYZ_to_Luv_uv(Luv_to_XYZ(Luv, illuminant))


def uv_to_Luv(uv, illuminant=CCS_D65, L=100.0):
    """CIE 1976 UCS u'v' → CIE L*u*v* with lightness ``L`` (default 100).

    Domain: u'v' in [0, 1], shape (..., 2); L in [0, 100]. Range: L*u*v*. References: CIE 015:2018.
    """
    u, v = tsplit(uv, 2)
    _, Y_r, _ = tsplit(white_XYZ(illuminant))
    Y = luminance_CIE1976(L, Y_r)
    with np.errstate(all="ignore"):
        X = sdiv(9.0 * Y * u, 4.0 * v)
        Z = sdiv(Y * (12.0 - 3.0 * u - 20.0 * v), 4.0 * v)
    return XYZ_to_Luv(tstack([X, Y, Z]), illuminant)


def XYZ_to_UCS(XYZ):
    """CIE XYZ → CIE 1960 UCS U V W: U = 2X/3, V = Y, W = (−X + 3Y + Z)/2.

    Domain: XYZ, shape (..., 3). Range: UVW, same scale. References: CIE 1960 UCS (MacAdam 1937), CIE 015:2018.
    """
    X, Y, Z = tsplit(XYZ)
    with np.errstate(all="ignore"):
        return tstack([2.0 / 3.0 * X, Y, 0.5 * (-X + 3.0 * Y + Z)])


def UCS_to_XYZ(UVW):
    """CIE 1960 UCS U V W → CIE XYZ: X = 3U/2, Y = V, Z = 3U/2 − 3V + 2W.

    Domain: UVW, shape (..., 3). Range: XYZ, same scale. References: CIE 015:2018.
    """
    U, V, W = tsplit(UVW)
    with np.errstate(all="ignore"):
        return tstack([1.5 * U, V, 1.5 * U - 3.0 * V + 2.0 * W])


def UCS_to_uv(UVW):
    """CIE 1960 UCS U V W → CIE 1960 uv = (U, V)/(U + V + W).

    Domain: UVW, shape (..., 3). Range: uv in [0, 1], shape (..., 2); (0, 0) for black. References: CIE 015:2018.
    """
    U, V, W = tsplit(UVW)
    with np.errstate(all="ignore"):
        s = U + V + W
        return tstack([sdiv(U, s), sdiv(V, s)])


def xy_to_UCS_uv(xy):
    """CIE xy → CIE 1960 UCS uv: u = 4x/(12y − 2x + 3), v = 6y/(12y − 2x + 3).

    Domain: xy in [0, 1], shape (..., 2). Range: CIE 1960 uv in [0, 1]. References: CIE 015:2018.
    """
    x, y = tsplit(xy, 2)
    with np.errstate(all="ignore"):
        d = 12.0 * y - 2.0 * x + 3.0
        return tstack([sdiv(4.0 * x, d), sdiv(6.0 * y, d)])


def UCS_uv_to_xy(uv):
    """CIE 1960 UCS uv → CIE xy: x = 3u/(2u − 8v + 4), y = 2v/(2u − 8v + 4).

    Domain: CIE 1960 uv in [0, 1], shape (..., 2). Range: xy in [0, 1]. References: CIE 015:2018.
    """
    u, v = tsplit(uv, 2)
    with np.errstate(all="ignore"):
        d = 2.0 * u - 8.0 * v + 4.0
        return tstack([sdiv(3.0 * u, d), sdiv(2.0 * v, d)])
