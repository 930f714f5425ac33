"""Directional-hemispherical reflectance and transmittance of any model (items 45-46).

ρ(θo) = ∫_upper f(wo, wi) cos θi dωi and τ(θo) = ∫_lower f(wo, wi) |cos θi| dωi, per
wavelength, for wo = (sin θo cos φo, sin θo sin φo, cos θo). By reciprocity (item 44)
this is also the fraction of light arriving from wo that is reflected. τ is in radiance
units (the BTDF includes the (n_o/n_i)² radiance scaling of specular.py): the fraction of
*power* transmitted is (n_i/n_o)² τ, so a lossless dielectric has ρ + (n_i/n_o)² τ = 1
(``white_furnace``: a furnace holding the basic radiance L/n² constant on both sides).

``albedo`` estimates them by importance sampling with the model's own sampler (mean of
the sample weights, delta events included), ``albedo_quadrature`` by a product rule
over the sphere from ``bsdf_eval`` (non-delta components only) — the two are
independent checks of each other.
"""
import functools
from typing import NamedTuple

import numpy as np

from .batch import OP_EVAL, OP_SAMPLE, _run, _spectra
from .params import BSDF_DISPERSIVE, check_row


class Albedo(NamedTuple):
    reflectance: np.ndarray  # (NW,)
    transmittance: np.ndarray  # (NW,)
    reflectance_se: np.ndarray  # standard errors (0 for the quadrature)
    transmittance_se: np.ndarray


@functools.lru_cache(maxsize=8)
def _gauss_legendre(n):
    x, w = np.polynomial.legendre.leggauss(n)
    x.flags.writeable = False
    w.flags.writeable = False
    return x, w


def _wo(theta_o, phi_o):
    t = float(theta_o)
    f = float(phi_o)
    return np.array([np.sin(t) * np.cos(f), np.sin(t) * np.sin(f), np.cos(t)])


def albedo(model, params, ra=1.0, rb=1.0, eta=1.5, kappa=0.0, theta_o=0.0, phi_o=0.0, n_samples=1 << 16,
           seed=0):
    """Monte Carlo estimate (Albedo) of ρ and τ per wavelength at incidence θo (radians).

    When eta varies with the wavelength, transmitted samples are dispersive (only the
    hero is valid), so each wavelength is then estimated on its own with a constant eta.
    """
    p = check_row(params)
    ra, rb, eta, kappa = _spectra(ra, rb, eta, kappa)
    nw = ra.size
    if n_samples < 2:
        raise ValueError("n_samples must be at least 2")
    rng = np.random.default_rng(seed)
    u = rng.random((int(n_samples), 3))
    wo = _wo(theta_o, phi_o)
    if np.all(eta == eta[0]):
        groups = [(slice(None), eta)]
    else:
        groups = [(slice(i, i + 1), np.full(nw, eta[i])) for i in range(nw)]
    r = np.zeros(nw)
    t = np.zeros(nw)
    rse = np.zeros(nw)
    tse = np.zeros(nw)
    for sl, e in groups:
        wi, w, _, flags = _run(OP_SAMPLE, model, p, ra, rb, e, kappa, wo, u)
        if np.any(flags & BSDF_DISPERSIVE):
            raise AssertionError("dispersive sample with a constant eta")
        same = (wi[:, 2] * wo[2] > 0.0)[:, None]
        wr = np.where(same, w, 0.0)
        wt = np.where(same, 0.0, w)
        r[sl] = wr.mean(axis=0)[sl]
        t[sl] = wt.mean(axis=0)[sl]
        rse[sl] = (wr.std(axis=0, ddof=1) / np.sqrt(len(u)))[sl]
        tse[sl] = (wt.std(axis=0, ddof=1) / np.sqrt(len(u)))[sl]
    return Albedo(r, t, rse, tse)


def albedo_quadrature(model, params, ra=1.0, rb=1.0, eta=1.5, kappa=0.0, theta_o=0.0, phi_o=0.0,
                      n_theta=256, n_phi=256):
    """ρ and τ by Gauss–Legendre in cos θi (each hemisphere) × midpoint rule in φi.

    Delta components are not seen (f = 0 for them). Narrow lobes need many nodes.
    """
    p = check_row(params)
    ra, rb, eta, kappa = _spectra(ra, rb, eta, kappa)
    x, wx = _gauss_legendre(int(n_theta))
    mu = 0.5 * (x + 1.0)  # cos θ in (0, 1)
    wmu = 0.5 * wx
    phi = (np.arange(int(n_phi)) + 0.5) * (2.0 * np.pi / n_phi)
    dphi = 2.0 * np.pi / n_phi
    mm, pp = np.meshgrid(mu, phi, indexing="ij")
    ww = (wmu[:, None] * dphi) * np.ones_like(pp)
    st = np.sqrt(np.maximum(1.0 - mm * mm, 0.0))
    up = np.stack([st * np.cos(pp), st * np.sin(pp), mm], axis=-1).reshape(-1, 3)
    wts = (ww * mm).reshape(-1)  # the cosine times the quadrature weight
    wo = _wo(theta_o, phi_o)
    out = []
    for sgn in (1.0, -1.0):
        wi = up * np.array([1.0, 1.0, sgn])
        _, f, _, _ = _run(OP_EVAL, model, p, ra, rb, eta, kappa, wo, wi)
        out.append((f * wts[:, None]).sum(axis=0))
    upper, lower = out
    if wo[2] < 0.0:
        upper, lower = lower, upper
    z = np.zeros(ra.size)
    return Albedo(upper, lower, z, z.copy())


def white_furnace(model, params, theta_o, eta=1.5, kappa=0.0, n_samples=1 << 16, seed=0):
    """ρ + (n_i/n_o)² τ per wavelength for white spectra (ra = rb = 1): the radiance leaving
    towards wo in a furnace of constant basic radiance L/n² (L = 1 outside, η² inside);
    1 for a lossless model. θo > π/2 puts wo inside."""
    _, _, eta_s, _ = _spectra(1.0, 1.0, eta, kappa)
    a = albedo(model, params, 1.0, 1.0, eta_s, kappa, theta_o, n_samples=n_samples, seed=seed)
    ratio2 = eta_s ** 2 if np.cos(theta_o) > 0.0 else 1.0 / eta_s ** 2
    return a.reflectance + ratio2 * a.transmittance


__all__ = ["Albedo", "albedo", "albedo_quadrature", "white_furnace"]
