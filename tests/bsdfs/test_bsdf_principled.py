"""The Principled BSDF's sheen and coat layers over the plastic (core/bsdfs/principled.py).

A NumPy oracle of the layered model (the base from the kernel's plain plastic, which has its own
oracle in test_bsdf.py), the sheen's LTC integrating to its albedo fit, the coat over a black
base being exactly the rough dielectric's reflection lobe (so reciprocal), white-furnace bounds
of the whole stack and the coat tint's Beer's law. Sampling against the pdf: test_bsdf_chi2.py.
"""
import math

import numpy as np
import pytest

from spectral_gi.core import bsdfs as B
from spectral_gi.core import constants as C
from spectral_gi.core.bsdfs import params
from spectral_gi.core.bsdfs.albedo import albedo, albedo_quadrature

NW = C.N_WAVELENGTHS
RA = np.array([0.2, 0.45, 0.6, 0.3])
RB = np.array([0.5, 0.4, 0.3, 0.6])
ETA = np.full(NW, 1.5)
TINT = np.array([0.9, 0.6, 0.3, 0.75])
WHITE = np.ones(NW)
BLACK = np.zeros(NW)


def wo_at(theta_deg, phi=0.3):
    t = math.radians(theta_deg)
    return np.array([math.sin(t) * math.cos(phi), math.sin(t) * math.sin(phi), math.cos(t)])


def random_dirs(rng, n):
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    v[:, 2] = np.abs(v[:, 2])
    return v


def np_fresnel(mu, eta):
    """Unpolarised dielectric Fresnel factor from the outside (η ≥ 1), from Hecht's amplitudes."""
    ct = np.sqrt(1.0 - (1.0 - mu * mu) / eta ** 2)
    rs = (mu - eta * ct) / (mu + eta * ct)
    rp = (eta * mu - ct) / (eta * mu + ct)
    return 0.5 * (rs ** 2 + rp ** 2)


def np_sheen_fit(mu, r):
    """(R, a, b) arrays: the sheen LTC table (sheen_table.py, nodes i/31) read by scipy's bilinear
    interpolation at roughness r (clamped to [0.001, 1]) and view cosines mu; R = 0 where a or R
    falls below 1e-5."""
    from scipy.interpolate import RegularGridInterpolator
    from spectral_gi.core.bsdfs.sheen_table import SHEEN_LTC

    nodes = np.linspace(0.0, 1.0, 32)
    pts = np.stack([np.full(np.shape(mu), min(max(r, 1e-3), 1.0)), np.clip(mu, 0.0, 1.0)], axis=-1)
    alb, a, b = (RegularGridInterpolator((nodes, nodes), SHEEN_LTC[k])(pts) for k in (2, 0, 1))
    dead = (a <= 1e-5) | (alb <= 1e-5)
    return np.where(dead, 0.0, np.minimum(alb, 1.0)), np.where(dead, 1.0, a), np.where(dead, 0.0, b)


def np_ltc(a, b, wo, wi):
    """D_ltc(wi): the clamped cosine of M⁻¹ wi / |M⁻¹ wi| times the Jacobian |det M⁻¹| / |M⁻¹ wi|³,
    in the frame (X, Y, Z) with X the projection of wo on the surface."""
    z = np.array([0.0, 0.0, 1.0])
    x = wo - wo[:, 2:3] * z
    n = np.linalg.norm(x, axis=1)
    x = np.where(n[:, None] > 0, x / np.maximum(n, 1e-300)[:, None], np.array([1.0, 0.0, 0.0]))
    y = np.cross(z, x)
    loc = np.stack([np.sum(wi * x, axis=1), np.sum(wi * y, axis=1), wi[:, 2]], axis=1)
    out = np.zeros(len(wo))
    for k in range(len(wo)):
        m_inv = np.array([[a[k], 0.0, b[k]], [0.0, a[k], 0.0], [0.0, 0.0, 1.0]])
        v = m_inv @ loc[k]
        lv = np.linalg.norm(v)
        out[k] = max(v[2] / lv, 0.0) / np.pi * abs(np.linalg.det(m_inv)) / lv ** 3
    return out


