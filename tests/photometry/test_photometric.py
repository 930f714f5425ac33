"""Photometric light profiles (IES LM-63, EULUMDAT): parsing of the shipped samples against
their closed forms, symmetry expansion, flux integrals, malformed files, the kernel's
bilinear lookup against a NumPy oracle, and renders of profiled point, sphere and spot
lights over a white Lambert plane (ρ/π · I(θ, C) cos θ' / d²)."""
import math

import numpy as np
import pytest
from helpers import RHO, check_luminance, ground_points, plane_scene, render_lum

from spectral_gi.core import constants as C
from spectral_gi.core.integrators import render as R
from spectral_gi.core.photometry import profiles as P
from spectral_gi.core.io.presets import PRESETS_DIR
from spectral_gi.core.scene import Light, Profile, SceneError, load, save, validate

IES = PRESETS_DIR / "ies"
I0 = 1000.0
D = np.radians


def _cos_down(t, c):
    return I0 * np.maximum(np.cos(D(t)), 0.0) + 0.0 * c


# the closed forms the samples were written from (presets/README.md)
CLOSED = {
    "cosine_downlight": _cos_down,
    "cosine_uplight": lambda t, c: I0 * np.maximum(-np.cos(D(t)), 0.0) + 0.0 * c,
    "wallwasher": lambda t, c: _cos_down(t, c) * (1 + 0.5 * np.cos(D(c)) + 0.3 * np.sin(D(c))),
    "bilateral_updown": lambda t, c: I0 * (0.75 + 0.25 * np.cos(D(t))) * (1 + 0.5 * np.cos(D(c))),
    "quadrant": lambda t, c: _cos_down(t, c) * (1 + 0.5 * np.cos(2 * D(c))),
    "side_c90": lambda t, c: _cos_down(t, c) * (1 + 0.5 * np.sin(D(c))),
}
FILES = sorted(p.name for p in IES.iterdir() if p.suffix in (".ies", ".ldt"))


def test_presets_are_listed():
    names = P.preset_profiles()
    assert set(names) == {n.rsplit(".", 1)[0] for n in FILES}
    assert len(FILES) == 11


@pytest.mark.parametrize("name", FILES)
def test_samples_match_their_closed_form_everywhere(name):
    """Every sample, expanded to C = 0 … 360, equals its formula at every node (4-decimal files)
    and between nodes (the bilinear lookup), and is 0 outside its θ range."""
    pr = P.read_profile(IES / name)
    f = CLOSED[pr.name]
    assert pr.phi[0] == 0 and pr.phi[-1] == 360 and np.all(np.diff(pr.phi) > 0)
    t, c = np.meshgrid(pr.theta, pr.phi)
    np.testing.assert_allclose(pr.candela, f(t, c), atol=2e-4)
    rng = np.random.default_rng(3)
    tt = rng.uniform(pr.theta[0], pr.theta[-1], 400)
    cc = rng.uniform(0, 360, 400)
    # bilinear on 5° × ≤ 15° steps of smooth functions: within 2 % of the peak
    np.testing.assert_allclose(P.evaluate(pr, tt, cc), f(tt, cc), atol=0.02 * pr.candela.max())
    if pr.theta[0] > 0:
        assert P.evaluate(pr, 30.0, 10.0) == 0.0
    if pr.theta[-1] < 180:
        assert P.evaluate(pr, 120.0, 10.0) == 0.0


