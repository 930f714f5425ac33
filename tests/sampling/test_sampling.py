"""Monte Carlo toolkit: warps, spherical triangles, off-normal lobes, distributions, MIS,
statistics (compendium items 1, 5–29). Statistical tests use tests/chi2.py."""
import math

import numpy as np
import pytest
from chi2 import chi2_interval, chi2_plane, chi2_sphere, integrate_cells, seed_for, ztest, ztest_samples
from scipy import integrate

from spectral_gi.core.sampling import batch, frame, lobes, mis, sphtri, stats, warps
from oracles import sampling as O
from spectral_gi.core.sampling import tags as T
from spectral_gi.core.sampling.distrib import (
    build_distribution_1d, build_distribution_2d, distribution_1d_parts, distribution_2d_parts)

N = 200_000
HALF_PI = 0.5 * math.pi


def rng_for(name):
    return np.random.default_rng(seed_for(name))


def sample(tag, params, n=N, name="x", cols=3):
    return batch.sample(tag, params, rng_for(name).random((n, cols)))


def cone_range(theta_max):
    return (math.cos(min(theta_max, math.pi)), 1.0)


# -- the warps of items 18–21 and their parameter sets --------------------------------------

# (id, tag, params, oracle pdf(w), histogram z range)
DIRECTION_CASES = [
    ("sphere", T.WARP_UNIFORM_SPHERE, [], O.uniform_sphere_pdf, (-1.0, 1.0)),
    ("hemisphere", T.WARP_UNIFORM_HEMISPHERE, [], O.uniform_hemisphere_pdf, (0.0, 1.0)),
    ("cosine", T.WARP_COSINE_HEMISPHERE, [], O.cosine_hemisphere_pdf, (0.0, 1.0)),
]
for tm in (1e-3, 0.3, 1.0, HALF_PI - 1e-3, 2.5):
    DIRECTION_CASES.append((f"cone-{tm:g}", T.WARP_UNIFORM_CONE, [tm],
                            (lambda t: lambda w: O.uniform_cone_pdf(t, w))(tm), cone_range(tm)))
for tm in (1e-2, 0.5, HALF_PI - 1e-3):
    DIRECTION_CASES.append((f"cosine-cone-{tm:g}", T.WARP_COSINE_CONE, [tm],
                            (lambda t: lambda w: O.cosine_cone_pdf(t, w))(tm), cone_range(tm)))
for n, zlo in ((0, 0.0), (1, 0.0), (10, 0.2), (100, 0.85)):
    DIRECTION_CASES.append((f"cos^{n}", T.WARP_COSN, [n], (lambda k: lambda w: O.cosn_pdf(k, w))(n), (zlo, 1.0)))
for n, tm in ((0, 0.7), (1, 1.2), (10, 0.3), (100, 0.05), (100, 1e-3)):
    DIRECTION_CASES.append((f"cos^{n}-cone-{tm:g}", T.WARP_COSN_CONE, [n, tm],
                            (lambda k, t: lambda w: O.cosn_cone_pdf(k, t, w))(n, tm), cone_range(tm)))


@pytest.mark.slow
@pytest.mark.statistical
@pytest.mark.parametrize("name,tag,params,pdf,zr", DIRECTION_CASES, ids=[c[0] for c in DIRECTION_CASES])
def test_direction_warps_chi2(name, tag, params, pdf, zr, alpha):
    """Items 18–21: sphere, hemisphere, cone, cosine and cosⁿ lobes (with θmax) by chi-square."""
    w, p, flag = sample(tag, params, name=name)
    assert np.all(flag == T.FLAG_VALID)
    assert np.allclose(np.linalg.norm(w, axis=1), 1.0, atol=1e-12)
    res = chi2_sphere(w, pdf, alpha, name, z_range=zr)
    assert res.passed, res.message


@pytest.mark.slow
@pytest.mark.parametrize("name,tag,params,pdf,zr", DIRECTION_CASES, ids=[c[0] for c in DIRECTION_CASES])
def test_direction_warps_pdf_matches_oracle(name, tag, params, pdf, zr):
    w, p, _ = sample(tag, params, n=20_000, name=name)
    # the pdf returned with a sample, the pdf evaluated at it, and the oracle agree
    pk, _ = batch.pdf_and_inverse(tag, params, w)
    np.testing.assert_allclose(p, pk, rtol=1e-9)
    np.testing.assert_allclose(pk, pdf(w), rtol=1e-6)
    # and off the support (random directions), the pdfs agree too
    v, _, _ = sample(T.WARP_UNIFORM_SPHERE, [], n=20_000, name=name + "v")
    np.testing.assert_allclose(batch.pdf(tag, params, v), pdf(v), rtol=1e-6, atol=1e-300)


ORACLE_SAMPLERS = {
    "sphere": lambda u: O.sample_uniform_sphere(u)[0],
    "hemisphere": lambda u: O.sample_uniform_hemisphere(u)[0],
    "cosine": lambda u: O.sample_cosine_hemisphere(u)[0],
}


@pytest.mark.parametrize("name,tag,params,pdf,zr", DIRECTION_CASES, ids=[c[0] for c in DIRECTION_CASES])
def test_direction_warps_equal_oracle_pointwise(name, tag, params, pdf, zr):
    u = rng_for(name).random((5000, 2))
    w, _, _ = batch.sample(tag, params, u)
    if tag == T.WARP_UNIFORM_CONE:
        ref = O.sample_uniform_cone(params[0], u)[0]
    elif tag == T.WARP_COSINE_CONE:
        ref = O.sample_cosine_cone(params[0], u)[0]
    elif tag == T.WARP_COSN:
        ref = O.sample_cosn(params[0], u)[0]
    elif tag == T.WARP_COSN_CONE:
        ref = O.sample_cosn_cone(params[0], params[1], u)[0]
    else:
        ref = ORACLE_SAMPLERS[name](u)
    np.testing.assert_allclose(w, ref, atol=1e-7)


