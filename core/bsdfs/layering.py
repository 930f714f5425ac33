"""Directional albedos of the GGX reflection lobe, tabulated for the Cycles-style layering of
the plastic model (plastic.py) and its multiple-scattering energy compensation.

Three functions of the isotropic GGX lobe with height-correlated Smith masking
(microfacet.py), r = √α the Blender roughness and μ = cos θo:

* E(r, μ) = ∫ D G2 / (4 cos θo cos θi) cos θi dωi, the lobe's albedo with F = 1 (the
  energy single scattering keeps);
* Ē(r) = 2 ∫₀¹ E(r, μ) μ dμ, its cosine-weighted average over the hemisphere;
* s̄(r, μ, z), the mean of s(wo·h) = (F(wo·h, η) − F0) / (1 − F0) over the normals h
  visible from wo (distribution D_wo, microfacet.py), counting 0 where the mirrored
  direction falls below the horizon; F is the dielectric Fresnel factor, F0 =
  ((η−1)/(η+1))² and η = (1 + z²)/(1 − z²), i.e. z = √((η−1)/(η+1)) = F0^¼.

Cycles estimates the albedo of a lobe with the Fresnel mix(F0·t, 1, s(wo·h)) (t a tint)
as mix(F0·t, 1, s̄) times the lobe's own albedo (E, or 1 with the energy compensation):
the per-sample ratio of the Fresnel to the F = 1 weight, averaged, which is what its
table holds. (The exact single-scattering albedo would weight s by G2/G1 and is a
little larger for rough lobes; the Cycles estimate is kept so that the layering
matches.) These are the quantities, grids and
parametrisations of Cycles' ``ggx_E`` (32 × 32), ``ggx_Eavg`` (32) and
``ggx_gen_schlick_ior_s`` (16 × 16 × 16) tables (Blender 4.x/5.x, intern/cycles
app/cycles_precompute.cpp and kernel/closure/bsdf_microfacet.h): nodes at i/(n−1) with
r and μ clamped to ≥ 1e-4 and z to [1e-4, 0.99], read multilinearly. Here they are
computed by a deterministic midpoint rule over the visible-normal sampling map (the
integrand G2/G1(wo) per visible normal, wi the mirror of wo) rather than by Monte
Carlo; ``compute_tables`` regenerates them (layering_tables.py holds the result)::

    python -m spectral_gi.core.bsdfs.layering     # rewrites core/bsdfs/layering_tables.py
"""
import math

import numpy as np

from ..jit import inline
from .layering_tables import GGX_E, GGX_E_AVG, GGX_S

N_R_E = 32  # E and Ē: roughness × μ
N_MU_E = 32
N_R_S = 16  # s̄: roughness × μ × z
N_MU_S = 16
N_Z_S = 16


def _nodes(n, lo=1e-4, hi=1.0):
    return np.clip(np.arange(n) / (n - 1), lo, hi)


def _fresnel(c, eta):
    """Unpolarised dielectric Fresnel factor (numpy; c = cos of incidence > 0, eta > 1)."""
    g2 = eta * eta - 1.0 + c * c
    g = np.sqrt(np.maximum(g2, 0.0))
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
    return np.where(g2 > 0.0, 0.5 * a * a * (1.0 + b * b), 1.0)


def _lambda(z2, alpha):
    """Smith Λ of the isotropic GGX for directions of squared cosine z2."""
    t2 = np.maximum(1.0 - z2, 0.0) / np.maximum(z2, 1e-300)
    x = alpha * alpha * t2
    return 0.5 * x / (1.0 + np.sqrt(1.0 + x))


def _lobe_samples(r, mu, n):
    """For wo at μ: wo·h, the weight G2/G1(wo) and whether wi is above the horizon, at the
    n × n midpoint nodes of the visible-normal map (Heitz 2018), flattened."""
    alpha = max(r * r, 1e-8)
    so = math.sqrt(max(1.0 - mu * mu, 0.0))
    u = (np.arange(n) + 0.5) / n
    u1, u2 = np.meshgrid(u, u, indexing="ij")
    u1 = u1.ravel()
    u2 = u2.ravel()
    # stretched view direction in the x-z plane
    vx, vz = alpha * so, mu
    vl = math.hypot(vx, vz)
    vx, vz = vx / vl, vz / vl
    # T1 = (0, 1, 0) (or x for normal incidence), T2 = V × T1 ... as in microfacet.py
    if vx > 0.0:
        t1 = (0.0, 1.0, 0.0)
    else:
        t1 = (1.0, 0.0, 0.0)
    t2 = (0.0 * t1[2] - vz * t1[1], vz * t1[0] - vx * t1[2], vx * t1[1] - 0.0 * t1[0])
    rad = np.sqrt(u1)
    phi = 2.0 * np.pi * u2
    p1 = rad * np.cos(phi)
    p2 = rad * np.sin(phi)
    s = 0.5 * (1.0 + vz)
    p2 = (1.0 - s) * np.sqrt(np.maximum(1.0 - p1 * p1, 0.0)) + s * p2
    p3 = np.sqrt(np.maximum(1.0 - p1 * p1 - p2 * p2, 0.0))
    nx = p1 * t1[0] + p2 * t2[0] + p3 * vx
    ny = p1 * t1[1] + p2 * t2[1]
    nz = p1 * t1[2] + p2 * t2[2] + p3 * vz
    hx, hy, hz = alpha * nx, alpha * ny, np.maximum(nz, 0.0)
    hl = np.sqrt(hx * hx + hy * hy + hz * hz)
    hx, hy, hz = hx / hl, hy / hl, hz / hl
    doh = so * hx + mu * hz
    wiz = 2.0 * doh * hz - mu
    lo = _lambda(mu * mu, alpha)
    li = _lambda(wiz * wiz, alpha)
    ok = (wiz > 0.0) & (doh > 0.0)
    return doh, np.where(ok, (1.0 + lo) / (1.0 + lo + li), 0.0), ok


