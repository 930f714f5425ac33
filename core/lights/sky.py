"""Daylight: the sky and sun of Blender's Sky Texture, computed spectrally from the atmosphere.

The sky's radiance is the light of the Sun scattered once by air molecules (Rayleigh) and
aerosols (Mie), attenuated on its way in and out by scattering and by absorption (aerosols,
ozone), in a spherical planet's atmosphere whose constituents thin out with height (Nishita
et al., "Display of the Earth taking into account atmospheric scattering", SIGGRAPH 1993).
For each wavelength λ of a 10 nm grid (360–830 nm) and each direction d from an observer at
altitude h₀:

    L(λ, d) = E☉(λ) ∫ Σₖ σₛ,ₖ(λ) ρₖ(h(t)) pₖ(d·s) exp(−τ_view(λ, t) − τ_sun(λ, x(t))) dt

with E☉ the Sun's spectral irradiance above the atmosphere, s the direction to the Sun,
k = molecules, aerosols (ozone absorbs only), ρₖ the relative density profile, σₛ,ₖ and
σₜ,ₖ the scattering and extinction coefficients at density 1, τ = Σₖ σₜ,ₖ ∫ ρₖ dt the
optical depths along the view ray and from x(t) to the Sun (zero light where the planet
shadows x(t)). The optical depth towards the Sun is looked up in a table over height and
zenith cosine (the transmittance table of Bruneton and Neyret, "Precomputed atmospheric
scattering", EGSR 2008), computed here by quadrature; the view ray is marched with steps
that grow away from the observer.

Two atmospheres, as Blender's two physical sky types:

* ``single`` (SINGLE_SCATTERING, the former Nishita): Blender's Nishita atmosphere — planet
  radius 6360 km, top 6420 km; molecules with an 8 km scale height and the Rayleigh
  coefficient of standard air, σ = 8π³(n²−1)²/(3Nλ⁴)·(6+3ρ)/(6−7ρ) (n from Peck and Reeder,
  J. Opt. Soc. Am. 62, 958 (1972); N = 2.547·10²⁵ m⁻³ at 15 °C, 1013.25 hPa; depolarisation
  ρ = 0.0279, Bucholtz, Appl. Opt. 34, 2765 (1995)); aerosols with a 1.2 km scale height,
  σₛ = 2·10⁻⁵ m⁻¹ at sea level, extinction 1.11 σₛ, the Cornette–Shanks phase function with
  g = 0.76 (Cornette and Shanks, Appl. Opt. 31, 3152 (1992)); ozone in a layer from 10 to
  40 km peaking at 25 km, 300 Dobson units, with the Chappuis band's cross-section below.
  Single scattering only, as Cycles' model.
* ``multiple`` (MULTIPLE_SCATTERING): the atmosphere of F. García Liñán's spectral sky
  (Blender 4.5+; https://fgarlin.com/posts/2024-12-06-spectral_sky/) — planet 6371 km,
  100 km thick, his fitted molecular, aerosol (urban, Henyey–Greenstein g = 0.8) and ozone
  (334.5 DU) profiles, coefficients from his four wavelengths (630, 560, 490, 430 nm)
  interpolated log–log, the Sun scaled to the luminance his model gives it (CYCLES_MS_SUN_Y);
  the single scattering is computed as above, and the higher orders
  are **approximated** by his analytic fit: an isotropic source of 0.02·c(λ)/(1 + 5e^(−17.92 μ☉))
  per unit scattering, plus the light reflected once by a grey ground of albedo 0.3.

A third, the Preetham sky (PREETHAM), is a closed-form fit in xyY of Perez's luminance
distribution (:func:`preetham_sky`), not a spectral model.

The Sun: a 5778 K blackbody of the IAU 2015 nominal solar radius (6.957·10⁸ m) seen from
1 au, E☉(λ) = π (R☉/au)² B(λ, 5778 K), 1367 W/m² in all — the extraterrestrial spectrum
Blender's model also uses; its direct irradiance at the observer is E☉(λ) times the
transmittance from the top of the atmosphere.

The sky is returned as an equirectangular image in linear Rec.709 (Blender's scene-linear,
RGB 1 = 683 cd/m², i.e. XYZ = ∫ x̄ L dλ in W/(m² sr)), the colour the core's world image
uplifts per texel: the world image is an RGB map, so the sky spectrum is reduced to XYZ and
Rec.709 as Cycles does (negative components clipped); keeping it spectral would take a
spectral world map in the kernels. The Sun stays spectral: its transmitted spectrum is the
shape of a sun light.
"""
from __future__ import annotations