@pytest.mark.parametrize("name,tag,params,pdf,zr", DIRECTION_CASES, ids=[c[0] for c in DIRECTION_CASES])
def test_direction_pdfs_integrate_to_one_by_quadrature(name, tag, params, pdf, zr):
    """Items 9, 19–21: every density integrates to 1 over the sphere (adaptive quadrature)."""
    def density(phi, z):
        s = np.sqrt(np.maximum(1 - z * z, 0))
        return batch.pdf(tag, params, np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1))

    # cells in cos θ concentrated where the density lives, plus the rest of the sphere
    edges = np.unique(np.concatenate([np.linspace(-1, zr[0], 4), np.linspace(zr[0], 1, 33)]))
    total = integrate_cells(density, np.linspace(0, 2 * np.pi, 9), edges, 1e12, rel_tol=1e-3).sum()
    assert abs(total - 1.0) < 2e-4, total


MC_CASES = [c for c in DIRECTION_CASES if c[0] in ("sphere", "hemisphere", "cosine", "cone-0.3", "cone-2.5",
                                                    "cosine-cone-0.5", "cos^10", "cos^1-cone-1.2")]


@pytest.mark.statistical
@pytest.mark.parametrize("name,tag,params,pdf,zr", MC_CASES, ids=[c[0] for c in MC_CASES])
def test_direction_pdfs_integrate_to_one_by_monte_carlo(name, tag, params, pdf, zr, alpha):
    v, _, _ = sample(T.WARP_UNIFORM_SPHERE, [], name=name + "mc")
    res = ztest_samples(batch.pdf(tag, params, v) * 4 * np.pi, 1.0, alpha, name)
    assert res.passed, res.message


INVERTIBLE = [c for c in DIRECTION_CASES]


@pytest.mark.parametrize("name,tag,params,pdf,zr", INVERTIBLE, ids=[c[0] for c in INVERTIBLE])
def test_direction_warps_invert(name, tag, params, pdf, zr):
    """invert(sample(u)) == u and sample(invert(w)) == w for items 18–21."""
    u = rng_for(name).random((20_000, 2))
    w, p, _ = batch.sample(tag, params, u)
    _, ui = batch.pdf_and_inverse(tag, params, w)
    # invert(sample(u)) == u (φ where the direction is not at the pole)
    far = np.hypot(w[:, 0], w[:, 1]) > 1e-6
    np.testing.assert_allclose(ui[:, 1], u[:, 1], atol=1e-7)
    np.testing.assert_allclose(ui[far, 0], u[far, 0], atol=1e-7)
    # sample(invert(w)) == w
    w2, _, _ = batch.sample(tag, params, ui)
    np.testing.assert_allclose(w2, w, atol=1e-7)


def test_degenerate_uniforms_never_give_nan():
    u = np.array([[0.0, 0.0], [0.0, 1.0], [1.0, 0.0], [1.0, 1.0], [0.5, 1.0], [1 - 2 ** -53, 1 - 2 ** -53]])
    tri = [0.1, 0.0, 1.0, 0.0, 0.1, 1.0, -0.1, -0.1, 1.0]
    cases = [(c[1], c[2]) for c in DIRECTION_CASES] + [
        (T.WARP_SPHERICAL_TRIANGLE, tri), (T.WARP_OFFNORMAL_COSN, [5, 0.3, 0.0, 0.2]),
        (T.WARP_DISK_CONCENTRIC, []), (T.WARP_DISK_POLAR, []), (T.WARP_TRIANGLE_AREA, []),
        (T.WARP_DISTRIBUTION_1D, build_distribution_1d([0, 1, 0, 2])),
        (T.WARP_DISTRIBUTION_2D, build_distribution_2d([[0, 1], [2, 0]]))]
    for tag, params in cases:
        w, p, flag = batch.sample(tag, params, u)
        assert np.all(np.isfinite(w)) and not np.any(np.isnan(p)), (tag, params, w, p)
        # a valid sample has a positive finite pdf; an invalid one is flagged
        assert np.all((flag == T.FLAG_VALID) == ((p > 0) & np.isfinite(p))), (tag, p, flag)
        pk, ui = batch.pdf_and_inverse(tag, params, w)
        assert not np.any(np.isnan(pk)) and not np.any(np.isnan(ui)), (tag, pk, ui)


def test_cosine_lobes_at_the_horizon_are_flagged_invalid():
    # u2 = 1 exactly puts cosⁿ samples on the horizon where the density is 0
    for tag, params in ((T.WARP_COSN, [3.0]), (T.WARP_COSN_CONE, [3.0, HALF_PI])):
        w, p, flag = batch.sample(tag, params, np.array([[0.3, 1.0]]))
        assert flag[0] == T.FLAG_INVALID and p[0] == 0 and np.all(np.isfinite(w))


def test_dirac_cases_are_flagged_delta():
    """Item 1: θmax = 0 and n = ∞ are Dirac directions: pdf inf, flag DELTA, direction +z,
    and the density evaluated anywhere is 0."""
    u = rng_for("delta").random((10, 2))
    z = np.array([[0.0, 0.0, 1.0]])
    for tag, params in ((T.WARP_UNIFORM_CONE, [0.0]), (T.WARP_COSINE_CONE, [0.0]), (T.WARP_COSN_CONE, [4.0, 0.0]),
                        (T.WARP_COSN, [np.inf])):
        w, p, flag = batch.sample(tag, params, u)
        assert np.all(flag == T.FLAG_DELTA) and np.all(p == np.inf)
        np.testing.assert_array_equal(w, np.repeat(z, 10, axis=0))
        assert batch.pdf(tag, params, z)[0] == 0.0


def test_item9_hemisphere_integrals_by_quadrature():
    """∫dω = 2π, ∫cos θ dω = π, ∫cosⁿθ dω = 2π/(n+1) (item 9), by 2D quadrature in (θ, φ)."""
    for n in (0, 1, 2, 5, 10, 100, 1000):
        val, _ = integrate.dblquad(lambda th, ph: math.cos(th) ** n * math.sin(th), 0, 2 * math.pi, 0, HALF_PI,
                                   epsabs=1e-12, epsrel=1e-10)
        assert abs(val - O.hemisphere_integral_cosn(n)) < 1e-8 * max(1.0, val), n
    assert O.hemisphere_integral_cosn(0) == 2 * math.pi and O.hemisphere_integral_cosn(1) == math.pi


