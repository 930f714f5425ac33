"""CIE 171:2006 analytical cases computed with the illuminance integrator: every point within
1 % of its closed form (or five standard errors of the estimate, whichever is larger) and,
without any allowance for noise, within the CIE tolerance (5 %); the flux balance and the mean
inter-reflected illuminance of the closed rooms within 1 %.

The reflecting cubes stop each point at a relative standard error of 0.7 % (at most 4096
samples): at 256 samples a point at ρ ≥ 0.9 has a relative standard error of about 1.9 %, and
one of the 384 points landed 4.2 standard errors (6.4 %) from its reference. That is noise, not
bias: at 16 384 samples the mean relative difference over 96 points is (+1.2 ± 2.5)·10⁻⁴ at
ρ = 0.95 and (+1.3 ± 2.4)·10⁻⁴ at ρ = 0.9, and
``test_case_5_8_at_high_reflectance_is_within_one_percent_everywhere`` holds single points to
1 % at a standard error that resolves it."""
import numpy as np
import pytest

from spectral_gi.core.integrators.illuminance import illuminance
from spectral_gi.core.lux import cie171

CASES = {c.name: c for c in cie171.reference_cases()}
EXACT = 0.01  # relative tolerance where the reference is exact
# 5.7's points see their only light, the wall S₂, over 3 to 16 % of the cosine-weighted hemisphere
OPTIONS = {"5.7": {"spp": 32768}}
REFLECTING = {"spp": 4096, "rel_error": 0.007}  # the reflecting cubes (5.6, 5.8 at ρ > 0)


def _options(case):
    if case.name in OPTIONS:
        return OPTIONS[case.name]
    return REFLECTING if case.extra.get("rho", 0.0) > 0.0 and case.expected_mean_indirect is not None \
        else {"spp": 256}


def _estimate(case, **options):
    lux, se, _ = illuminance(case.scene, case.points, case.normals, seed=11, threads=2,
                             **(options or _options(case)))
    return lux, se


def _slow_if_long(name):
    """The cubes of ρ ≥ 0.8 take 10 to 40 s at their relative standard error."""
    return pytest.param(name, marks=pytest.mark.slow) if CASES[name].extra.get("rho", 0.0) >= 0.8 else name


@pytest.mark.statistical
@pytest.mark.parametrize("name", [_slow_if_long(n) for n in sorted(CASES)])
def test_cie171_case_matches_its_closed_form(name):
    case = CASES[name]
    lux, se = _estimate(case)
    if case.expected_total is not None:
        exp = case.expected_total
        err = np.abs(lux - exp)
        allowed = np.maximum(EXACT * exp, 5.0 * se)
        assert np.all(err <= allowed), (name, err.max(), np.argmax(err - allowed))
        cie = case.tolerance * np.maximum(exp, 1e-9)  # no allowance for noise
        assert np.all(err <= cie), (name, float(np.max(err / np.maximum(exp, 1e-9))), int(np.argmax(err - cie)))
    w = case.weights / case.weights.sum()
    if case.expected_flux is not None:
        # the lamp's flux reaches the walls directly; in a closed room every inter-reflected lumen
        # lands on a wall too: the total is Φ + A · Ē_indirect (= Φ / (1 − ρ) for one reflectance)
        expected = case.expected_flux + case.weights.sum() * (case.expected_mean_indirect or 0.0)
        flux = float(case.weights @ lux)
        flux_se = float(np.sqrt((case.weights ** 2) @ (se ** 2)))
        assert abs(flux - expected) <= EXACT * expected, (flux, expected, flux_se)
    if case.expected_mean_indirect is not None:
        indirect = float(w @ (lux - case.expected_direct))
        indirect_se = float(np.sqrt((w ** 2) @ (se ** 2)))
        exp = case.expected_mean_indirect
        allowed = EXACT * exp if exp > 0.0 else 5.0 * indirect_se  # ρ = 0: nothing to be 1 % of
        assert abs(indirect - exp) <= allowed, (indirect, exp, indirect_se)


@pytest.mark.slow
@pytest.mark.statistical
def test_case_5_8_at_high_reflectance_is_within_one_percent_everywhere():
    """At ρ = 0.95 (most of the light inter-reflected, paths of 20 bounces and more) the ten
    distinct points of a face (its symmetry gives the other 54) at 32 768 samples each: a
    relative standard error of about 0.17 %, so 1 % is six standard errors and every point must
    be within it of the radiosity reference."""
    case = CASES["5.8 rho=0.95"]
    on_face = np.flatnonzero(case.extra["face_index"] == 0)
    side = case.extra["area"] ** 0.5 / 6 ** 0.5
    p = case.points[on_face]
    normal = case.normals[on_face[0]]
    uv = p - p.mean(axis=0)
    axes = [a for a in np.eye(3) if abs(a @ normal) < 0.5]
    i = np.rint(uv @ axes[0] / side * 8 + 3.5).astype(int)
    j = np.rint(uv @ axes[1] / side * 8 + 3.5).astype(int)
    pick = on_face[(i <= j) & (j <= 3)]
    assert pick.size == 10
    lux, se, _ = illuminance(case.scene, case.points[pick], case.normals[pick], spp=32768, seed=5, threads=2)
    exp = case.expected_total[pick]
    assert np.all(se <= 0.003 * exp), se / exp
    assert np.all(np.abs(lux - exp) <= EXACT * exp), (lux - exp) / exp


@pytest.mark.statistical
def test_the_check_catches_a_bounce_limit():
    """A program that stops after eight bounces keeps 1 − ρ⁸ of the indirect light at ρ = 0.95
    (CIE 171's discriminating case): the same check must fail it."""
    case = CASES["5.8 rho=0.95"]
    lux, se, _ = illuminance(case.scene, case.points, case.normals, spp=64, seed=11, threads=2, max_depth=8)
    w = case.weights / case.weights.sum()
    indirect = float(w @ (lux - case.expected_direct))
    assert indirect < (1.0 - EXACT) * case.expected_mean_indirect, indirect