def compute_tables(n=256):
    """(E (32, 32) [μ, r], Ē (32,) [r], s̄ (16, 16, 16) [z, μ, r]) by an n × n midpoint rule."""
    e_tab = np.zeros((N_MU_E, N_R_E))
    for j, mu in enumerate(_nodes(N_MU_E)):
        for i, r in enumerate(_nodes(N_R_E)):
            _, w, _ = _lobe_samples(r, mu, n)
            e_tab[j, i] = w.mean()
    # Ē = 2 ∫ E μ dμ by Gauss–Legendre in μ over finer nodes of the same quadrature
    x, wx = np.polynomial.legendre.leggauss(48)
    mus = 0.5 * (x + 1.0)
    e_avg = np.zeros(N_R_E)
    for i, r in enumerate(_nodes(N_R_E)):
        e_avg[i] = sum(0.5 * wk * 2.0 * m * _lobe_samples(r, m, n)[1].mean() for m, wk in zip(mus, wx))
    s_tab = np.zeros((N_Z_S, N_MU_S, N_R_S))
    for k, z in enumerate(_nodes(N_Z_S, hi=0.99)):
        eta = (1.0 + z * z) / (1.0 - z * z)
        f0 = ((eta - 1.0) / (eta + 1.0)) ** 2
        for j, mu in enumerate(_nodes(N_MU_S)):
            for i, r in enumerate(_nodes(N_R_S)):
                doh, _, ok = _lobe_samples(r, mu, n)
                s = np.clip((_fresnel(np.maximum(doh, 1e-12), eta) - f0) / (1.0 - f0), 0.0, 1.0)
                s_tab[k, j, i] = np.where(ok, s, 0.0).mean()
    return np.clip(e_tab, 0.0, 1.0), np.clip(e_avg, 0.0, 1.0), np.clip(s_tab, 0.0, 1.0)


# -- kernel lookups (nodes at i/(n−1), multilinear, as Cycles' lookup_table_read) ---------------

@inline
def _cell(x, n):
    x = min(max(x, 0.0), 1.0) * (n - 1)
    i = min(int(x), n - 1)
    return i, min(i + 1, n - 1), x - i


@inline
def ggx_albedo(r, mu):
    """E(r, μ) (module docstring)."""
    i0, i1, tx = _cell(r, N_R_E)
    j0, j1, ty = _cell(mu, N_MU_E)
    a = (1.0 - tx) * GGX_E[j0, i0] + tx * GGX_E[j0, i1]
    b = (1.0 - tx) * GGX_E[j1, i0] + tx * GGX_E[j1, i1]
    return (1.0 - ty) * a + ty * b


@inline
def ggx_albedo_avg(r):
    """Ē(r)."""
    i0, i1, tx = _cell(r, N_R_E)
    return (1.0 - tx) * GGX_E_AVG[i0] + tx * GGX_E_AVG[i1]


@inline
def ggx_fresnel_mean(r, mu, eta):
    """s̄(r, μ, z(η)): the lobe-weighted mean of the Fresnel interpolation factor."""
    z = math.sqrt(abs(eta - 1.0) / (eta + 1.0))
    i0, i1, tx = _cell(r, N_R_S)
    j0, j1, ty = _cell(mu, N_MU_S)
    k0, k1, tz = _cell(z, N_Z_S)
    a = (1.0 - tx) * GGX_S[k0, j0, i0] + tx * GGX_S[k0, j0, i1]
    b = (1.0 - tx) * GGX_S[k0, j1, i0] + tx * GGX_S[k0, j1, i1]
    c = (1.0 - tx) * GGX_S[k1, j0, i0] + tx * GGX_S[k1, j0, i1]
    d = (1.0 - tx) * GGX_S[k1, j1, i0] + tx * GGX_S[k1, j1, i1]
    return (1.0 - tz) * ((1.0 - ty) * a + ty * b) + tz * ((1.0 - ty) * c + ty * d)


def tables_source(e_tab, e_avg, s_tab, n):
    """The text of layering_tables.py for these tables (8 numbers a line)."""

    def rows(a):
        v = [f"{x:.6f}" for x in a.ravel()]
        return ",\n".join("    " + ", ".join(v[k:k + 8]) for k in range(0, len(v), 8))

    return (
        '"""GGX albedo tables of layering.py (generated by ``python -m spectral_gi.core.bsdfs.layering``;\n'
        f'midpoint rule of {n} × {n} visible normals per node). Do not edit by hand."""\n'
        "import numpy as np\n\n"
        f"GGX_E = np.array([\n{rows(e_tab)},\n]).reshape({e_tab.shape})\n"
        "GGX_E.flags.writeable = False\n\n"
        f"GGX_E_AVG = np.array([\n{rows(e_avg)},\n])\n"
        "GGX_E_AVG.flags.writeable = False\n\n"
        f"GGX_S = np.array([\n{rows(s_tab)},\n]).reshape({s_tab.shape})\n"
        "GGX_S.flags.writeable = False\n")


def _write_tables(path, n=256):
    from ..io.atomic import write_text

    write_text(path, tables_source(*compute_tables(n), n))


if __name__ == "__main__":  # pragma: no cover - the generator
    from pathlib import Path

    _write_tables(Path(__file__).with_name("layering_tables.py"))
