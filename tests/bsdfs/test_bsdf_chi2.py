"""Chi-square goodness of fit of every non-delta BSDF sampler against its own pdf
(compendium items 20, 21, 23, 47-50, the GGX models and the plastic), at θo = 0°, 45°, 80°, 89°.

The shared harness (tests/chi2.py) integrates the supplied pdf over (cos θ, φ) cells
about the normal, with rows of cos θ at quantiles of the samples so that narrow lobes
are resolved, and the horizon always a row boundary. Samples the sampler gives up on (a direction below the horizon, a
rejected lobe) are one more cell, whose expectation is N (1 − ∫ pdf dω): the pdf must
integrate to the fraction of successful samples, and to 1 for the samplers that never
lose one (Lambert, Phong, Lafortune).
"""
import math

import numpy as np
import pytest

from spectral_gi.core import bsdfs as B
from spectral_gi.core import constants as C
from spectral_gi.core import jit
from spectral_gi.core.spectra.library import metal_ior

import chi2

NW = C.N_WAVELENGTHS
AU_ETA, AU_K = metal_ior("Au", np.array([450.0, 520.0, 600.0, 680.0]))
RA = np.array([0.2, 0.45, 0.6, 0.3])
RB = np.array([0.5, 0.4, 0.3, 0.6])
ETA = np.full(NW, 1.5)
N_SAMPLES = 20000

CASES = {
    "lambert": (C.MAT_LAMBERT, B.lambert_params(), RA, RB, ETA, 0.0),
    "phong_n3": (C.MAT_PHONG, B.phong_params(3), RA, RB, ETA, 0.0),
    "phong_n150": (C.MAT_PHONG, B.phong_params(150), RA, RB, ETA, 0.0),
    "phong_n7.5": (C.MAT_PHONG, B.phong_params(7.5), RA, RB, ETA, 0.0),
    "blinn_n5": (C.MAT_BLINN_PHONG, B.blinn_phong_params(5), RA, RB, ETA, 0.0),
    "blinn_n200": (C.MAT_BLINN_PHONG, B.blinn_phong_params(200), RA, RB, ETA, 0.0),
    "ward_iso_0.3": (C.MAT_WARD, B.ward_params(0.3), RA, RB, ETA, 0.0),
    "ward_aniso": (C.MAT_WARD, B.ward_params(0.05, 0.25), RA, RB, ETA, 0.0),
    "lafortune_3": (C.MAT_LAFORTUNE, B.lafortune_params([(-0.9, -0.7, 0.6, 8.5), (0.6, 0.6, 0.4, 3),
                                                         (-1.1, -1.1, 0.3, 40)]), RA, RB, ETA, 0.0),
    "lafortune_sharp": (C.MAT_LAFORTUNE, B.lafortune_params([(-1.0, -1.0, 1.0, 60)]), RA, RB, ETA, 0.0),
    "ggx_cond_0.5": (C.MAT_GGX_CONDUCTOR, B.ggx_conductor_params(0.5), RB, RB, AU_ETA, AU_K),
    "ggx_cond_0.05": (C.MAT_GGX_CONDUCTOR, B.ggx_conductor_params(0.05), RB, RB, AU_ETA, AU_K),
    "ggx_cond_aniso": (C.MAT_GGX_CONDUCTOR, B.ggx_conductor_params(0.05, 0.4), RB, RB, AU_ETA, AU_K),
    "ggx_diel_0.5": (C.MAT_GGX_DIELECTRIC, B.ggx_dielectric_params(0.5), RA, RB, ETA, 0.0),
    "ggx_diel_0.05": (C.MAT_GGX_DIELECTRIC, B.ggx_dielectric_params(0.05), RA, RB, ETA, 0.0),
    "ggx_diel_aniso": (C.MAT_GGX_DIELECTRIC, B.ggx_dielectric_params(0.1, 0.4), RA, RB, ETA, 0.0),
    "plastic_0.3": (C.MAT_PLASTIC, B.plastic_params(0.3), RA, RB, ETA, 0.0),
    "plastic_0.05_eta2.4": (C.MAT_PLASTIC, B.plastic_params(0.05), RA, RB, np.full(NW, 2.4), 0.0),
    "plastic_aniso_eta1.33": (C.MAT_PLASTIC, B.plastic_params(0.03, 0.3), RA, RB, np.full(NW, 1.33), 0.0),
    "plastic_0.1_white_dispersive": (C.MAT_PLASTIC, B.plastic_params(0.1), np.ones(NW), np.ones(NW),
                                     np.array([1.53, 1.52, 1.51, 1.50]), 0.0),
    "plastic_cycles_0.3_ms": (C.MAT_PLASTIC, B.plastic_params(0.3, layering="cycles", multiscatter=True), RA, RB, ETA,
                              0.0),
    "plastic_cycles_0.05_eta2.4": (C.MAT_PLASTIC, B.plastic_params(0.05, layering="cycles"), RA, RB,
                                   np.full(NW, 2.4), 0.0),
    "plastic_cycles_aniso_ms": (C.MAT_PLASTIC, B.plastic_params(0.03, 0.3, layering="cycles", multiscatter=True), RA,
                                RB, np.full(NW, 1.33), 0.0),
    # the Principled outer layers (principled.py); kappa: the coat tint
    "principled_coat_sheen": (C.MAT_PLASTIC, B.plastic_params(0.3, layering="cycles", multiscatter=True, coat=1.0,
                                                              coat_alpha=0.05, coat_tinted=True, sheen=1.0),
                              RA, RB, ETA, np.array([0.9, 0.6, 0.3, 0.75])),
    "principled_sheen_rough": (C.MAT_PLASTIC, B.plastic_params(0.1, sheen=0.8, sheen_roughness=1.0), RA, RB, ETA, 0.0),
    "principled_coat_rough": (C.MAT_PLASTIC, B.plastic_params(0.05, layering="cycles", coat=0.7, coat_alpha=0.4,
                                                              coat_ior=1.8, sheen=0.3, sheen_roughness=0.1),
                              RA, RB, ETA, 0.0),
}