import math
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from .. import constants as C

WAVELENGTHS = np.arange(360.0, 831.0, 10.0)  # nm, the sky's spectral grid (the renderer's range)

SUN_TEMPERATURE = 5778.0  # K
SUN_RADIUS = 6.957e8  # m, IAU 2015 Resolution B3 nominal solar radius
AU = 1.495978707e11  # m, IAU 2012 Resolution B2

SKY_TYPES = ("single", "multiple")

# Ozone absorption cross-section (m²) in the Chappuis band, 380–780 nm every 20 nm: the
# ozone absorption of Blender's Nishita sky (intern/sky, 300 DU in its 10–40 km layer)
# divided by the layer's peak number density, 5.38·10¹⁸ m⁻³; 3.9·10⁻²⁵ m² at 560 nm, as
# García Liñán's 3.914·10⁻²⁵ and the Chappuis maximum of ≈5·10⁻²⁵ m² near 600 nm
# (Serdyuchenko et al., Atmos. Meas. Tech. 7, 625 (2014)).
_OZONE_WL = np.arange(380.0, 781.0, 20.0)
_OZONE_SIGMA = np.array([
    0.000604, 0.001088, 0.003675, 0.01359, 0.03733, 0.07506, 0.1181, 0.1798, 0.2877, 0.3885, 0.4575,
    0.5084, 0.3998, 0.2956, 0.2088, 0.1367, 0.08633, 0.06151, 0.04184, 0.02766, 0.03128]) * 1e-24
DOBSON = 2.6867e20  # molecules per m² in one Dobson unit


# García Liñán's model reduces its four radiance samples to XYZ with a fitted matrix; with his
# solar irradiance samples (1.679, 1.828, 1.986, 1.307 W m⁻² nm⁻¹ at 630, 560, 490, 430 nm) it
# gives the Sun above the atmosphere Y = 208.68 W m⁻² sr⁰ (142.5 klx), 13 % more than the CIE
# integral of the 5778 K Sun (184.28, 125.9 klx). Cycles' Multiple Scattering sky and sun are
# that much brighter; the "multiple" atmosphere scales the Sun to it, so it renders at Cycles'
# brightness (its colour stays the spectral computation's).
CYCLES_MS_SUN_Y = 208.68


def _sun_y():
    return float(np.sum(_v_lambda(WAVELENGTHS) * sun_irradiance_top()) * (WAVELENGTHS[1] - WAVELENGTHS[0]))


def sun_irradiance_top(wl=WAVELENGTHS):
    """Spectral irradiance (W m⁻² nm⁻¹) of the Sun above the atmosphere: π (R☉/au)² B(λ, 5778 K)."""
    h, c, k = 6.62607015e-34, 299792458.0, 1.380649e-23
    lam = np.asarray(wl, np.float64) * 1e-9
    planck = 2.0 * h * c * c / lam ** 5 / np.expm1(h * c / (lam * k * SUN_TEMPERATURE))  # W m⁻² sr⁻¹ m⁻¹
    return planck * math.pi * (SUN_RADIUS / AU) ** 2 * 1e-9


def rayleigh_coefficient(wl=WAVELENGTHS):
    """Rayleigh scattering coefficient (m⁻¹) of standard air at sea level (Bucholtz 1995)."""
    lam = np.asarray(wl, np.float64) * 1e-9
    s2 = (1.0 / (lam * 1e6)) ** 2
    n = 1.0 + (8060.51 + 2480990.0 / (132.274 - s2) + 17455.7 / (39.32957 - s2)) * 1e-8
    rho = 0.0279
    return 8.0 * math.pi ** 3 * (n * n - 1.0) ** 2 / (3.0 * 2.547e25 * lam ** 4) * (6 + 3 * rho) / (6 - 7 * rho)


def ozone_cross_section(wl=WAVELENGTHS):
    return np.interp(np.asarray(wl, np.float64), _OZONE_WL, _OZONE_SIGMA)