# -- item 22: spherical triangles --------------------------------------------------------------

TRIANGLES = {
    "small": ([0.01, 0.0, 1.0], [0.0, 0.012, 1.0], [-0.011, -0.004, 1.0]),
    "tiny": ([1e-5, 0.0, 1.0], [0.0, 1.2e-5, 1.0], [-1.1e-5, -4e-6, 1.0]),  # flat-triangle branch
    "medium": ([0.2, 0.1, 1.0], [-0.3, 0.4, 0.9], [0.5, 0.6, 0.7]),
    "large": ([1.0, 0.0, 0.05], [-0.5, 0.86, 0.05], [-0.5, -0.86, 0.3]),
    "octant": ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
    "obtuse": ([1.0, 0.0, 0.0], [-0.99, 0.1, 0.0], [0.0, 0.05, 1.0]),
    "sliver": ([1.0, 0.0, 0.5], [-1.0, 0.001, 0.5], [0.0, 0.0005, 1.0]),
    "needle": ([0.3, 0.0, 1.0], [0.3001, 0.0002, 1.0], [-0.2, 0.01, 1.0]),
    "below-horizon": ([0.3, 0.2, -1.0], [-0.4, 0.1, -1.0], [0.0, -0.5, -0.8]),
}


def _tri_setup(name):
    """Vertices, and the axis and cos θ range of the histogram: about the centroid for a
    well-shaped triangle; for a thin one about the pole of its longest edge's great
    circle, so that the thin direction is cos θ (resolved by narrow cells) rather than
    a curve around the pole."""
    a, b, c = (np.asarray(v, float) for v in TRIANGLES[name])
    units = [v / np.linalg.norm(v) for v in (a, b, c)]
    al, be, ga = O.spherical_triangle_angles(*units)
    if min(al, be, ga) > 0.05:
        ctr = sum(units)
        ctr /= np.linalg.norm(ctr)
        zlo = min(float(np.dot(v, ctr)) for v in units)
        return a, b, c, ctr, (max(zlo - 0.02 * (1.0 - zlo), -1.0), 1.0)
    edges = [(0, 1, 2), (1, 2, 0), (2, 0, 1)]
    i, j, k = max(edges, key=lambda e: np.arccos(np.clip(units[e[0]] @ units[e[1]], -1, 1)))
    axis = np.cross(units[i], units[j])
    axis /= np.linalg.norm(axis)
    r = float(units[k] @ axis)
    lo, hi = min(0.0, r), max(0.0, r)
    pad = 0.1 * (hi - lo)
    return a, b, c, axis, (lo - pad, hi + pad)


@pytest.mark.slow
@pytest.mark.statistical
@pytest.mark.parametrize("name", list(TRIANGLES))
def test_spherical_triangle_chi2(name, alpha):
    """Item 22: Arvo's sampler is uniform in solid angle, from tiny to near-degenerate triangles."""
    a, b, c, axis, zr = _tri_setup(name)
    params = np.concatenate([a, b, c])
    w, p, flag = sample(T.WARP_SPHERICAL_TRIANGLE, params, name=name)
    assert np.all(flag == T.FLAG_VALID)
    res = chi2_sphere(w, lambda d: O.spherical_triangle_pdf(a, b, c, d), alpha, "tri-" + name, axis=axis,
                      z_range=zr, n_z=24, n_phi=48)
    assert res.passed, res.message


@pytest.mark.parametrize("name", list(TRIANGLES))
def test_spherical_triangle_solid_angle(name):
    """Items 5, 22: Van Oosterom–Strackee against the unnormalised form, L'Huilier and Girard."""
    a, b, c, _, _ = _tri_setup(name)
    ref = O.spherical_triangle_area_vos(a, b, c)
    got = sphtri.spherical_triangle_solid_angle(*a, *b, *c)
    assert abs(got - ref) <= 1e-12 * max(ref, 1e-300) + 1e-15
    # against the two other classical formulas (L'Huilier, Girard), which lose digits on thin triangles
    assert abs(got - O.spherical_triangle_area_lhuilier(a, b, c)) < 1e-9 * max(1.0, got) + 1e-6 * got
    if got > 1e-3:
        assert abs(got - O.spherical_triangle_area_girard(a, b, c)) < 1e-9
    # the sampler's pdf is 1/Ω
    w, p, _ = sample(T.WARP_SPHERICAL_TRIANGLE, np.concatenate([a, b, c]), n=100, name=name)
    np.testing.assert_allclose(p, 1.0 / got, rtol=1e-12 + 10 * got)  # flat branch: 1/Ω to O(Ω)


@pytest.mark.statistical
@pytest.mark.parametrize("name", ["medium", "large", "octant"])
def test_spherical_triangle_solid_angle_against_monte_carlo(name, alpha):
    a, b, c, _, _ = _tri_setup(name)
    v, _, _ = sample(T.WARP_UNIFORM_SPHERE, [], n=400_000, name=name + "mc")
    hit = (batch.pdf(T.WARP_SPHERICAL_TRIANGLE, np.concatenate([a, b, c]), v) > 0) * 4 * np.pi
    res = ztest_samples(hit, sphtri.spherical_triangle_solid_angle(*a, *b, *c), alpha, name)
    assert res.passed, res.message


@pytest.mark.parametrize("name", [n for n in TRIANGLES if n not in ("sliver", "needle")])
def test_spherical_triangle_matches_arvo_oracle_and_inverts(name):
    """Item 22: the kernel follows Arvo's construction step by step (the oracle), and inverts it."""
    a, b, c, _, _ = _tri_setup(name)
    params = np.concatenate([a, b, c])
    u = rng_for(name).random((3000, 2))
    w, _, _ = batch.sample(T.WARP_SPHERICAL_TRIANGLE, params, u)
    if name != "tiny":  # the tiny triangle takes the flat-triangle branch instead
        ref, _ = O.sample_spherical_triangle(a, b, c, u)
        np.testing.assert_allclose(w, ref, atol=1e-8)
    pk, ui = batch.pdf_and_inverse(T.WARP_SPHERICAL_TRIANGLE, params, w)
    assert np.all(pk > 0)
    np.testing.assert_allclose(ui, u, atol=1e-6)
    w2, _, _ = batch.sample(T.WARP_SPHERICAL_TRIANGLE, params, ui)
    np.testing.assert_allclose(w2, w, atol=1e-9 * max(1e-4, sphtri.spherical_triangle_solid_angle(*params) ** 0.5))


