"""Built-in spectra (core/spectra/library.py) against colour-science and physics."""

import math
import warnings

import numpy as np
import pytest

from spectral_gi.core.io import presets
from spectral_gi.core.spectra import library as L

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # colour warns about the missing matplotlib
    import colour  # test dependency (colour-science 0.4.6): the oracle

# CODATA 2018 (exact in the SI since 2019), and derived constants.
H, C, K = 6.62607015e-34, 299792458.0, 1.380649e-23
WIEN_B_NM_K = 2.897771955e6  # CODATA 2018 Wien wavelength displacement constant, 2.897771955e-3 m·K
SIGMA = 5.670374419e-8  # CODATA 2018 Stefan–Boltzmann constant, W/(m²·K⁴)


# --------------------------------------------------------------------------- blackbody


@pytest.mark.parametrize("T", [1000.0, 2856.0, 5000.0, 6504.0, 10000.0, 30000.0])
def test_blackbody_matches_colour_planck_law(T):
    wl = np.linspace(200.0, 5000.0, 2401)
    # colour's planck_law is per metre of wavelength (W/(m²·sr·m)) and takes c1 = 2πhc²
    # (it divides by π); its default constants are rounded, so pass CODATA 2018 ones.
    ref = colour.colorimetry.planck_law(wl * 1e-9, T, c1=2 * math.pi * H * C**2, c2=H * C / K, n=1) * 1e-9
    ours = L.blackbody(T, wl)
    assert ours.shape == wl.shape
    np.testing.assert_allclose(ours, ref, rtol=1e-10, atol=0)


def test_blackbody_constants():
    assert L.C2 == pytest.approx(1.438776877e-2, rel=1e-9)  # CODATA 2018 c2, m·K
    assert L.C1L == pytest.approx(1.191042972e-16, rel=1e-9)  # CODATA 2018 c1L = 2hc², W·m²/sr


def _golden_max(f, lo, hi, iters=200):
    g = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = lo, hi
    c, d = b - g * (b - a), a + g * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(iters):
        if fc > fd:
            b, d, fd = d, c, fc
            c = b - g * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + g * (b - a)
            fd = f(d)
        if b - a < 1e-9 * a:
            break
    return 0.5 * (a + b)


@pytest.mark.parametrize("T", [1500.0, 2856.0, 5778.0, 10000.0])
def test_wien_displacement(T):
    guess = WIEN_B_NM_K / T
    # Coarse scan first (the search must find the peak, not be told it), then refine.
    grid = np.geomspace(0.2 * guess, 5.0 * guess, 2001)
    i = int(np.argmax(L.blackbody(T, grid)))
    peak = _golden_max(lambda x: float(L.blackbody(T, x)), grid[i - 1], grid[i + 1])
    assert peak * T == pytest.approx(WIEN_B_NM_K, rel=1e-5)


@pytest.mark.parametrize("T", [3000.0, 5000.0, 6504.0])
def test_stefan_boltzmann(T):
    wl = np.geomspace(10.0, 1e7, 400001)  # 10 nm .. 1 cm
    exitance = math.pi * np.trapz(L.blackbody(T, wl), wl)  # W/m²
    assert exitance == pytest.approx(SIGMA * T**4, rel=1e-4)


def test_blackbody_broadcasts_and_validates():
    T = np.array([3000.0, 6000.0])
    wl = np.array([400.0, 500.0, 600.0])
    table = L.blackbody(T[:, None], wl[None, :])
    assert table.shape == (2, 3)
    for i, t in enumerate(T):
        np.testing.assert_array_equal(table[i], L.blackbody(t, wl))
    assert np.ndim(L.blackbody(5000, 550)) == 0
    assert L.blackbody(100.0, 100.0) == 0.0  # deep Wien tail: exp overflows, B -> 0 without error
    for bad_T in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="temperature"):
            L.blackbody(bad_T, 500.0)
    for bad_wl in (0.0, -5.0, float("nan")):
        with pytest.raises(ValueError, match="wavelengths"):
            L.blackbody(5000.0, [500.0, bad_wl])


