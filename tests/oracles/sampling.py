"""Slow, plain NumPy references for the sampling kernels (tests only).

Each function is vectorised over a batch of uniforms (N, 2) or directions (N, 3) and is
written from the textbook formula in the most direct way (angles, acos, searchsorted,
scipy quadrature) rather than the numerically careful forms of the kernels, so that an
error in one is unlikely to be repeated in the other.
"""
from fractions import Fraction
import math

import numpy as np

TWO_PI = 2.0 * np.pi


def _dirs(theta, phi):
    st = np.sin(theta)
    return np.stack([st * np.cos(phi), st * np.sin(phi), np.cos(theta)], axis=-1)


def _theta_phi(w):
    w = np.asarray(w, dtype=np.float64)
    theta = np.arccos(np.clip(w[..., 2], -1.0, 1.0))
    phi = np.mod(np.arctan2(w[..., 1], w[..., 0]), TWO_PI)
    return theta, phi


# -- items 18–21 -----------------------------------------------------------------------

def sample_uniform_sphere(u):
    u = np.atleast_2d(u)
    return _dirs(np.arccos(1.0 - 2.0 * u[:, 1]), TWO_PI * u[:, 0]), np.full(len(u), 1.0 / (4.0 * np.pi))


def uniform_sphere_pdf(w):
    return np.full(np.shape(w)[0], 1.0 / (4.0 * np.pi))


def invert_uniform_sphere(w):
    theta, phi = _theta_phi(w)
    return np.stack([phi / TWO_PI, (1.0 - np.cos(theta)) / 2.0], axis=-1)


def sample_uniform_cone(theta_max, u):
    u = np.atleast_2d(u)
    c = 1.0 - u[:, 1] * (1.0 - np.cos(theta_max))
    return _dirs(np.arccos(c), TWO_PI * u[:, 0]), np.full(len(u), uniform_cone_pdf_value(theta_max))


def uniform_cone_pdf_value(theta_max):
    return 1.0 / (TWO_PI * (1.0 - np.cos(theta_max)))


def uniform_cone_pdf(theta_max, w):
    theta, _ = _theta_phi(w)
    return np.where(theta <= theta_max, uniform_cone_pdf_value(theta_max), 0.0)


def invert_uniform_cone(theta_max, w):
    theta, phi = _theta_phi(w)
    return np.stack([phi / TWO_PI, (1.0 - np.cos(theta)) / (1.0 - np.cos(theta_max))], axis=-1)


def sample_uniform_hemisphere(u):
    return sample_uniform_cone(np.pi / 2, u)


def uniform_hemisphere_pdf(w):
    return np.where(np.asarray(w)[:, 2] >= 0, 1.0 / TWO_PI, 0.0)


def sample_cosine_cone(theta_max, u):
    u = np.atleast_2d(u)
    theta = np.arcsin(np.sqrt(u[:, 1]) * np.sin(theta_max))
    w = _dirs(theta, TWO_PI * u[:, 0])
    return w, cosine_cone_pdf(theta_max, w)


def cosine_cone_pdf(theta_max, w):
    theta, _ = _theta_phi(w)
    inside = (theta <= theta_max + 1e-12) & (theta < np.pi / 2)
    return np.where(inside, np.cos(theta) / (np.pi * np.sin(theta_max) ** 2), 0.0)


def invert_cosine_cone(theta_max, w):
    theta, phi = _theta_phi(w)
    return np.stack([phi / TWO_PI, (np.sin(theta) / np.sin(theta_max)) ** 2], axis=-1)


def sample_cosine_hemisphere(u):
    return sample_cosine_cone(np.pi / 2, u)


def cosine_hemisphere_pdf(w):
    return cosine_cone_pdf(np.pi / 2, w)


def sample_cosn_cone(n, theta_max, u):
    u = np.atleast_2d(u)
    k = 1.0 - np.cos(theta_max) ** (n + 1)
    c = (1.0 - u[:, 1] * k) ** (1.0 / (n + 1))
    w = _dirs(np.arccos(c), TWO_PI * u[:, 0])
    return w, cosn_cone_pdf(n, theta_max, w)