def test_hand_checked_values():
    """A few numbers read off the files by hand."""
    pr = P.read_profile(IES / "cosine_downlight.ies")
    assert P.evaluate(pr, 0.0, 0.0) == pytest.approx(1000.0)
    assert P.evaluate(pr, 60.0, 123.0) == pytest.approx(500.0, abs=1e-3)
    assert P.evaluate(pr, 90.0, 0.0) == pytest.approx(0.0, abs=1e-3)
    # LM-63-1995: value 750 × multiplier 2 × ballast 0.8 × ballast-lamp factor 1.25 = 1500 cd
    bi = P.read_profile(IES / "bilateral_updown.ies")
    assert P.evaluate(bi, 0.0, 0.0) == pytest.approx(1500.0, abs=1e-3)
    assert P.evaluate(bi, 180.0, 180.0) == pytest.approx(250.0, abs=1e-3)  # 0.5 × 0.5 × 1000
    # EULUMDAT: 500 cd/klm × 2000 lm / 1000 = 1000 cd
    ldt = P.read_profile(IES / "cosine_downlight.ldt")
    assert ldt.candela[0, 0] == pytest.approx(1000.0)
    # LM-63-2019 wall washer at C = 90 (sin C = 1) and C = 270, θ = 0: 1000 (1 ± 0.3)
    ww = P.read_profile(IES / "wallwasher.ies")
    assert P.evaluate(ww, 0.0, 90.0) == pytest.approx(1300.0, abs=1e-3)
    assert P.evaluate(ww, 45.0, 270.0) == pytest.approx(1000 * math.cos(math.pi / 4) * 0.7, abs=1e-3)


@pytest.mark.parametrize("stem", ["cosine_downlight", "wallwasher", "bilateral_updown", "quadrant", "side_c90"])
def test_ies_and_eulumdat_versions_agree(stem):
    a = P.read_profile(IES / f"{stem}.ies")
    b = P.read_profile(IES / f"{stem}.ldt")
    rng = np.random.default_rng(5)
    t = rng.uniform(0, 180, 2000)
    c = rng.uniform(0, 360, 2000)
    np.testing.assert_allclose(P.evaluate(a, t, c), P.evaluate(b, t, c), atol=0.03 * a.candela.max())
    assert P.flux(a) == pytest.approx(P.flux(b), rel=2e-3)


def test_symmetry_expansion_by_hand():
    """The four symmetries on a tiny table: quadrant, bilateral, C90–C270 and rotational."""
    row = lambda k: np.array([k, k + 0.5])  # noqa: E731
    phi, tab = P.expand_symmetry("x", [0, 45, 90], [row(1), row(2), row(3)])
    np.testing.assert_array_equal(phi, [0, 45, 90, 135, 180, 225, 270, 315, 360])
    np.testing.assert_array_equal(tab[:, 0], [1, 2, 3, 2, 1, 2, 3, 2, 1])
    phi, tab = P.expand_symmetry("x", [0, 90, 180], [row(1), row(2), row(3)])
    np.testing.assert_array_equal(phi, [0, 90, 180, 270, 360])
    np.testing.assert_array_equal(tab[:, 0], [1, 2, 3, 2, 1])
    phi, tab = P.expand_symmetry("x", [90, 180, 270], [row(1), row(2), row(3)])
    # I(C) = I(180 − C): C0 ≡ C180, C270 given, C360 ≡ C0
    np.testing.assert_array_equal(phi, [0, 90, 180, 270, 360])
    np.testing.assert_array_equal(tab[:, 0], [2, 1, 2, 3, 2])
    phi, tab = P.expand_symmetry("x", [0], [row(7)])
    np.testing.assert_array_equal(phi, [0, 360])
    np.testing.assert_array_equal(tab[:, 1], [7.5, 7.5])
    with pytest.raises(P.PhotometricError, match="not a supported symmetry"):
        P.expand_symmetry("x", [0, 30, 60], [row(1), row(2), row(3)])