def test_degenerate_spherical_triangles_are_invalid():
    u = rng_for("degenerate-tri").random((8, 2))
    for tri in ([1, 0, 0, 2, 0, 0, 0, 0, 1],  # two vertices in the same direction
                [1, 0, 0, 0, 1, 0, 1, 1, 0],  # all three on one great circle
                [0, 0, 0, 0, 1, 0, 0, 0, 1],  # a vertex at the shading point
                [1, 0, 1, 1, 0, 1, 1, 0, 1]):  # a point
        w, p, flag = batch.sample(T.WARP_SPHERICAL_TRIANGLE, tri, u)
        assert np.all(flag == T.FLAG_INVALID) and np.all(np.isfinite(w)) and np.all(p == 0)
        assert np.all(batch.pdf(T.WARP_SPHERICAL_TRIANGLE, tri, w) == 0)
        assert sphtri.spherical_triangle_solid_angle(*tri) == 0.0


# -- items 10 and 23: double-axis moments and off-normal lobes ---------------------------------

MOMENT_CASES = [(n, d) for n in (0, 1, 2, 3, 4, 7, 10, 25, 100)
                for d in (1.0, 0.999, 0.9, 0.5, 0.1, 1e-3, 0.0, -1e-3, -0.1, -0.3)]


def test_double_axis_moments_against_quadrature():
    """Item 10: the closed-form recurrences equal adaptive quadrature for many (n, m·N),
    including grazing axes on both sides of the horizon."""
    for n, d in MOMENT_CASES:
        g = lobes.digon_moment(n, d)
        f = lobes.digon_cos_moment(n, d)
        gq = O.digon_moment_quad(n, d)
        fq = O.digon_cos_moment_quad(n, d)
        full = 2 * math.pi / (n + 1)
        assert abs(g - gq) <= 1e-9 * full, (n, d, g, gq)
        assert abs(f - fq) <= 1e-9 * full, (n, d, f, fq)


@pytest.mark.slow
def test_double_axis_moments_against_brute_force_grid():
    for n, theta_m in ((0, 0.4), (1, 1.2), (3, HALF_PI), (10, HALF_PI + 0.2), (20, 1.0)):
        m = np.array([math.sin(theta_m), 0.0, math.cos(theta_m)])
        for cosw in (False, True):
            grid = O.digon_moment_grid(n, m, cos_weight=cosw, res=1500)
            val = (lobes.digon_cos_moment if cosw else lobes.digon_moment)(n, m[2])
            assert abs(val - grid) < 2e-4 * 2 * math.pi / (n + 1), (n, theta_m, cosw, val, grid)
    # arbitrary normal: only m·N matters
    m = np.array([0.3, -0.5, 0.2])
    nrm = np.array([0.1, 0.7, 0.4])
    m /= np.linalg.norm(m)
    nrm /= np.linalg.norm(nrm)
    grid = O.digon_moment_grid(5, m, nrm, cos_weight=True, res=1500)
    assert abs(lobes.digon_cos_moment(5, float(m @ nrm)) - grid) < 2e-4


def test_double_axis_moment_identities():
    for n in range(0, 30):
        assert abs(lobes.digon_moment(n, 1.0) - 2 * math.pi / (n + 1)) < 1e-12
        assert abs(lobes.digon_cos_moment(n, 1.0) - 2 * math.pi / (n + 2)) < 1e-12
        assert abs(lobes.digon_moment(n, -1.0)) < 1e-15 and abs(lobes.digon_cos_moment(n, -1.0)) < 1e-15
        for d in (0.2, 0.7):
            # the two halves of the lobe (above and below the horizon) add up to the full lobe
            assert abs(lobes.digon_moment(n, d) + lobes.digon_moment(n, -d) - 2 * math.pi / (n + 1)) < 1e-12
            assert abs(lobes.digon_cos_moment(n, d) - lobes.digon_cos_moment(n, -d) - 2 * math.pi * d / (n + 2)) \
                < 1e-12


LOBE_CASES = [(n, th) for n in (0, 1, 10, 100) for th in (0.0, 0.6, 1.3, HALF_PI - 0.02, HALF_PI + 0.15)]


@pytest.mark.slow
@pytest.mark.statistical
@pytest.mark.parametrize("n,theta_m", LOBE_CASES, ids=[f"n{n}-axis{t:.3f}" for n, t in LOBE_CASES])
def test_offnormal_lobe_chi2(n, theta_m, alpha):
    """Items 17, 23: the off-normal cosⁿ lobe by rejection, normalised by item 10b, incl. grazing axes."""
    m = np.array([math.sin(theta_m) * math.cos(0.7), math.sin(theta_m) * math.sin(0.7), math.cos(theta_m)])
    name = f"lobe-n{n}-{theta_m:.3f}"
    w, p, flag = sample(T.WARP_OFFNORMAL_COSN, np.concatenate([[n], m]), name=name)
    assert np.all(flag == T.FLAG_VALID) and np.all(w[:, 2] > 0)
    g = O.digon_moment_quad(n, m[2])
    # histogram about the lune's bisector, so that neither clipping circle passes near the
    # pole of the (cos θ, φ) cells; the range holds all but 1e-4 of the lobe's mass
    axis = m + np.array([0.0, 0.0, 1.0])
    axis /= np.linalg.norm(axis)
    spread = math.acos(1e-4 ** (1.0 / (n + 1)))
    zlo = math.cos(min(math.pi, math.acos(min(1.0, float(axis @ m))) + spread))
    res = chi2_sphere(w, lambda d: O.offnormal_cosn_pdf(n, m, d, g), alpha, name, axis=axis, z_range=(zlo, 1.0),
                      n_phi=128 if n >= 100 else 64)
    assert res.passed, res.message
    np.testing.assert_allclose(batch.pdf(T.WARP_OFFNORMAL_COSN, np.concatenate([[n], m]), w), p, rtol=1e-12)
    np.testing.assert_allclose(p, O.offnormal_cosn_pdf(n, m, w, g), rtol=1e-7)