def _loglog(wl, x, y):
    """Log–log interpolation of samples (x ascending), extrapolated with the end slopes."""
    lx, ly, lw = np.log(x), np.log(y), np.log(np.asarray(wl, np.float64))
    out = np.interp(lw, lx, ly)
    lo, hi = lw < lx[0], lw > lx[-1]
    out[lo] = ly[0] + (lw[lo] - lx[0]) * (ly[1] - ly[0]) / (lx[1] - lx[0])
    out[hi] = ly[-1] + (lw[hi] - lx[-1]) * (ly[-1] - ly[-2]) / (lx[-1] - lx[-2])
    return np.exp(out)


class Atmosphere(NamedTuple):
    """A spherically symmetric atmosphere: radii (m), species coefficients at density 1 (3, L),
    the density profile kind, the aerosol phase ('cs' Cornette–Shanks, 'hg') and its g."""

    kind: str  # "single" or "multiple"
    earth_radius: float
    top_radius: float
    scattering: np.ndarray  # (3, L) m⁻¹: molecules, aerosols, ozone (0)
    extinction: np.ndarray  # (3, L) m⁻¹
    phase: str
    g: float
    ms: np.ndarray  # (L,) García Liñán's multiple-scattering colour c(λ); zeros for none
    sun_scale: float = 1.0  # the Sun's spectrum × this (Cycles' normalisation, see CYCLES_MS_SUN_Y)


def atmosphere(kind="single", air_density=1.0, aerosol_density=1.0, ozone_density=1.0):
    """The atmosphere of Blender's ``SINGLE_SCATTERING`` ("single") or ``MULTIPLE_SCATTERING``
    ("multiple") sky, with Blender's density factors."""
    wl = WAVELENGTHS
    if kind == "single":
        mol = rayleigh_coefficient(wl) * air_density
        aer_s = np.full_like(wl, 2e-5 * aerosol_density)
        oz = ozone_cross_section(wl) * 5.38e18 * ozone_density  # at the layer's peak
        scat = np.stack([mol, aer_s, 0 * wl])
        ext = np.stack([mol, 1.11 * aer_s, oz])
        return Atmosphere(kind, 6360e3, 6420e3, scat, ext, "cs", 0.76, np.zeros_like(wl))
    if kind == "multiple":
        x = np.array([430.0, 490.0, 560.0, 630.0])
        mol = _loglog(wl, x, np.array([3.156e-2, 1.842e-2, 1.067e-2, 6.605e-3]) * 1e-3) * air_density
        base = 1.3681e20 * 1e-3 * aerosol_density  # cross-sections (km² scale) × base density → m⁻¹
        aer_s = _loglog(wl, x, np.array([2.4033e-22, 2.0942e-22, 1.7711e-22, 1.5908e-22])) * base
        aer_a = _loglog(wl, x, np.array([1.3578e-23, 7.9706e-24, 4.6168e-24, 2.8722e-24])) * base
        # ozone: cross-section × 334.5 DU × the profile's number density per DU (per m³)
        oz = ozone_cross_section(wl) * ozone_density
        scat = np.stack([mol, aer_s, 0 * wl])
        ext = np.stack([mol, aer_s + aer_a, oz])
        ms = _loglog(wl, x, np.array([1.0, 0.594, 0.347, 0.217]))
        return Atmosphere(kind, 6371e3, 6471e3, scat, ext, "hg", 0.8, ms, CYCLES_MS_SUN_Y / _sun_y())
    raise ValueError(f"unknown sky type {kind!r} (expected one of {SKY_TYPES})")


def densities(atm, h):
    """Relative densities (3, ...) of molecules, aerosols and ozone at heights ``h`` (m); for
    the "multiple" atmosphere ozone's is its number density in m⁻³ (the cross-section carries no density)."""
    h = np.maximum(np.asarray(h, np.float64), 0.0)
    if atm.kind == "single":
        return np.stack([np.exp(-h / 8000.0), np.exp(-h / 1200.0),
                         np.maximum(0.0, 1.0 - np.abs(h - 25000.0) / 15000.0)])
    km = h * 1e-3
    mol = np.exp(-0.07771971 * km ** 1.16364243)
    aer = np.exp(-km / 0.73) + 2e6 / 1.3681e20
    lh = np.log(np.maximum(km, 1e-4))
    oz = 3.78547397e20 * np.exp(-(lh - 3.22261) ** 2 * 5.55555555 - lh) * 334.5 * 1e-3  # m⁻³ (× σ: m⁻¹)
    return np.stack([mol, aer, oz])