def test_flux_against_closed_forms():
    """∫ I dω: 1000 cos θ on one hemisphere → π · 1000 lm; (0.75 + 0.25 cos θ)(1 + 0.5 cos C) → 4π · 750;
    the bilinear table of cos θ on 5° steps lies below the cosine by its chord error (< 1e-3)."""
    for name in ("cosine_downlight.ies", "cosine_uplight.ies", "wallwasher.ies", "quadrant.ldt", "side_c90.ies"):
        pr = P.read_profile(IES / name)
        assert P.flux(pr) == pytest.approx(math.pi * I0, rel=1e-3), name
        assert P.flux(pr) < math.pi * I0
    assert P.flux(P.read_profile(IES / "bilateral_updown.ldt")) == pytest.approx(4 * math.pi * 750, rel=1e-6)
    # the closed-form integral of the bilinear table equals brute-force quadrature of evaluate()
    pr = P.read_profile(IES / "wallwasher.ies")
    t = np.linspace(0, np.pi, 1801)
    c = np.linspace(0, 2 * np.pi, 721)
    tt, cc = np.meshgrid(t, c, indexing="ij")
    vals = P.evaluate(pr, np.degrees(tt), np.degrees(cc)) * np.sin(tt)
    brute = np.trapz(np.trapz(vals, c, axis=1), t)
    assert P.flux(pr) == pytest.approx(brute, rel=1e-4)
    # the masked quadrature agrees with the exact one for a mask of 1
    assert P.flux(pr, mask=lambda mu: np.ones_like(mu)) == pytest.approx(P.flux(pr), rel=1e-6)


# --------------------------------------------------------------------------- bad files

GOOD_IES = (IES / "cosine_downlight.ies").read_text()
GOOD_LDT = (IES / "cosine_downlight.ldt").read_text(encoding="latin-1")


def _ies_numbers_replaced(old, new, count=1):
    return GOOD_IES.replace(old, new, count)


@pytest.mark.parametrize("text, match", [
    (GOOD_IES[:-40], "truncated: candela value"),
    (_ies_numbers_replaced("TILT=NONE", "TILT=INCLUDE"), "TILT=INCLUDE is not supported"),
    (_ies_numbers_replaced("1 -1 1 19 1 1 2 0 0 0", "1 -1 1 19 1 2 2 0 0 0"), "type B is not supported"),
    (_ies_numbers_replaced("1 -1 1 19 1 1 2 0 0 0", "1 -1 1 18 1 1 2 0 0 0"), "numbers more than"),
    (_ies_numbers_replaced("1 -1 1 19 1 1 2 0 0 0", "1 -1 1 19.5 1 1 2 0 0 0"), "positive integer"),
    (_ies_numbers_replaced("1000 996.1947", "1000 abc"), "'abc' is not a number"),
    (_ies_numbers_replaced("1000 996.1947", "1000 -996.1947"), "negative candela"),
    (_ies_numbers_replaced("1000 996.1947", "1000 nan"), "'nan' is not a number"),
    ("IESNA:LM-63-2002\n[TEST] x\n", "no TILT= line"),
    ("", "empty file"),
], ids=["truncated", "tilt", "type-b", "counts", "non-integer", "non-numeric", "negative", "nan", "no-tilt",
        "empty"])
def test_bad_ies_files_name_the_file_and_problem(tmp_path, text, match):
    assert "1000 996.1947" in GOOD_IES and "1 -1 1 19 1 1 2 0 0 0" in GOOD_IES
    p = tmp_path / "broken.ies"
    p.write_text(text)
    with pytest.raises(P.PhotometricError, match=match) as e:
        P.read_profile(p)
    assert "broken.ies" in str(e.value)
    assert isinstance(e.value, ValueError)


def _ldt_line(k, value):
    lines = GOOD_LDT.replace("\r\n", "\n").split("\n")
    lines[k - 1] = value
    return "\n".join(lines)


@pytest.mark.parametrize("text, match", [
    (_ldt_line(3, "5"), "Isym must be 0–4"),
    (_ldt_line(4, "x"), "'x' is not a number"),
    ("\n".join(GOOD_LDT.split("\n")[:60]), "truncated"),
    (GOOD_LDT + "1\n2\n", "lines more than"),
    (_ldt_line(29, "-3"), "total luminous flux must be positive"),
    (_ldt_line(90, "-5"), "negative candela"),
    (_ldt_line(3, "4"), "truncated: intensity 20 of 133"),
], ids=["isym", "non-numeric", "truncated", "too-long", "no-flux", "negative", "counts"])
def test_bad_eulumdat_files_name_the_file_and_problem(tmp_path, text, match):
    assert GOOD_LDT.replace("\r\n", "\n").split("\n")[28] == "2000"
    p = tmp_path / "broken.ldt"
    p.write_text(text, encoding="latin-1")
    with pytest.raises(P.PhotometricError, match=match) as e:
        P.read_profile(p)
    assert "broken.ldt" in str(e.value)


