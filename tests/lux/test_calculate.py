"""The integrator interface: a stand-in integrator (the CIE 171 point-source closed form) run
through the .pts → CSV workflow and on calculation surfaces."""
import numpy as np
import pytest

from spectral_gi.core.lux import LuxError, calculate_pts_file, calculate_surface, cie171, read_results_csv
from spectral_gi.core.lux import report, workplane, write_pts


def _analytic(scene, points, normals, samples=16):
    """A stand-in for the illuminance integrator: the exact direct illuminance of the point lights."""
    lux = np.zeros(len(points))
    for li in scene.lights:
        lux += cie171.point_source_illuminance(li.intensity, li.position, points, normals)
    return lux, lux / np.sqrt(samples)


def test_pts_to_csv_through_an_integrator(tmp_path):
    case = cie171.case_5_2()
    write_pts(tmp_path / "in.pts", case.points, case.normals * 3.0)
    lux, se = calculate_pts_file(_analytic, case.scene, tmp_path / "in.pts", tmp_path / "out.csv", samples=4)
    np.testing.assert_allclose(lux, case.expected_direct, rtol=1e-12)
    np.testing.assert_allclose(se, case.expected_direct / 2, rtol=1e-12)
    d = read_results_csv(tmp_path / "out.csv")
    np.testing.assert_allclose(d["lux"], case.expected_direct, rtol=1e-12)
    np.testing.assert_allclose(np.stack([d["x"], d["y"], d["z"]], axis=1), case.points)


def test_surface_statistics_from_an_integrator():
    case = cie171.case_5_2(intensity=1000.0, height=2.0)
    w = workplane([(-2, -2), (2, -2), (2, 2), (-2, 2)], height=0.0, band=0.0, spacing=1.0)
    lux, se = calculate_surface(_analytic, case.scene, w)
    st = report.statistics(w, lux, se, samples=16)
    # 16 cells centred at (±0.5, ±1.5)²: E = I h / d³ with h = 2
    r2 = np.array([0.5, 2.5, 4.5])  # x² + y² for (0.5, 0.5), (0.5, 1.5), (1.5, 1.5)
    e = 1000.0 * 2.0 / (4.0 + r2) ** 1.5
    assert st.mean == pytest.approx((4 * e[0] + 8 * e[1] + 4 * e[2]) / 16)
    assert (st.minimum, st.maximum) == (pytest.approx(e[2]), pytest.approx(e[0]))
    assert st.max_rel_std_error == pytest.approx(0.25)


@pytest.mark.parametrize("bad, what", [
    (lambda s, p, n: np.zeros(len(p)), "must return"),
    (lambda s, p, n: (np.zeros(len(p) - 1), np.zeros(len(p))), "lux must have one value per point"),
    (lambda s, p, n: (np.full(len(p), np.nan), np.zeros(len(p))), "lux must be finite"),
    (lambda s, p, n: (np.zeros(len(p)), -np.ones(len(p))), "std_error must be ≥ 0"),
])
def test_bad_integrator_results_are_named(tmp_path, bad, what):
    case = cie171.case_5_2()
    write_pts(tmp_path / "in.pts", case.points, case.normals)
    (tmp_path / "out.csv").write_text("old\n")
    with pytest.raises(LuxError, match=what):
        calculate_pts_file(bad, case.scene, tmp_path / "in.pts", tmp_path / "out.csv")
    assert (tmp_path / "out.csv").read_text() == "old\n"
