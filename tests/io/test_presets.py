"""Shipped data tables (presets/) and their loaders (core/presets.py, core/tables.py)."""

import filecmp
import tomllib
import warnings

import numpy as np
import pytest

from spectral_gi.core.io import presets, tables

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # colour warns about the missing matplotlib
    import colour  # test dependency (colour-science 0.4.6): the oracle for the tables

OBSERVERS = {
    "CIE 1931 2 Degree Standard Observer": "1931",
    "CIE 1964 10 Degree Standard Observer": "1964",
}


# --------------------------------------------------------------------------- CIE / colour-science


@pytest.mark.parametrize("name", sorted(OBSERVERS))
def test_cmfs_match_colour_science(name):
    ref = colour.MSDS_CMFS[name]
    for key in (name, OBSERVERS[name]):
        wl, xyz = presets.cmfs(key)
        assert xyz.shape == (471, 3)
        np.testing.assert_array_equal(wl, np.arange(360.0, 831.0))
        np.testing.assert_array_equal(wl, ref.wavelengths)
        np.testing.assert_allclose(xyz, ref.values, rtol=0, atol=1e-9)
    # The files are written with repr(): values are bit-identical, not just close.
    np.testing.assert_array_equal(presets.cmfs(name)[1], ref.values)


def test_cmfs_unknown_observer():
    with pytest.raises(ValueError, match="unknown observer"):
        presets.cmfs("1976")


@pytest.mark.parametrize("name", ["A", "D50", "D65", "E"])
def test_illuminants_match_colour_science(name):
    ref = colour.SDS_ILLUMINANTS[name]
    wl, values = presets.illuminant(name)
    np.testing.assert_array_equal(wl, ref.wavelengths)
    np.testing.assert_array_equal(values, ref.values)


def test_illuminant_unknown_name():
    with pytest.raises(ValueError, match="unknown illuminant"):
        presets.illuminant("D93")
    assert {"A", "D50", "D65", "E"} <= set(presets.illuminant_names())


def test_mallett2019_basis_matches_colour_science():
    ref = colour.recovery.MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019
    wl, rgb = presets.mallett2019_basis()
    np.testing.assert_array_equal(wl, ref.wavelengths)
    np.testing.assert_array_equal(rgb, ref.values)
    # The three basis spectra sum to 1 at every wavelength (to the ~1e-5 the paper stores).
    np.testing.assert_allclose(rgb.sum(axis=1), 1.0, atol=2e-5)


def test_regenerated_tables_identical_to_shipped(tmp_path):
    written = tables.generate_tables(tmp_path)
    assert written, "generate_tables wrote nothing"
    for path in written:
        rel = path.relative_to(tmp_path)
        shipped = presets.PRESETS_DIR / rel
        assert shipped.is_file(), f"{rel} is generated but not shipped"
        assert filecmp.cmp(path, shipped, shallow=False), f"{rel} differs from the shipped file"
    # No leftover temporary files from the atomic writes.
    assert not [p for p in tmp_path.rglob("*") if p.name.startswith(".")]


def test_d65_white_point():
    """D65 x CMF summed over 360..830 nm at D65's native 5 nm sampling, Y normalised to 1."""
    wl, xyz_bar = presets.cmfs("1931")
    dwl, d65 = presets.illuminant("D65")
    inside = (dwl >= 360.0) & (dwl <= 830.0)
    idx = np.searchsorted(wl, dwl[inside])
    np.testing.assert_array_equal(wl[idx], dwl[inside])
    XYZ = (d65[inside, None] * xyz_bar[idx]).sum(axis=0)
    XYZ /= XYZ[1]
    assert XYZ[1] == 1.0
    xy = XYZ[:2] / XYZ.sum()
    ref = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    np.testing.assert_allclose(ref, [0.3127, 0.3290])
    np.testing.assert_allclose(xy, ref, atol=1e-4)


# --------------------------------------------------------------------------- Cornell box