def test_missing_and_unknown_files(tmp_path):
    with pytest.raises(P.PhotometricError, match="no such file"):
        P.read_profile(tmp_path / "nope.ies")
    (tmp_path / "a.txt").write_text("x")
    with pytest.raises(P.PhotometricError, match="expected .ies or .ldt"):
        P.read_profile(tmp_path / "a.txt")


# --------------------------------------------------------------------------- scene contract

def _profiled(profile=0, pos=(0.0, 0.0, 1.0), kind=C.LIGHT_POINT, direction=(0, 0, -1), axis_u=(1, 0, 0), **kw):
    return Light("lum", kind, pos, axis_u, (0, 0, 0), 0, 0.0, direction=direction, profile=profile, **kw)


@pytest.mark.parametrize("change, match", [
    (dict(profile=3), "profile index 3 out of range"),
    (dict(profile_mode="lumens"), "unknown mode"),
    (dict(axis_u=(0, 0, 2)), "local \\+X axis"),
    (dict(direction=(0, 0, 0)), "direction"),
    (dict(kind=C.LIGHT_RECT, axis_v=(0, 1, 0), luminance=1.0), "only point and spot"),
    (dict(flux=-1.0, profile_mode="flux"), "flux"),
])
def test_profiled_light_fields_are_validated(change, match):
    sc = plane_scene([_profiled()])
    sc.profiles = [P.read_profile(IES / "wallwasher.ies")]
    validate(sc)
    for k, v in change.items():
        setattr(sc.lights[0], k, v)
    with pytest.raises(SceneError, match=match):
        validate(sc)


def test_profile_table_is_validated():
    sc = plane_scene([_profiled()])
    pr = P.read_profile(IES / "quadrant.ies")
    sc.profiles = [Profile("p", pr.theta, pr.phi[:-1].copy(), pr.candela[:-1].copy())]
    with pytest.raises(SceneError, match="profiles\\[0\\].*phi"):
        validate(sc)
    bad = pr.candela.copy()
    bad[3, 4] = -1
    sc.profiles = [Profile("p", pr.theta, pr.phi, bad)]
    with pytest.raises(SceneError, match="negative"):
        validate(sc)


def test_profiles_survive_save_and_load(tmp_path):
    sc = plane_scene([_profiled(profile_mode="flux", flux=1234.0)])
    sc.profiles = [P.read_profile(IES / "side_c90.ldt")]
    back = load(save(sc, tmp_path / "s.json"))
    assert back.lights[0].profile == 0 and back.lights[0].profile_mode == "flux" and back.lights[0].flux == 1234.0
    np.testing.assert_array_equal(back.profiles[0].candela, sc.profiles[0].candela)
    np.testing.assert_array_equal(back.profiles[0].phi, sc.profiles[0].phi)
    assert back.profiles[0].source == "side_c90.ldt"


# --------------------------------------------------------------------------- kernel lookup

def _frame(direction, axis_u):
    n = np.asarray(direction, float)
    n /= np.linalg.norm(n)
    u = np.asarray(axis_u, float)
    u = u - (u @ n) * n
    u /= np.linalg.norm(u)
    return n, u, np.cross(-n, u)


def _angles(q, direction, axis_u):
    """(θ, C) in degrees of unit directions q (…, 3) in the documented frame: θ from the nadir
    (local −Z = direction), C = 0 towards local −Y, 90 towards local −X (Cycles' IES texture)."""
    n, x, y = _frame(direction, axis_u)
    th = np.degrees(np.arccos(np.clip(q @ n, -1, 1)))
    # written out per quadrant rather than with the kernel's atan2 + π
    a, b = q @ x, q @ y
    c = np.degrees(np.arctan2(-a, -b)) % 360.0
    return th, c