def _phase(atm, mu):
    ray = 3.0 / (16.0 * math.pi) * (1.0 + mu * mu)
    g2 = atm.g * atm.g
    if atm.phase == "cs":
        aer = 3.0 * (1.0 - g2) * (1.0 + mu * mu) / (8.0 * math.pi * (2.0 + g2) * (1.0 + g2 - 2.0 * atm.g * mu) ** 1.5)
    else:
        aer = (1.0 - g2) / (4.0 * math.pi * (1.0 + g2 - 2.0 * atm.g * mu) ** 1.5)
    return ray, aer


def _to_sphere(r, mu, radius):
    """Distance along a ray from radius r with zenith cosine mu to the sphere of ``radius`` (outwards)."""
    disc = np.maximum(r * r * (mu * mu - 1.0) + radius * radius, 0.0)
    return -r * mu + np.sqrt(disc)


def _hits_ground(atm, r, mu):
    return (mu < 0.0) & (r * r * (1.0 - mu * mu) < atm.earth_radius ** 2)


class _DepthTable(NamedTuple):
    heights: np.ndarray  # (NH,)
    depth: np.ndarray  # (3, NH, NX) column ∫ρ dt (m) to the top, over x = sqrt((μ − μ_h)/(1 − μ_h))


def _depth_table(atm, nh=96, nx=256, nt=256):
    """Column densities of the three species from height h towards zenith cosine μ to the top of
    the atmosphere (μ above the horizon), for the optical depth towards the Sun."""
    top = atm.top_radius - atm.earth_radius
    heights = top * np.linspace(0.0, 1.0, nh) ** 2
    r = (atm.earth_radius + heights)[:, None]
    x = np.linspace(0.0, 1.0, nx)[None, :]
    mu_h = -np.sqrt(np.maximum(1.0 - (atm.earth_radius / r) ** 2, 0.0))
    mu = mu_h + (1.0 - mu_h) * x * x
    length = _to_sphere(r, mu, atm.top_radius)
    w = (np.arange(nt) + 0.5) / nt  # t = length·w², dt = 2·length·w dw: dense near the start
    depth = np.zeros((3, nh, nx))
    for wi in w:
        t = length * wi * wi
        rr = np.sqrt(r * r + t * t + 2.0 * r * t * mu)
        depth += densities(atm, rr - atm.earth_radius) * (2.0 * length * wi / nt)
    return _DepthTable(heights, depth)


def _lookup_depth(atm, table, h, mu):
    """Column densities (3, ...) towards zenith cosine ``mu`` from height ``h``; inf where the planet
    is in the way."""
    top = atm.top_radius - atm.earth_radius
    h = np.clip(h, 0.0, top)
    r = atm.earth_radius + h
    mu_h = -np.sqrt(np.maximum(1.0 - (atm.earth_radius / r) ** 2, 0.0))
    shadow = mu < mu_h
    x = np.sqrt(np.clip((mu - mu_h) / (1.0 - mu_h), 0.0, 1.0))
    nh, nx = table.depth.shape[1:]
    fh = np.sqrt(h / top) * (nh - 1)
    fx = x * (nx - 1)
    i0 = np.minimum(fh.astype(np.int64), nh - 2)
    j0 = np.minimum(fx.astype(np.int64), nx - 2)
    a, b = fh - i0, fx - j0
    d = table.depth
    out = ((1 - a) * (1 - b) * d[:, i0, j0] + (1 - a) * b * d[:, i0, j0 + 1]
           + a * (1 - b) * d[:, i0 + 1, j0] + a * b * d[:, i0 + 1, j0 + 1])
    return np.where(shadow, np.inf, out)


