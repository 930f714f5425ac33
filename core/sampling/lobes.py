"""cosⁿ lobes around an axis m that is not the normal (compendium items 10, 17, 23).

The lobe cosⁿ(Θ, m) is clipped twice: by its own hemisphere (Θ·m ≥ 0) and by the
surface's (Θ·N ≥ 0). The domain is the spherical digon (lune) D between the two great
circles. Its moments, with d = m·N and c = sqrt(1 - d²):

    G_n = ∫_D cosⁿ(Θ, m) dω                  (10b, the normaliser of item 23)
    F_n = ∫_D cosⁿ(Θ, m) cos(Θ, N) dω        (10a, Arvo's double-axis moment)

Recurrence (derived here with the divergence theorem on the sphere; Arvo 1995,
"Applications of irradiance tensors", derives the same family from irradiance
tensors). With t = Θ·m the surface Laplacian gives Δt^k = k(k-1)t^{k-2} - k(k+1)t^k;
integrating over D, the boundary term lives on the horizon arc only (t = 0 on the other
arc), where t = c cos φ and the outward co-normal is -N:

    G_0 = 2(π - acos d)        (area of a lune of dihedral angle π - acos d)
    G_1 = π(1 + d)/2
    G_k = ((k-1) G_{k-2} + d c^{k-1} C_{k-1}) / (k+1),          k ≥ 2
    F_0 = π(1 + d)/2,   F_n = (n d G_{n-1} + cⁿ C_n) / (n+2),   n ≥ 1

where C_j = ∫_{-π/2}^{π/2} cos^j φ dφ (C_0 = π, C_1 = 2, C_j = (j-1)/j C_{j-2}).
(k+1) G_k telescopes, so G_n costs O(min(n, log ε / log c²)) operations.
Checks: d = 1 gives 2π/(n+1) and 2π/(n+2) (item 9). For d < 0 the recurrence
subtracts nearly equal terms, so the complements are used instead:
G_n(d) = 2π/(n+1) - G_n(-d) and F_n(d) = F_n(-d) + 2π d/(n+2) (the lobe's full
moments minus the part below the horizon), which keeps the absolute error at the
rounding of the full lobe's mass.

The exponent n is an integer (rounded); non-integer exponents need a numeric base case.

Sampling (item 23): draw Θ from the full cosⁿ lobe around m (item 21), reject it when
it falls below the horizon; the accepted directions have density cosⁿ(Θ, m) / G_n.
The first attempt uses (u1, u2); retries draw from a counter-based stream keyed by
(u1, u2, u3), so the result is a deterministic function of the three numbers. After
MAX_REJECTION_TRIES failures (acceptance G_n (n+1)/2π below ~1e-3) the sample is
returned with pdf 0.
"""
import math

import numpy as np

from ..jit import inline
from .rng import mix64, uniform
from .frame import frame_from_z, normalize, to_world
from .warps import sample_cosn

TWO_PI = 2.0 * math.pi
MAX_REJECTION_TRIES = 4096
_TWO53 = 9007199254740992.0
_K1 = np.uint64(0x9E3779B97F4A7C15)
_K2 = np.uint64(0xD1B54A32D192ED03)


@inline
def _digon_moment_nonneg(n, d):
    """G_n for d in [0, 1]. With T_k = (k+1) G_k the recurrence telescopes to
    T_n = T_{n mod 2} + d Σ c^j C_j over j = n-1, n-3, ... ≥ 1; the terms are
    non-negative and fall geometrically (ratio c²(j+1)/(j+2)), so the sum stops once they
    no longer change it."""
    c2 = max((1.0 - d) * (1.0 + d), 0.0)
    c = math.sqrt(c2)
    if n % 2 == 0:
        base = 2.0 * (math.pi - math.acos(d))  # T_0 = G_0
        q = 2.0 * c  # c^1 C_1
        j = 1
    else:
        base = math.pi * (1.0 + d)  # T_1 = 2 G_1
        q = 0.5 * math.pi * c2  # c^2 C_2
        j = 2
    s = 0.0
    while j <= n - 1:
        s += q
        if d * q <= 1e-17 * (base + d * s):
            break
        q *= c2 * (j + 1) / (j + 2)
        j += 2
    return (base + d * s) / (n + 1)


