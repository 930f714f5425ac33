"""Participating media (compendium item 54): Henyey–Greenstein phase function, free-flight
sampling with spectral MIS, transmittance e^(−σ s) through slabs and along shadow rays,
energy conservation of an albedo-1 medium in a furnace, and the scene contract."""
import math

import numpy as np
import pytest
from chi2 import chi2_interval, chi2_sphere, seed_for, ztest, ztest_samples
from helpers import box_mesh, flat_emission, flat_reflectance, furnace_scene, look_at

from spectral_gi.core import constants as C
from spectral_gi.core.integrators import render as R
from spectral_gi.core import scene as S
from spectral_gi.core.film import Film, develop
from spectral_gi.core.media import kernel as M
from spectral_gi.core.scene import (
    Camera, Material, Medium, Mesh, RenderSettings, Scene, SceneError, SpectrumTable)
from spectral_gi.core.scene.builtin import cornell_box
from spectral_gi.core.spectra import uplift

NW = C.N_WAVELENGTHS
GRID = np.linspace(C.LAMBDA_MIN, C.LAMBDA_MAX, C.N_LAMBDA)


# --------------------------------------------------------------------------- helpers

def hg_numpy(g, c):
    """Henyey–Greenstein in NumPy (the oracle), c = cos between travel directions."""
    return (1 - g * g) / (4 * np.pi * (1 + g * g - 2 * g * c) ** 1.5)