@pytest.mark.slow
def test_offnormal_lobe_pdf_integrates_to_one():
    for n, th in ((1, 1.3), (10, HALF_PI + 0.1), (40, 0.5)):
        m = [n, math.sin(th), 0.0, math.cos(th)]

        def density(phi, z):
            s = np.sqrt(np.maximum(1 - z * z, 0))
            return batch.pdf(T.WARP_OFFNORMAL_COSN, m, np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1))

        total = integrate_cells(density, np.linspace(0, 2 * np.pi, 33), np.linspace(0, 1, 33), 1e12,
                                rel_tol=1e-3).sum()
        assert abs(total - 1) < 1e-3, (n, th, total)


def test_offnormal_lobe_rejection_is_a_function_of_u():
    params = [20.0, math.sin(HALF_PI + 0.1), 0.0, math.cos(HALF_PI + 0.1)]
    u = rng_for("lobe-det").random((1000, 3))
    a = batch.sample(T.WARP_OFFNORMAL_COSN, params, u)
    b = batch.sample(T.WARP_OFFNORMAL_COSN, params, u)
    np.testing.assert_array_equal(a[0], b[0])
    # an axis pointing straight down leaves an empty lune: no sample, no NaN
    w, p, flag = batch.sample(T.WARP_OFFNORMAL_COSN, [5.0, 0.0, 0.0, -1.0], u[:10])
    assert np.all(flag == T.FLAG_INVALID) and np.all(np.isfinite(w))


# -- items 11–16: piecewise-constant distributions ----------------------------------------------

def _func_1d():
    f = rng_for("f1d").random(37) ** 2
    f[[0, 5, 6, 7, 20, 36]] = 0.0
    return f


def _func_2d():
    f = rng_for("f2d").random((13, 21)) ** 3
    f[4, :] = 0.0
    f[:, 0] = 0.0
    f[7, 3:9] = 0.0
    return f


@pytest.mark.statistical
def test_distribution_1d_chi2(alpha):
    """Items 11–16: piecewise-constant 1D density by inverse cdf, with zero cells."""
    f = _func_1d()
    d = build_distribution_1d(f)
    x, p, flag = sample(T.WARP_DISTRIBUTION_1D, d, name="d1", cols=1)
    assert np.all(flag == T.FLAG_VALID)
    res = chi2_interval(x[:, 0], lambda t: O.piecewise_1d_pdf(f, t), alpha, "dist1d", bins=37 * 3)
    assert res.passed, res.message


@pytest.mark.statistical
def test_distribution_2d_chi2(alpha):
    """Items 11–16: marginal and conditional inverse cdfs of a 2D table with zero rows and columns."""
    f = _func_2d()
    d = build_distribution_2d(f)
    x, p, flag = sample(T.WARP_DISTRIBUTION_2D, d, name="d2", cols=2)
    assert np.all(flag == T.FLAG_VALID)
    res = chi2_plane(x[:, :2], lambda a, b: O.piecewise_2d_pdf(f, a, b), alpha, "dist2d", nx=42, ny=26)
    assert res.passed, res.message
    np.testing.assert_allclose(p, O.piecewise_2d_pdf(f, x[:, 0], x[:, 1]), rtol=1e-12)


def test_distribution_1d_exact_inversion_and_zero_cells():
    """Item 16: u = cdf_i maps exactly to i/n; zero cells are never sampled; round trips."""
    f = _func_1d()
    d = build_distribution_1d(f)
    func, cdf, integral = distribution_1d_parts(d)
    n = len(f)
    assert cdf[0] == 0.0 and cdf[-1] == 1.0 and np.all(np.diff(cdf) >= 0)
    assert integral == pytest.approx(f.mean())
    # at every cell boundary of a non-empty cell, u = cdf_i maps exactly to i/n
    nz = np.nonzero(f)[0]
    x, p, _ = batch.sample(T.WARP_DISTRIBUTION_1D, d, cdf[nz][:, None])
    assert np.all(x[:, 0] == nz / n)
    np.testing.assert_allclose(p, f[nz] / integral, rtol=1e-14)
    # zero cells are never sampled, even from the u values that border them
    probe = np.concatenate([cdf, np.nextafter(cdf, 2), np.nextafter(cdf, -1), np.linspace(0, 1, 100001)])
    probe = probe[(probe >= 0) & (probe <= 1)]
    x, p, flag = batch.sample(T.WARP_DISTRIBUTION_1D, d, probe[:, None])
    cell = np.minimum((x[:, 0] * n).astype(int), n - 1)
    assert np.all(f[cell] > 0) and np.all(p > 0) and np.all(x[:, 0] < 1.0)
    # matches the searchsorted oracle
    xo, po = O.sample_piecewise_1d(f, probe[probe < 1])
    np.testing.assert_allclose(x[probe < 1, 0], xo, atol=1e-12)
    # inverse round trips
    _, ui = batch.pdf_and_inverse(T.WARP_DISTRIBUTION_1D, d, x[:, :1])
    x2, _, _ = batch.sample(T.WARP_DISTRIBUTION_1D, d, ui[:, :1])
    np.testing.assert_allclose(x2[:, 0], x[:, 0], atol=1e-12)


def test_guided_distribution_matches_the_binary_search():
    """The guide table (cutpoint method) finds the same cell as the binary search: same x,
    pdf and cell for every u, at and next to every cell boundary, zero cells included
    (they are never sampled), for the camera's filter tables too."""
    from spectral_gi.core import constants as C
    from spectral_gi.core.camera.kernel import filter_table
    from spectral_gi.core.sampling.distrib import build_guided_1d, sample_1d_block, sample_1d_guided

    rng = np.random.default_rng(11)
    skewed = np.where(rng.random(300) < 0.3, 0.0, rng.random(300) ** 6)  # zero runs, spikes
    tables = [build_guided_1d(_func_1d()), build_guided_1d(skewed), build_guided_1d(np.zeros(7)),
              filter_table(C.FILTER_BLACKMAN_HARRIS, 1.5), filter_table(C.FILTER_BOX, 1.0)]
    for g in tables:
        n = int(g[0])
        block = g[:3 + 2 * n]
        _, cdf, _ = distribution_1d_parts(block)
        probe = np.concatenate([cdf, np.nextafter(cdf, 2), np.nextafter(cdf, -1), rng.random(4000),
                                np.arange(n + 1) / n, [-0.5, 1.5]])
        for u in probe:
            got = sample_1d_guided(g, u)
            want = sample_1d_block(block, 0, u)
            assert got == want, (n, u, got, want)
        func = block[2:2 + n]
        if func.sum() > 0:
            assert all(func[sample_1d_guided(g, u)[2]] > 0 for u in probe)


