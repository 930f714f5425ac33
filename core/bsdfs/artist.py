"""Artist-friendly conductor parameters (NumPy, not compiled).

Gulbrandsen 2014, "Artist Friendly Metallic Fresnel", JCGT 3(4): a conductor's complex
index N = η + iκ from two colours in [0, 1], per wavelength,

* r, the reflectivity at normal incidence, R(0) = ((η−1)² + κ²) / ((η+1)² + κ²), and
* g, the edge tint, which moves η between the two ends of the family of indices having
  that R(0): g = 0 gives η_max(r) = (1 + √r)/(1 − √r) with κ = 0 (a dielectric-like
  edge, the least tinted towards grazing), g = 1 gives η_min(r) = (1 − r)/(1 + r)::

    η(r, g) = g η_min(r) + (1 − g) η_max(r)
    κ(r, η)² = (r (η + 1)² − (η − 1)²) / (1 − r)   (R(0) = r solved for κ)

The conductor Fresnel factor of (η, κ) (fresnel.py) then equals r at normal incidence and
rises to 1 at grazing, bending towards g's hue on the way. ``conductor_from_colour`` is the
mapping, ``colour_from_conductor`` its inverse.
"""
import numpy as np

R_MAX = 0.9999  # r = 1 would need η or κ = ∞


def _colour(name, x):
    a = np.asarray(x, dtype=np.float64)
    if a.size and np.any(np.isnan(a)):
        raise ValueError(f"{name} contains NaN")
    return a


def conductor_from_colour(r, g):
    """(eta, kappa) arrays from the normal-incidence reflectivity ``r`` and the edge tint ``g``.

    r and g are array-like per wavelength (broadcast against each other); r is clipped to
    [0, 0.9999] and g to [0, 1]. ValueError on NaN.
    """
    r = np.clip(_colour("r (reflectivity)", r), 0.0, R_MAX)
    g = np.clip(_colour("g (edge tint)", g), 0.0, 1.0)
    r, g = np.broadcast_arrays(r, g)
    sr = np.sqrt(r)
    n_min = (1.0 - r) / (1.0 + r)
    n_max = (1.0 + sr) / (1.0 - sr)
    eta = g * n_min + (1.0 - g) * n_max
    k2 = (r * (eta + 1.0) ** 2 - (eta - 1.0) ** 2) / (1.0 - r)
    kappa = np.sqrt(np.maximum(k2, 0.0))  # k2 < 0 only by rounding at g = 0
    return eta, kappa


def colour_from_conductor(eta, kappa):
    """The inverse mapping: (r, g) of a complex index η + iκ (η > 0, κ ≥ 0)."""
    eta = _colour("eta", eta)
    kappa = _colour("kappa", kappa)
    if np.any(eta <= 0.0) or np.any(kappa < 0.0):
        raise ValueError("eta must be > 0 and kappa >= 0")
    r = ((eta - 1.0) ** 2 + kappa ** 2) / ((eta + 1.0) ** 2 + kappa ** 2)
    sr = np.sqrt(r)
    n_min = (1.0 - r) / (1.0 + r)
    n_max = (1.0 + sr) / (1.0 - sr)
    span = n_max - n_min
    with np.errstate(invalid="ignore", divide="ignore"):
        g = np.where(span > 0.0, (n_max - eta) / np.where(span > 0.0, span, 1.0), 0.0)
    return r, g


__all__ = ["conductor_from_colour", "colour_from_conductor"]