def np_principled(pr, ra, rb, eta, tint, wo, wi, f_base, pdf_base, t_base):
    """f (N, NW) and pdf (N,) of the layered model from the base's f, pdf and Σ_λ albedo estimate."""
    c, ac, ec, s, rs = pr["coat"], max(pr["coat_alpha"], 1e-4), pr["coat_ior"], pr["sheen"], pr["sheen_roughness"]
    mu_o, mu_i = wo[:, 2], wi[:, 2]
    alb, a, b = np_sheen_fit(mu_o, rs)
    sr = s * alb
    d_s = np_ltc(a, b, wo, wi) if s > 0 else np.zeros(len(wo))
    h = wo + wi
    h /= np.linalg.norm(h, axis=1)[:, None]
    d = 1.0 / (np.pi * ac * ac * ((h[:, 0] ** 2 + h[:, 1] ** 2) / ac ** 2 + h[:, 2] ** 2) ** 2)

    def lam(w):
        return 0.5 * (-1.0 + np.sqrt(1.0 + ac ** 2 * (w[:, 0] ** 2 + w[:, 1] ** 2) / w[:, 2] ** 2))

    g2 = 1.0 / (1.0 + lam(wo) + lam(wi))
    pdf_c = d / (1.0 + lam(wo)) / (4 * mu_o)
    cf = c * np_fresnel(mu_o, ec)
    ws, wc = 1 - np.minimum(sr, 1), 1 - np.minimum(cf, 1)
    ct = np.sqrt(1 - (1 - mu_o ** 2) / ec ** 2)
    t = 1 - c + c * tint[None, :] ** (1 / ct[:, None])
    f_coat = c * np_fresnel(np.sum(wo * h, axis=1), ec) * d * g2 / (4 * mu_o * mu_i)
    f = (sr * d_s / mu_i + ws * f_coat)[:, None] + (ws * wc)[:, None] * t * f_base
    w_s, w_c, w_b = sr * NW, ws * cf * NW, ws * wc * t.mean(axis=1) * t_base
    tot = w_s + w_c + w_b
    return f, (w_s * d_s + w_c * pdf_c + w_b * pdf_base) / tot


LAYERS = [dict(coat=1.0, coat_alpha=0.04, coat_ior=1.5, coat_tinted=True, sheen=0.0, sheen_roughness=0.0),
          dict(coat=0.0, coat_alpha=0.0, coat_ior=1.5, coat_tinted=False, sheen=1.0, sheen_roughness=0.5),
          dict(coat=0.6, coat_alpha=0.3, coat_ior=1.8, coat_tinted=True, sheen=0.7, sheen_roughness=0.2),
          dict(coat=1.0, coat_alpha=0.0, coat_ior=1.3, coat_tinted=False, sheen=0.4, sheen_roughness=1.0)]


@pytest.mark.parametrize("layers", range(len(LAYERS)))
def test_principled_matches_the_numpy_oracle(layers):
    """f and pdf over the physical base (whose Σ_λ albedo estimate is Σ rb F + ra (1 − F)), f over the
    Cycles base: the kernel agrees with the oracle to rounding."""
    pr = LAYERS[layers]
    rng = np.random.default_rng(40 + layers)
    wo, wi = random_dirs(rng, 1500), random_dirs(rng, 1500)
    eta = np.array([1.45, 1.5, 1.62, 2.4])
    tint = TINT if pr["coat_tinted"] else WHITE
    for layering, ms in (("physical", False), ("cycles", True)):
        base_p = B.plastic_params(0.2, 0.1, layering=layering, multiscatter=ms)
        p = B.plastic_params(0.2, 0.1, layering=layering, multiscatter=ms, **pr)
        f, pd = B.evaluate(C.MAT_PLASTIC, p, RA, RB, eta, TINT, wo, wi)
        f_b, pd_b = B.evaluate(C.MAT_PLASTIC, base_p, RA, RB, eta, TINT, wo, wi)
        fo = np_fresnel(wo[:, 2:3], eta[None, :])
        t_b = np.sum(RB * fo + RA * (1 - fo), axis=1)
        f_ref, pd_ref = np_principled(pr, RA, RB, eta, tint, wo, wi, f_b, pd_b, t_b)
        np.testing.assert_allclose(f, f_ref, rtol=1e-9, atol=1e-300)
        if layering == "physical":
            np.testing.assert_allclose(pd, pd_ref, rtol=1e-9)
        assert np.all(pd > 0)


@pytest.mark.parametrize("rough", [0.05, 0.3, 0.5, 1.0])
def test_sheen_lobe_integrates_to_its_albedo(rough):
    """Over a black base (physical layering, ρ = tint = 0) the sheen's albedo is s R(μo, r): the LTC
    is a density of directions inside the upper hemisphere, so a quadrature of f cos θi from the
    evaluation alone gives the table's R back; R grows towards grazing views and with roughness."""
    p = B.plastic_params(0.3, sheen=0.8, sheen_roughness=rough)
    prev = -1.0
    for th in (0.0, 30.0, 60.0, 75.0, 85.0):
        q = albedo_quadrature(C.MAT_PLASTIC, p, BLACK, BLACK, ETA, 0.0, math.radians(th), n_theta=384, n_phi=384)
        r_fit = np_sheen_fit(np.array([math.cos(math.radians(th))]), rough)[0][0]
        np.testing.assert_allclose(q.reflectance, 0.8 * r_fit, rtol=2e-3, atol=2e-5)
        assert r_fit >= prev - 1e-3
        prev = r_fit
    assert np_sheen_fit(np.array([0.5]), 1.0)[0][0] > np_sheen_fit(np.array([0.5]), 0.3)[0][0] > 0.02


