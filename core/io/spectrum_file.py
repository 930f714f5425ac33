"""Tabulated spectrum files: two columns, wavelength (nm) and value.

Format (CSV or whitespace separated; ``,``, ``;``, tabs and spaces all separate fields):

* one optional header line of non-numeric fields (e.g. ``wavelength,reflectance``) before
  the data; blank lines and lines starting with ``#`` are ignored anywhere;
* then one sample a line: wavelength in nm, value; wavelengths strictly increasing;
* the samples must cover 380–780 nm (the visible range; outside the file's range the
  end values are held, as colour-science extrapolates);
* values finite and non-negative.

Reflectances (``kind="reflectance"``) are fractions in [0, 1] or percentages: a file whose
largest value is above 1.05 and at most 100 is read as percent (and divided by 100);
values up to 1.05 are read as fractions and clipped to 1 (measurement noise); larger
than 100 is an error. Emission (``kind="emission"``) is a relative shape of any scale,
normalised to a peak of 1 (the light's power is set by its photometric units).

Every problem raises :class:`SpectrumFileError` whose message names the file and, where it
applies, the line.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import constants as C
from .strict import is_number_text
from ..spectra.uplift import emission_from_samples, reflectance_from_samples

VISIBLE = (380.0, 780.0)  # nm the file must cover
PERCENT_ABOVE = 1.05  # a reflectance whose peak is above this is read as percent
KINDS = ("reflectance", "emission")
_SPLIT = re.compile(r"[,;\s]+")


class SpectrumFileError(ValueError):
    """A spectrum file cannot be used; the message names the file and line."""


@dataclass
class SpectrumFile:
    path: str
    kind: str
    wavelengths: np.ndarray  # float64 (N,), nm, strictly increasing
    values: np.ndarray  # float64 (N,): reflectance in [0, 1], or emission shape with peak 1
    scale: str  # 'fraction', 'percent' (reflectance) or 'relative' (emission)
    notes: list = field(default_factory=list)  # substitutions made (clipping), for the user

    def coeffs(self, n_coeffs=C.N_COEFFS_DEFAULT):
        """Fourier (trigonometric-moment) coefficients for a core SpectrumTable row."""

        if self.kind == "reflectance":
            return reflectance_from_samples(self.wavelengths, self.values, n_coeffs)
        return emission_from_samples(self.wavelengths, self.values, n_coeffs)

    @property
    def spectrum_kind(self):
        return C.SPECTRUM_BOUNDED if self.kind == "reflectance" else C.SPECTRUM_UNBOUNDED


MAX_FILE_BYTES = 1 << 24  # 16 MiB: far above any tabulated spectrum


def _number(text):
    """A plain decimal number (no ``1_0``, ``nan`` or ``inf`` spellings), or None."""
    if not is_number_text(text):
        return None
    return float(text)


def parse_spectrum_text(text, name="<text>", kind="reflectance"):
    """Parse the text of a spectrum file (see the module doc); ``name`` is used in errors."""
    if kind not in KINDS:
        raise ValueError(f"spectrum kind {kind!r}: expected one of {KINDS}")
    wl, val, lines = [], [], []
    header_seen = False
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip().lstrip("\ufeff")
        if not line or line.startswith("#"):
            continue
        fields = [f for f in _SPLIT.split(line) if f]
        nums = [_number(f) for f in fields]
        if all(n is None for n in nums) and not wl and not header_seen:
            header_seen = True  # a header line of names
            continue
        where = f"{name}, line {lineno}"
        if len(fields) != 2:
            raise SpectrumFileError(f"{where}: expected 2 columns (wavelength in nm, value), got {len(fields)}: "
                                    f"{line[:60]!r}")
        if nums[0] is None or nums[1] is None:
            bad = fields[0] if nums[0] is None else fields[1]
            raise SpectrumFileError(f"{where}: {bad!r} is not a number")
        w, v = nums
        if not (math.isfinite(w) and math.isfinite(v)):
            raise SpectrumFileError(f"{where}: wavelength and value must be finite numbers, got {w}, {v}")
        if w <= 0.0:
            raise SpectrumFileError(f"{where}: wavelength {w:g} nm is not positive")
        if v < 0.0:
            raise SpectrumFileError(f"{where}: negative value {v:g} (a spectrum is non-negative)")
        if wl and w <= wl[-1]:
            raise SpectrumFileError(f"{where}: wavelength {w:g} nm does not increase (previous {wl[-1]:g} nm, "
                                    f"line {lines[-1]}); sort the samples by wavelength")
        wl.append(w)
        val.append(v)
        lines.append(lineno)
    if len(wl) < 2:
        raise SpectrumFileError(f"{name}: needs at least 2 samples (wavelength, value), found {len(wl)}")
    wl = np.array(wl)
    val = np.array(val)
    if wl[0] > VISIBLE[0] or wl[-1] < VISIBLE[1]:
        raise SpectrumFileError(f"{name}: the samples cover {wl[0]:g}–{wl[-1]:g} nm, they must cover "
                                f"{VISIBLE[0]:g}–{VISIBLE[1]:g} nm (are the wavelengths in nm?)")
    notes = []
    peak = float(val.max())
    if kind == "reflectance":
        if peak > 100.0:
            i = int(np.argmax(val))
            raise SpectrumFileError(f"{name}, line {lines[i]}: reflectance {peak:g} is above 100 (neither a "
                                    "fraction in [0, 1] nor a percentage)")
        if peak > PERCENT_ABOVE:
            scale = "percent"
            val = val / 100.0
        else:
            scale = "fraction"
            if peak > 1.0:
                notes.append(f"{name}: reflectance up to {peak:g} clipped to 1")
                val = np.minimum(val, 1.0)
    else:
        if not peak > 0.0:
            raise SpectrumFileError(f"{name}: every value is 0, an emission spectrum needs some power")
        scale = "relative"
        val = val / peak
    return SpectrumFile(path=str(name), kind=kind, wavelengths=wl, values=val, scale=scale, notes=notes)


def load_spectrum_file(path, kind="reflectance"):
    """Read a spectrum file (see the module doc): a :class:`SpectrumFile`; SpectrumFileError on any problem."""
    p = Path(path)
    if not p.is_file():
        raise SpectrumFileError(f"{p}: no such file")
    try:
        if p.stat().st_size > MAX_FILE_BYTES:
            raise SpectrumFileError(f"{p}: {p.stat().st_size} bytes, more than a spectrum file holds "
                                    f"({MAX_FILE_BYTES})")
        text = p.read_bytes().decode("utf-8")
    except UnicodeDecodeError:
        try:
            text = p.read_bytes().decode("latin-1")
        except Exception as e:  # pragma: no cover
            raise SpectrumFileError(f"{p}: cannot read ({e})") from None
    except OSError as e:
        raise SpectrumFileError(f"{p}: cannot read ({e})") from None
    return parse_spectrum_text(text, str(p), kind)


def spectrum_file_coeffs(path, kind="reflectance", n_coeffs=C.N_COEFFS_DEFAULT):
    """(coefficients, SpectrumFile) of a spectrum file, for a SpectrumTable row of width ``n_coeffs``."""
    sf = load_spectrum_file(path, kind)
    return sf.coeffs(n_coeffs), sf
