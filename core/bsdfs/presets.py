"""Named spectral presets for materials, on the renderer's 1 nm grid.

The add-on builds its menus from the ``*_names`` functions (ColorChecker patches,
measured metals, catalogue glasses) and its exporter turns a chosen name into what a
:class:`~.scene.Material` references: bounded-spectrum coefficients for a reflectance,
or refractive-index curves for :class:`~.scene.IORTable`. Everything is a pure function
of a name; the data come from :mod:`.spectra.library` (files under ``presets/``).
"""
import numpy as np

from .. import constants as C
from ..spectra import library, moments
from ..spectra.uplift import reflectance_from_samples


def wavelength_grid():
    """The renderer's wavelengths (nm): LAMBDA_MIN..LAMBDA_MAX in LAMBDA_STEP steps (N_LAMBDA values)."""
    return np.linspace(C.LAMBDA_MIN, C.LAMBDA_MAX, C.N_LAMBDA)


def reflectance_preset_names():
    """Names of the preset reflectances: the 24 ColorChecker patches in chart order."""
    return library.colorchecker_names()


def metal_preset_names():
    """Names (chemical symbols) of the measured metals."""
    return library.metal_names()


def glass_preset_names():
    """Names of the catalogue glasses (Sellmeier or Cauchy dispersion)."""
    return library.glass_names()


def reflectance_preset(name, n_coeffs=C.N_COEFFS_DEFAULT):
    """Bounded-spectrum coefficients (``n_coeffs`` of them) of a ColorChecker patch (by name or 0-based index)."""
    wl = wavelength_grid()
    return reflectance_from_samples(wl, np.clip(library.colorchecker(name, wl), 0.0, 1.0), n_coeffs)


def metal_preset(name):
    """(η, κ) of a measured metal on the grid: two float64 arrays of N_LAMBDA values."""
    eta, kappa = library.metal_ior(name, wavelength_grid())
    return np.asarray(eta, np.float64), np.asarray(kappa, np.float64)


def glass_preset(name):
    """Refractive index η(λ) of a catalogue glass on the grid (float64, N_LAMBDA values)."""
    return np.asarray(library.glass_ior(name, wavelength_grid()), np.float64)


def tabulate_reflectance(coeffs):
    """A bounded spectrum's values on the grid (float64, N_LAMBDA), as the renderer reconstructs it."""
    c = np.asarray(coeffs, dtype=np.float64).reshape(1, -1)
    return moments.tabulate(c, np.array([C.SPECTRUM_BOUNDED], np.int32))[0].astype(np.float64)