@pytest.fixture(autouse=True, scope="module")
def one_thread():
    """Many small kernel calls: on a busy machine the parallel launch waits for
    descheduled worker threads (tens of ms per call); one thread avoids the wait."""
    import numba
    before = numba.get_num_threads()
    jit.set_threads(1)
    yield
    jit.set_threads(before)


NO_LOSS = (C.MAT_LAMBERT, C.MAT_PHONG, C.MAT_LAFORTUNE)
ANGLES = (0.0, 45.0, 80.0, 89.0)


def _z_edges(model, z, n_z):
    """Edges in cos θ: at quantiles of the samples (equal counts per row, so narrow lobes
    get narrow rows), always including the poles and the horizon, where the pdf jumps
    to 0, so that no cell straddles it."""
    fixed = [-1.0, 0.0, 1.0] if model == C.MAT_GGX_DIELECTRIC else [0.0, 1.0]
    if len(z) > n_z:
        q = np.quantile(z, np.linspace(0.0, 1.0, n_z + 1)[1:-1])
    else:
        q = np.linspace(fixed[0], 1.0, n_z + 1)[1:-1]
    e = np.unique(np.concatenate([fixed, q]))
    return e[np.concatenate([[True], np.diff(e) > 1e-9])]


def chi2_bsdf(case, wo, alpha, name, n=N_SAMPLES, n_z=12, n_phi=24):
    """The harness's cell integration and test, with a last cell for failed samples;
    returns (result, ∫ pdf over the sphere)."""
    model, p, ra, rb, eta, kappa = case
    u = np.random.default_rng(chi2.seed_for(name)).random((n, 3))
    wi, _, _, fl = B.sample(model, p, ra, rb, eta, kappa, wo, u)
    ok = fl != 0
    dirs = wi[ok]

    def pdf(v):
        return B.pdf(model, p, ra, rb, eta, kappa, wo, np.ascontiguousarray(v))

    if model == C.MAT_GGX_DIELECTRIC:
        n_z *= 2
    z = np.clip(dirs[:, 2], -1.0, 1.0)
    phi = np.mod(np.arctan2(dirs[:, 1], dirs[:, 0]), 2 * np.pi)
    z_edges = _z_edges(model, z, n_z)
    phi_edges = np.linspace(0.0, 2 * np.pi, n_phi + 1)

    def density(pp, zz):
        s = np.sqrt(np.maximum(1.0 - zz * zz, 0.0))
        return pdf(np.stack([s * np.cos(pp), s * np.sin(pp), zz], axis=-1))

    hist, _, _ = np.histogram2d(phi, z, bins=[phi_edges, z_edges])
    inside = (z >= z_edges[0]) & (z <= z_edges[-1])
    # near grazing the lobes pile up against the horizon (p(wi) = p(h)/(4 wo·h) with
    # wo·h → cos θo): start the quadrature finer so it cannot converge on a missed peak
    depth = 4 if abs(wo[2]) < 0.2 else 2
    exp_grid = n * chi2.integrate_cells(density, phi_edges, z_edges, n, support=np.stack([phi, z], axis=1),
                                        min_depth=depth)
    exp_out = 0.0
    if z_edges[0] > -1.0:  # below the horizon of a reflective model: the pdf must be 0 there
        exp_out = n * chi2.integrate_cells(density, np.linspace(0, 2 * np.pi, 9), np.linspace(-1.0, z_edges[0], 3),
                                           n).sum()
    total = (exp_grid.sum() + exp_out) / n  # ∫ pdf over the sphere
    obs = np.concatenate([hist.T.ravel(), [np.count_nonzero(~inside), np.count_nonzero(~ok)]])
    exp = np.concatenate([exp_grid.ravel(), [exp_out, max(n - exp_grid.sum() - exp_out, 0.0)]])
    if len(dirs) and not np.all(pdf(dirs) > 0):
        return chi2.Chi2Result(math.inf, 0, 0.0, alpha, False, f"{name}: a sample where the pdf is 0"), total
    return chi2.chi2_test(obs, exp, alpha, name, extra={"observed_grid": hist.T, "expected_grid": exp_grid}), total