@inline
def digon_moment(n, d):
    """G_n(d) = ∫ cosⁿ(Θ, m) dω over the lune {Θ·m ≥ 0, Θ·N ≥ 0}, d = m·N (item 10b)."""
    ni = int(round(n))
    if ni < 0:
        return 0.0
    d = min(max(d, -1.0), 1.0)
    if d >= 0.0:
        return _digon_moment_nonneg(ni, d)
    return max(TWO_PI / (ni + 1) - _digon_moment_nonneg(ni, -d), 0.0)


@inline
def _c_pow_cj(j, c):
    """c^j C_j = c^j ∫_{-π/2}^{π/2} cos^j φ dφ = c^j sqrt(π) Γ((j+1)/2) / Γ(j/2 + 1)."""
    if j == 0:
        return math.pi
    if c == 0.0:
        return 0.0
    return math.exp(j * math.log(c) + 0.5 * math.log(math.pi) + math.lgamma(0.5 * (j + 1)) - math.lgamma(0.5 * j + 1.0))


@inline
def _digon_cos_moment_nonneg(n, d):
    if n == 0:
        return 0.5 * math.pi * (1.0 + d)
    c = math.sqrt(max((1.0 - d) * (1.0 + d), 0.0))
    return (n * d * _digon_moment_nonneg(n - 1, d) + _c_pow_cj(n, c)) / (n + 2)


@inline
def digon_cos_moment(n, d):
    """F_n(d) = ∫ cosⁿ(Θ, m) cos(Θ, N) dω over the lune (item 10a, Arvo's double-axis moment)."""
    ni = int(round(n))
    if ni < 0:
        return 0.0
    d = min(max(d, -1.0), 1.0)
    if d >= 0.0:
        return _digon_cos_moment_nonneg(ni, d)
    return max(_digon_cos_moment_nonneg(ni, -d) + TWO_PI * d / (ni + 2), 0.0)


@inline
def offnormal_cosn_pdf(n, mx, my, mz, x, y, z):
    """Density cosⁿ(Θ, m) / G_n on the lune; the normal is +z of the local frame."""
    mx, my, mz, lm = normalize(mx, my, mz)
    if lm == 0.0 or z <= 0.0:
        return 0.0
    t = mx * x + my * y + mz * z
    if t <= 0.0:
        return 0.0
    g = digon_moment(n, mz)
    if not (g > 0.0):
        return 0.0
    ni = int(round(n))
    if ni == 0:
        return 1.0 / g
    return math.exp(ni * math.log(t)) / g


@inline
def _retry_key(u1, u2, u3):
    k = mix64(np.uint64(u1 * _TWO53) ^ _K1)
    k = mix64(k ^ (np.uint64(u2 * _TWO53) * _K2))
    return mix64(k ^ np.uint64(u3 * _TWO53))


@inline
def sample_offnormal_cosn(n, mx, my, mz, u1, u2, u3):
    """Direction with density cosⁿ(Θ, m)/G_n restricted to z > 0, by rejection (item 23).

    Returns (x, y, z, pdf); pdf = 0 if the lune is empty or every try was rejected.
    """
    ni = int(round(n))
    mx, my, mz, lm = normalize(mx, my, mz)
    if lm == 0.0 or ni < 0:
        return 0.0, 0.0, 1.0, 0.0
    g = digon_moment(ni, mz)
    if not (g > 0.0):
        return 0.0, 0.0, 1.0, 0.0
    tx, ty, tz, bx, by, bz = frame_from_z(mx, my, mz)
    a = u1
    b = u2
    key = _retry_key(u1, u2, u3)
    for attempt in range(MAX_REJECTION_TRIES):
        if attempt > 0:
            a = uniform(key, 2 * attempt)
            b = uniform(key, 2 * attempt + 1)
        lx, ly, lz, _ = sample_cosn(float(ni), a, b)
        if lz <= 0.0:
            continue
        x, y, z = to_world(tx, ty, tz, bx, by, bz, mx, my, mz, lx, ly, lz)
        if z > 0.0:
            if ni == 0:
                return x, y, z, 1.0 / g
            return x, y, z, math.exp(ni * math.log(lz)) / g
    return 0.0, 0.0, 1.0, 0.0
