"""Regenerate the colour-science-derived tables shipped in ``presets/``.

This is a developer tool: it needs colour-science (0.4.6 was used for the
shipped files), which Blender's Python does not have, so ``colour`` is only
imported inside :func:`generate_tables`.  Nothing is written at import time.

Usage::

    python -c "from spectral_gi.core.io.tables import generate_tables; \\
               from spectral_gi.core.io.presets import PRESETS_DIR; \\
               generate_tables(PRESETS_DIR)"

The hand-transcribed files (the Cornell box under ``presets/scenes/``, the
metal optical constants under ``presets/metals/`` and ``presets/glasses.toml``)
are not generated and are never touched here.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .atomic import write_text

# colour-science dataset key -> file written, relative to the output folder.
CMFS_OUTPUTS = {
    "CIE 1931 2 Degree Standard Observer": "cie/cie1931_2deg.csv",
    "CIE 1964 10 Degree Standard Observer": "cie/cie1964_10deg.csv",
}

# colour.SDS_ILLUMINANTS keys, each written to illuminants/<key>.csv (the file
# stem is colour-science's name, e.g. "FL11" for CIE F11, "LED-B1" for CIE LED-B1).
ILLUMINANT_KEYS = (
    "A", "D50", "D55", "D65", "D75", "E",
    # CIE fluorescent illuminants F1..F12 (CIE 015:2018).
    "FL1", "FL2", "FL3", "FL4", "FL5", "FL6", "FL7", "FL8", "FL9", "FL10", "FL11", "FL12",
    # CIE LED illuminants (introduced in CIE 015:2018).
    "LED-B1", "LED-B2", "LED-B3", "LED-B4", "LED-B5", "LED-BH1", "LED-RGB1", "LED-V1", "LED-V2",
)

# The 24 patches of the ColorChecker (N. Ohta's measurement), one column per patch.
COLORCHECKER_KEY = "ColorChecker N Ohta"
COLORCHECKER_OUTPUT = "colorchecker/colorchecker_n_ohta.csv"

MALLETT2019_OUTPUT = "uplift/mallett2019_srgb.csv"


def format_number(x: float) -> str:
    """Shortest decimal string that round-trips the float64 exactly.

    Integral values lose the trailing ``.0`` (``360.0`` -> ``360``) to keep the
    files readable; ``float()`` of the string is always bit-identical to ``x``.
    """
    s = repr(float(x))
    if s.endswith(".0"):
        s = s[:-2]
    return s


def _table_text(header: list[str], wavelengths, columns) -> str:
    lines = [",".join(header)]
    for i, wl in enumerate(wavelengths):
        lines.append(",".join([format_number(wl)] + [format_number(c[i]) for c in columns]))
    return "\n".join(lines) + "\n"


def generate_tables(out_dir: str | os.PathLike) -> list[Path]:
    """Rebuild every colour-science-derived table under ``out_dir``.

    ``out_dir`` plays the role of ``presets/``; the files written are
    ``cie/*.csv``, ``illuminants/*.csv``, ``colorchecker/colorchecker_n_ohta.csv``
    and ``uplift/mallett2019_srgb.csv``.
    Returns the list of paths written.
    """
    import colour  # developer-only dependency, deliberately not at module level

    out = Path(out_dir)
    written: list[Path] = []

    def emit(relpath: str, header: list[str], wavelengths, columns) -> None:
        path = out / relpath
        # Temporary file in the same folder, then os.replace (core/io/atomic.py).
        write_text(path, _table_text(header, wavelengths, columns))
        # mkstemp creates files 0600; shipped data must be world-readable.
        os.chmod(path, 0o644)
        written.append(path)

    for key, relpath in CMFS_OUTPUTS.items():
        msds = colour.MSDS_CMFS[key]
        values = msds.values
        emit(
            relpath,
            ["wavelength_nm", "xbar", "ybar", "zbar"],
            msds.wavelengths,
            [values[:, 0], values[:, 1], values[:, 2]],
        )

    for key in ILLUMINANT_KEYS:
        sd = colour.SDS_ILLUMINANTS[key]
        emit(f"illuminants/{key}.csv", ["wavelength_nm", "value"], sd.wavelengths, [sd.values])

    patches = colour.SDS_COLOURCHECKERS[COLORCHECKER_KEY]
    names = list(patches)
    if len(names) != 24:
        raise RuntimeError(f"expected 24 ColorChecker patches, got {len(names)}")
    first = patches[names[0]]
    for name in names:
        if "," in name or not np.array_equal(patches[name].wavelengths, first.wavelengths):
            raise RuntimeError(f"ColorChecker patch {name!r} cannot share one table")
    emit(
        COLORCHECKER_OUTPUT,
        ["wavelength_nm"] + names,
        first.wavelengths,
        [patches[name].values for name in names],
    )

    basis = colour.recovery.MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019
    if list(basis.labels) != ["red", "green", "blue"]:
        raise RuntimeError(f"unexpected Mallett 2019 basis labels {basis.labels}")
    values = basis.values
    emit(
        MALLETT2019_OUTPUT,
        ["wavelength_nm", "r", "g", "b"],
        basis.wavelengths,
        [values[:, 0], values[:, 1], values[:, 2]],
    )

    return written
