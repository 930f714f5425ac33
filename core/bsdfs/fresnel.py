"""Fresnel reflectance of smooth interfaces (compendium item 42), scalar helpers.

Every function is ``@inline``: kernels inline it, and Python may call it with plain
floats (numba compiles it on the first call).

Conventions
-----------
* ``cos_i`` is the cosine between the incident direction (pointing away from the
  surface, towards where the light or viewer is) and the normal that points to the
  *outside* medium. ``cos_i < 0`` means the incident direction is inside.
* ``eta`` is the relative index n_inside / n_outside (real, > 0) for dielectrics.
  Incidence from inside is handled by using 1/eta.
* Conductors: the complex relative index N = eta + i·kappa of the metal against the
  outside medium; incidence is always from the outside (|cos_i| is used).

Dielectric (Hecht, *Optics*, §4.6; amplitude coefficients, n1 on the incident side,
n2 = n1·eta', θt from Snell's law n1 sin θi = n2 sin θt, items 38-40)::

    r_s = (cos θi − eta' cos θt) / (cos θi + eta' cos θt)
    r_p = (eta' cos θi − cos θt) / (eta' cos θi + cos θt)
    R_s = r_s²,  R_p = r_p²,  R = (R_s + R_p)/2 (unpolarised light)

and R = 1 beyond the critical angle sin θg = 1/eta' (items 39, 41). R_p vanishes at
Brewster's angle tan θB = eta'.

Conductor: the compendium's real-valued form (item 42), with
2a² = sqrt((η²−κ²−sin²θ)² + 4η²κ²) + (η²−κ²−sin²θ) and a² + b² = sqrt(...)::

    F_s = (a² + b² − 2a cos θ + cos² θ) / (a² + b² + 2a cos θ + cos² θ)
    F_p = F_s · (a² + b² − 2a sin θ tan θ + sin²θ tan²θ)
              / (a² + b² + 2a sin θ tan θ + sin²θ tan²θ)

(The text of the compendium as extracted reads "2a cos θ tan θ" in F_p; the correct
term is 2a sin θ tan θ — checked in the tests against the complex amplitude
coefficients.) F_p is evaluated multiplied through by cos²θ so grazing incidence is
finite. For κ = 0 it reduces to the dielectric formulas (from the outside).
"""
import math

from ..jit import inline


@inline
def fresnel_dielectric_sp(cos_i, eta):
    """(R_s, R_p) of a smooth dielectric interface; see the module conventions."""
    if not (eta > 0.0) or eta == math.inf:
        return 0.0, 0.0
    if cos_i < 0.0:
        eta = 1.0 / eta
        cos_i = -cos_i
    if eta == 1.0:
        return 0.0, 0.0
    if not (cos_i <= 1.0):  # > 1 by rounding, or NaN
        if cos_i > 1.0:
            cos_i = 1.0
        else:
            return 0.0, 0.0
    # cos²θt = 1 − (1 − cos²θi)/eta² = (eta² − 1 + cos²θi)/eta², without cancellation
    q = (eta - 1.0) * (eta + 1.0) + cos_i * cos_i
    if q <= 0.0:
        return 1.0, 1.0  # total internal reflection (item 41)
    cos_t = math.sqrt(q) / eta
    ds = cos_i + eta * cos_t
    dp = eta * cos_i + cos_t
    if ds <= 0.0 or dp <= 0.0:
        return 1.0, 1.0  # grazing limit
    rs = (cos_i - eta * cos_t) / ds
    rp = (eta * cos_i - cos_t) / dp
    return rs * rs, rp * rp


@inline
def fresnel_dielectric(cos_i, eta):
    """Unpolarised reflectance (R_s + R_p)/2 of a smooth dielectric interface.

    The same arithmetic as ``fresnel_dielectric_sp``, written out flat: an ``@inline``
    callee is copied at every call site, and nesting multiplies compile time.
    """
    if not (eta > 0.0) or eta == math.inf:
        return 0.0
    if cos_i < 0.0:
        eta = 1.0 / eta
        cos_i = -cos_i
    if eta == 1.0:
        return 0.0
    if not (cos_i <= 1.0):
        if cos_i > 1.0:
            cos_i = 1.0
        else:
            return 0.0
    q = (eta - 1.0) * (eta + 1.0) + cos_i * cos_i
    if q <= 0.0:
        return 1.0
    cos_t = math.sqrt(q) / eta
    ds = cos_i + eta * cos_t
    dp = eta * cos_i + cos_t
    if ds <= 0.0 or dp <= 0.0:
        return 1.0
    rs = (cos_i - eta * cos_t) / ds
    rp = (eta * cos_i - cos_t) / dp
    return 0.5 * (rs * rs + rp * rp)


@inline
def mean_fresnel_dielectric(eta, cos_i):
    """The mean over the wavelengths of F(cos_i, eta[λ]): the probability with which the
    dielectrics choose reflection."""
    nw = eta.shape[0]
    s = 0.0
    for i in range(nw):
        s += fresnel_dielectric(cos_i, eta[i])
    return s / nw


