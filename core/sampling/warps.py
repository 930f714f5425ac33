"""Warps from the unit square to directions and points (compendium items 18–21).

Each warp is a ``sample_*`` / ``*_pdf`` / ``invert_*`` triplet of ``@inline`` functions
in the local frame (z = normal). Samplers return ``(x, y, z, pdf)`` with the pdf per
unit solid angle (per unit area for the disk and triangle warps).

pdf convention (item 1, Dirac impulses), shared by the whole package:

* ``0 < pdf < inf``: an ordinary sample of a density;
* ``pdf == 0``: no sample (degenerate input, or a direction where the density is 0,
  e.g. exactly on the horizon of a cosine lobe); the caller discards it;
* ``pdf == inf``: a Dirac (delta) event, e.g. a cone of half-angle 0. The direction is
  exact; weight it as a discrete event (no division by a density). Evaluating the
  density of a delta distribution at any direction (``*_pdf``) returns 0, because no
  other technique can produce that direction, and the MIS weight of a delta event is
  1 (``mis.py``).

All warps use φ = 2π u1 and put u2 on the polar angle with u2 = 0 at the pole, so
``invert_*`` is ``(φ / 2π, F(θ))`` with F the cdf of θ, and u in [0, 1) never lands
exactly on the horizon where cosine lobes have zero density.
"""
import math

from ..jit import inline
from .frame import INV_TWO_PI, TWO_PI, safe_sqrt, spherical_phi

INV_PI = 1.0 / math.pi
INV_FOUR_PI = 1.0 / (4.0 * math.pi)
HALF_PI = 0.5 * math.pi
PI_OVER_4 = 0.25 * math.pi


# -- item 18: uniform sphere -------------------------------------------------------

@inline
def sample_uniform_sphere(u1, u2):
    z = 1.0 - 2.0 * u2
    r = 2.0 * safe_sqrt(u2 * (1.0 - u2))  # sqrt(1 - z²) without cancellation at the poles
    phi = TWO_PI * u1
    return r * math.cos(phi), r * math.sin(phi), z, INV_FOUR_PI


@inline
def uniform_sphere_pdf():
    return INV_FOUR_PI


@inline
def invert_uniform_sphere(x, y, z):
    return spherical_phi(x, y) * INV_TWO_PI, min(max(0.5 * (1.0 - z), 0.0), 1.0)


@inline
def sample_sphere_point(cx, cy, cz, radius, u1, u2):
    """Item 18 as stated: a point on the sphere (c, R), pdf 1/(4π R²) per unit area."""
    x, y, z, _ = sample_uniform_sphere(u1, u2)
    area = 4.0 * math.pi * radius * radius
    pdf = 1.0 / area if area > 0.0 else math.inf
    return cx + radius * x, cy + radius * y, cz + radius * z, pdf


# -- item 19: uniform hemisphere and cone ------------------------------------------

@inline
def cone_one_minus_cos(theta_max):
    """1 - cos θmax, accurate for tiny angles; θmax is clamped to [0, π]."""
    t = min(max(theta_max, 0.0), math.pi)
    s = math.sin(0.5 * t)
    return 2.0 * s * s


@inline
def sample_uniform_cone(theta_max, u1, u2):
    """Uniform in the cone θ ≤ θmax around z: p = 1 / (2π (1 - cos θmax)).

    θmax = π/2 is the uniform hemisphere, θmax = π the sphere; θmax = 0 is a Dirac
    direction (pdf = inf).
    """
    k = cone_one_minus_cos(theta_max)
    if k == 0.0:
        return 0.0, 0.0, 1.0, math.inf
    t = u2 * k  # 1 - cos θ
    z = 1.0 - t
    r = safe_sqrt(t * (2.0 - t))
    phi = TWO_PI * u1
    return r * math.cos(phi), r * math.sin(phi), z, 1.0 / (TWO_PI * k)


@inline
def uniform_cone_pdf(theta_max, x, y, z):
    k = cone_one_minus_cos(theta_max)
    if k == 0.0:
        return 0.0
    # inside test on 1 - cos θ (exact for tiny cones), with a relative tolerance
    t = (x * x + y * y) / (1.0 + abs(z)) if z >= 0.0 else 1.0 - z
    if t > k * (1.0 + 1e-12):
        return 0.0
    return 1.0 / (TWO_PI * k)


@inline
def invert_uniform_cone(theta_max, x, y, z):
    k = cone_one_minus_cos(theta_max)
    if k == 0.0:
        return 0.0, 0.0
    t = (x * x + y * y) / (1.0 + z) if z >= 0.0 else 1.0 - z
    return spherical_phi(x, y) * INV_TWO_PI, min(max(t / k, 0.0), 1.0)


