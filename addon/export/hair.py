"""Principled Hair BSDF and Hair BSDF → the core's existing models (a documented substitute).

The core has no fibre scattering model (Chiang et al. 2016, "A Practical and Controllable
Hair and Fur Model for Production Path Tracing"); a new BSDF model would lengthen every
scene's cold compile (core/bsdfs/dispatch.py compiles every model). The hair nodes are
therefore mapped onto the plastic model (Cycles' Principled layering), keeping how much
light a fibre scatters and its colour, not where it sends it:

* Principled Hair (Chiang or Huang): the fibre's absorption coefficient σ_a (per unit
  fibre radius) is found as Cycles finds it — Absorption Coefficient as given; Melanin →
  eumelanin and pheomelanin concentrations (−ln(1 − melanin), split by Melanin Redness)
  times Cycles' absorption per concentration, plus the Tint's σ_a; Direct Coloring → the σ_a
  of the colour by Chiang's relation between σ_a and the colour of a mass of hair at radial
  roughness β_n (§4.2): σ_a = (ln c / (5.969 − 0.215 β_n + 2.532 β_n² − 10.73 β_n³ +
  5.574 β_n⁴ + 0.245 β_n⁵))². The fibre's albedo is then the energy a smooth dielectric
  cylinder of that σ_a and the node's IOR scatters at normal incidence, averaged over the
  offsets h across it: A = F + (1 − F)² T / (1 − F T) with F the Fresnel reflectance at
  the angle asin h and T = exp(−2 σ_a cos γ_t) the transmittance of the chord (the sum of
  Chiang's / Marschner's lobes R, TT, TRT, …). The strand is a plastic whose coat (the
  node's IOR, GGX α = Roughness) gives R and whose base, (A − F̄) / (1 − F̄), the rest; a
  mass of such strands gets its colour by multiple scattering between them, as in Cycles.
  Not carried over: the lobes' directions (the light TT sends on through the strand is
  scattered back here, so a strand is opaque and casts a full shadow, and backlit hair does
  not glow), the cuticle tilt (Offset), Coat, Random Color / Roughness, Huang's aspect ratio
  and lobe weights; the substitute is listed in the export warning.
* Hair BSDF: Reflection → a GGX reflector of its colour (as Glossy, α = Roughness U);
  Transmission → a transparent surface of its colour (light goes on through the fibre).
"""
import math

import numpy as np

from .nodes import input_value

EUMELANIN_SIGMA = (0.506, 0.841, 1.653)  # Cycles' σ_a per unit concentration (R, G, B)
PHEOMELANIN_SIGMA = (0.343, 0.733, 1.924)
MIN_ALPHA = 0.01


def radial_factor(beta_n):
    """Chiang et al.'s polynomial in the radial (azimuthal) roughness β_n."""
    x = float(beta_n)
    return (((((0.245 * x) + 5.574) * x - 10.73) * x + 2.532) * x - 0.215) * x + 5.969


def sigma_from_colour(rgb, beta_n):
    """σ_a (per unit fibre diameter) whose multiple-scattering colour is ``rgb`` (Chiang's relation)."""
    c = np.clip(np.asarray(rgb, np.float64)[:3], 1e-6, 1.0)
    return (np.log(c) / radial_factor(beta_n)) ** 2


def colour_from_sigma(sigma, beta_n):
    """The hair colour c of absorption ``sigma`` (the inverse of :func:`sigma_from_colour`)."""
    s = np.maximum(np.asarray(sigma, np.float64)[:3], 0.0)
    return np.exp(-np.sqrt(s) * radial_factor(beta_n))


def sigma_from_melanin(melanin, redness):
    """Cycles' σ_a of Melanin (0..1, perceptually linear) and Melanin Redness."""
    m = -math.log(max(1.0 - float(melanin), 1e-4))
    eu, pheo = m * (1.0 - float(redness)), m * float(redness)
    return eu * np.array(EUMELANIN_SIGMA) + pheo * np.array(PHEOMELANIN_SIGMA)


def principled_hair_sigma(parametrization, colour, melanin, redness, tint, absorption, radial_roughness):
    """Cycles' absorption coefficient σ_a (R, G, B; per unit fibre radius) of a Principled Hair BSDF."""
    beta_n = min(max(float(radial_roughness), 0.0), 1.0)
    if parametrization == "ABSORPTION":
        return np.maximum(np.asarray(absorption, np.float64)[:3], 0.0)
    if parametrization == "MELANIN":
        return sigma_from_melanin(melanin, redness) + sigma_from_colour(tint, beta_n)
    return sigma_from_colour(colour, beta_n)  # COLOR (direct colouring)


