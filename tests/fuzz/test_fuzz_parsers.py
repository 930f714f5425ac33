"""Fuzzing the photometric (IES LM-63, EULUMDAT) and spectrum-file parsers.

Files are generated from each format's grammar (with values from tiny to near the float64
limit, so the files' multipliers can overflow) and then mutated token by token. The
contract: the parser returns a result every later stage accepts (finite, non-negative
candela of at most MAX_PHOTOMETRIC, a profile the scene validator takes; a spectrum whose
coefficients are finite) or raises its own error (PhotometricError, SpectrumFileError),
whose message is one line naming the file. Never another exception, never an infinite or
NaN value.
"""
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from helpers import furnace_scene

from spectral_gi.core import scene as S
from spectral_gi.core.io.spectrum_file import SpectrumFileError, parse_spectrum_text
from spectral_gi.core.photometry.profiles import PhotometricError, read_profile
from spectral_gi.core.scene.checks import MAX_PHOTOMETRIC

pytestmark = pytest.mark.fuzz

# numbers as files write them, from ordinary to absurd
magnitudes = st.sampled_from([0.0, 1e-300, 1e-6, 0.5, 1.0, 100.0, 1e4, 1e12, 1e100, 1e200, 1e300, 1.7e308])
positive = st.builds(lambda m, f: m * f, magnitudes, st.floats(0.0, 1.0))
BAD_TOKENS = ["1_0", "nan", "NaN", "inf", "-inf", "Infinity", "1e999", "-1e999", "", " ", "0x10", "1,5", "1.2.3",
              "\u0663", "1e", "e5", "--1", "+", "9" * 500, "-0", "0.0", "-1", "1e-400", "abc", "\x00", "1" * 40]
tokens = st.one_of(st.sampled_from(BAD_TOKENS), st.text(max_size=12),
                   st.floats(allow_nan=True, allow_infinity=True).map(repr))


def _fmt(x):
    return repr(float(x))


@st.composite
def ies_text(draw):
    n_v = draw(st.integers(2, 6))
    top = draw(st.sampled_from([90.0, 180.0]))
    theta = np.linspace(0.0, top, n_v)
    cset = draw(st.sampled_from(["single", "quadrant", "half", "full", "c90"]))
    c = {"single": [0.0], "quadrant": [0.0, 45.0, 90.0], "half": [0.0, 90.0, 180.0],
         "full": [0.0, 90.0, 180.0, 270.0, 360.0], "c90": [90.0, 180.0, 270.0]}[cset]
    cd = [draw(positive) for _ in range(n_v * len(c))]
    multiplier = draw(positive.filter(lambda x: x > 0))
    lumens = draw(st.sampled_from([-1.0, 1000.0, 1e300]))
    lamps = draw(st.sampled_from([1, 2, 10 ** 10]))
    head = ["IESNA:LM-63-2002", "[TEST] fuzz", "TILT=NONE",
            f"{lamps} {_fmt(lumens)} {_fmt(multiplier)} {n_v} {len(c)} 1 2 0 0 0",
            "1.0 1.0 10.0"]
    body = [" ".join(_fmt(t) for t in theta), " ".join(_fmt(x) for x in c)]
    body += [" ".join(_fmt(x) for x in cd[k * n_v:(k + 1) * n_v]) for k in range(len(c))]
    return "\n".join(head + body) + "\n"