@inline
def sample_uniform_hemisphere(u1, u2):
    """Item 19: p = 1/(2π); z = 1 - u2 so that u2 in [0, 1) never gives the horizon."""
    return sample_uniform_cone(HALF_PI, u1, u2)


@inline
def uniform_hemisphere_pdf(x, y, z):
    return INV_TWO_PI if z >= 0.0 else 0.0


@inline
def invert_uniform_hemisphere(x, y, z):
    return invert_uniform_cone(HALF_PI, x, y, z)


# -- item 20: cosine-weighted hemisphere and cone ------------------------------------

@inline
def sample_cosine_cone(theta_max, u1, u2):
    """p = cos θ / (π sin² θmax) for θ ≤ θmax ≤ π/2 (θmax = π/2: the Lambertian lobe).

    sin²θ = u2 sin²θmax (polar map of the disk of radius sin θmax, projected up).
    """
    tm = min(max(theta_max, 0.0), HALF_PI)
    s2max = math.sin(tm) ** 2
    if s2max == 0.0:
        return 0.0, 0.0, 1.0, math.inf
    s2 = u2 * s2max
    z = math.sqrt(1.0 - s2)
    r = math.sqrt(s2)
    phi = TWO_PI * u1
    return r * math.cos(phi), r * math.sin(phi), z, z * INV_PI / s2max


@inline
def cosine_cone_pdf(theta_max, x, y, z):
    tm = min(max(theta_max, 0.0), HALF_PI)
    s2max = math.sin(tm) ** 2
    if s2max == 0.0 or z <= 0.0:
        return 0.0
    if x * x + y * y > s2max * (1.0 + 1e-12):
        return 0.0
    return z * INV_PI / s2max


@inline
def invert_cosine_cone(theta_max, x, y, z):
    tm = min(max(theta_max, 0.0), HALF_PI)
    s2max = math.sin(tm) ** 2
    if s2max == 0.0:
        return 0.0, 0.0
    return spherical_phi(x, y) * INV_TWO_PI, min(max((x * x + y * y) / s2max, 0.0), 1.0)


@inline
def sample_cosine_hemisphere(u1, u2):
    """Item 20: p = cos θ / π (z = sqrt(1 - u2))."""
    return sample_cosine_cone(HALF_PI, u1, u2)


@inline
def cosine_hemisphere_pdf(x, y, z):
    return z * INV_PI if z > 0.0 else 0.0


@inline
def invert_cosine_hemisphere(x, y, z):
    return invert_cosine_cone(HALF_PI, x, y, z)


# -- item 21: cos^n lobe around z, optionally limited to θ ≤ θmax ---------------------

@inline
def _cosn_cap_mass(n, theta_max):
    """1 - cos^{n+1} θmax (the lobe's mass fraction inside the cap), accurate for tiny caps."""
    tm = min(max(theta_max, 0.0), HALF_PI)
    if tm >= HALF_PI:
        return 1.0
    k = cone_one_minus_cos(tm)
    return -math.expm1((n + 1.0) * math.log1p(-k))


@inline
def sample_cosn_cone(n, theta_max, u1, u2):
    """p = (n+1) cosⁿθ / (2π (1 - cos^{n+1} θmax)) for θ ≤ θmax ≤ π/2.

    cos^{n+1} θ = 1 - u2 K with K = 1 - cos^{n+1}θmax, evaluated through
    log1p/expm1 so that n up to ~1e6 and tiny θmax keep full precision. n = 0 is the
    uniform cone, n = 1 the cosine-weighted cone. θmax = 0 or n = inf is a Dirac.
    """
    if not (n >= 0.0):
        return 0.0, 0.0, 1.0, 0.0
    mass = _cosn_cap_mass(n, theta_max)
    if mass == 0.0 or n == math.inf:
        return 0.0, 0.0, 1.0, math.inf
    lc = math.log1p(-u2 * mass) / (n + 1.0)  # log cos θ
    t = -math.expm1(lc)  # 1 - cos θ
    z = 1.0 - t
    r = safe_sqrt(t * (2.0 - t))
    if z <= 0.0:
        return r, 0.0, 0.0, 0.0
    phi = TWO_PI * u1
    pdf = (n + 1.0) * math.exp(n * lc) / (TWO_PI * mass)
    return r * math.cos(phi), r * math.sin(phi), z, pdf


