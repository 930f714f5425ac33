"""CIE 171:2006 analytical cases computed with the illuminance integrator: each within 1 % of
its closed form (or five standard errors of the estimate, whichever is larger), and never worse
than the CIE tolerance."""
import numpy as np
import pytest

from spectral_gi.core.integrators.illuminance import illuminance
from spectral_gi.core.lux import cie171

CASES = {c.name: c for c in cie171.reference_cases()}
EXACT = 0.01  # relative tolerance where the reference is exact
# 5.7's points see their only light, the wall S₂, over 3 to 16 % of the cosine-weighted hemisphere
SPP = {"5.7": 32768}


def _estimate(case, spp=None):
    spp = spp or SPP.get(case.name, 256)
    lux, se, _ = illuminance(case.scene, case.points, case.normals, spp=spp, seed=11, threads=2)
    return lux, se


@pytest.mark.statistical
@pytest.mark.parametrize("name", sorted(CASES))
def test_cie171_case_matches_its_closed_form(name):
    case = CASES[name]
    lux, se = _estimate(case)
    if case.expected_total is not None:
        exp = case.expected_total
        err = np.abs(lux - exp)
        allowed = np.maximum(EXACT * exp, 5.0 * se)
        assert np.all(err <= allowed), (name, err.max(), np.argmax(err - allowed))
        assert np.all(err <= case.tolerance * np.maximum(exp, 1e-9) + 5.0 * se)
    w = case.weights / case.weights.sum()
    if case.expected_flux is not None:
        # the lamp's flux reaches the walls directly; in a closed room every inter-reflected lumen
        # lands on a wall too: the total is Φ + A · Ē_indirect (= Φ / (1 − ρ) for one reflectance)
        expected = case.expected_flux + case.weights.sum() * (case.expected_mean_indirect or 0.0)
        flux = float(case.weights @ lux)
        flux_se = float(np.sqrt((case.weights ** 2) @ (se ** 2)))
        assert abs(flux - expected) <= max(EXACT * expected, 5.0 * flux_se), (flux, expected, flux_se)
    if case.expected_mean_indirect is not None:
        indirect = float(w @ (lux - case.expected_direct))
        indirect_se = float(np.sqrt((w ** 2) @ (se ** 2)))
        exp = case.expected_mean_indirect
        assert abs(indirect - exp) <= max(EXACT * exp, 5.0 * indirect_se), (indirect, exp, indirect_se)


@pytest.mark.statistical
def test_the_check_catches_a_bounce_limit():
    """A program that stops after eight bounces keeps 1 − ρ⁸ of the indirect light at ρ = 0.95
    (CIE 171's discriminating case): the same check must fail it."""
    case = CASES["5.8 rho=0.95"]
    lux, se, _ = illuminance(case.scene, case.points, case.normals, spp=64, seed=11, threads=2, max_depth=8)
    w = case.weights / case.weights.sum()
    indirect = float(w @ (lux - case.expected_direct))
    assert indirect < (1.0 - EXACT) * case.expected_mean_indirect, indirect