# --------------------------------------------------------------------------- illuminants

FL_NAMES = [f"FL{i}" for i in range(1, 13)]
LED_NAMES = ["LED-B1", "LED-B2", "LED-B3", "LED-B4", "LED-B5", "LED-BH1", "LED-RGB1", "LED-V1", "LED-V2"]


def test_illuminant_names():
    names = L.illuminant_names()
    assert names == ["A", "D50", "D55", "D65", "D75", "E"] + FL_NAMES + LED_NAMES
    assert set(names) == set(presets.illuminant_names())
    assert L.led_names() == LED_NAMES
    # Every LED illuminant colour-science 0.4.6 has is shipped.
    assert sorted(k for k in colour.SDS_ILLUMINANTS if k.startswith("LED-")) == sorted(LED_NAMES)


@pytest.mark.parametrize("name", ["A", "D50", "D55", "D65", "D75", "E"] + FL_NAMES + LED_NAMES)
def test_illuminant_equals_colour_at_native_wavelengths(name):
    ref = colour.SDS_ILLUMINANTS[name]
    np.testing.assert_array_equal(L.illuminant(name, ref.wavelengths), ref.values)
    wl, values = presets.illuminant(name)
    np.testing.assert_array_equal(wl, ref.wavelengths)
    np.testing.assert_array_equal(values, ref.values)


@pytest.mark.parametrize(
    "alias, name",
    [("F11", "FL11"), ("f1", "FL1"), ("CIE F2", "FL2"), ("fl12", "FL12"), ("d65", "D65"),
     ("Illuminant A", "A"), ("led_b1", "LED-B1"), ("LED RGB1", "LED-RGB1"), ("ledv2", "LED-V2")],
)
def test_illuminant_aliases(alias, name):
    assert L.resolve_illuminant_name(alias) == name
    wl = np.arange(380.0, 781.0, 7.0)
    np.testing.assert_array_equal(L.illuminant(alias, wl), L.illuminant(name, wl))


def test_illuminant_interpolation_any_sampling():
    ref = colour.SDS_ILLUMINANTS["FL11"]
    rng = np.random.default_rng(1)
    wl = rng.uniform(380.0, 780.0, size=(7, 11))  # unsorted, 2-D, off-grid
    got = L.illuminant("F11", wl)
    assert got.shape == wl.shape
    np.testing.assert_allclose(got, np.interp(wl, ref.wavelengths, ref.values), rtol=0, atol=1e-12)
    # Midpoints lie halfway between neighbours (linear interpolation).
    mid = 0.5 * (ref.wavelengths[:-1] + ref.wavelengths[1:])
    np.testing.assert_allclose(L.illuminant("FL11", mid), 0.5 * (ref.values[:-1] + ref.values[1:]), atol=1e-12)
    # Outside the table: the edge value is held, or 0 on request.
    d65 = colour.SDS_ILLUMINANTS["D65"]
    np.testing.assert_array_equal(L.illuminant("D65", [250.0, 830.0]), [d65.values[0], d65.values[-1]])
    np.testing.assert_array_equal(L.illuminant("D65", [250.0, 560.0, 830.0], extrapolate="zero"), [0.0, 100.0, 0.0])
    with pytest.raises(ValueError, match="extrapolate"):
        L.illuminant("D65", 500.0, extrapolate="linear")


def test_illuminant_unknown_names():
    for bad in ("D93", "F13", "FL0", "LED-B6", "", "../D65", None, 65):
        with pytest.raises(ValueError, match="unknown illuminant") as exc:
            L.illuminant(bad, 500.0)
        assert "FL11" in str(exc.value) and "LED-B1" in str(exc.value)
    with pytest.raises(ValueError, match="'D93'"):
        L.illuminant("D93", 500.0)


# --------------------------------------------------------------------------- ColorChecker

OHTA = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]