@inline
def cosn_cone_pdf(n, theta_max, x, y, z):
    if not (n >= 0.0) or z <= 0.0:
        return 0.0
    mass = _cosn_cap_mass(n, theta_max)
    if mass == 0.0 or n == math.inf:
        return 0.0
    tm = min(max(theta_max, 0.0), HALF_PI)
    if tm < HALF_PI:
        t = (x * x + y * y) / (1.0 + z)
        if t > cone_one_minus_cos(tm) * (1.0 + 1e-12):
            return 0.0
    if n == 0.0:
        return 1.0 / (TWO_PI * mass)
    return (n + 1.0) * math.exp(n * math.log(z)) / (TWO_PI * mass)


@inline
def invert_cosn_cone(n, theta_max, x, y, z):
    mass = _cosn_cap_mass(n, theta_max)
    if not (n >= 0.0) or mass == 0.0 or n == math.inf or z <= 0.0:
        return 0.0, 0.0
    t = (x * x + y * y) / (1.0 + z)  # 1 - cos θ
    v = -math.expm1((n + 1.0) * math.log1p(-t)) / mass
    return spherical_phi(x, y) * INV_TWO_PI, min(max(v, 0.0), 1.0)


@inline
def sample_cosn(n, u1, u2):
    """Item 21: p = (n+1) cosⁿθ / (2π) over the hemisphere."""
    return sample_cosn_cone(n, HALF_PI, u1, u2)


@inline
def cosn_pdf(n, x, y, z):
    return cosn_cone_pdf(n, HALF_PI, x, y, z)


@inline
def invert_cosn(n, x, y, z):
    return invert_cosn_cone(n, HALF_PI, x, y, z)


# -- area samplers: disk and triangle -----------------------------------------------

@inline
def sample_disk_concentric(u1, u2):
    """Unit disk, p = 1/π, by Shirley and Chiu's concentric map (1997): squares to
    rings, so strata stay compact. Returns (x, y, pdf)."""
    a = 2.0 * u1 - 1.0
    b = 2.0 * u2 - 1.0
    if a == 0.0 and b == 0.0:
        return 0.0, 0.0, INV_PI
    if abs(a) > abs(b):
        r = a
        phi = PI_OVER_4 * (b / a)
    else:
        r = b
        phi = HALF_PI - PI_OVER_4 * (a / b)
    return r * math.cos(phi), r * math.sin(phi), INV_PI


@inline
def invert_disk_concentric(x, y):
    r = math.sqrt(x * x + y * y)
    if r == 0.0:
        return 0.5, 0.5
    phi = math.atan2(y, x)
    # back to the quadrant where the map's (a, b) live
    if phi < -PI_OVER_4:
        phi += 2.0 * math.pi
    if phi < PI_OVER_4:  # right wedge: a = r, b/a = phi / (π/4)
        a = r
        b = r * phi / PI_OVER_4
    elif phi < 3.0 * PI_OVER_4:  # top: b = r, a/b = (π/2 - phi) / (π/4)
        b = r
        a = r * (HALF_PI - phi) / PI_OVER_4
    elif phi < 5.0 * PI_OVER_4:  # left: a = -r, phi = π + (π/4) b/a
        a = -r
        b = a * (phi - math.pi) / PI_OVER_4
    else:  # bottom: b = -r, phi = 3π/2 - (π/4) a/b
        b = -r
        a = b * (1.5 * math.pi - phi) / PI_OVER_4
    return min(max(0.5 * (a + 1.0), 0.0), 1.0), min(max(0.5 * (b + 1.0), 0.0), 1.0)


@inline
def sample_disk_polar(u1, u2):
    """Unit disk, p = 1/π: r = sqrt(u2), φ = 2π u1. Returns (x, y, pdf)."""
    r = math.sqrt(u2)
    phi = TWO_PI * u1
    return r * math.cos(phi), r * math.sin(phi), INV_PI


@inline
def invert_disk_polar(x, y):
    return spherical_phi(x, y) * INV_TWO_PI, min(x * x + y * y, 1.0)


@inline
def disk_pdf(x, y):
    return INV_PI if x * x + y * y <= 1.0 else 0.0


@inline
def sample_triangle_area(u1, u2):
    """Uniform barycentrics (b0, b1, b2) on a triangle: b0 = 1 - sqrt(u1), b1 = u2 sqrt(u1).

    The density is 1/area per unit area of the triangle (2 on the reference triangle
    (0,0), (1,0), (0,1) where the point is (b1, b2)).
    """
    s = math.sqrt(u1)
    b0 = 1.0 - s
    b1 = u2 * s
    return b0, b1, max(1.0 - b0 - b1, 0.0)


@inline
def invert_triangle_area(b0, b1):
    s = 1.0 - b0
    if s <= 0.0:
        return 0.0, 0.5
    return min(s * s, 1.0), min(max(b1 / s, 0.0), 1.0)