@inline
def refract_cos(cos_i, eta):
    """cos θt (≥ 0) of the refracted direction, or -1 under total internal reflection.

    Same conventions as ``fresnel_dielectric``: cos_i signed, eta = n_in / n_out.
    """
    if cos_i < 0.0:
        eta = 1.0 / eta
        cos_i = -cos_i
    q = (eta - 1.0) * (eta + 1.0) + min(cos_i * cos_i, 1.0)
    if not (q > 0.0):
        return -1.0
    return min(math.sqrt(q) / eta, 1.0)


@inline
def fresnel_conductor_sp(cos_i, eta, kappa):
    """(F_s, F_p) of a smooth conductor with complex relative index eta + i·kappa."""
    return _conductor(cos_i, eta, kappa)


@inline
def _conductor(cos_i, eta, kappa):
    c = min(abs(cos_i), 1.0)
    if not (c >= 0.0) or not (eta >= 0.0) or not (kappa >= 0.0):
        return 0.0, 0.0
    if kappa == 0.0 and eta == 1.0:
        return 0.0, 0.0
    c2 = c * c
    s2 = 1.0 - c2
    t0 = eta * eta - kappa * kappa - s2
    a2b2 = math.sqrt(t0 * t0 + 4.0 * eta * eta * kappa * kappa)
    a = math.sqrt(max(0.5 * (a2b2 + t0), 0.0))
    num_s = a2b2 - 2.0 * a * c + c2
    den_s = a2b2 + 2.0 * a * c + c2
    if not (den_s > 0.0):
        return 1.0, 1.0
    fs = max(num_s, 0.0) / den_s
    # F_p / F_s with numerator and denominator multiplied by cos²θ
    t3 = a2b2 * c2 + s2 * s2
    t4 = 2.0 * a * c * s2
    den_p = t3 + t4
    if not (den_p > 0.0):
        return fs, fs
    fp = fs * max(t3 - t4, 0.0) / den_p
    return min(fs, 1.0), min(fp, 1.0)


@inline
def fresnel_conductor(cos_i, eta, kappa):
    """Unpolarised reflectance (F_s + F_p)/2 of a smooth conductor (item 42)."""
    fs, fp = _conductor(cos_i, eta, kappa)
    return 0.5 * (fs + fp)


@inline
def normal_incidence_reflectance(eta, kappa):
    """R(0) = ((η−1)² + κ²) / ((η+1)² + κ²)."""
    num = (eta - 1.0) * (eta - 1.0) + kappa * kappa
    den = (eta + 1.0) * (eta + 1.0) + kappa * kappa
    if not (den > 0.0):
        return 0.0
    return num / den


@inline
def _hemispherical_fresnel_ext(n):
    """2 ∫₀¹ F(μ, n) μ dμ for n ≥ 1.001: the closed form of the integral for unpolarised
    light (Stern 1964; checked against quadrature of ``fresnel_dielectric`` in the tests).
    Its terms cancel towards n = 1; the caller interpolates below 1.001."""
    n2 = n * n
    n4 = n2 * n2
    m4 = n4 - 1.0
    return (0.5 + (n - 1.0) * (3.0 * n + 1.0) / (6.0 * (n + 1.0) * (n + 1.0))
            + n2 * (n2 - 1.0) * (n2 - 1.0) / ((n2 + 1.0) ** 3) * math.log((n - 1.0) / (n + 1.0))
            - 2.0 * n * n2 * (n2 + 2.0 * n - 1.0) / ((n2 + 1.0) * m4)
            + 8.0 * n4 * (n4 + 1.0) / ((n2 + 1.0) * m4 * m4) * math.log(n))


FRESNEL_AVG_ETA_MAX = 1.0e6  # beyond, the average is taken at this index (F̄ > 1 − 1e-5)


@inline
def fresnel_diffuse_reflectance(eta):
    """F̄(η) = 2 ∫₀¹ F(μ, η) μ dμ: the unpolarised dielectric reflectance averaged over a
    cosine-weighted (diffuse) hemisphere of incident directions, from the side where the
    relative index is eta (conventions of ``fresnel_dielectric``; 0 where it returns 0).

    η < 1 (incidence from the denser side, total internal reflection included) follows
    from η > 1 by the exact identity 1 − F̄(1/n) = (1 − F̄(n)) / n² (the transmitted
    power of a diffuse field is the same both ways, with radiance scaled by n²).
    Between 1 and 1.001 F̄ is interpolated linearly to 0 at η = 1 (error < 1e-6).
    """
    if not (eta > 0.0) or eta == math.inf or eta == 1.0:
        return 0.0
    n = eta if eta > 1.0 else 1.0 / eta
    n = min(n, FRESNEL_AVG_ETA_MAX)
    f = _hemispherical_fresnel_ext(max(n, 1.001))
    if n < 1.001:
        f *= (n - 1.0) / 0.001
    if eta > 1.0:
        return f
    return 1.0 - (1.0 - f) / (n * n)