def cosn_cone_pdf(n, theta_max, w):
    theta, _ = _theta_phi(w)
    k = 1.0 - np.cos(theta_max) ** (n + 1)
    inside = (theta <= theta_max + 1e-12) & (theta < np.pi / 2)
    return np.where(inside, (n + 1) * np.cos(np.minimum(theta, np.pi / 2)) ** n / (TWO_PI * k), 0.0)


def invert_cosn_cone(n, theta_max, w):
    theta, phi = _theta_phi(w)
    k = 1.0 - np.cos(theta_max) ** (n + 1)
    return np.stack([phi / TWO_PI, (1.0 - np.cos(theta) ** (n + 1)) / k], axis=-1)


def sample_cosn(n, u):
    return sample_cosn_cone(n, np.pi / 2, u)


def cosn_pdf(n, w):
    return cosn_cone_pdf(n, np.pi / 2, w)


def hemisphere_integral_cosn(n):
    """Item 9: ∫_Ω cosⁿθ dω = 2π/(n+1) (n = 0: 2π; n = 1: π)."""
    return TWO_PI / (n + 1)


# -- disk and triangle -----------------------------------------------------------------

def sample_disk_polar(u):
    u = np.atleast_2d(u)
    r = np.sqrt(u[:, 1])
    a = TWO_PI * u[:, 0]
    return np.stack([r * np.cos(a), r * np.sin(a)], axis=-1)


def sample_disk_concentric(u):
    u = np.atleast_2d(u)
    a = 2.0 * u[:, 0] - 1.0
    b = 2.0 * u[:, 1] - 1.0
    out = np.zeros((len(u), 2))
    for k in range(len(u)):
        if a[k] == 0 and b[k] == 0:
            continue
        if a[k] * a[k] > b[k] * b[k]:
            r, phi = a[k], (np.pi / 4) * (b[k] / a[k])
        else:
            r, phi = b[k], (np.pi / 2) - (np.pi / 4) * (a[k] / b[k])
        out[k] = r * np.cos(phi), r * np.sin(phi)
    return out


def disk_pdf(p):
    p = np.asarray(p)
    return np.where((p ** 2).sum(-1) <= 1.0, 1.0 / np.pi, 0.0)


def sample_triangle_area(u):
    """Barycentrics of a uniform point (square-root parameterisation)."""
    u = np.atleast_2d(u)
    s = np.sqrt(u[:, 0])
    return np.stack([1.0 - s, u[:, 1] * s, 1.0 - (1.0 - s) - u[:, 1] * s], axis=-1)


# -- item 22: spherical triangles --------------------------------------------------------

def _unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def spherical_triangle_angles(a, b, c):
    """Vertex angles (α, β, γ) from the normals of the edge planes (acos form)."""
    a, b, c = _unit(a), _unit(b), _unit(c)

    def angle(p, q, r):
        n1 = _unit(np.cross(p, q))
        n2 = _unit(np.cross(p, r))
        return np.arccos(np.clip(np.dot(n1, n2), -1.0, 1.0))

    return angle(a, b, c), angle(b, c, a), angle(c, a, b)


def spherical_triangle_area_girard(a, b, c):
    """Girard's theorem: Ω = α + β + γ - π (cancels for small triangles: use with care)."""
    al, be, ga = spherical_triangle_angles(a, b, c)
    return al + be + ga - np.pi


def spherical_triangle_area_lhuilier(a, b, c):
    """L'Huilier's theorem from the arc lengths: tan(E/4)² = tan(s/2) Π tan((s - x)/2)."""
    a, b, c = _unit(a), _unit(b), _unit(c)
    la = np.arccos(np.clip(np.dot(b, c), -1, 1))
    lb = np.arccos(np.clip(np.dot(c, a), -1, 1))
    lc = np.arccos(np.clip(np.dot(a, b), -1, 1))
    s = 0.5 * (la + lb + lc)
    t = np.tan(s / 2) * np.tan((s - la) / 2) * np.tan((s - lb) / 2) * np.tan((s - lc) / 2)
    return 4.0 * np.arctan(np.sqrt(max(t, 0.0)))