def sun_transmittance(atm, elevation, altitude, ozone=True, table=None):
    """Spectral transmittance (L,) of the atmosphere from its top to an observer at ``altitude`` (m)
    towards a Sun at ``elevation`` (rad); 0 below the horizon. ``ozone=False`` leaves ozone's
    absorption out, as Cycles' single-scattering sun disc does."""
    table = _depth_table(atm) if table is None else table
    depth = _lookup_depth(atm, table, np.asarray(float(altitude)), np.asarray(math.sin(elevation)))
    ext = atm.extinction if ozone else atm.extinction[:2]
    return np.exp(-_tau(ext, depth[:ext.shape[0]]))


def sky_radiance(atm, elevations, azimuths, sun_elevation, altitude, steps=64, table=None):
    """Spectral radiance (len(elevations), len(azimuths), L) in W m⁻² sr⁻¹ nm⁻¹ of the sky seen
    from ``altitude`` (m) towards view elevations (rad) and azimuths measured from the Sun's
    (rad), for a Sun at ``sun_elevation``; rays below the horizon end at the ground."""
    table = _depth_table(atm) if table is None else table
    e = np.asarray(elevations, np.float64)[:, None]
    a = np.asarray(azimuths, np.float64)[None, :]
    d = np.stack(np.broadcast_arrays(np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)), -1)  # (E, A, 3)
    s = np.array([math.cos(sun_elevation), 0.0, math.sin(sun_elevation)])
    r0 = atm.earth_radius + float(altitude)
    mu0 = d[..., 2]
    ground = _hits_ground(atm, r0, mu0)
    length = np.where(ground, r0 * -mu0 - np.sqrt(np.maximum(r0 * r0 * (mu0 * mu0 - 1) + atm.earth_radius ** 2, 0)),
                      _to_sphere(r0, mu0, atm.top_radius))
    mu_s = d @ s  # (E, A): cosine between the view and the Sun
    ray_p, aer_p = _phase(atm, mu_s)
    sun = sun_irradiance_top(WAVELENGTHS) * atm.sun_scale
    edges = (np.arange(steps + 1) / steps) ** 2
    depth_view = np.zeros((3,) + mu0.shape)
    out = np.zeros(mu0.shape + (atm.scattering.shape[1],))
    for i in range(steps):
        t = length * 0.5 * (edges[i] + edges[i + 1])
        dt = length * (edges[i + 1] - edges[i])
        p = np.array([0.0, 0.0, r0]) + d * t[..., None]
        rp = np.linalg.norm(p, axis=-1)
        h = rp - atm.earth_radius
        rho = densities(atm, h)
        mid = depth_view + 0.5 * rho * dt
        depth_view = depth_view + rho * dt
        up = p / rp[..., None]
        cos_sun = up @ s
        depth_sun = _lookup_depth(atm, table, h, cos_sun)
        lit = np.isfinite(depth_sun[0])
        depth_sun = np.where(lit, depth_sun, 0.0)
        t_view_sun = np.exp(-_tau(atm.extinction, mid + depth_sun)) * lit[..., None]
        scat_m = rho[0][..., None] * atm.scattering[0]
        scat_a = rho[1][..., None] * atm.scattering[1]
        source = (scat_m * ray_p[..., None] + scat_a * aer_p[..., None]) * t_view_sun
        if atm.kind == "multiple":
            source = source + (scat_m + scat_a) * np.exp(-_tau(atm.extinction, mid)) \
                * _multiple_term(atm, table, h, rp, cos_sun)
        out += source * dt[..., None]
    return out * sun


def _tau(ext, depth):
    """Optical depth (..., L) of column densities (3, ...) with extinction coefficients (3, L)."""
    return np.moveaxis(depth, 0, -1) @ ext