# The manufacturer's sRGB values of the 24 patches (X-Rite, as listed in the Wikipedia
# article "ColorChecker", Colors table), in the standard order.
PUBLISHED_SRGB_HEX = (
    "735244 c29682 627a9d 576c43 8580b1 67bdaa d67e2c 505ba6 c15a63 5e3c6c 9dbc40 e0a32e "
    "383d96 469449 af363c e7c71f bb5695 0885a1 f3f3f2 c8c8c8 a0a0a0 7a7a79 555555 343434"
).split()


def test_colorchecker_names():
    names = L.colorchecker_names()
    assert len(names) == 24
    assert names == list(OHTA)
    assert names[0] == "dark skin" and names[18].startswith("white") and names[23].startswith("black")


@pytest.mark.parametrize("index", range(24))
def test_colorchecker_equals_colour(index):
    name = L.colorchecker_names()[index]
    ref = OHTA[name]
    np.testing.assert_array_equal(L.colorchecker(name, ref.wavelengths), ref.values)
    np.testing.assert_array_equal(L.colorchecker(index, ref.wavelengths), ref.values)
    np.testing.assert_array_equal(L.colorchecker(np.int64(index), ref.wavelengths), ref.values)
    np.testing.assert_array_equal(L.colorchecker(name.upper(), ref.wavelengths), ref.values)
    assert np.all((ref.values >= 0) & (ref.values <= 1))


def test_colorchecker_file_sampling():
    wl, values, names = presets.colorchecker_table()
    np.testing.assert_array_equal(wl, np.arange(380.0, 781.0, 5.0))
    assert values.shape == (81, 24) and names == L.colorchecker_names()


def test_colorchecker_short_names_and_interpolation():
    wl = np.array([[552.5, 400.0], [377.0, 800.0]])
    for short, full in [("white", "white 9.5 (.05 D)"), ("neutral 8", "neutral 8 (.23 D)"),
                        ("black", "black 2 (1.5 D)"), ("Black 2", "black 2 (1.5 D)")]:
        np.testing.assert_array_equal(L.colorchecker(short, wl), L.colorchecker(full, wl))
    ref = OHTA["red"]
    got = L.colorchecker("red", wl)
    assert got.shape == (2, 2)
    assert got[0, 0] == pytest.approx(0.5 * (ref.values[34] + ref.values[35]), abs=1e-12)  # 550, 555 nm
    assert got[1, 0] == ref.values[0] and got[1, 1] == ref.values[-1]  # held beyond the ends


def test_colorchecker_unknown():
    for bad in ("chartreuse", "neutral", 24, -1, True, 2.0, None):
        with pytest.raises(ValueError) as exc:
            L.colorchecker(bad, 500.0)
        assert "dark skin" in str(exc.value) or "out of range" in str(exc.value)


def test_colorchecker_srgb_under_d65_matches_published_chart():
    """Loose check: rendered under D65 the patches have the published chart's hues, in the same order."""
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    d65 = colour.SDS_ILLUMINANTS["D65"]
    wl = np.arange(380.0, 781.0, 5.0)
    white = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    ours, published = [], []
    for i, name in enumerate(L.colorchecker_names()):
        sd = colour.SpectralDistribution(L.colorchecker(name, wl), wl)
        with warnings.catch_warnings():
            # colour aligns the 380-780 nm chart and D65 to the CMFs' range, and says so.
            warnings.simplefilter("ignore", colour.utilities.ColourRuntimeWarning)
            XYZ = colour.sd_to_XYZ(sd, cmfs, d65) / 100.0
        srgb = np.clip(colour.XYZ_to_sRGB(XYZ), 0.0, 1.0)
        ours.append(colour.XYZ_to_Lab(colour.sRGB_to_XYZ(srgb), white))
        rgb8 = [int(PUBLISHED_SRGB_HEX[i][j:j + 2], 16) / 255.0 for j in (0, 2, 4)]
        published.append(colour.XYZ_to_Lab(colour.sRGB_to_XYZ(rgb8), white))
    ours, published = np.array(ours), np.array(published)
    hue = lambda lab: np.degrees(np.arctan2(lab[:, 2], lab[:, 1])) % 360.0  # noqa: E731
    chromatic = slice(0, 18)
    # Same hue order around the circle for the 18 chromatic patches ...
    assert list(np.argsort(hue(ours[chromatic]))) == list(np.argsort(hue(published[chromatic])))
    # ... each hue within a few degrees, and close overall (ΔE*ab).
    dh = (hue(ours[chromatic]) - hue(published[chromatic]) + 180.0) % 360.0 - 180.0
    assert np.max(np.abs(dh)) < 8.0
    assert np.max(colour.delta_E(ours, published, method="CIE 1976")) < 4.0
    # The six neutrals are neutral and get darker along the row.
    assert np.all(np.hypot(ours[18:, 1], ours[18:, 2]) < 2.0)
    assert np.all(np.diff(ours[18:, 0]) < -10.0)