def spherical_triangle_area_vos(a, b, c):
    """Van Oosterom–Strackee, written from the paper (unnormalised form):
    tan(Ω/2) = |a·(b×c)| / (|a||b||c| + (a·b)|c| + (a·c)|b| + (b·c)|a|)."""
    a, b, c = (np.asarray(v, dtype=np.float64) for v in (a, b, c))
    la, lb, lc = (np.linalg.norm(v) for v in (a, b, c))
    num = abs(np.dot(a, np.cross(b, c)))
    den = la * lb * lc + np.dot(a, b) * lc + np.dot(a, c) * lb + np.dot(b, c) * la
    return 2.0 * np.arctan2(num, den)


def sample_spherical_triangle(a, b, c, u):
    """Arvo (1995) step by step with the angle of the paper's notation, computed via acos."""
    A, B, C = _unit(a), _unit(b), _unit(c)
    alpha, beta, gamma = spherical_triangle_angles(A, B, C)
    area = alpha + beta + gamma - np.pi
    u = np.atleast_2d(u)
    out = np.zeros((len(u), 3))
    cos_c = np.dot(A, B)
    for k, (u1, u2) in enumerate(u):
        ah = u1 * area
        s, t = np.sin(ah - alpha), np.cos(ah - alpha)
        uu = t - np.cos(alpha)
        vv = s + np.sin(alpha) * cos_c
        q = ((vv * t - uu * s) * np.cos(alpha) - vv) / ((vv * s + uu * t) * np.sin(alpha))
        q = np.clip(q, -1.0, 1.0)
        ch = q * A + np.sqrt(1.0 - q * q) * _unit(C - np.dot(C, A) * A)
        z = 1.0 - u2 * (1.0 - np.dot(ch, B))
        perp = ch - np.dot(ch, B) * B
        nrm = np.linalg.norm(perp)
        perp = perp / nrm if nrm > 0 else perp
        out[k] = z * B + np.sqrt(max(1.0 - z * z, 0.0)) * perp
    return out, np.full(len(u), 1.0 / area)


def spherical_triangle_pdf(a, b, c, w):
    """1/Ω (L'Huilier) inside the triangle: on the inner side of the three edge planes,
    within 1e-12 rad (the kernel's tolerance)."""
    A, B, C = _unit(a), _unit(b), _unit(c)
    w = _unit(w)
    s = np.sign(np.dot(A, np.cross(B, C)))
    inside = np.ones(len(w), dtype=bool)
    for p, q in ((A, B), (B, C), (C, A)):
        n = np.cross(p, q)
        inside &= s * (w @ n) / np.linalg.norm(n) >= -1e-12
    return np.where(inside, 1.0 / spherical_triangle_area_lhuilier(A, B, C), 0.0)


# -- items 10 and 23: digon moments by quadrature, off-normal lobes -------------------------

def _phi_extent(u, d):
    """Measure of φ (around m) with Θ·N ≥ 0 on the circle Θ·m = u, for d = m·N."""
    c = math.sqrt(max(1.0 - d * d, 0.0))
    s = math.sqrt(max(1.0 - u * u, 0.0))
    if c * s == 0.0:
        return TWO_PI if d * u >= 0 else 0.0
    x = d * u / (c * s)  # condition: cos φ ≥ -x
    return 2.0 * math.acos(min(max(-x, -1.0), 1.0))


def digon_moment_quad(n, d):
    """G_n(d) = ∫ cosⁿ(Θ, m) dω over {Θ·m ≥ 0, Θ·N ≥ 0} by adaptive quadrature in u = Θ·m."""
    from scipy.integrate import quad

    c = math.sqrt(max(1.0 - d * d, 0.0))
    pts = [c] if 0.0 < c < 1.0 else None
    val, _ = quad(lambda u: u ** n * _phi_extent(u, d), 0.0, 1.0, points=pts, limit=400, epsabs=1e-14,
                  epsrel=1e-12)
    return val


