"""Small array helpers shared by the colour modules (numpy only).

Conventions of the whole ``colour`` package:

* every function accepts array-likes of any leading shape ``(..., 3)`` (or
  ``(..., 2)`` for chromaticities) and returns float64 arrays of the same
  leading shape; a 1-D input gives a 1-D output, a scalar quantity a 0-d
  array (use ``float()`` when a Python number is wanted);
* non-finite inputs give non-finite outputs and never raise or warn: the
  arithmetic is wrapped in ``np.errstate(all="ignore")``;
* a quotient whose denominator is exactly zero (black, for instance) is
  returned as 0, as colour-science's default "Ignore Zero Conversion" mode
  does for finite data. Unlike colour-science, a NaN or infinite input is not
  turned into 0: it propagates, and a quotient by a non-finite denominator is
  NaN (so X/(X+Y+Z) with Z = inf is NaN, not 0).
"""
from __future__ import annotations

import numpy as np


def as_float(a) -> np.ndarray:
    """``a`` as a float64 ndarray (a copy only when needed)."""
    return np.asarray(a, dtype=np.float64)


def tsplit(a, n: int = 3):
    """Split the last axis of ``a`` into ``n`` arrays, checking its length."""
    a = as_float(a)
    if a.ndim == 0 or a.shape[-1] != n:
        raise ValueError(f"expected an array whose last axis has length {n}, got shape {a.shape}")
    return tuple(a[..., i] for i in range(n))


def tstack(arrays) -> np.ndarray:
    """Stack arrays of one (broadcast) shape along a new last axis."""
    arrays = np.broadcast_arrays(*[as_float(a) for a in arrays])
    return np.stack(arrays, axis=-1)


def sdiv(a, b) -> np.ndarray:
    """``a / b`` with 0 where ``b == 0`` exactly and NaN where ``b`` is not finite.

    The second rule keeps non-finite data visible: a chromaticity such as X/(X+Y+Z) with
    an infinite Z would otherwise be a plausible-looking 0.
    """
    a = as_float(a)
    b = as_float(b)
    with np.errstate(all="ignore"):
        q = a / b
        return np.where(b == 0, 0.0, np.where(np.isfinite(b), q, np.nan))


def white_XYZ(illuminant) -> np.ndarray:
    """Tristimulus values of a white point given as CIE xy (then Y = 1) or CIE xyY."""
    w = as_float(illuminant)
    if w.ndim == 0 or w.shape[-1] not in (2, 3):
        raise ValueError(f"illuminant must be CIE xy or xyY (last axis 2 or 3), got shape {w.shape}")
    x, y = w[..., 0], w[..., 1]
    Y = w[..., 2] if w.shape[-1] == 3 else np.ones_like(x)
    Y_y = sdiv(Y, y)
    with np.errstate(all="ignore"):
        return tstack([x * Y_y, Y, (1.0 - x - y) * Y_y])


def matvec(M, v) -> np.ndarray:
    """``M @ v`` over the last axis of ``v`` (shape ``(..., 3)``); ``M`` is ``(3, 3)`` or ``(..., 3, 3)``."""
    M = as_float(M)
    v = as_float(v)
    with np.errstate(all="ignore"):
        return np.einsum("...ij,...j->...i", M, v)
