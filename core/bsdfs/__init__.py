"""BSDF library (compendium items 37-50): every model is an integer tag (``MAT_*`` in
core/constants.py) and a float64[16] parameter row (``params``).

* ``dispatch``   the interface for kernels: bsdf_eval, bsdf_pdf, bsdf_sample (``@function``), bsdf_flags
* ``params``     row layouts, sample flags (BSDF_*), NumPy builders with validation
* ``fresnel``    dielectric and conductor Fresnel equations (item 42), scalar helpers
* ``phong``      Lambert (47), modified Phong in the half-vector form (48b)
* ``ward``       Ward isotropic / anisotropic with three normalisations (49)
* ``lafortune``  generalised cosine lobes: Lafortune (50) and the mirror-direction Phong (48a)
* ``specular``   mirror (37), smooth dielectric (38-42), smooth conductor (42)
* ``microfacet`` GGX distribution, Smith masking, visible-normal sampling
* ``ggx``        rough conductor and rough dielectric (Walter et al. 2007)
* ``plastic``    rough dielectric coat over a Lambertian base: Kelemen-style (reciprocal) or Cycles' layering
* ``principled`` the Principled BSDF's sheen and coat layers over the plastic (Cycles' layering)
* ``layering``   tabulated GGX albedos of the Cycles layering (tables in ``layering_tables``)
* ``batch``      the entry kernel ``bsdf_batch`` and its wrappers evaluate / pdf / sample
* ``albedo``     directional-hemispherical reflectance and transmittance (items 45-46)
* ``artist``     conductor (η, κ) from a reflectivity and an edge tint (Gulbrandsen 2014), NumPy
"""
from .albedo import Albedo, albedo, albedo_quadrature, white_furnace
from .artist import colour_from_conductor, conductor_from_colour
from .batch import OP_EVAL, OP_PDF, OP_SAMPLE, evaluate, pdf, sample
from .params import (
    BSDF_DELTA, BSDF_DIFFUSE, BSDF_DISPERSIVE, BSDF_GLOSSY, BSDF_REFLECTION, BSDF_TRANSMISSION, WARD_BOUNDED,
    WARD_DUER, WARD_ORIGINAL, blinn_phong_params, conductor_params, dielectric_params, ggx_conductor_params,
    ggx_dielectric_params, lafortune_params, lambert_params, make_params, mirror_params, phong_params,
    plastic_params, ward_params)

__all__ = [
    "Albedo", "albedo", "albedo_quadrature", "white_furnace",
    "conductor_from_colour", "colour_from_conductor",
    "OP_EVAL", "OP_PDF", "OP_SAMPLE", "evaluate", "pdf", "sample",
    "BSDF_REFLECTION", "BSDF_TRANSMISSION", "BSDF_DIFFUSE", "BSDF_GLOSSY", "BSDF_DELTA", "BSDF_DISPERSIVE",
    "WARD_BOUNDED", "WARD_DUER", "WARD_ORIGINAL",
    "lambert_params", "phong_params", "blinn_phong_params", "ward_params", "lafortune_params", "mirror_params",
    "dielectric_params", "conductor_params", "ggx_conductor_params", "ggx_dielectric_params", "plastic_params",
    "make_params",
]