# --------------------------------------------------------------------------- metals


def reflectance(eta, k):
    return ((eta - 1.0) ** 2 + k**2) / ((eta + 1.0) ** 2 + k**2)


def test_metal_names_and_tables():
    assert L.metal_names() == ["Ag", "Al", "Au", "Cu"]
    for name in L.metal_names():
        path = presets.PRESETS_DIR / "metals" / f"{name}.csv"
        assert path.read_text(encoding="utf-8").splitlines()[0] == "wavelength_nm,eta,k"
        wl, eta, k = presets.metal_table(name)
        assert wl[0] <= 380.0 and wl[-1] >= 780.0, name
        assert np.all(eta > 0) and np.all(k > 0), name
        # At the tabulated wavelengths the tabulated values come back exactly.
        got_eta, got_k = L.metal_ior(name, wl)
        np.testing.assert_array_equal(got_eta, eta)
        np.testing.assert_array_equal(got_k, k)


def test_johnson_christy_transcription():
    """Spot values of Johnson & Christy (1972), tabulated at photon energies 0.64..6.60 eV."""
    for name in ("Au", "Ag", "Cu"):
        wl, _, _ = presets.metal_table(name)
        assert wl.size == 49
        energies = np.round(1239.84198 / wl, 2)
        assert energies[-1] == 0.64 and energies[0] == 6.60
        assert np.all(np.diff(energies) < 0) and np.all(np.abs(np.diff(energies) + 0.125) < 0.02)
    au = dict(zip(presets.metal_table("Au")[0], zip(*presets.metal_table("Au")[1:])))
    assert au[495.9] == (1.04, 1.833)  # 2.50 eV
    assert au[659.5] == (0.14, 3.697)  # 1.88 eV
    ag = dict(zip(presets.metal_table("Ag")[0], zip(*presets.metal_table("Ag")[1:])))
    assert ag[548.6] == (0.06, 3.586)  # 2.26 eV
    cu = dict(zip(presets.metal_table("Cu")[0], zip(*presets.metal_table("Cu")[1:])))
    assert cu[616.8] == (0.3, 3.205)  # 2.01 eV
    al = dict(zip(presets.metal_table("Al")[0], zip(*presets.metal_table("Al")[1:])))
    assert al[619.93] == (1.366, 7.4052)  # Rakić 1995 at 2.0 eV


def test_gold_reflectance():
    eta, k = L.metal_ior("Au", [450.0, 650.0])
    R = reflectance(eta, k)
    assert R[1] > 0.9
    assert R[0] < 0.45


def test_silver_reflectance():
    wl = np.linspace(450.0, 700.0, 251)
    assert np.all(reflectance(*L.metal_ior("silver", wl)) > 0.9)


def test_aluminium_reflectance():
    wl = np.linspace(380.0, 780.0, 401)
    R = reflectance(*L.metal_ior("Al", wl))
    assert np.all((R > 0.87) & (R < 0.94))
    assert abs(R.mean() - 0.9) < 0.03