@st.composite
def ldt_text(draw):
    isym = draw(st.sampled_from([0, 1, 2, 3, 4]))
    mc = 4 * draw(st.integers(1, 3))
    ng = draw(st.integers(2, 5))
    c = [i * 360.0 / mc for i in range(mc)]
    g = list(np.linspace(0.0, draw(st.sampled_from([90.0, 180.0])), ng))
    planes = {0: mc, 1: 1, 2: mc // 2 + 1, 3: mc // 2 + 1, 4: mc // 4 + 1}[isym]
    cfli = draw(positive.filter(lambda x: x > 0))
    flux = draw(positive.filter(lambda x: x > 0))
    n_lamps = draw(st.sampled_from([1, -1, 3]))
    lines = ["fuzz company", "1", str(isym), str(mc), _fmt(360.0 / mc), str(ng), _fmt(g[1] - g[0]),
             "report", "luminaire", "number", "file.ldt", "date"]
    lines += ["100", "100", "50", "80", "80", "0", "0", "0", "0", "100", "100", _fmt(cfli), "0", "1",
              str(n_lamps), "lamp", _fmt(flux), "3000 K", "1B", "10"]
    lines += ["0.5"] * 10 + [_fmt(x) for x in c] + [_fmt(x) for x in g]
    lines += [_fmt(draw(positive)) for _ in range(planes * ng)]
    return "\n".join(lines) + "\n"


def _mutate(draw, text, sep):
    parts = text.split(sep)
    for _ in range(draw(st.integers(1, 3))):
        k = draw(st.integers(0, len(parts) - 1))
        how = draw(st.sampled_from(["replace", "delete", "duplicate"]))
        if how == "replace":
            parts[k] = draw(tokens)
        elif how == "delete" and len(parts) > 1:
            del parts[k]
        else:
            parts.insert(k, parts[k])
    return sep.join(parts)


def _check_profile_contract(path):
    try:
        pr = read_profile(path)
    except PhotometricError as e:
        msg = str(e)
        assert msg and "\n" not in msg and str(path.name) in msg
        return None
    assert np.all(np.isfinite(pr.candela)) and pr.candela.min() >= 0.0 and pr.candela.max() <= MAX_PHOTOMETRIC
    sc = furnace_scene()
    sc.profiles.append(pr)
    S.validate(sc)  # what the parser returns, the scene takes
    return pr


@given(ies_text())
def test_generated_ies_files_parse_or_raise_their_error(tmp_path_factory, text):
    path = tmp_path_factory.mktemp("ies") / "f.ies"
    path.write_text(text, encoding="utf-8")
    _check_profile_contract(path)


@given(ldt_text())
def test_generated_eulumdat_files_parse_or_raise_their_error(tmp_path_factory, text):
    path = tmp_path_factory.mktemp("ldt") / "f.ldt"
    path.write_text(text, encoding="utf-8")
    _check_profile_contract(path)


@given(st.data())
def test_mutated_ies_files_parse_or_raise_their_error(tmp_path_factory, data):
    text = _mutate(data.draw, data.draw(ies_text()), data.draw(st.sampled_from([" ", "\n"])))
    path = tmp_path_factory.mktemp("ies") / "m.ies"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    _check_profile_contract(path)


@given(st.data())
def test_mutated_eulumdat_files_parse_or_raise_their_error(tmp_path_factory, data):
    text = _mutate(data.draw, data.draw(ldt_text()), "\n")
    path = tmp_path_factory.mktemp("ldt") / "m.ldt"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    _check_profile_contract(path)


@given(st.binary(max_size=400), st.sampled_from([".ies", ".ldt"]))
def test_arbitrary_bytes_are_refused_with_the_parsers_error(tmp_path_factory, blob, suffix):
    path = tmp_path_factory.mktemp("bin") / ("b" + suffix)
    path.write_bytes(blob)
    _check_profile_contract(path)


def test_an_overflowing_eulumdat_multiplier_is_refused_not_infinite(tmp_path):
    # cd/klm × a lamp flux of 1e300 lm overflows float64: the probe got infinite candela back
    lines = ["c", "1", "1", "4", "90", "2", "90", "r", "l", "n", "f.ldt", "d", "100", "100", "50", "80", "80", "0", "0",
             "0", "0", "100", "100", "1", "0", "1", "1", "lamp", "1e300", "3000 K", "1B", "10"]
    lines += ["0.5"] * 10 + ["0", "90", "180", "270", "0", "90", "1e10", "5e9"]
    path = tmp_path / "over.ldt"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(PhotometricError, match="over.ldt: .*(NaN or Inf|at most)"):
        read_profile(path)


# --------------------------------------------------------------------------- spectrum files

@st.composite
def spectrum_text(draw):
    n = draw(st.integers(2, 12))
    lo = draw(st.sampled_from([300.0, 360.0, 380.0, 400.0]))
    hi = draw(st.sampled_from([700.0, 780.0, 830.0]))
    wl = np.linspace(lo, hi, n)
    scale = draw(st.sampled_from([1.0, 100.0, 1e-300, 1e300]))
    vals = [scale * draw(st.floats(0.0, 1.0)) for _ in range(n)]
    sep = draw(st.sampled_from([",", ";", "\t", " "]))
    lines = ["wavelength" + sep + "value"] if draw(st.booleans()) else []
    lines += [f"{w!r}{sep}{v!r}" for w, v in zip(wl, vals)]
    return "\n".join(lines) + "\n"


def _check_spectrum_contract(text, kind):
    try:
        sf = parse_spectrum_text(text, "fuzz.csv", kind)
    except SpectrumFileError as e:
        assert str(e) and "\n" not in str(e) and str(e).startswith("fuzz.csv")
        return
    assert np.all(np.isfinite(sf.wavelengths)) and np.all(np.diff(sf.wavelengths) > 0)
    assert np.all(np.isfinite(sf.values)) and sf.values.min() >= 0.0
    if kind == "reflectance":
        assert sf.values.max() <= 1.0
    else:
        assert math.isclose(float(sf.values.max()), 1.0)
    assert np.all(np.isfinite(sf.coeffs()))


@given(spectrum_text(), st.sampled_from(["reflectance", "emission"]))
def test_generated_spectrum_files_parse_or_raise_their_error(text, kind):
    _check_spectrum_contract(text, kind)


@given(st.data(), st.sampled_from(["reflectance", "emission"]))
def test_mutated_spectrum_files_parse_or_raise_their_error(data, kind):
    text = data.draw(spectrum_text())
    _check_spectrum_contract(_mutate(data.draw, text, data.draw(st.sampled_from(["\n", ",", "\t"]))), kind)