def test_kernel_profile_factor_matches_numpy_oracle():
    from spectral_gi.core.lights import kernel as LG

    sc = plane_scene([_profiled(direction=(0.3, -0.2, -1.0), axis_u=(0.2, 1.0, 0.1))])
    pr = P.read_profile(IES / "wallwasher.ies")
    sc.profiles = [pr]
    prep = R.prepare(sc)
    rng = np.random.default_rng(11)
    q = rng.normal(size=(500, 3))
    q /= np.linalg.norm(q, axis=1)[:, None]
    got = np.array([LG.profile_factor(prep.emitters.light_geo, prep.emitters.light_prof, 0, *v) for v in q])
    th, c = _angles(q, sc.lights[0].direction, sc.lights[0].axis_u)
    np.testing.assert_allclose(got, P.evaluate(pr, th, c) / pr.candela.max(), atol=1e-9)
    # the named directions: C0 towards local −Y, C90 towards −X, C270 towards +X (θ = 90°, the horizon)
    n, x, y = _frame(sc.lights[0].direction, sc.lights[0].axis_u)
    for v, cc in ((-y, 0.0), (-x, 90.0), (y, 180.0), (x, 270.0)):
        d = 0.6 * v + 0.8 * n  # θ = acos 0.8
        f = LG.profile_factor(prep.emitters.light_geo, prep.emitters.light_prof, 0, *d)
        assert f == pytest.approx(P.evaluate(pr, math.degrees(math.acos(0.8)), cc) / pr.candela.max(), abs=1e-9)


# --------------------------------------------------------------------------- prepare: units and flux

def test_profile_modes_set_brightness_and_selection_flux():
    """file: the profile's candela; peak: its maximum = intensity; flux: ∫ I dω = flux lm. Light
    selection follows each light's ∫ I dω (two profiled lights and a plain point light)."""
    ww = P.read_profile(IES / "wallwasher.ies")
    bi = P.read_profile(IES / "bilateral_updown.ies")
    plain = Light("plain", C.LIGHT_POINT, (0, 0, 1), (0, 0, 0), (0, 0, 0), 0, 0.0, intensity=100.0)
    lights = [_profiled(0), _profiled(1, profile_mode="peak", intensity=300.0),
              _profiled(1, profile_mode="flux", flux=2000.0), plain]
    sc = plane_scene(lights)
    sc.profiles = [ww, bi]
    prep = R.prepare(sc)
    flux = np.array([math.pi * 1000.0, 4 * math.pi * 750 * 300 / 1500, 2000.0, 4 * math.pi * 100])
    np.testing.assert_allclose(prep.emitters.emit_prob, flux / flux.sum(), rtol=2e-3)
    # light_scale is proportional to the peak candela: plain 100 cd ↔ peaks 1300, 300, 2000/Φ · 1500
    s = prep.emitters.light_scale / prep.emitters.light_scale[3] * 100.0
    np.testing.assert_allclose(s[:3], [ww.candela.max(), 300.0, 2000.0 / P.flux(bi) * 1500.0], rtol=1e-9)


def test_profiled_spot_flux_includes_its_cone():
    size, blend = math.radians(60), 0.3
    spot = _profiled(0, kind=C.LIGHT_SPOT, spot_angle=size, spot_blend=blend, profile_mode="flux", flux=500.0)
    plain = Light("plain", C.LIGHT_POINT, (0, 0, 1), (0, 0, 0), (0, 0, 0), 0, 0.0, intensity=500.0 / (4 * math.pi))
    sc = plane_scene([spot, plain])
    sc.profiles = [P.read_profile(IES / "cosine_downlight.ies")]
    prep = R.prepare(sc)
    np.testing.assert_allclose(prep.emitters.emit_prob, [0.5, 0.5], rtol=1e-9)
    # the spot emits 500 lm inside the cone: its peak is 500 / ∫ cos θ · mask dω
    mu = np.linspace(math.cos(size / 2), 1, 200001)
    from spectral_gi.core.photometry.units import spot_falloff
    integral = 2 * math.pi * np.trapz(mu * spot_falloff(mu, size, blend), mu)
    s = prep.emitters.light_scale[0] / prep.emitters.light_scale[1] * 500.0 / (4 * math.pi)
    assert s == pytest.approx(500.0 / integral, rel=2e-3)


