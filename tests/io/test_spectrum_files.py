"""Tabulated spectrum files (core/io/spectrum_file.py): parsing, scale detection, clear errors,
and the colour of what they become (oracle: colour-science 0.4.6)."""
import numpy as np
import pytest

from spectral_gi.core import constants as C
from spectral_gi.core.io.spectrum_file import (
    SpectrumFileError, load_spectrum_file, parse_spectrum_text, spectrum_file_coeffs)
from spectral_gi.core.spectra import moments

colour = pytest.importorskip("colour")

SHAPE = colour.SpectralShape(360, 830, 1)


def write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def patch_sd(name="dark skin"):
    return colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"][name]


def XYZ_of(values, illuminant="D65"):
    """colour-science XYZ (Y = 100 for the perfect white) of values on the 360–830 nm grid."""
    sd = colour.SpectralDistribution(dict(zip(np.arange(360, 831), values)))
    return colour.sd_to_XYZ(sd, colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"],
                            colour.SDS_ILLUMINANTS[illuminant].copy().align(SHAPE), method="Integration")


def tabulated(coeffs, kind):
    return moments.tabulate(np.asarray(coeffs).reshape(1, -1), np.array([kind], np.int32))[0].astype(float)


@pytest.mark.parametrize("fmt", ["csv_header", "whitespace_percent", "semicolon_comments"])
def test_a_measured_patch_keeps_its_colour(tmp_path, fmt):
    sd = patch_sd()
    wl, v = sd.wavelengths, sd.values
    if fmt == "csv_header":
        text = "wavelength_nm,reflectance\n" + "".join(f"{w:g},{x:.6f}\n" for w, x in zip(wl, v))
    elif fmt == "whitespace_percent":
        text = "".join(f"  {w:g}\t {100 * x:.4f}\n" for w, x in zip(wl, v))
    else:
        text = "# measured\n\n" + "".join(f"{w:g};{x:.6f}\n" for w, x in zip(wl, v)) + "# end\n"
    path = write(tmp_path, "patch.txt", text)
    coeffs, sf = spectrum_file_coeffs(path, "reflectance")
    assert sf.scale == ("percent" if fmt == "whitespace_percent" else "fraction")
    np.testing.assert_allclose(sf.values, v, atol=1e-5)
    assert coeffs.shape == (C.N_COEFFS_DEFAULT,)
    # the reconstruction has the patch's colour under D65: ΔE2000 < 1 against colour-science
    rec = tabulated(coeffs, C.SPECTRUM_BOUNDED)
    ref = colour.sd_to_XYZ(sd.copy().align(SHAPE, extrapolator_kwargs={"method": "Constant"}),
                           illuminant=colour.SDS_ILLUMINANTS["D65"].copy().align(SHAPE), method="Integration")
    got = XYZ_of(rec)
    white = colour.xy_to_XYZ(colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]) * 100
    de = colour.delta_E(colour.XYZ_to_Lab(got / 100, white / 100), colour.XYZ_to_Lab(ref / 100, white / 100),
                        method="CIE 2000")
    assert de < 1.0


def test_an_emission_file_becomes_its_shape_peak_one(tmp_path):
    sd = colour.SDS_ILLUMINANTS["A"].copy().align(colour.SpectralShape(300, 830, 5))
    path = write(tmp_path, "a.csv", "".join(f"{w:g} {x:.5f}\n" for w, x in zip(sd.wavelengths, sd.values)))
    coeffs, sf = spectrum_file_coeffs(path, "emission")
    assert sf.scale == "relative" and sf.values.max() == pytest.approx(1.0)
    rec = tabulated(coeffs, C.SPECTRUM_UNBOUNDED)
    xy = colour.XYZ_to_xy(XYZ_of(rec, "E"))
    ref = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["A"]
    np.testing.assert_allclose(xy, ref, atol=2e-3)


@pytest.mark.parametrize("text, needle", [
    ("400,0.5\n500,abc\n780,0.4\n", "line 2: 'abc' is not a number"),
    ("380,0.5\n600,0.4\n500,0.3\n780,0.2\n", "line 3: wavelength 500 nm does not increase"),
    ("380,0.5\n500,0.5\n500,0.6\n780,0.2\n", "line 3: wavelength 500 nm does not increase"),
    ("380,0.5\n500,-0.1\n780,0.2\n", "line 2: negative value"),
    ("380,0.5\n500,1e999\n780,0.2\n", "line 2: wavelength and value must be finite"),
    ("380,0.5\n500,nan\n780,0.2\n", "line 2: 'nan' is not a number"),
    ("380,0.5\n5_00,0.1\n780,0.2\n", "line 2: '5_00' is not a number"),
    ("400,0.5\n780,0.2\n", "must cover 380–780 nm"),
    ("0.38,0.5\n0.78,0.2\n", "must cover 380–780 nm"),
    ("380,0.5,1\n780,0.2,1\n", "line 1: expected 2 columns"),
    ("380,50\n500,150\n780,20\n", "line 2: reflectance 150 is above 100"),
    ("# only a comment\n", "needs at least 2 samples"),
    ("wl,value\n380,0.5\nwl,value\n780,0.5\n", "line 3: 'wl' is not a number"),
])
def test_bad_files_name_the_file_and_line(tmp_path, text, needle):
    path = write(tmp_path, "bad.csv", text)
    with pytest.raises(SpectrumFileError) as e:
        load_spectrum_file(path, "reflectance")
    assert str(path) in str(e.value) and needle in str(e.value)


def test_missing_file_and_empty_emission_are_errors(tmp_path):
    with pytest.raises(SpectrumFileError, match="no such file"):
        load_spectrum_file(tmp_path / "nope.csv")
    with pytest.raises(SpectrumFileError, match="every value is 0"):
        parse_spectrum_text("380 0\n780 0\n", "dark.csv", "emission")


def test_reflectance_scale_detection():
    frac = parse_spectrum_text("380 0.2\n780 1.03\n", "f", "reflectance")
    assert frac.scale == "fraction" and frac.values.max() == 1.0 and frac.notes  # clipped, said so
    pct = parse_spectrum_text("380 2\n780 90\n", "p", "reflectance")
    assert pct.scale == "percent"
    np.testing.assert_allclose(pct.values, [0.02, 0.9])
    # an emission file is a shape: any scale
    em = parse_spectrum_text("380 200\n780 400\n", "e", "emission")
    np.testing.assert_allclose(em.values, [0.5, 1.0])
