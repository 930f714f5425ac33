"""Sensor points in (.pts) and results out (CSV)."""
import numpy as np
import pytest

from spectral_gi.core.lux import points as P
from spectral_gi.core.lux import LuxError


def test_parse_pts_comments_blank_lines_and_normalised_normals(tmp_path):
    f = tmp_path / "room.pts"
    f.write_text("# sensors\n\n1 2 3 0 0 2\n  4.5 -1 0.75   3 4 0  # a comment\n\n")
    p, n = P.read_pts(f)
    np.testing.assert_array_equal(p, [[1, 2, 3], [4.5, -1, 0.75]])
    np.testing.assert_allclose(n, [[0, 0, 1], [0.6, 0.8, 0]])


@pytest.mark.parametrize("text, line, what", [
    ("0 0 0 0 0 1\n1 2 3 0 0\n", 2, "expected 6 numbers"),
    ("# c\n\n0 0 0 0 0 1 7\n", 3, "expected 6 numbers"),
    ("0 0 0 0 0 1\n0 0 x 0 0 1\n", 2, "not a number"),
    ("0 0 nan 0 0 1\n", 1, "non-finite"),
    ("0 0 0 0 0 1\n0 0 0 0 0 1\n0 inf 0 0 0 1\n", 3, "non-finite"),
    ("0 0 0 0 0 1\n\n1 1 1 0 0 0\n", 3, "normal is zero"),
])
def test_pts_errors_name_file_and_line(tmp_path, text, line, what):
    f = tmp_path / "bad.pts"
    f.write_text(text)
    with pytest.raises(LuxError, match=what) as exc:
        P.read_pts(f)
    assert f"{f}, line {line}:" in str(exc.value)
    assert isinstance(exc.value, ValueError)


def test_pts_empty_and_missing_files(tmp_path):
    f = tmp_path / "empty.pts"
    f.write_text("# nothing\n\n")
    with pytest.raises(LuxError, match="no points"):
        P.read_pts(f)
    with pytest.raises(LuxError, match="no such points file"):
        P.read_pts(tmp_path / "absent.pts")


def test_pts_round_trip(tmp_path):
    rng = np.random.default_rng(1)
    p = rng.normal(size=(20, 3))
    n = rng.normal(size=(20, 3))
    P.write_pts(tmp_path / "a.pts", p, n)
    p2, n2 = P.read_pts(tmp_path / "a.pts")
    np.testing.assert_array_equal(p2, p)
    np.testing.assert_allclose(n2, n / np.linalg.norm(n, axis=1, keepdims=True), rtol=1e-15)


def test_results_csv_header_order_and_values(tmp_path):
    p = np.array([[3.0, 0, 0], [1.0, 0, 0], [2.0, 0.5, 0.75]])
    n = np.array([[0, 0, 1.0], [0, 0, 2.0], [1.0, 0, 0]])
    lux = np.array([300.0, 100.0, 200.25])
    se = np.array([3.0, 1.0, 0.5])
    out = tmp_path / "res.csv"
    P.write_results_csv(out, p, n, lux, se)
    lines = out.read_text().splitlines()
    assert lines[0] == "x,y,z,nx,ny,nz,lux,std_error"
    assert len(lines) == 4
    assert lines[1].split(",")[0] == "3.0" and lines[2].split(",")[0] == "1.0"  # input order, not sorted
    assert lines[3] == "2.0,0.5,0.75,1.0,0.0,0.0,200.25,0.5"
    back = P.read_results_csv(out)
    np.testing.assert_array_equal(back["lux"], lux)
    np.testing.assert_array_equal(back["std_error"], se)
    np.testing.assert_array_equal(back["nz"], [1, 1, 0])  # normals written normalised


def test_results_csv_rejects_bad_arrays_and_keeps_the_old_file(tmp_path):
    out = tmp_path / "res.csv"
    out.write_text("old\n")
    p = np.zeros((2, 3))
    n = np.tile([0, 0, 1.0], (2, 1))
    with pytest.raises(LuxError, match="lux must have one value per point"):
        P.write_results_csv(out, p, n, [1.0], [0.0, 0.0])
    with pytest.raises(LuxError, match="std_error must be finite"):
        P.write_results_csv(out, p, n, [1.0, 2.0], [0.0, np.nan])
    with pytest.raises(LuxError, match="lux must be ≥ 0"):
        P.write_results_csv(out, p, n, [1.0, -2.0], [0.0, 0.0])
    with pytest.raises(LuxError, match="normal 1 is zero"):
        P.write_results_csv(out, p, [[0, 0, 1], [0, 0, 0]], [1.0, 2.0], [0.0, 0.0])
    assert out.read_text() == "old\n"
    assert sorted(x.name for x in tmp_path.iterdir()) == ["res.csv"]  # no temporary file left


def test_public_names():
    import spectral_gi.core.lux as lux

    assert len(lux.__all__) == len(set(lux.__all__))
    for name in lux.__all__:
        assert hasattr(lux, name), name
    assert issubclass(lux.LuxError, ValueError)