def digon_cos_moment_quad(n, d):
    """F_n(d) = ∫ cosⁿ(Θ, m) cos(Θ, N) dω over the lune, by quadrature.

    On the circle Θ·m = u: Θ·N = d u + c sqrt(1-u²) cos φ, integrated over the φ range.
    """
    from scipy.integrate import quad

    c = math.sqrt(max(1.0 - d * d, 0.0))

    def inner(u):
        ext = _phi_extent(u, d)
        half = ext / 2.0
        s = math.sqrt(max(1.0 - u * u, 0.0))
        return u ** n * (d * u * ext + 2.0 * c * s * math.sin(half))

    pts = [c] if 0.0 < c < 1.0 else None
    val, _ = quad(inner, 0.0, 1.0, points=pts, limit=400, epsabs=1e-14, epsrel=1e-12)
    return val


def digon_moment_grid(n, m, normal=(0.0, 0.0, 1.0), cos_weight=False, res=2000):
    """Brute-force (θ, φ) midpoint quadrature over the sphere of cosⁿ(Θ, m) [· cos(Θ, N)]
    on the lune: an independent, slow check of the two quadratures above."""
    m = _unit(m)
    nn = _unit(normal)
    th = (np.arange(res) + 0.5) * (np.pi / res)
    ph = (np.arange(2 * res) + 0.5) * (np.pi / res)
    T, P = np.meshgrid(th, ph, indexing="ij")
    w = _dirs(T, P)
    t = w @ m
    z = w @ nn
    f = np.where((t > 0) & (z > 0), np.maximum(t, 0.0) ** n * (z if cos_weight else 1.0), 0.0)
    return float((f * np.sin(T)).sum() * (np.pi / res) ** 2)


def offnormal_cosn_pdf(n, m, w, norm=None):
    m = _unit(m)
    w = np.asarray(w, dtype=np.float64)
    g = digon_moment_quad(n, float(m[2])) if norm is None else norm
    t = w @ m
    ok = (t > 0) & (w[:, 2] > 0)
    return np.where(ok, np.maximum(t, 0.0) ** n / g, 0.0)