def test_distribution_2d_inverse_and_layout():
    f = _func_2d()
    d = build_distribution_2d(f)
    func, ccdf, mf, mc, integral = distribution_2d_parts(d)
    np.testing.assert_array_equal(func, f)
    np.testing.assert_allclose(mf, f.mean(axis=1))
    assert integral == pytest.approx(f.mean()) and mc[-1] == 1.0 and np.all(ccdf[:, -1] == 1.0)
    u = rng_for("d2inv").random((20000, 2))
    x, p, _ = batch.sample(T.WARP_DISTRIBUTION_2D, d, u)
    pk, ui = batch.pdf_and_inverse(T.WARP_DISTRIBUTION_2D, d, x[:, :2])
    np.testing.assert_allclose(pk, p, rtol=1e-14)
    np.testing.assert_allclose(ui, u, atol=1e-9)
    cells = f[np.minimum((x[:, 1] * 13).astype(int), 12), np.minimum((x[:, 0] * 21).astype(int), 20)]
    assert np.all(cells > 0)


def test_distribution_all_zero_function_is_uniform():
    for d, tag, cols in ((build_distribution_1d(np.zeros(5)), T.WARP_DISTRIBUTION_1D, 1),
                         (build_distribution_2d(np.zeros((3, 4))), T.WARP_DISTRIBUTION_2D, 2)):
        u = rng_for("zero").random((1000, cols))
        x, p, flag = batch.sample(tag, d, u)
        assert np.all(flag == T.FLAG_VALID) and np.all(p == 1.0) and np.all(np.isfinite(x))
        np.testing.assert_allclose(x[:, :cols], u, atol=1e-12)
    assert build_distribution_1d(np.zeros(5))[1] == 0.0


def test_distribution_builder_rejects_bad_input():
    for bad in ([], [1, -1], [np.nan, 1], [np.inf]):
        with pytest.raises(ValueError):
            build_distribution_1d(bad)
    with pytest.raises(ValueError):
        build_distribution_2d([1, 2, 3])


# -- disk and triangle area samplers -----------------------------------------------------------

@pytest.mark.slow
@pytest.mark.statistical
@pytest.mark.parametrize("tag", [T.WARP_DISK_CONCENTRIC, T.WARP_DISK_POLAR], ids=["concentric", "polar"])
def test_disk_chi2_and_inverse(tag, alpha):
    x, p, flag = sample(tag, [], name=f"disk{tag}", cols=2)
    assert np.all(flag == T.FLAG_VALID) and np.all(p == 1 / np.pi)
    res = chi2_plane(x[:, :2], lambda a, b: O.disk_pdf(np.stack([a, b], -1)), alpha, f"disk{tag}",
                     nx=30, ny=30, x_range=(-1, 1), y_range=(-1, 1))
    assert res.passed, res.message
    u = rng_for(f"diskinv{tag}").random((20000, 2))
    x, _, _ = batch.sample(tag, [], u)
    _, ui = batch.pdf_and_inverse(tag, [], x[:, :2])
    np.testing.assert_allclose(ui, u, atol=1e-9)
    ref = O.sample_disk_concentric(u[:2000]) if tag == T.WARP_DISK_CONCENTRIC else O.sample_disk_polar(u[:2000])
    np.testing.assert_allclose(x[:2000, :2], ref, atol=1e-12)


@pytest.mark.statistical
def test_triangle_area_chi2_and_inverse(alpha):
    b, p, flag = sample(T.WARP_TRIANGLE_AREA, [], name="trianglearea", cols=2)
    assert np.all(flag == T.FLAG_VALID) and np.allclose(b.sum(axis=1), 1.0) and np.all(b >= 0)

    def pdf(x, y):
        return np.where((x >= 0) & (y >= 0) & (x + y <= 1), 2.0, 0.0)

    res = chi2_plane(b[:, 1:], pdf, alpha, "triangle-area", nx=24, ny=24)
    assert res.passed, res.message
    u = rng_for("triinv").random((10000, 2))
    b, _, _ = batch.sample(T.WARP_TRIANGLE_AREA, [], u)
    np.testing.assert_allclose(b, O.sample_triangle_area(u), atol=1e-14)
    pk, ui = batch.pdf_and_inverse(T.WARP_TRIANGLE_AREA, [], b)
    assert np.all(pk == 2.0)
    np.testing.assert_allclose(ui, u, atol=1e-9)


# -- items 5–8: coordinates, frames, measures ----------------------------------------------------

def test_angles_round_trip_and_frames():
    """Item 6: direction ↔ (θ, φ) round trips; orthonormal shading frames."""
    rng = rng_for("frames")
    for _ in range(200):
        th, ph = rng.uniform(0, math.pi), rng.uniform(0, 2 * math.pi)
        x, y, z = frame.direction_from_angles(th, ph)
        t2, p2 = frame.angles_from_direction(x, y, z)
        assert abs(t2 - th) < 1e-12 and abs((p2 - ph + math.pi) % (2 * math.pi) - math.pi) < 1e-12
        assert 0.0 <= p2 < 2 * math.pi
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        f = np.array(frame.frame_from_z(*n)).reshape(2, 3)
        m = np.stack([f[0], f[1], n])
        np.testing.assert_allclose(m @ m.T, np.eye(3), atol=1e-12)
        np.testing.assert_allclose(np.cross(f[0], f[1]), n, atol=1e-12)
        v = rng.normal(size=3)
        loc = frame.to_local(*f[0], *f[1], *n, *v)
        np.testing.assert_allclose(frame.to_world(*f[0], *f[1], *n, *loc), v, atol=1e-12)
    # poles and the -z special case of the frame
    np.testing.assert_allclose(np.cross(*np.array(frame.frame_from_z(0.0, 0.0, -1.0)).reshape(2, 3)), [0, 0, -1])
    assert frame.spherical_phi(-1.0, -1e-300) < 2 * math.pi
    # item 18 as a point on a sphere (c, R): |p - c| = R, pdf 1/(4π R²) per unit area
    x, y, z, pa = warps.sample_sphere_point(1.0, -2.0, 0.5, 3.0, 0.3, 0.7)
    assert math.isclose(math.dist((x, y, z), (1.0, -2.0, 0.5)), 3.0) and math.isclose(pa, 1 / (36 * math.pi))