def test_copper_red_rise():
    wl = np.linspace(400.0, 750.0, 351)
    R = reflectance(*L.metal_ior("copper", wl))
    at = lambda x: R[np.argmin(np.abs(wl - x))]  # noqa: E731
    assert at(450.0) < 0.6 and at(500.0) < 0.65
    assert at(650.0) > 0.9
    assert at(650.0) - at(500.0) > 0.3
    # The rise is steep between 550 and 620 nm and monotone across it.
    band = (wl >= 550.0) & (wl <= 650.0)
    assert np.all(np.diff(R[band]) > 0)
    assert at(620.0) - at(560.0) > 0.2


def test_metal_interpolation_any_sampling_and_aliases():
    rng = np.random.default_rng(7)
    wl = rng.uniform(360.0, 830.0, size=(5, 4))
    eta, k = L.metal_ior("gold", wl)
    assert eta.shape == k.shape == wl.shape
    twl, teta, tk = presets.metal_table("Au")
    np.testing.assert_allclose(eta, np.interp(wl, twl, teta), atol=1e-12)
    np.testing.assert_allclose(k, np.interp(wl, twl, tk), atol=1e-12)
    for alias in ("AU", "au", "Gold"):
        np.testing.assert_array_equal(L.metal_ior(alias, wl)[0], eta)
    assert L.resolve_metal_name("aluminum") == L.resolve_metal_name("Aluminium") == "Al"
    # Beyond the table (J&C ends at 1937 nm): edge held, or zero.
    e, kk = L.metal_ior("Au", 5000.0)
    assert (e, kk) == (teta[-1], tk[-1])
    assert L.metal_ior("Au", 5000.0, extrapolate="zero") == (0.0, 0.0)


def test_metal_unknown():
    with pytest.raises(ValueError, match=r"unknown metal 'Pt'.*'Au'"):
        L.metal_ior("Pt", 500.0)
    with pytest.raises(ValueError, match="unknown metal"):
        presets.metal_table("../illuminants/D65")


# --------------------------------------------------------------------------- glasses


def test_glass_names():
    names = L.glass_names()
    assert {"N-BK7", "N-SF11", "N-F2", "fused_silica", "crown", "flint"} <= set(names)
    kinds = {n: L.glass_info(n)["formula"] for n in names}
    assert kinds["N-BK7"] == "sellmeier" and kinds["crown"] == kinds["flint"] == "cauchy"


def test_n_bk7_nd_and_abbe():
    assert L.glass_nd("N-BK7") == pytest.approx(1.5168, abs=2e-4)
    assert L.glass_abbe("N-BK7") == pytest.approx(64.17, abs=0.1)
    assert L.glass_nd("BK7") == L.glass_nd("n-bk7") == L.glass_nd("N-BK7")


@pytest.mark.parametrize("name", L.glass_names())
def test_glass_matches_published_nd_and_abbe(name):
    info = L.glass_info(name)
    # Catalogue precision: nd to 5 decimals, Abbe number to 2.
    assert L.glass_nd(name) == pytest.approx(info["nd"], abs=1e-5)
    assert L.glass_abbe(name) == pytest.approx(info["abbe"], abs=1e-2)
    lo, hi = info["range_nm"]
    wl = np.linspace(max(lo, 380.0), min(hi, 780.0), 200)
    n = L.glass_ior(name, wl)
    assert np.all(np.diff(n) < 0), "normal dispersion: n falls with wavelength in the visible"
    assert np.all((n > 1.4) & (n < 1.9))


def test_glass_published_values_from_other_sources():
    # Malitson's fused silica against SCHOTT's LITHOSIL-Q fused silica catalogue values
    # (nd 1.45844, νd 67.83): the same material measured independently.
    assert L.glass_nd("fused silica") == pytest.approx(1.45844, abs=3e-5)
    assert L.glass_abbe("fused silica") == pytest.approx(67.83, abs=0.05)
    # SCHOTT N-SF11 catalogue: nd 1.78472, νd 25.68; N-F2: nd 1.62005, νd 36.43.
    assert L.glass_nd("N-SF11") == pytest.approx(1.78472, abs=1e-5)
    assert L.glass_abbe("N-SF11") == pytest.approx(25.68, abs=0.01)
    assert L.glass_nd("N-F2") == pytest.approx(1.62005, abs=1e-5)
    assert L.glass_abbe("N-F2") == pytest.approx(36.43, abs=0.01)


