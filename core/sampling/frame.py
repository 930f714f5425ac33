"""Directions, shading frames and changes of measure (compendium items 5–8).

Every sampler in this package works in a local shading frame whose z axis is the
surface normal: a direction is ``(x, y, z)`` with ``z = cos θ`` and
``φ = atan2(y, x)`` in [0, 2π) (item 6). Helpers return plain tuples of floats.
"""
import math

from ..jit import inline

TWO_PI = 2.0 * math.pi
INV_TWO_PI = 1.0 / TWO_PI


@inline
def clamp01(x):
    return min(max(x, 0.0), 1.0)


@inline
def safe_sqrt(x):
    """sqrt of max(x, 0): rounding can push 1 - z² a little below 0."""
    return math.sqrt(max(x, 0.0))


@inline
def spherical_direction(sin_theta, cos_theta, phi):
    """(θ, φ) → unit vector of item 6 (x = sin θ cos φ, y = sin θ sin φ, z = cos θ)."""
    return sin_theta * math.cos(phi), sin_theta * math.sin(phi), cos_theta


@inline
def direction_from_angles(theta, phi):
    return spherical_direction(math.sin(theta), math.cos(theta), phi)


@inline
def spherical_phi(x, y):
    """φ in [0, 2π) (0 for the poles). Branch-free: it is inlined in many places."""
    p = math.atan2(y, x)
    p += TWO_PI * (p < 0.0)
    # -tiny + 2π rounds to 2π
    return p * (p < TWO_PI)


@inline
def spherical_theta(x, y, z):
    """θ in [0, π], accurate near the poles (atan2 of the two legs, not acos)."""
    return math.atan2(math.sqrt(x * x + y * y), z)


@inline
def angles_from_direction(x, y, z):
    """Unit vector → (θ, φ); the inverse of ``direction_from_angles``."""
    return spherical_theta(x, y, z), spherical_phi(x, y)


@inline
def normalize(x, y, z):
    """(x, y, z, length); a zero vector is returned unchanged with length 0."""
    n = math.sqrt(x * x + y * y + z * z)
    if n == 0.0:
        return x, y, z, 0.0
    return x / n, y / n, z / n, n


@inline
def dot(ax, ay, az, bx, by, bz):
    return ax * bx + ay * by + az * bz


@inline
def cross(ax, ay, az, bx, by, bz):
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@inline
def frame_from_z(nx, ny, nz):
    """Orthonormal tangents (t, b) with t × b = n for a unit n, without branches on a
    threshold (Duff, Burgess, Christensen, Hery, Kensler, Liani, Villemin, JCGT 2017).

    Returns (tx, ty, tz, bx, by, bz).
    """
    s = math.copysign(1.0, nz)
    a = -1.0 / (s + nz)
    b = nx * ny * a
    return 1.0 + s * nx * nx * a, s * b, -s * nx, b, s + ny * ny * a, -ny


@inline
def to_world(tx, ty, tz, bx, by, bz, nx, ny, nz, x, y, z):
    """Local (x, y, z) in the frame (t, b, n) → world."""
    return (x * tx + y * bx + z * nx, x * ty + y * by + z * ny, x * tz + y * bz + z * nz)


@inline
def to_local(tx, ty, tz, bx, by, bz, nx, ny, nz, x, y, z):
    """World (x, y, z) → local coordinates in the frame (t, b, n)."""
    return (x * tx + y * ty + z * tz, x * bx + y * by + z * bz, x * nx + y * ny + z * nz)


@inline
def pdf_area_to_solid_angle(pdf_area, dist2, cos_at_light):
    """Item 8: dω = cos θ_y dA_y / r², so p_ω = p_A r² / |cos θ_y|.

    A grazing sample (cos = 0) has an unbounded solid-angle density and carries no
    radiance; it is returned as 0, which callers treat as "no contribution".
    """
    c = abs(cos_at_light)
    if c == 0.0 or pdf_area == 0.0:
        return 0.0
    return pdf_area * dist2 / c


@inline
def pdf_solid_angle_to_area(pdf_omega, dist2, cos_at_light):
    """Item 8 the other way: p_A = p_ω |cos θ_y| / r² (0 for a zero distance)."""
    if dist2 == 0.0:
        return 0.0
    return pdf_omega * abs(cos_at_light) / dist2


@inline
def solid_angle_of_small_area(area, dist2, cos_at_area):
    """Item 5: Ω ≈ A cos θ / r² for an area small compared with its distance."""
    if dist2 == 0.0:
        return 0.0
    return area * abs(cos_at_area) / dist2