@pytest.fixture(scope="module")
def cbox():
    return presets.load_cornell_box_data()


def test_cornell_reflectances(cbox):
    refl = cbox["reflectance"]
    assert set(refl) == {"white", "red", "green"}
    for name, (wl, values) in refl.items():
        assert wl.shape == values.shape == (76,)
        np.testing.assert_array_equal(wl, np.arange(400.0, 701.0, 4.0))
        assert np.all((values >= 0.0) & (values <= 1.0)), name
    assert refl["white"][1][0] == 0.343
    assert refl["green"][1][0] == 0.092
    assert refl["red"][1][0] == 0.040
    assert refl["red"][1][-1] == 0.642
    # Published ranges: the red paint peaks at 0.657 and never falls below 0.040.
    assert refl["red"][1].max() == 0.657 and refl["red"][1].min() == 0.040
    assert refl["green"][1].max() == 0.481
    assert refl["white"][1].max() == 0.777


def test_cornell_light_spectrum(cbox):
    wl, values = cbox["light"]
    np.testing.assert_array_equal(wl, [400.0, 500.0, 600.0, 700.0])
    np.testing.assert_array_equal(values, [0.0, 8.0, 15.6, 18.4])


def test_cornell_surfaces(cbox):
    assert cbox["units"] == "mm"
    names = [s["name"] for s in cbox["surfaces"]]
    assert names == [
        "floor", "light", "ceiling", "back_wall",
        "right_wall", "left_wall", "short_block", "tall_block",
    ]
    materials = {s["name"]: s["material"] for s in cbox["surfaces"]}
    assert materials["left_wall"] == "red" and materials["right_wall"] == "green"
    assert materials["light"] == "light"
    counts = {s["name"]: len(s["quads"]) for s in cbox["surfaces"]}
    assert counts["short_block"] == counts["tall_block"] == 5
    # Published: 6 room quads (incl. the light) + 2 blocks x 5 faces.
    assert sum(counts.values()) == 16
    for s in cbox["surfaces"]:
        assert s["quads"].dtype == np.float64 and s["quads"].shape[1:] == (4, 3)
    # Box extents as published (mm).
    allv = np.concatenate([s["quads"].reshape(-1, 3) for s in cbox["surfaces"]])
    np.testing.assert_array_equal(allv.min(axis=0), [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(allv.max(axis=0), [556.0, 548.8, 559.2])


def _fourth_vertex_offplane(q):
    n = np.cross(q[1] - q[0], q[2] - q[0])
    return abs(np.dot(q[3] - q[0], n / np.linalg.norm(n)))


def _newell_normal(q):
    n = np.zeros(3)
    for a, b in zip(q, np.roll(q, -1, axis=0)):
        n += [(a[1] - b[1]) * (a[2] + b[2]), (a[2] - b[2]) * (a[0] + b[0]), (a[0] - b[0]) * (a[1] + b[1])]
    return n / np.linalg.norm(n)


def test_cornell_quads_planarity(cbox):
    """All published quads are planar except the left (red) wall.

    The box was measured, not drawn: the floor is 552.8 mm wide at the front and
    549.6 mm at the back while the ceiling is 556.0 mm, so the left wall's four
    published corners are not coplanar; the 4th lies 3.2 mm off the plane of
    the first three. That is what the data says, and it is kept as published.
    """
    for s in cbox["surfaces"]:
        for i, q in enumerate(s["quads"]):
            d = _fourth_vertex_offplane(q)
            if s["name"] == "left_wall":
                assert 3.1 < d < 3.3, d
            else:
                assert d < 1e-9, (s["name"], i, d)


def test_cornell_quads_face_interior(cbox):
    """Published winding (right-hand rule) faces into the box / out of the blocks."""
    centre = np.array([278.0, 274.4, 279.6])
    for s in cbox["surfaces"]:
        block_centre = s["quads"].reshape(-1, 3).mean(axis=0)
        for q in s["quads"]:
            n = _newell_normal(q)
            c = q.mean(axis=0)
            target = c - block_centre if s["name"].endswith("block") else centre - c
            assert np.dot(n, target) > 0, s["name"]


def test_cornell_light_in_ceiling(cbox):
    """As published the light lies in the ceiling plane (y = 548.8), inside its outline.

    It is not below the ceiling: any offset to avoid coincident surfaces is a
    renderer's choice, so here it is asserted to be at most 1 mm below and facing down.
    """
    surf = {s["name"]: s["quads"] for s in cbox["surfaces"]}
    light, ceiling = surf["light"][0], surf["ceiling"][0]
    assert np.ptp(light[:, 1]) == 0.0 and np.ptp(ceiling[:, 1]) == 0.0
    gap = ceiling[0, 1] - light[0, 1]
    assert 0.0 <= gap < 1.0
    assert ceiling[:, 0].min() < light[:, 0].min() < light[:, 0].max() < ceiling[:, 0].max()
    assert ceiling[:, 2].min() < light[:, 2].min() < light[:, 2].max() < ceiling[:, 2].max()
    np.testing.assert_array_equal(np.ptp(light, axis=0), [130.0, 0.0, 105.0])
    assert _newell_normal(light)[1] == pytest.approx(-1.0)


def test_cornell_camera(cbox):
    cam = cbox["camera"]
    assert cam["position"] == [278.0, 273.0, -800.0]
    assert cam["direction"] == [0.0, 0.0, 1.0]
    assert cam["up"] == [0.0, 1.0, 0.0]
    assert cam["focal_length_mm"] == 35.0
    assert cam["film_width_mm"] == cam["film_height_mm"] == 25.0


def test_cornell_geometry_is_valid_toml():
    path = presets.PRESETS_DIR / "scenes" / "cornell_box" / "geometry.toml"
    with path.open("rb") as fh:
        doc = tomllib.load(fh)
    assert doc["units"] == "mm"


# --------------------------------------------------------------------------- read_table


def test_read_table_relative_and_absolute_agree():
    rel = presets.read_table("illuminants/D65.csv")
    absolute = presets.read_table(presets.PRESETS_DIR / "illuminants" / "D65.csv")
    assert rel[2] == absolute[2] == ["value"]
    np.testing.assert_array_equal(rel[0], absolute[0])
    np.testing.assert_array_equal(rel[1], absolute[1])
    assert rel[1].shape == (rel[0].size, 1)


def test_read_table_accepts_comments_and_blank_lines(tmp_path):
    path = tmp_path / "ok.csv"
    path.write_text("# comment\nwavelength_nm,a,b\n\n400,0.5,1\n410,0.25,2\n")
    wl, values, names = presets.read_table(str(path))
    assert names == ["a", "b"]
    np.testing.assert_array_equal(wl, [400.0, 410.0])
    np.testing.assert_array_equal(values, [[0.5, 1.0], [0.25, 2.0]])


@pytest.mark.parametrize(
    "content",
    [
        "",  # empty
        "wavelength_nm,value\n",  # no rows
        "lambda,value\n400,1\n",  # wrong first column
        "wavelength_nm\n400\n",  # no value column
        "wavelength_nm,value,value\n400,1,2\n",  # duplicate column
        "wavelength_nm,value\n400,1\n410\n",  # short row
        "wavelength_nm,value\n400,1,2\n",  # long row
        "wavelength_nm,value\n400,abc\n",  # not a number
        "wavelength_nm,value\n400,nan\n",  # not finite
        "wavelength_nm,value\n410,1\n400,2\n",  # decreasing
        "wavelength_nm,value\n400,1\n400,2\n",  # repeated wavelength
    ],
)
def test_read_table_malformed_raises_naming_file(tmp_path, content):
    path = tmp_path / "broken_table.csv"
    path.write_text(content)
    with pytest.raises(ValueError, match="broken_table.csv"):
        presets.read_table(path)


def test_read_table_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError):
        presets.read_table(tmp_path / "nope.csv")