def _multiple_term(atm, table, h, rp, cos_sun):
    """García Liñán's approximation of the higher scattering orders (1/sr, per unit irradiance)
    at points of height ``h``: his isotropic fit plus the Sun's light reflected by a ground of
    albedo 0.3 and scattered once (the ground seen under its solid angle, through the air)."""
    fit = 0.02 * atm.ms / (1.0 + 5.0 * np.exp(-17.92 * cos_sun))[..., None]
    omega = 2.0 * math.pi * (1.0 - np.sqrt(np.maximum(1.0 - (atm.earth_radius / rp) ** 2, 0.0)))
    # transmittance ground → Sun along the Sun's zenith angle at the point, and ground → point straight down
    to_ground = _lookup_depth(atm, table, np.zeros_like(h), cos_sun)
    lit = np.isfinite(to_ground[0])
    t_ground_sun = np.exp(-_tau(atm.extinction, np.where(lit, to_ground, 0.0)))
    up_ground = _lookup_depth(atm, table, np.zeros_like(h), np.ones_like(h))
    up_point = _lookup_depth(atm, table, h, np.ones_like(h))
    t_between = np.exp(-_tau(atm.extinction, up_ground - up_point))
    ground = (1.0 / (4.0 * math.pi)) * omega[..., None] * (0.3 / math.pi) * t_ground_sun * t_between \
        * (np.maximum(cos_sun, 0.0) * lit)[..., None]
    return fit + ground


def spectrum_to_rgb(L, wl=WAVELENGTHS):
    """XYZ = Σ x̄ L Δλ → linear Rec.709 (negative components clipped, as Cycles' sky), (..., 3)."""
    from ..colour.rgb import XYZ_to_sRGB_linear
    from ..colour.tristimulus import cmfs

    cwl, bar = cmfs("1931")
    w = np.stack([np.interp(wl, cwl, bar[:, c]) for c in range(3)], -1) * (wl[1] - wl[0])
    xyz = L @ w
    return np.maximum(XYZ_to_sRGB_linear(xyz), 0.0)


class Daylight(NamedTuple):
    """A Sky Texture as the core renders it: a world image and an optional sun light.

    image: float32 (H, W, 3) linear Rec.709 equirectangular map (the core's World layout).
    sun_direction: unit vector the sunlight travels along (towards the ground), or None (no disc).
    sun_wavelengths, sun_irradiance: the sun's spectral irradiance (W m⁻² nm⁻¹) on a surface
    facing it at the observer; sun_illuminance: its lux (K_m ∫ V E dλ); sun_angle: rad.
    """

    image: np.ndarray
    sun_direction: tuple | None
    sun_wavelengths: np.ndarray
    sun_irradiance: np.ndarray
    sun_illuminance: float
    sun_angle: float


# Cycles' sun disc: the centre's radiance is the transmitted irradiance over the disc's solid
# angle, darkened towards the limb by 1 − u(1 − cos ψ) with u = 0.6 (intern/cycles
# kernel/svm/sky.h); the disc then delivers on average 1 − u/3 = 0.8 of that irradiance.
CYCLES_LIMB_DARKENING = 0.6