@pytest.mark.statistical
def test_area_to_solid_angle_pdf_integrates_to_one(alpha):
    """Items 5, 7, 8: a rectangle sampled by area, its pdf turned into solid angle
    (p_ω = p_A r²/cos θ_y), integrates to 1 over the directions that see it."""
    c = np.array([0.3, -0.2, 2.0])
    ex, ey = np.array([0.8, 0.0, 0.3]), np.array([0.0, 0.5, 0.0])
    nrm = np.cross(ex, ey)
    area = np.linalg.norm(nrm)
    nrm /= area
    v, _, _ = sample(T.WARP_UNIFORM_SPHERE, [], n=400_000, name="dA-dw")
    den = v @ nrm
    t = np.where(np.abs(den) > 1e-12, (c @ nrm) / np.where(den == 0, 1, den), -1)
    pts = v * t[:, None]
    rel = pts - c
    a = rel @ ex / (ex @ ex)
    b = rel @ ey / (ey @ ey)
    ok = (t > 0) & (np.abs(a) <= 0.5) & (np.abs(b) <= 0.5)
    pw = np.zeros(len(v))
    pw[ok] = [frame.pdf_area_to_solid_angle(1.0 / area, tt * tt, dd) for tt, dd in zip(t[ok], den[ok])]
    res = ztest_samples(pw * 4 * np.pi, 1.0, alpha, "dA-dw")
    assert res.passed, res.message
    # the conversion and its inverse
    assert frame.pdf_solid_angle_to_area(frame.pdf_area_to_solid_angle(0.25, 9.0, 0.5), 9.0, 0.5) == \
        pytest.approx(0.25)
    assert frame.pdf_area_to_solid_angle(1.0, 4.0, 0.0) == 0.0
    assert frame.solid_angle_of_small_area(1e-4, 4.0, 1.0) == pytest.approx(2.5e-5)


# -- items 1, 27, 28: MIS ----------------------------------------------------------------------

BETAS = [0.0, 1.0, 2.0, 3.5, np.inf]


def test_mis_weights_sum_to_one():
    """Items 27–28: power heuristic for any β (0, 1, 2, 3.5, ∞) sums to 1; NumPy and kernel versions agree."""
    rng = rng_for("mis")
    pdfs = rng.random((3, 500)) * 10
    pdfs[1, :50] = 0.0
    pdfs[:, 60] = 0.0
    counts = np.array([1.0, 4.0, 2.0])
    for beta in BETAS:
        w = mis.mis_weights(pdfs, counts, beta)
        s = w.sum(axis=0)
        np.testing.assert_allclose(s[np.any(pdfs > 0, axis=0)], 1.0, rtol=1e-12)
        assert np.all(s[~np.any(pdfs > 0, axis=0)] == 0)
        if np.isfinite(beta) and beta > 0:
            np.testing.assert_allclose(w, O.power_heuristic_weights(pdfs, counts, beta), rtol=1e-10, atol=1e-300)
        # the scalar kernel versions agree
        for col in (0, 1, 55, 60, 100):
            ws = [mis.mis_weight_k(j, counts, pdfs[:, col], 3, beta) for j in range(3)]
            np.testing.assert_allclose(ws, w[:, col], rtol=1e-12, atol=1e-300)
    for beta in BETAS:
        for pa, pb in ((0.3, 0.7), (1e-300, 1e300), (5.0, 0.0)):
            wa = mis.mis_weight(1.0, pa, 2.0, pb, beta)
            wb = mis.mis_weight(2.0, pb, 1.0, pa, beta)
            assert abs(wa + wb - 1.0) < 1e-12 and 0 <= wa <= 1
    assert mis.balance_heuristic(1.0, 0.2, 1.0, 0.6) == pytest.approx(0.25)
    assert mis.power_heuristic(1.0, 0.2, 1.0, 0.6) == pytest.approx(0.1)


def test_mis_weight_of_a_delta_event_is_one():
    """Item 1: a Dirac sample (pdf inf) gets weight 1, and the other technique 0."""
    for beta in BETAS:
        assert mis.mis_weight(1.0, np.inf, 1.0, 3.0, beta) == 1.0
        assert mis.mis_weight(1.0, 3.0, 1.0, np.inf, beta) == 0.0
        assert mis.mis_weight(1.0, np.inf, 1.0, 0.0, beta) == 1.0
        assert mis.mis_weight_k(0, np.ones(2), np.array([np.inf, 3.0]), 2, beta) == 1.0
        w = mis.mis_weights(np.array([[np.inf, 1.0], [2.0, 1.0]]), beta=beta)
        np.testing.assert_allclose(w[:, 0], [1.0, 0.0])
    # a delta technique's density at another technique's direction is 0 (warps.py)
    assert batch.pdf(T.WARP_UNIFORM_CONE, [0.0], np.array([[0.0, 0.0, 1.0]]))[0] == 0.0