def icosphere(name, centre, radius, material, subdiv=2):
    """A closed sphere mesh with outward-facing triangles."""
    p = (1 + 5 ** 0.5) / 2
    v = [(-1, p, 0), (1, p, 0), (-1, -p, 0), (1, -p, 0), (0, -1, p), (0, 1, p), (0, -1, -p), (0, 1, -p),
         (p, 0, -1), (p, 0, 1), (-p, 0, -1), (-p, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
         (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
         (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    verts = [np.array(x, float) / np.linalg.norm(x) for x in v]
    for _ in range(subdiv):
        cache = {}
        nf = []

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                m = verts[a] + verts[b]
                verts.append(m / np.linalg.norm(m))
                cache[key] = len(verts) - 1
            return cache[key]
        for a, b, c in f:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = nf
    pos = np.asarray(centre, float) + radius * np.array(verts)
    idx = np.array(f, np.int32)
    # make every face point outwards
    n = np.cross(pos[idx[:, 1]] - pos[idx[:, 0]], pos[idx[:, 2]] - pos[idx[:, 0]])
    flip = np.einsum("ij,ij->i", n, pos[idx].mean(1) - centre) < 0
    idx[flip] = idx[flip][:, ::-1]
    return Mesh(name, pos.astype(np.float32), idx, np.full(len(idx), material, np.int32))


def quad(name, centre, half, normal_z, material):
    """A square in the plane z = centre[2], facing +z (normal_z > 0) or -z."""
    cx, cy, cz = centre
    p = np.array([[cx - half, cy - half, cz], [cx + half, cy - half, cz], [cx + half, cy + half, cz],
                  [cx - half, cy + half, cz]], np.float32)
    idx = np.array([[0, 1, 2], [0, 2, 3]] if normal_z > 0 else [[0, 2, 1], [0, 3, 2]], np.int32)
    return Mesh(name, p, idx, np.full(2, material, np.int32))


def ramp_reflectance(a, b):
    return uplift.reflectance_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX], [a, b], C.N_COEFFS_DEFAULT)


def mw_for(sa, ss, r=None):
    mw = np.zeros((M.MW_ROWS, NW))
    mw[M.MW_SA] = sa
    mw[M.MW_SS] = ss
    mw[M.MW_R] = 1.0 if r is None else r
    return mw


# --------------------------------------------------------------------------- phase function

@pytest.mark.parametrize("g", [0.0, 0.0005, 0.3, -0.6, 0.9])
def test_hg_normalised_and_matches_oracle(g):
    """∫ p dω = 2π ∫ p(c) dc = 1, and the kernel's values equal the closed form."""
    c = np.linspace(-1, 1, 20001)
    vals = np.array([M.hg_eval(g, x) for x in c[::50]])
    g_eff = 0.0 if abs(g) < M.G_ISOTROPIC else g
    np.testing.assert_allclose(vals, hg_numpy(g_eff, c[::50]), rtol=1e-12)
    # Simpson's rule on a fine grid (the peak of g = 0.9 is 1/(4π)·1.9/0.001 wide enough at this step)
    from scipy.integrate import simpson
    assert 2 * np.pi * simpson(hg_numpy(g_eff, c), x=c) == pytest.approx(1.0, abs=1e-6)
    # the mean cosine of HG is g
    assert 2 * np.pi * simpson(c * hg_numpy(g_eff, c), x=c) == pytest.approx(g_eff, abs=1e-6)


@pytest.mark.statistical
@pytest.mark.parametrize("g", [0.0, 0.5, -0.8, 0.95])
def test_hg_sampling_chi2(g, alpha):
    """HG samples around a skew travel direction against the HG pdf; the returned pdf is the phase value."""
    rng = np.random.default_rng(seed_for(f"hg{g}"))
    d = np.array([0.3, -0.5, 0.81])
    d /= np.linalg.norm(d)
    n = 60000
    u = rng.random((n, 2))
    out = np.array([M.hg_sample(g, d[0], d[1], d[2], a, b) for a, b in u])
    w, pdf = out[:, :3], out[:, 3]
    np.testing.assert_allclose(np.linalg.norm(w, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(pdf, hg_numpy(g, w @ d), rtol=1e-9)
    res = chi2_sphere(w, lambda x: hg_numpy(g, x @ d), alpha, f"hg{g}", axis=d, n_z=40, n_phi=16)
    assert res.passed, res.message


# --------------------------------------------------------------------------- distance sampling

@pytest.mark.statistical
def test_free_flight_samples_hero_extinction(alpha):
    sa = np.array([0.5, 0.1, 2.0, 0.0])
    ss = np.array([1.0, 0.4, 0.5, 0.3])
    mw = mw_for(sa, ss)
    st0 = sa[0] + ss[0]
    rng = np.random.default_rng(seed_for("ff"))
    s = np.array([M.free_flight(0, mw, u) for u in rng.random(40000)])
    hi = 3.0
    # samples beyond `hi` are one more cell: test the truncated density plus that cell's count
    inside = s[s < hi]
    res = chi2_interval(inside / hi, lambda x: st0 * hi * np.exp(-st0 * x * hi) / (1 - np.exp(-st0 * hi)),
                        alpha, "ff", bins=48)
    assert res.passed, res.message
    z = ztest(np.mean(s >= hi), math.sqrt(np.exp(-st0 * hi) * (1 - np.exp(-st0 * hi)) / len(s)),
              np.exp(-st0 * hi), alpha, "ff-tail")
    assert z.passed, z.message
    # no scattering at any of the path's wavelengths: never sampled (analytic transmittance)
    assert M.free_flight(0, mw_for(sa, np.zeros(NW)), 0.5) == np.inf
    assert M.free_flight(-1, mw, 0.5) == np.inf


def test_segment_weights_against_numpy_oracle():
    """β_i ← β_i f_i Σr / Σ r_j p_j and r_j ← r_j p_j / p_0, for scattering and passing events."""
    rng = np.random.default_rng(seed_for("seg"))
    for trial in range(20):
        sa = rng.random(NW) * 2
        ss = rng.random(NW) * 3
        r = np.concatenate([[1.0], rng.random(NW - 1) * 3])
        d = rng.random() * 2
        st = sa + ss
        tr = np.exp(-st * d)
        for scatter in (True, False):
            p = st * tr if scatter else tr
            f = tr * ss if scatter else tr
            beta = rng.random(NW) + 0.5
            mw = mw_for(sa, ss, r)
            b = beta.copy()
            M.segment(0, mw, b, d, scatter)
            np.testing.assert_allclose(b, beta * f * r.sum() / (r * p).sum(), rtol=1e-12)
            np.testing.assert_allclose(mw[M.MW_R], r * p / p[0], rtol=1e-12)
            # arrival factor at distance d (light inside the medium): τ_i Σr / Σ r_j τ_j
            mw = mw_for(sa, ss, r)
            M.arrival(0, mw, d)
            np.testing.assert_allclose(mw[M.MW_TR], tr * r.sum() / (r * tr).sum(), rtol=1e-12)
    # absorption only: deterministic transmittance, ratios untouched
    mw = mw_for(np.array([0.5, 1.0, 2.0, 0.0]), np.zeros(NW))
    b = np.ones(NW)
    M.segment(0, mw, b, 0.7, False)
    np.testing.assert_allclose(b, np.exp(-np.array([0.5, 1.0, 2.0, 0.0]) * 0.7), rtol=1e-14)
    assert np.all(mw[M.MW_R] == 1.0)


@pytest.mark.statistical
def test_spectral_mis_free_flight_is_unbiased_per_wavelength(alpha):
    """Over a random hero (the kernel's rotation of the wavelength set), the MIS-weighted
    collision estimator of ∫_0^L τ_i(s) σs_i h(s) ds + τ_i(L) h(L) is unbiased for every
    wavelength, over two successive segments (whole-path pdf ratios, not per-event
    averages), and also when the hero cannot scatter at all (hero-only weights would miss
    the other wavelengths' collisions then)."""
    sa = np.array([0.2, 1.5, 0.0, 0.0])
    ss = np.array([1.0, 0.2, 2.5, 0.0])  # the last wavelength sees no medium: as hero it never scatters
    st = sa + ss
    L = 0.8
    rng = np.random.default_rng(seed_for("mis"))
    n = 30000
    h = lambda s: 1.0 + s  # noqa: E731  (a smooth test integrand)
    est = np.zeros((n, NW))
    for k in range(n):
        hero = rng.integers(NW)
        perm = np.roll(np.arange(NW), -hero)  # slot 0 is the hero
        mw = mw_for(sa[perm], ss[perm])
        beta = np.ones(NW)
        total = np.zeros(NW)
        for seg in range(2):  # two segments of length L in a row, scoring at the end of each
            s = M.free_flight(0, mw, rng.random())
            if s < L:
                M.segment(0, mw, beta, s, True)
                total += beta * h(s)
                break
            M.segment(0, mw, beta, L, False)
            total += beta * h(L) * (seg + 1)
        est[k, perm] = total
    # exact: first segment's collisions + pass × (h(L) + second segment's collisions + 2 h(L) pass)
    s = np.linspace(0, L, 4001)
    from scipy.integrate import simpson
    coll = np.array([simpson(np.exp(-st[i] * s) * ss[i] * h(s), x=s) for i in range(NW)])
    tr = np.exp(-st * L)
    exact = coll + tr * (h(L) + coll + tr * 2 * h(L))
    for i in range(NW):
        res = ztest_samples(est[:, i], exact[i], alpha, f"mis{i}")
        assert res.passed, res.message


# --------------------------------------------------------------------------- shadow rays

def _shadow_setup(materials, media, meshes):
    spectra = SpectrumTable.empty()
    sc = Scene(meshes=meshes, spectra=spectra, materials=materials, media=media,
               camera=Camera(look_at((0, 0, 10), (0, 0, 0)), width=2, height=2))
    return R.prepare(sc)


def _shadow(prep, o, w, dist, medium=-1):
    lam = np.array([400.0, 500.0, 600.0, 700.0])
    mw = np.zeros((M.MW_ROWS, NW))
    from spectral_gi.core.geometry.bvh import STACK_SIZE
    stack = np.empty(STACK_SIZE, np.int32)
    ok = M.shadow((float(o[0]), float(o[1]), float(o[2])), (float(w[0]), float(w[1]), float(w[2])), dist, medium, -1,
                  lam, mw, prep.geometry, prep.materials.model, prep.media, 1e-6, stack)
    return ok, mw[M.MW_TR].copy()


def test_shadow_ray_transmittance_through_two_null_boundaries():
    """Two null-bounded boxes with different grey media along a shadow ray: τ = e^(−σ1 l1 − σ2 l2);
    a Lambert or dielectric surface on the way blocks it."""
    mats = [Material("fog1", model=C.MAT_NULL, interior=0), Material("fog2", model=C.MAT_NULL, interior=1),
            Material("wall"), Material("glass", model=C.MAT_DIELECTRIC)]
    media = [Medium("a", absorption_density=0.8, scattering_density=0.4),
             Medium("b", absorption_density=2.0)]
    meshes = [box_mesh("b1", (-1, -1, 1), (1, 1, 1.5), 0), box_mesh("b2", (-1, -1, 2), (1, 1, 2.25), 1)]
    prep = _shadow_setup(mats, media, meshes)
    ok, tr = _shadow(prep, (0.1, 0.2, 0.0), (0, 0, 1), 3.0)
    assert ok
    np.testing.assert_allclose(tr, np.exp(-1.2 * 0.5 - 2.0 * 0.25), rtol=1e-5)
    # the same from inside the first box, going down and out
    ok, tr = _shadow(prep, (0.1, 0.2, 1.2), (0, 0, -1), 1.2, medium=0)
    assert ok
    np.testing.assert_allclose(tr, np.exp(-1.2 * 0.2), rtol=1e-5)
    # a slanted ray: lengths grow by 1/cos
    w = np.array([0.3, 0.0, 1.0]) / math.hypot(0.3, 1.0)
    ok, tr = _shadow(prep, (0.0, 0.0, 0.0), w, 3.0 / w[2])
    np.testing.assert_allclose(tr, np.exp(-(1.2 * 0.5 + 2.0 * 0.25) / w[2]), rtol=1e-5)
    for blocker in (2, 3):
        prep = _shadow_setup(mats, media, meshes + [quad("q", (0, 0, 1.8), 2.0, 1, blocker)])
        ok, tr = _shadow(prep, (0.1, 0.2, 0.0), (0, 0, 1), 3.0)
        assert not ok and np.all(tr == 0.0)


# --------------------------------------------------------------------------- renders

def slab_scene(absorption=-1, density=0.7, thickness=1.0, spectra=None, spp=64, res=4, luminance=100.0):
    """Camera → null-bounded absorbing slab of ``thickness`` → emitting square (flat spectrum)."""
    spectra = spectra or SpectrumTable.empty()
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    mats = [Material("emitter", reflectance=-1, emission=e, emission_luminance=luminance),
            Material("slab", model=C.MAT_NULL, interior=0)]
    media = [Medium("ink", absorption=absorption, absorption_density=density)]
    meshes = [quad("emitter", (0, 0, 0), 3.0, 1, 0), box_mesh("slab", (-2, -2, 1), (2, 2, 1 + thickness), 1)]
    cam = Camera(look_at((0, 0, 6), (0, 0, 0), up=(0, 1, 0)), width=res, height=res, lens_mm=3000.0)
    return Scene(meshes=meshes, spectra=spectra, materials=mats, media=media, camera=cam,
                 settings=RenderSettings(spp=spp, max_depth=4, seed=5))


@pytest.mark.statistical
def test_grey_absorbing_slab_transmits_exp_minus_sigma_s(alpha):
    sc = slab_scene(density=0.7, thickness=1.0)
    film, _ = R.render(sc)
    d = develop(film.sums)
    free = sc
    free.media = []
    free.materials[1].interior = -1
    d0 = develop(R.render(free)[0].sums)
    # the same wavelengths on both films: the ratio is the transmittance up to rounding
    # (off-axis pixels cross the slab over 1/cos θ ≤ 1 + 2e-5 of its thickness)
    np.testing.assert_allclose(d.luminance / d0.luminance, math.exp(-0.7), rtol=3e-5)
    res = ztest(d.luminance.mean(), math.sqrt(d.variance.mean() / d.luminance.size), 100.0 * math.exp(-0.7),
                alpha, "grey-slab")
    assert res.passed, res.message


@pytest.mark.statistical
def test_chromatic_absorbing_slab_per_wavelength(alpha):
    """σa(λ) = 2.5 · A(λ) with A a ramp 0.05 → 0.9: every spectral bin equals
    mean_bin L(λ) e^(−σa(λ) s) (z-test across pixels), and so does the luminance."""
    spectra = SpectrumTable.empty()
    a = spectra.add("ramp", ramp_reflectance(0.05, 0.9), C.SPECTRUM_BOUNDED)
    sc = slab_scene(absorption=a, density=2.5, thickness=0.6, spectra=spectra, spp=300, res=6)
    prep = R.prepare(sc)
    bins = 8
    film = Film(6, 6, bins)
    R.run_pass(prep, film, 0, sc.settings.spp)
    sr = film.spectral_radiance()  # (H, W, bins)
    emis = prep.materials.emis_scale[0] * prep.materials.spec[sc.materials[0].emission].astype(np.float64)
    sig = prep.media.med_tab[0]
    np.testing.assert_allclose(sig, 2.5 * prep.materials.spec[a], rtol=1e-6)
    lt = emis * np.exp(-sig * 0.6)
    edges = np.linspace(C.LAMBDA_MIN, C.LAMBDA_MAX, bins + 1)
    for b in range(bins):
        x = np.linspace(edges[b], edges[b + 1], 2001)
        expected = np.interp(x, GRID, lt).mean()
        vals = sr[..., b].ravel()
        res = ztest_samples(vals, expected, alpha, f"bin{b}")
        assert res.passed, res.message
    d = develop(film.sums)
    y_exp = C.K_M * np.trapz(lt * prep.cmf[:, 1], GRID)
    res = ztest(d.luminance.mean(), math.sqrt(d.variance.mean() / d.luminance.size), y_exp, alpha, "chromatic-Y")
    assert res.passed, res.message
    # a strong colour change, so the test above can see a wrong σa(λ)
    assert lt[-1] / emis[-1] < 0.5 * lt[0] / emis[0]


def _furnace_expected(d, alpha, name, expected=200.0):
    mean = d.luminance.mean()
    res = ztest(mean, math.sqrt(d.variance.mean() / d.luminance.size), expected, alpha, name)
    assert res.passed, res.message
    assert abs(mean / expected - 1) < 0.03
    xyz = d.XYZ.reshape(-1, 3).sum(0)
    assert xyz[0] / xyz.sum() == pytest.approx(1 / 3, abs=3e-3)
    assert xyz[1] / xyz.sum() == pytest.approx(1 / 3, abs=3e-3)


@pytest.mark.statistical
def test_albedo_one_medium_in_null_sphere_conserves_furnace_radiance(alpha):
    """Walls emit L_e and reflect ρ = 0.5: L = L_e / (1 − ρ) = 200 cd/m² everywhere. A sphere
    of chromatic, forward-scattering, non-absorbing medium (σs from 0.5 to 12 /m across the
    spectrum) in front of the camera changes nothing, at any wavelength: this holds only if the
    spectral MIS of the free-flight sampler, the HG sampling and the NEE from the medium
    (through the null boundary) are right."""
    sc = furnace_scene(rho=0.5, luminance=100.0, width=6, height=6, spp=384)
    s = sc.spectra.add("ramp", ramp_reflectance(0.04, 1.0), C.SPECTRUM_BOUNDED)
    sc.media = [Medium("cloud", scattering=s, scattering_density=12.0, anisotropy=0.6)]
    sc.materials.append(Material("cloud boundary", model=C.MAT_NULL, interior=0))
    sc.meshes.append(icosphere("cloud", (0.55, 0.11, 0.055), 0.35, 1))
    prep = R.prepare(sc)
    assert prep.media.cam_medium == -1
    film, _ = R.render(sc)
    d = develop(film.sums)
    _furnace_expected(d, alpha, "null-sphere")


@pytest.mark.statistical
def test_camera_inside_fog_filled_furnace(alpha):
    """The furnace's own walls bound an albedo-1 fog (interior of the wall material): the camera
    starts in the medium, and surfaces inside it do NEE through it. Still L = 200 cd/m²."""
    sc = furnace_scene(rho=0.5, luminance=100.0, width=6, height=6, spp=256)
    sc.media = [Medium("fog", scattering_density=1.5, anisotropy=-0.3)]
    sc.materials[0].interior = 0
    prep = R.prepare(sc)
    assert prep.media.cam_medium == 0
    film, _ = R.render(sc)
    d = develop(film.sums)
    _furnace_expected(d, alpha, "fog-furnace")


@pytest.mark.statistical
def test_light_through_null_slab_matches_analytic_irradiance(alpha):
    """A Lambert plane lit by a disk light through an absorbing slab between two null faces:
    E = 2π L ∫ e^(−σ τ / cos θ) cos θ sin θ dθ over the disk's cone (NEE shadow rays and
    BSDF-sampled rays both cross the two boundaries)."""
    from helpers import disk_over_plane_scene
    radius, h, rho, lum, sigma, tau = 0.5, 1.0, 0.8, 1000.0, 1.2, 0.2
    sc = disk_over_plane_scene(radius, h, rho, lum, spp=512, res=5)
    sc.media = [Medium("grey", absorption_density=sigma)]
    sc.materials.append(Material("slab", model=C.MAT_NULL, interior=0))
    sc.meshes.append(box_mesh("slab", (-5, -5, 0.6), (5, 5, 0.6 + tau), 1))
    film, _ = R.render(sc)
    d = develop(film.sums)
    th = np.linspace(0, math.atan(radius / h), 20001)
    from scipy.integrate import simpson
    e_over_l = 2 * np.pi * simpson(np.exp(-sigma * tau / np.cos(th)) * np.cos(th) * np.sin(th), x=th)
    expected = rho * lum * e_over_l / np.pi
    res = ztest(d.luminance.mean(), math.sqrt(d.variance.mean() / d.luminance.size), expected, alpha, "slab-light")
    assert res.passed, res.message
    assert abs(d.luminance.mean() / expected - 1) < 0.02
    # without the medium it would be ρ L R²/(h² + R²) = 160: the slab visibly darkens it
    assert expected < 0.85 * rho * lum * radius ** 2 / (h * h + radius ** 2)


def test_media_machinery_is_neutral_without_media():
    """A scene whose media are defined but used by no material takes the media code path
    (shadow-ray loop, tracking) and renders bit-identically to the scene without media."""
    sc = cornell_box(width=12, height=10, spp=3, seed=4)
    a = Film(12, 10)
    R.run_pass(R.prepare(sc), a, 0, 3)
    sc.media = [Medium("unused", absorption_density=3.0, scattering_density=1.0)]
    prep = R.prepare(sc)
    assert prep.media.med_tab.shape[0] == 2
    b = Film(12, 10)
    R.run_pass(prep, b, 0, 3)
    assert np.array_equal(a.sums, b.sums)


# --------------------------------------------------------------------------- scene contract

def _media_scene():
    spectra = SpectrumTable.empty()
    r = spectra.add("grey", flat_reflectance(0.5), C.SPECTRUM_BOUNDED)
    return Scene(meshes=[box_mesh("b", (0, 0, 0), (1, 1, 1), 1)], spectra=spectra,
                 materials=[Material("wall", reflectance=r), Material("fog", model=C.MAT_NULL, interior=0)],
                 media=[Medium("fog", absorption=r, absorption_density=0.5, scattering_density=2.0, anisotropy=0.4)],
                 camera=Camera(look_at((3, 3, 3), (0, 0, 0))))


@pytest.mark.parametrize("change, field", [
    (lambda s: setattr(s.media[0], "anisotropy", 1.0), "media[0] ('fog').anisotropy"),
    (lambda s: setattr(s.media[0], "anisotropy", -1.5), "media[0] ('fog').anisotropy"),
    (lambda s: setattr(s.media[0], "absorption_density", -0.1), "media[0] ('fog').absorption_density"),
    (lambda s: setattr(s.media[0], "scattering_density", float("nan")), "media[0] ('fog').scattering_density"),
    (lambda s: setattr(s.media[0], "scattering", 5), "media[0] ('fog').scattering"),
    (lambda s: setattr(s.media[0], "absorption", 0.5), "media[0] ('fog').absorption"),
    (lambda s: setattr(s.materials[1], "interior", 1), "materials[1] ('fog').interior"),
    (lambda s: setattr(s.materials[0], "interior", -2), "materials[0] ('wall').interior"),
])
def test_bad_media_parameters_name_the_field(change, field):
    sc = _media_scene()
    S.validate(sc)
    change(sc)
    with pytest.raises(SceneError) as e:
        S.validate(sc)
    assert str(e.value).startswith(field + ":"), str(e.value)


def test_null_surfaces_cannot_emit_or_be_mixed():
    sc = _media_scene()
    e = sc.spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    sc.materials[1].emission = e
    sc.materials[1].emission_luminance = 10.0
    with pytest.raises(SceneError, match=r"materials\[1\] \('fog'\)\.emission: a null surface"):
        S.validate(sc)
    sc = _media_scene()
    sc.materials.append(Material("mix", model=C.MAT_MIX, params=[0.5, 0, 1]))
    with pytest.raises(SceneError, match=r"materials\[2\] \('mix'\)\.params: component 1 is a null surface"):
        S.validate(sc)


def test_media_save_load_round_trip(tmp_path):
    sc = _media_scene()
    path = S.save(sc, tmp_path / "fog.json")
    back = S.load(path)
    assert back.media == sc.media
    assert back.materials[1].model == C.MAT_NULL and back.materials[1].interior == 0
    # files written before media existed still load (no "media" key, no "interior")
    import json
    doc = json.loads(path.read_text())
    del doc["media"]
    for m in doc["materials"]:
        del m["interior"]
    doc["materials"][1]["model"] = C.MAT_LAMBERT
    path.write_text(json.dumps(doc))
    old = S.load(path)
    assert old.media == [] and all(m.interior == -1 for m in old.materials)


@pytest.mark.statistical
def test_point_light_and_fog_agree_with_small_sphere_light(alpha):
    """A grey room with a cloud of fog (null sphere) lit by a delta point light (reached by NEE
    alone, from surfaces and from scattering points) or by a sphere light of 1 mm radius
    and the same intensity (NEE and phase/BSDF-sampled hits under MIS): the same image, the
    two differing by O(r) ≈ 0.1 %, well below the noise; and the cloud is visible."""
    from spectral_gi.core.scene import Light

    def room(radius, fog=True):
        spectra = SpectrumTable.empty()
        r = spectra.add("grey", flat_reflectance(0.5), C.SPECTRUM_BOUNDED)
        e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
        light = Light("bulb", C.LIGHT_POINT, (0.5, -0.6, 0.6), (0, 0, 0), (0, 0, 0), e, 0.0, radius=radius,
                      intensity=10.0)
        return Scene(meshes=[box_mesh("room", (-1, -1, -1), (1, 1, 1), 0), icosphere("cloud", (0, 0, 0), 0.5, 1)],
                     spectra=spectra, lights=[light],
                     materials=[Material("wall", reflectance=r), Material("cloud", model=C.MAT_NULL,
                                                                          interior=0 if fog else -1)],
                     media=[Medium("fog", absorption_density=0.5, scattering_density=3.0, anisotropy=0.3)],
                     camera=Camera(look_at((-0.9, 0.8, -0.3), (0, 0, 0)), width=6, height=6, lens_mm=35.0),
                     settings=RenderSettings(spp=256, max_depth=16, seed=9))

    res = []
    for radius in (0.0, 1e-3):
        d = develop(R.render(room(radius))[0].sums)
        res.append((d.luminance.mean(), d.variance.mean() / d.luminance.size))
    (a, va), (b, vb) = res
    z = ztest(a - b, math.sqrt(va + vb), 0.0, alpha, "point-vs-sphere")
    assert z.passed, z.message
    assert math.sqrt(va + vb) < 0.03 * a
    # same seed, so the same paths but for the rare hits of the tiny sphere: far closer than the noise
    assert abs(a / b - 1) < 1e-3
    clear = develop(R.render(room(0.0, fog=False))[0].sums).luminance.mean()
    assert abs(a / clear - 1) > 0.2