def test_dark_profile_cannot_take_a_flux():
    pr = P.read_profile(IES / "cosine_uplight.ies")
    sc = plane_scene([_profiled(0, kind=C.LIGHT_SPOT, spot_angle=math.radians(40), profile_mode="flux", flux=10.0)])
    sc.profiles = [pr]
    with pytest.raises(SceneError, match="emits no light inside the spot's cone"):
        R.prepare(sc)


# --------------------------------------------------------------------------- renders

def profile_expected(sc, li, pr, scale=1.0):
    """ρ/π · I(θ, C) · cos θ' / d² averaged over each pixel, I from the NumPy oracle."""
    p = ground_points(sc)
    v = p - np.asarray(li.position)
    d2 = (v ** 2).sum(-1)
    q = v / np.sqrt(d2)[..., None]
    th, c = _angles(q, li.direction, li.axis_u)
    cos = -q[..., 2]
    return (RHO / np.pi * scale * P.evaluate(pr, th, c) * cos / d2).mean(-1)


@pytest.mark.statistical
@pytest.mark.parametrize("radius, axis_u, nee", [(0.0, (1, 0, 0), True), (0.0, (1, 1, 0), True),
                                                 (0.25, (0, 1, 0), True), (0.25, (0, 1, 0), False)])
def test_profiled_light_over_a_lambert_plane(radius, axis_u, nee):
    """The asymmetric wall washer 1 m above the plane: below it, at 45° and beyond, the plane
    shows ρ/π · I(θ, C) cos θ / d². A sphere of radius 25 cm (radiance I(ω_c)/(π r²) towards
    the direction ω_c from its centre, so the irradiance is the same exactly) with NEE + MIS
    and with BSDF hits only (nee off) sees the same factor."""
    pr = P.read_profile(IES / "wallwasher.ies")
    li = _profiled(0, pos=(0.1, 0.0, 1.0), axis_u=axis_u, radius=radius)
    sc = plane_scene([li], res=12, half_view=1.6, spp=8 if radius == 0 else (64 if nee else 512))
    sc.settings.next_event = nee
    sc.profiles = [pr]
    d = render_lum(sc)
    exp = profile_expected(sc, li, pr)
    assert exp.max() > 3 * exp[exp > 0].min()  # a real variation across the view
    check_luminance(d, exp, 0.03 if radius == 0 else 0.05)


@pytest.mark.statistical
def test_profiled_spot_is_profile_times_mask():
    from helpers import blender_spot_mask

    size, blend = math.radians(80), 0.4
    pr = P.read_profile(IES / "quadrant.ldt")
    li = _profiled(0, kind=C.LIGHT_SPOT, direction=(0.2, 0.0, -1.0), axis_u=(1, 0, 0.2), spot_angle=size,
                   spot_blend=blend, profile_mode="peak", intensity=200.0)
    sc = plane_scene([li], res=12, half_view=1.2, spp=16)
    sc.profiles = [pr]
    d = render_lum(sc)
    p = ground_points(sc)
    v = p - np.asarray(li.position)
    q = v / np.linalg.norm(v, axis=-1)[..., None]
    a = np.asarray(li.direction) / np.linalg.norm(li.direction)
    mask = blender_spot_mask(q @ a, size, blend)
    th, c = _angles(q, li.direction, li.axis_u)
    d2 = (v ** 2).sum(-1)
    exp = (RHO / np.pi * 200.0 / pr.candela.max() * P.evaluate(pr, th, c) * mask * -q[..., 2] / d2).mean(-1)
    assert (exp == 0).sum() > 10 and exp.max() > 0
    check_luminance(d, exp, 0.03)