def test_coat_alone_is_the_dielectric_reflection_and_reciprocal():
    """A full coat over a black base is the plastic's coat of the same α and η with a white tint
    (the reflection lobe of the rough GGX dielectric), hence symmetric in wo and wi."""
    rng = np.random.default_rng(7)
    wo, wi = random_dirs(rng, 2000), random_dirs(rng, 2000)
    for ac, ec in ((0.05, 1.5), (0.4, 1.9)):
        p = B.plastic_params(0.3, coat=1.0, coat_alpha=ac, coat_ior=ec)
        f, _ = B.evaluate(C.MAT_PLASTIC, p, BLACK, BLACK, ETA, 0.0, wo, wi)
        g, _ = B.evaluate(C.MAT_PLASTIC, B.plastic_params(ac), BLACK, WHITE, np.full(NW, ec), 0.0, wo, wi)
        back, _ = B.evaluate(C.MAT_PLASTIC, p, BLACK, BLACK, ETA, 0.0, wi, wo)
        np.testing.assert_allclose(f, g, rtol=1e-12, atol=1e-300)
        np.testing.assert_allclose(f, back, rtol=1e-12, atol=1e-300)


@pytest.mark.slow
def test_white_stack_energy_and_the_coat_estimate():
    """White base (Cycles layering, Multiscatter GGX) under a full coat and a sheen: the albedo never
    exceeds 1 (+ 0.5 % for the base's own compensation, test_bsdf.py); under a smooth coat it is
    within 2 % of 1 (its real albedo is about F(μo), Cycles' estimate) up to 75°, where a rough
    coat loses what its estimate F(μo) over-credits (measured 0.86 at 75° for α 0.25)."""
    for ca, sheen, lo in ((0.01, 0.0, 0.98), (0.01, 1.0, 0.98), (0.25, 0.0, 0.8), (0.25, 1.0, 0.8)):
        p = B.plastic_params(0.25, layering="cycles", multiscatter=True, coat=1.0, coat_alpha=ca, sheen=sheen)
        for th in (0.0, 45.0, 75.0):
            a = albedo(C.MAT_PLASTIC, p, WHITE, WHITE, ETA, 0.0, math.radians(th), n_samples=100000, seed=5)
            r, se = a.reflectance[0], a.reflectance_se[0]
            assert r <= 1.005 + 4 * se, (ca, sheen, th, r)
            assert r >= lo - 4 * se, (ca, sheen, th, r)


def test_coat_tint_is_beers_law_along_the_refracted_view():
    """Over a white Lambert base (index-matched specular, η = 1): the base's weight is
    (1 − F(μo, η_c)) t^(1/cos θt) for a full coat, 1 − c + c t^(1/cos θt) blended by the weight;
    at normal incidence just t (1 − F0)."""
    wi = np.array([[0.3, -0.2, math.sqrt(1 - 0.13)]])
    for th in (0.0, 50.0, 80.0):
        wo = wo_at(th)[None, :]
        for c in (1.0, 0.5):
            p = B.plastic_params(0.3, coat=c, coat_alpha=0.5, coat_ior=1.5, coat_tinted=True)
            plain = B.plastic_params(0.3, coat=c, coat_alpha=0.5, coat_ior=1.5)
            f, _ = B.evaluate(C.MAT_PLASTIC, p, WHITE, BLACK, np.ones(NW), TINT, wo, wi)
            g, _ = B.evaluate(C.MAT_PLASTIC, plain, WHITE, BLACK, np.ones(NW), TINT, wo, wi)
            coat, _ = B.evaluate(C.MAT_PLASTIC, plain, BLACK, BLACK, np.ones(NW), 0.0, wo, wi)
            mu = wo[0, 2]
            ct = math.sqrt(1 - (1 - mu * mu) / 1.5 ** 2)
            np.testing.assert_allclose((f - coat)[0], (g - coat)[0] * (1 - c + c * TINT ** (1 / ct)), rtol=1e-12)
            np.testing.assert_allclose((g - coat)[0], (1 - c * np_fresnel(mu, 1.5)) / np.pi, rtol=1e-12)


def test_plain_rows_and_builder():
    """Without coat and sheen the row is the plain plastic's (entries 5-10 zero); bad inputs raise."""
    p = B.plastic_params(0.3, layering="cycles", multiscatter=True)
    assert np.all(p[params.P_COAT:params.P_SHEEN_ROUGHNESS + 1] == 0.0)
    q = B.plastic_params(0.3, coat=0.5, coat_alpha=0.0, coat_ior=1.6, coat_tinted=True, sheen=0.2,
                         sheen_roughness=0.4)
    assert q[params.P_COAT] == 0.5 and q[params.P_COAT_ALPHA] == params.ALPHA_MIN
    assert q[params.P_COAT_IOR] == 1.6 and q[params.P_COAT_TINTED] == 1.0
    assert q[params.P_SHEEN] == 0.2 and q[params.P_SHEEN_ROUGHNESS] == 0.4
    for kw, msg in ((dict(coat=1.5), "coat must be in"), (dict(coat=1.0, coat_ior=0.9), "coat_ior"),
                    (dict(sheen=-0.1), "sheen"), (dict(sheen=1.0, sheen_roughness=2.0), "sheen_roughness"),
                    (dict(coat=1.0, coat_alpha=1.2), "coat_alpha")):
        with pytest.raises(ValueError, match=msg):
            B.plastic_params(0.3, **kw)