def fresnel_dielectric(cos_i, eta):
    """Unpolarised Fresnel reflectance from outside a dielectric of relative index ``eta``."""
    cos_i = np.clip(np.asarray(cos_i, np.float64), 0.0, 1.0)
    sin_t2 = (1.0 - cos_i * cos_i) / (eta * eta)
    cos_t = np.sqrt(np.maximum(1.0 - sin_t2, 0.0))
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (rs * rs + rp * rp)


def fibre_energies(sigma, ior, n=4096):
    """(F̄, A): the mean Fresnel reflectance (R lobe) and the total albedo (R + TT + TRT + …) per
    channel of a smooth cylindrical fibre of absorption ``sigma`` (per unit radius) lit at normal
    incidence, averaged over the offsets h ∈ (−1, 1) across it."""
    h = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    f = fresnel_dielectric(np.sqrt(1.0 - h * h), float(ior))
    cos_t = np.sqrt(1.0 - (h / float(ior)) ** 2)
    t = np.exp(-2.0 * np.asarray(sigma, np.float64)[:, None] * cos_t[None, :])
    total = f + (1.0 - f) ** 2 * t / (1.0 - f * t)
    return float(f.mean()), total.mean(axis=1)


def principled_hair_albedo(sigma, ior):
    """The substitute plastic's base colour: the fibre's albedo beyond its R lobe, (A − F̄) / (1 − F̄)."""
    f_mean, total = fibre_energies(sigma, ior)
    return tuple(float(v) for v in np.clip((total - f_mean) / (1.0 - f_mean), 0.0, 1.0))


def _val(ctx, owner, node, name, kind="value", default=0.0):
    if node.inputs.get(name) is None:
        return default
    v = input_value(ctx, owner, node, (name,), kind)
    return default if v is None else v


def principled_hair(ctx, owner, node):
    """(base colour, GGX α, IOR) of the plastic that stands in for a Principled Hair BSDF; the
    substitute and the ignored inputs are recorded in the export warning."""
    label = f"{owner}/{node.name}"
    parametrization = getattr(node, "parametrization", "COLOR")
    radial = _val(ctx, owner, node, "Radial Roughness", default=0.3)
    sigma = principled_hair_sigma(
        parametrization, _val(ctx, owner, node, "Color", "colour", (0.0175, 0.0058, 0.0021)),
        _val(ctx, owner, node, "Melanin", default=0.8), _val(ctx, owner, node, "Melanin Redness", default=1.0),
        _val(ctx, owner, node, "Tint", "colour", (1.0, 1.0, 1.0)),
        _val(ctx, owner, node, "Absorption Coefficient", "colour", (0.245531, 0.52, 1.365)), radial)
    roughness = min(max(_val(ctx, owner, node, "Roughness", default=0.3), MIN_ALPHA), 1.0)
    ior = float(_val(ctx, owner, node, "IOR", default=1.55))
    rgb = principled_hair_albedo(sigma, max(ior, 1.0 + 1e-6))
    model = getattr(node, "model", "CHIANG").lower()
    ctx.skip("Principled Hair BSDF (an opaque plastic of the fibre's albedo: no fibre lobes)",
             f"{label} ({model}, base colour {rgb[0]:.3g}, {rgb[1]:.3g}, {rgb[2]:.3g})")
    ignored = [what for inp, what in (("Coat", "coat"), ("Random Color", "random colour"),
                                      ("Random Roughness", "random roughness"))
               if _val(ctx, owner, node, inp) > 0.0]
    if ignored:
        ctx.note(f"{label}: {', '.join(ignored)} ignored")
    return rgb, roughness, ior


def hair_bsdf(ctx, owner, node):
    """(component, colour, GGX α) of a Hair BSDF's substitute: Reflection → a GGX reflector of the
    colour, Transmission → a transparent surface of the colour (recorded in the export warning)."""
    colour = _val(ctx, owner, node, "Color", "colour", (0.8, 0.8, 0.8))
    component = getattr(node, "component", "Reflection")
    label = f"{owner}/{node.name}"
    if component == "Transmission":
        ctx.skip("Hair BSDF (Transmission: a transparent surface of its colour)", label)
        return "Transmission", colour, None
    alpha = min(max(_val(ctx, owner, node, "RoughnessU", default=0.1), MIN_ALPHA), 1.0)
    ctx.skip("Hair BSDF (Reflection: a GGX reflector of its colour)", label)
    return "Reflection", colour, alpha