@lru_cache(maxsize=8)
def blender_sky(sky_type="single", sun_elevation=math.radians(15.0), sun_rotation=0.0, sun_size=math.radians(0.545),
                sun_intensity=1.0, sun_disc=True, altitude=100.0, air_density=1.0, aerosol_density=1.0,
                ozone_density=1.0, width=512, height=256):
    """The sky and sun of Blender's Sky Texture node (``sky_type`` "single": SINGLE_SCATTERING,
    "multiple": MULTIPLE_SCATTERING, angles in rad, altitude in m), as a :class:`Daylight`,
    following Cycles' conventions where they are choices rather than physics:

    * the Sun at azimuth π/2 − ``sun_rotation`` from +X (rotation 0: towards +Y);
    * the single-scattering sky below the horizon is its horizon's colour faded by (1 + 2.5 z)³
      to black at z = −0.4; the multiple-scattering sky is marched to the ground;
    * altitude clamped to [1, 59999] m (single) or [1, 99999] m (multiple);
    * the sun disc's light is the transmitted spectrum × ``sun_intensity`` × 0.8 (Cycles'
      limb darkening, see CYCLES_LIMB_DARKENING), without ozone in the single-scattering
      model (Cycles leaves it out there); no sun light when the disc is off or its centre is
      below the horizon.
    """
    if sky_type not in SKY_TYPES:
        raise ValueError(f"unknown sky type {sky_type!r} (expected one of {SKY_TYPES})")
    if width < 4 or height < 4 or height % 2:
        raise ValueError("the sky image needs at least 4 × 4 texels and an even height")
    altitude = float(np.clip(altitude, 1.0, 59999.0 if sky_type == "single" else 99999.0))
    atm = atmosphere(sky_type, air_density, aerosol_density, ozone_density)
    table = _depth_table(atm)
    rows = math.pi / 2 - math.pi * (np.arange(height) + 0.5) / height  # row elevations, zenith first
    rel = np.linspace(0.0, math.pi, 181)  # azimuth from the Sun's, 1° apart
    # elevations computed: (π/2)x² for x evenly spaced (dense at the horizon, as Cycles' table),
    # then interpolated linearly to the image's rows
    n = max(height // 4, 8)
    ups = math.pi / 2 * np.linspace(0.0, 1.0, n + 1) ** 2
    upper_rows = rows[: height // 2]
    if sky_type == "single":
        horizon = math.pi / 2 * 0.016 ** 2  # Cycles' texture row just above the horizon
        rgb = spectrum_to_rgb(sky_radiance(atm, np.append(ups, horizon), rel, sun_elevation, altitude, table=table))
        z = np.sin(rows[height // 2:])
        fade = np.where(z > -0.4, (1.0 + 2.5 * z) ** 3, 0.0)
        table_rgb = np.concatenate([_rows_at(ups, rgb[:-1], upper_rows), rgb[-1][None] * fade[:, None, None]])
    else:
        downs = -ups[::-1]
        rgb = spectrum_to_rgb(sky_radiance(atm, np.concatenate([downs, ups[1:]]), rel, sun_elevation, altitude,
                                           table=table))
        table_rgb = _rows_at(np.concatenate([downs, ups[1:]]), rgb, rows)
    # resample from the Sun's azimuth to the image's columns (u = 1/2 − φ/2π)
    phi = math.pi - 2.0 * math.pi * (np.arange(width) + 0.5) / width
    sun_phi = math.pi / 2 - sun_rotation
    psi = np.abs((phi - sun_phi + math.pi) % (2.0 * math.pi) - math.pi)
    j = np.clip(psi / (rel[1] - rel[0]), 0, rel.size - 1.000001)
    j0 = j.astype(np.int64)
    f = (j - j0)[None, :, None]
    image = (1 - f) * table_rgb[:, j0] + f * table_rgb[:, j0 + 1]
    image = np.ascontiguousarray(image, np.float32)
    image.setflags(write=False)  # cached: shared by every export of the same sky

    wl = WAVELENGTHS
    irr = np.zeros_like(wl)
    direction = None
    if sun_disc and sun_size > 0.0 and sun_intensity > 0.0 and sun_elevation > 0.0:
        trans = sun_transmittance(atm, sun_elevation, altitude, ozone=sky_type != "single", table=table)
        irr = sun_irradiance_top(wl) * atm.sun_scale * trans * sun_intensity * (1.0 - CYCLES_LIMB_DARKENING / 3.0)
        ce = math.cos(sun_elevation)
        direction = (-ce * math.cos(sun_phi), -ce * math.sin(sun_phi), -math.sin(sun_elevation))
    irr.setflags(write=False)
    illuminance = float(C.K_M * np.sum(_v_lambda(wl) * irr) * (wl[1] - wl[0]))
    return Daylight(image, direction, wl, irr, illuminance, float(sun_size))


def _rows_at(elevations, values, rows):
    """``values`` (len(elevations) ascending, A, 3) interpolated linearly to the elevations ``rows``."""
    i = np.clip(np.searchsorted(elevations, rows) - 1, 0, elevations.size - 2)
    f = np.clip((rows - elevations[i]) / (elevations[i + 1] - elevations[i]), 0.0, 1.0)[:, None, None]
    return (1.0 - f) * values[i] + f * values[i + 1]


def _v_lambda(wl):
    from ..colour.tristimulus import cmfs

    cwl, bar = cmfs("1931")
    return np.interp(wl, cwl, bar[:, 1])


# ----------------------------------------------------------------------------- Preetham

# Perez et al.'s sky luminance distribution, F(θ, γ) = (1 + A e^(B/cos θ))(1 + C e^(Dγ) + E cos²γ),
# with the coefficients of Y, x and y linear in turbidity T (Preetham, Shirley and Smits, "A
# practical analytic model for daylight", SIGGRAPH 1999, appendix A.2): rows (slope, offset).
_PEREZ = {
    "Y": ((0.1787, -1.4630), (-0.3554, 0.4275), (-0.0227, 5.3251), (0.1206, -2.5771), (-0.0670, 0.3703)),
    "x": ((-0.0193, -0.2592), (-0.0665, 0.0008), (-0.0004, 0.2125), (-0.0641, -0.8989), (-0.0033, 0.0452)),
    "y": ((-0.0167, -0.2608), (-0.0950, 0.0092), (-0.0079, 0.2102), (-0.0441, -1.6537), (-0.0109, 0.0529)),
}
# zenith chromaticity: [T², T, 1] · M · [θs³, θs², θs, 1] (ibid.)
_ZENITH_X = np.array([[0.00166, -0.00375, 0.00209, 0.0], [-0.02903, 0.06377, -0.03202, 0.00394],
                      [0.11693, -0.21196, 0.06052, 0.25886]])
_ZENITH_Y = np.array([[0.00275, -0.00610, 0.00317, 0.0], [-0.04214, 0.08970, -0.04153, 0.00516],
                      [0.15346, -0.26756, 0.06670, 0.26688]])
# Cycles' scale of the zenith luminance (kcd/m² in the paper) to its scene-linear Y
CYCLES_PREETHAM_SCALE = 0.06


def _perez(coeffs, theta, gamma):
    A, B, Cc, D, E = coeffs
    return (1.0 + A * np.exp(B / np.cos(theta))) * (1.0 + Cc * np.exp(D * gamma) + E * np.cos(gamma) ** 2)


def preetham_sky(sun_direction=(0.0, 0.0, 1.0), turbidity=2.2, width=512, height=256):
    """The Preetham sky (closed form: Perez distributions of Y, x, y scaled to the zenith's value)
    as an equirectangular linear Rec.709 image in Blender's scene-linear units, as Cycles'
    PREETHAM Sky Texture: the zenith luminance Y_z (kcd/m²) × 0.06, directions below the horizon
    take the horizon's colour, no sun disc. ``sun_direction``: towards the Sun (normalised here)."""
    if not 1.0 <= float(turbidity) <= 10.0:
        raise ValueError(f"Preetham turbidity {turbidity!r} outside the model's range [1, 10]")
    s = np.asarray(sun_direction, np.float64)
    if not np.linalg.norm(s) > 0.0:
        raise ValueError("the Preetham sun direction is a zero vector")
    s = s / np.linalg.norm(s)
    T = float(turbidity)
    ts = math.acos(min(max(s[2], -1.0), 1.0))
    coeffs = {k: tuple(a * T + b for a, b in rows) for k, rows in _PEREZ.items()}
    chi = (4.0 / 9.0 - T / 120.0) * (math.pi - 2.0 * ts)
    zen_Y = ((4.0453 * T - 4.9710) * math.tan(chi) - 0.2155 * T + 2.4192) * CYCLES_PREETHAM_SCALE
    tv = np.array([ts ** 3, ts ** 2, ts, 1.0])
    zen = {"Y": zen_Y, "x": np.array([T * T, T, 1.0]) @ _ZENITH_X @ tv, "y": np.array([T * T, T, 1.0]) @ _ZENITH_Y @ tv}
    theta = math.pi * (np.arange(height) + 0.5) / height
    phi = math.pi - 2.0 * math.pi * (np.arange(width) + 0.5) / width
    d = np.stack(np.broadcast_arrays(np.sin(theta)[:, None] * np.cos(phi)[None], np.sin(theta)[:, None]
                                     * np.sin(phi)[None], np.cos(theta)[:, None]), -1)
    gamma = np.arccos(np.clip(d @ s, -1.0, 1.0))
    th = np.minimum(theta, math.pi / 2 - 0.001)[:, None]
    v = {k: zen[k] * _perez(coeffs[k], th, gamma) / _perez(coeffs[k], 0.0, ts) for k in ("Y", "x", "y")}
    Y, x, y = v["Y"], v["x"], v["y"]
    xyz = np.stack([x / y * Y, Y, (1.0 - x - y) / y * Y], -1)
    from ..colour.rgb import XYZ_to_sRGB_linear

    image = np.ascontiguousarray(np.maximum(XYZ_to_sRGB_linear(xyz), 0.0), np.float32)
    return image