@pytest.mark.slow
@pytest.mark.statistical
@pytest.mark.parametrize("theta", ANGLES)
@pytest.mark.parametrize("name", list(CASES))
def test_bsdf_sampling_chi2(name, theta, alpha):
    case = CASES[name]
    t = math.radians(theta)
    wo = np.array([math.sin(t) * math.cos(0.4), math.sin(t) * math.sin(0.4), math.cos(t)])
    res, total = chi2_bsdf(case, wo, alpha, f"bsdf_{name}_{theta:g}")
    assert res.passed, res.message
    assert total <= 1.0 + 2e-3, (name, theta, total)
    if case[0] in NO_LOSS:
        assert total == pytest.approx(1.0, abs=2e-3)


@pytest.mark.slow
@pytest.mark.statistical
@pytest.mark.parametrize("name", ["ggx_diel_0.5", "ggx_diel_aniso"])
def test_bsdf_sampling_chi2_from_inside(name, alpha):
    """The rough dielectric seen from inside (wo below), beyond the critical angle too."""
    case = CASES[name]
    for theta in (150.0, 120.0):
        t = math.radians(theta)
        wo = np.array([math.sin(t) * math.cos(0.4), math.sin(t) * math.sin(0.4), math.cos(t)])
        res, total = chi2_bsdf(case, wo, alpha, f"bsdf_{name}_{theta:g}_inside")
        assert res.passed, res.message
        assert total <= 1.0 + 2e-3