@pytest.mark.parametrize("cauchy, sellmeier", [("crown", "N-K5"), ("flint", "F2")])
def test_cauchy_glasses_follow_their_catalogue_glass(cauchy, sellmeier):
    wl = np.linspace(400.0, 700.0, 301)
    # Two Cauchy terms cannot follow the Sellmeier curve into the blue exactly: ~2e-3 at 400 nm.
    assert np.max(np.abs(L.glass_ior(cauchy, wl) - L.glass_ior(sellmeier, wl))) < 3e-3
    mid = (wl >= 480.0) & (wl <= 660.0)
    assert np.max(np.abs(L.glass_ior(cauchy, wl[mid]) - L.glass_ior(sellmeier, wl[mid]))) < 5e-4
    assert L.glass_info(cauchy)["nd"] == L.glass_info(sellmeier)["nd"]
    assert L.glass_info(cauchy)["abbe"] == L.glass_info(sellmeier)["abbe"]


def test_glass_formulas_by_hand():
    # Sellmeier for N-BK7 at 1 µm, and Cauchy for "crown" at 500 nm, written out.
    l2 = 1.0
    n2 = 1 + 1.03961212 * l2 / (l2 - 0.00600069867) + 0.231792344 * l2 / (l2 - 0.0200179144) \
        + 1.01046945 * l2 / (l2 - 103.560653)
    assert L.glass_ior("N-BK7", 1000.0) == pytest.approx(math.sqrt(n2), rel=1e-14)
    info = L.glass_info("crown")
    assert L.glass_ior("crown", 500.0) == pytest.approx(info["A"] + info["B_nm2"] / 500.0**2, rel=1e-14)


def test_glass_ior_any_sampling():
    rng = np.random.default_rng(3)
    wl = rng.uniform(380.0, 780.0, size=(3, 5, 2))
    n = L.glass_ior("N-SF11", wl)
    assert n.shape == wl.shape
    flat = L.glass_ior("N-SF11", wl.ravel())
    np.testing.assert_array_equal(n.ravel(), flat)


def test_glass_unknown():
    with pytest.raises(ValueError, match=r"unknown glass 'unobtainium'.*N-BK7"):
        L.glass_ior("unobtainium", 500.0)
    for fn in (L.glass_nd, L.glass_abbe, L.glass_info):
        with pytest.raises(ValueError, match="unknown glass"):
            fn("SF57")
    with pytest.raises(ValueError, match="wavelengths"):
        L.glass_ior("N-BK7", [500.0, -1.0])


def test_glasses_file_validation(tmp_path, monkeypatch):
    monkeypatch.setattr(presets, "PRESETS_DIR", tmp_path)
    path = tmp_path / "glasses.toml"
    good = ('schema = 1\n[glass.x]\nformula = "cauchy"\nA = 1.5\nB_nm2 = 4000\nnd = 1.51\nabbe = 60\n'
            'range_nm = [400, 700]\n')
    path.write_text(good)
    assert presets.glasses()["x"]["C_nm4"] == 0.0
    for broken, message in [
        (good.replace('"cauchy"', '"abbe"'), "formula"),
        (good.replace("A = 1.5\n", ""), "A must be"),
        (good.replace("B_nm2 = 4000", 'B_nm2 = "4000"'), "B_nm2 must be"),
        (good.replace("schema = 1", "schema = 2"), "schema"),
        (good.replace("[400, 700]", "[700, 400]"), "range_nm"),
        ("schema = 1\n", "no \\[glass"),
        ("schema = 1\n[glass.x\n", "invalid TOML"),
    ]:
        path.write_text(broken)
        with pytest.raises(ValueError, match=message):
            presets.glasses()


def test_shipped_glasses_toml_is_data_only():
    text = (presets.PRESETS_DIR / "glasses.toml").read_text(encoding="utf-8")
    assert "import" not in text and "eval" not in text
    assert set(presets.glasses()) == set(L.glass_names())