def sample_offnormal_cosn(n, m, count, rng):
    """Rejection sampling from the full lobe with NumPy's generator (a distribution-level oracle)."""
    m = _unit(m)
    t = np.array([1.0, 0.0, 0.0]) if abs(m[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t = _unit(t - np.dot(t, m) * m)
    b = np.cross(m, t)
    out = []
    while sum(len(o) for o in out) < count:
        loc, _ = sample_cosn(n, rng.random((count, 2)))
        w = loc[:, :1] * t + loc[:, 1:2] * b + loc[:, 2:3] * m
        out.append(w[w[:, 2] > 0])
    return np.concatenate(out)[:count]


# -- items 11–16: piecewise-constant distributions --------------------------------------------

def sample_piecewise_1d(f, u):
    """Inverse cdf of the piecewise-constant density ∝ f on [0, 1) by searchsorted."""
    f = np.asarray(f, dtype=np.float64)
    n = len(f)
    if f.sum() <= 0:
        f = np.ones(n)
    cdf = np.concatenate([[0.0], np.cumsum(f)]) / f.sum()
    i = np.searchsorted(cdf, u, side="right") - 1
    i = np.clip(i, 0, n - 1)
    # skip zero-width cells (the search lands on the last cell starting at this value)
    frac = (u - cdf[i]) / np.where(cdf[i + 1] > cdf[i], cdf[i + 1] - cdf[i], 1.0)
    x = (i + frac) / n
    return x, f[i] / (f.sum() / n)


def piecewise_1d_pdf(f, x):
    f = np.asarray(f, dtype=np.float64)
    n = len(f)
    if f.sum() <= 0:
        return np.ones_like(np.asarray(x, dtype=np.float64))
    i = np.clip((np.asarray(x) * n).astype(int), 0, n - 1)
    return f[i] / (f.sum() / n)


def piecewise_2d_pdf(f, x, y):
    f = np.asarray(f, dtype=np.float64)
    ny, nx = f.shape
    if f.sum() <= 0:
        return np.ones_like(np.asarray(x, dtype=np.float64))
    i = np.clip((np.asarray(x) * nx).astype(int), 0, nx - 1)
    j = np.clip((np.asarray(y) * ny).astype(int), 0, ny - 1)
    return f[j, i] / f.mean()


# -- item 30: radical inverse in exact arithmetic ---------------------------------------------

def radical_inverse_exact(b, i):
    """Φ_b(i) as a Fraction."""
    r = Fraction(0)
    p = Fraction(1, b)
    while i > 0:
        i, d = divmod(i, b)
        r += d * p
        p /= b
    return r


def first_primes(n):
    out = []
    k = 2
    while len(out) < n:
        if all(k % p for p in out):
            out.append(k)
        k += 1
    return out


def halton_exact(n, dims):
    ps = first_primes(dims)
    return np.array([[float(radical_inverse_exact(p, i)) for p in ps] for i in range(n)])


def hammersley_exact(n, dims):
    ps = first_primes(dims - 1)
    return np.array([[i / n] + [float(radical_inverse_exact(p, i)) for p in ps] for i in range(n)])


def l2_star_discrepancy(x):
    """Warnock's formula for the L2 star discrepancy of points x (N, d) in [0, 1)^d:
    T² = 3^{-d} - (2^{1-d}/N) Σ_i Π_k (1 - x_ik²) + (1/N²) Σ_ij Π_k (1 - max(x_ik, x_jk))."""
    x = np.asarray(x, dtype=np.float64)
    n, d = x.shape
    t1 = 3.0 ** -d
    t2 = 2.0 ** (1 - d) / n * np.prod(1.0 - x ** 2, axis=1).sum()
    prod = np.ones((n, n))
    for k in range(d):
        prod *= 1.0 - np.maximum(x[:, None, k], x[None, :, k])
    t3 = prod.sum() / n ** 2
    return math.sqrt(max(t1 - t2 + t3, 0.0))


def star_discrepancy_2d(x):
    """Exact star discrepancy D*_N of 2D points by checking all boxes anchored at the grid
    of point coordinates (O(N³) with NumPy; fine for N ≤ 1024)."""
    x = np.asarray(x, dtype=np.float64)
    n = len(x)
    xs = np.concatenate([np.unique(x[:, 0]), [1.0]])
    ys = np.concatenate([np.unique(x[:, 1]), [1.0]])
    best = 0.0
    for a in xs:
        in_a_open = x[:, 0] < a
        in_a_closed = x[:, 0] <= a
        ya_open = np.sort(x[in_a_open, 1])
        ya_closed = np.sort(x[in_a_closed, 1])
        open_counts = np.searchsorted(ya_open, ys, side="left")
        closed_counts = np.searchsorted(ya_closed, ys, side="right")
        vol = a * ys
        best = max(best, np.max(vol - open_counts / n), np.max(closed_counts / n - vol))
    return float(best)


# -- items 27–28 -------------------------------------------------------------------------------

def power_heuristic_weights(pdfs, counts, beta):
    """w_j = (N_j p_j)^β / Σ_k (N_k p_k)^β, column by column, with plain loops."""
    pdfs = np.asarray(pdfs, dtype=np.float64)
    k, n = pdfs.shape
    w = np.zeros((k, n))
    for col in range(n):
        q = [counts[j] * pdfs[j, col] for j in range(k)]
        s = sum(v ** beta for v in q if v > 0)
        for j in range(k):
            w[j, col] = (q[j] ** beta / s) if (q[j] > 0 and s > 0) else 0.0
    return w
