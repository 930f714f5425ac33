"""The film's record: the arrays the path kernel adds its samples to, and the observer's
colour-matching table it weighs spectral radiance with."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..io import presets
from ..spectra import moments


class FilmRecord(NamedTuple):
    """What the path kernel writes, per pixel (x, y) of an H × W film.

    sums: float64 (H, W, 5) X, Y, Z (∫ L x̄ dλ ... with L in W/(m² sr nm)), the sample count
        and Y²; (H, W, 6) when ``cmf`` has a V(λ) column: channel 5 the V-weighted
        (photometric) Y and channel 4 its square.
    spectral: float64 (H, W, B) sums of the spectral radiance averaged over B equal bins of
        [LAMBDA_MIN, LAMBDA_MAX] (W/(m² sr nm)); (1, 1, 0): none.
    aov: float64 (H, W, 9) sums per sample: 0-2 CIE XYZ of the first non-delta hit's
        reflectance under D65, 3-5 the first hit's shading normal facing the camera, 6 the
        first hit's distance along the camera ray, 7 the number of samples whose camera ray
        hit something, 8 the number of samples that left the pixel transparent.
    cmf: float32 (N_LAMBDA, 3) x̄, ȳ, z̄ of the observer on the 1 nm grid, or (N_LAMBDA, 4)
        with V(λ) in column 3 when the observer is not CIE 1931 (``cmf_table``).
    """

    sums: np.ndarray
    spectral: np.ndarray
    aov: np.ndarray
    cmf: np.ndarray


def pack(film, cmf) -> FilmRecord:
    """The record of a :class:`~core.film.Film` (its arrays, not copies) and ``cmf_table``."""
    return FilmRecord(film.sums, film.spectral, film.aov, cmf)


def cmf_table(observer="1931"):
    """CIE colour-matching functions on the renderer's grid: float32 (N_LAMBDA, 3) for the
    CIE 1931 observer; for another observer (N_LAMBDA, 4): its x̄, ȳ, z̄ and V(λ) (the 1931
    ȳ), which photometry keeps using (see core/film/__init__.py and the path kernel)."""
    from . import check_observer

    observer = check_observer(observer)
    grid = moments.grid()
    wl, xyz = presets.cmfs(observer)
    cols = [np.interp(grid, wl, xyz[:, k], left=0, right=0) for k in range(3)]
    if observer != "1931":
        wl1, xyz1 = presets.cmfs("1931")
        cols.append(np.interp(grid, wl1, xyz1[:, 1], left=0, right=0))
    return np.ascontiguousarray(np.stack(cols, axis=1), np.float32)


def v_lambda(cmf):
    """The V(λ) column of a cmf_table: column 3 if present, else ȳ (CIE 1931)."""
    return cmf[:, 3] if cmf.shape[1] > 3 else cmf[:, 1]