@pytest.mark.statistical
def test_mis_estimators_are_unbiased(alpha):
    """Items 27–28: multi-sample and one-sample MIS of cosine and uniform hemisphere
    sampling estimate ∫ f dω for f = cos³θ (1 + sin φ cos θ) (exact: π/2), and the
    balance-heuristic combination has no more variance than the worse technique."""
    def f(w):
        return w[:, 2] ** 3 * (1 + w[:, 1])

    exact = 2 * math.pi / 4
    n = 100_000
    wa, pa, _ = sample(T.WARP_COSINE_HEMISPHERE, [], n=n, name="misa")
    wb, pb, _ = sample(T.WARP_UNIFORM_HEMISPHERE, [], n=n, name="misb")
    tabs = [np.stack([pa, batch.pdf(T.WARP_UNIFORM_HEMISPHERE, [], wa)]),
            np.stack([batch.pdf(T.WARP_COSINE_HEMISPHERE, [], wb), pb])]
    # per-sample contributions of the multi-sample estimator (one sample of each per pair)
    contrib = (mis.mis_weights(tabs[0], [1, 1], 2.0)[0] * f(wa) / pa +
               mis.mis_weights(tabs[1], [1, 1], 2.0)[1] * f(wb) / pb)
    res = ztest_samples(contrib, exact, alpha, "multi-sample")
    assert res.passed, res.message
    assert mis.combine_multi_sample([f(wa), f(wb)], tabs, [n, n]) == pytest.approx(contrib.mean())
    # one-sample model: pick a technique with probability c_j
    rng = rng_for("one-sample")
    chosen = (rng.random(n) < 0.3).astype(int)
    w = np.where(chosen[:, None] == 0, wa, wb)
    pd = np.stack([batch.pdf(T.WARP_COSINE_HEMISPHERE, [], w), batch.pdf(T.WARP_UNIFORM_HEMISPHERE, [], w)])
    est = mis.combine_one_sample(f(w), pd, chosen, [0.7, 0.3], beta=1.0)
    res = ztest_samples(est, exact, alpha, "one-sample")
    assert res.passed, res.message
    assert contrib.var() / 2 <= max((f(wa) / pa).var(), (f(wb) / pb).var())


# -- items 11–15, 29: statistics -----------------------------------------------------------------

def test_estimator_statistics():
    """Items 11–15, 29: mean, variance, standard error and efficiency 1/(T σ²)."""
    y = rng_for("stats").normal(3.0, 2.0, size=10_000)
    s = stats.estimator_stats(y, seconds=0.5)
    assert s.n == 10_000 and s.mean == pytest.approx(y.mean())
    assert s.variance == pytest.approx(y.var(ddof=1)) and s.std_error == pytest.approx(y.std(ddof=1) / 100)
    assert s.time_per_sample == pytest.approx(5e-5)
    assert s.efficiency == pytest.approx(1.0 / (5e-5 * y.var(ddof=1)))
    m, v = stats.running_mean_variance(y + 1e9)
    assert m == pytest.approx(y.mean() + 1e9) and v == pytest.approx(y.var(ddof=1), rel=1e-6)
    assert math.isnan(stats.estimator_stats([1.0]).variance)
    assert stats.efficiency(0.0, 1.0) == math.inf
    with pytest.raises(ValueError):
        stats.estimator_stats([])


# -- negative controls: the harness rejects wrong samplers ---------------------------------------

@pytest.mark.slow
def test_harness_rejects_a_wrong_sampler():
    """The chi-square harness has power: slightly wrong densities fail."""
    w, _, _ = sample(T.WARP_COSN, [10], name="neg")
    assert not chi2_sphere(w, lambda d: O.cosn_pdf(11, d), 0.01, "neg-cos11", z_range=(0.2, 1),
                           dump=False).passed
    w, _, _ = sample(T.WARP_UNIFORM_CONE, [0.3], name="neg2")
    assert not chi2_sphere(w, lambda d: O.uniform_cone_pdf(0.31, d), 0.01, "neg-cone", z_range=(0.9, 1),
                           dump=False).passed
    # the area-uniform (not solid-angle-uniform) distribution of a big triangle must fail
    a, b, c, axis, zr = _tri_setup("large")
    bary, _, _ = sample(T.WARP_TRIANGLE_AREA, [], name="neg4", cols=2)
    pts = bary[:, :1] * a + bary[:, 1:2] * b + bary[:, 2:3] * c
    pts /= np.linalg.norm(pts, axis=1, keepdims=True)
    assert not chi2_sphere(pts, lambda d: O.spherical_triangle_pdf(a, b, c, d), 0.01, "neg-area", axis=axis,
                           z_range=zr, dump=False).passed
    assert not ztest(1.0, 0.01, 1.1, 0.01).passed


def test_visible_wavelength_sampling_inverts_its_cdf_and_reports_its_density():
    """The path kernel's wavelength draw: λ(u) inverts the cdf of the mixture (1 − m) sech² + m
    (x̄ + ȳ + z̄) (integrated here from its definition, independently of the table), the density
    it returns is that of λ (visible_pdf) and integrates to 1 over the visible range, and it is
    the mixture's within the table's resolution."""
    from spectral_gi.core import constants as C
    from spectral_gi.core.integrators import path as P
    from spectral_gi.core.io import presets

    u = np.linspace(0.0, 1.0, 2001)[:-1] + 1.0 / 4002
    lam, pdf = np.array([P.sample_visible(v) for v in u]).T
    assert np.all(np.diff(lam) > 0) and lam[0] > C.LAMBDA_MIN and lam[-1] < C.LAMBDA_MAX
    grid = np.linspace(C.LAMBDA_MIN, C.LAMBDA_MAX, 47001)
    wl, xyz = presets.cmfs("1931")
    cie = sum(np.interp(grid, wl, xyz[:, k], left=0.0, right=0.0) for k in range(3))
    sech = 1.0 / np.cosh(P.VIS_B * (grid - P.VIS_C)) ** 2
    mix = (1 - P.VIS_MIX) * sech / np.trapz(sech, grid) + P.VIS_MIX * cie / np.trapz(cie, grid)
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (mix[1:] + mix[:-1]) * np.diff(grid))])
    np.testing.assert_allclose(np.interp(lam, grid, cdf / cdf[-1]), u, atol=2e-4)
    np.testing.assert_allclose(pdf, [P.visible_pdf(x) for x in lam], rtol=1e-10)
    np.testing.assert_allclose(pdf, np.interp(lam, grid, mix / cdf[-1]), rtol=0.03)
    dens = np.array([P.visible_pdf(x) for x in grid])
    assert np.trapz(dens, grid) == pytest.approx(1.0, rel=1e-4)
