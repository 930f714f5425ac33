"""An independent reference path tracer for the product's statistical tests.

A deliberately plain spectral path tracer in NumPy, written from the scene contract
(``spectral_gi.core.Scene``) and not from the product's kernels, so that a bug in the
product's transport (camera rays, ray casting, random numbers, wavelength sampling,
film, Russian roulette, emission lookup, light sampling, MIS) shows up as a
disagreement instead of cancelling out.

What it shares with the product, and nothing else:

* the scene records (meshes, materials, lights, camera, settings) and their spectra,
  decoded at each wavelength by ``spectral_gi.core.spectra.moments.reconstruct``;
* the BSDF models, evaluated and sampled through ``spectral_gi.core.bsdfs.batch``
  (any material model works, and the models themselves are tested elsewhere against
  closed forms and by chi-square tests).

Everything else is its own: ray generation (:mod:`.camera`), brute-force Möller–Trumbore
intersection over all triangles and the analytic area lights (:mod:`.geometry`),
NumPy's PCG64 random numbers, wavelength sampling and the CIE 1931 colour-matching
functions of colour-science (:mod:`.spectral`), and a BSDF-sampling-only estimator with
a plain Russian roulette (:mod:`.integrator`).

Entry point: :func:`render_reference`, returning per-pixel mean luminance (cd/m²) and
its standard error estimated from independent batches.
"""
from .integrator import ReferenceImage, render_reference

__all__ = ["ReferenceImage", "render_reference"]
