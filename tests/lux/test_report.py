"""Statistics, maintenance factor, CSV/JSON outputs and the one-page report."""
import json

import numpy as np
import pytest

from spectral_gi.core.lux import grids as G
from spectral_gi.core.lux import report as R
from spectral_gi.core.lux import LuxError
from spectral_gi.core.lux.points import read_results_csv

LUMINAIRES = [
    {"type": "Recessed panel 600", "count": 6, "lumens": 3400.0, "profile": "/data/ies/panel600.ies"},
    {"type": "Downlight", "count": 2, "lumens": 1200, "profile": "dl.ldt", "power_w": 11.5},
]


def _square():
    """A 1 × 1 m grid of 2 × 2 cells (0.5 m)."""
    return G.rectangle_grid((0, 0, 0), (1, 0, 0), (0, 1, 0), spacing=0.5, name="desk")


def test_statistics_against_hand_values():
    s = _square()
    st = R.statistics(s, [100.0, 200.0, 300.0, 400.0], [1.0, 2.0, 3.0, 8.0], samples=64)
    assert (st.mean, st.minimum, st.maximum) == (250.0, 100.0, 400.0)
    assert st.u0 == pytest.approx(0.4) and st.ud == pytest.approx(0.25)
    assert st.max_rel_std_error == pytest.approx(0.02) and st.mean_rel_std_error == pytest.approx(0.0125)
    assert st.samples == 64 and st.n_points == 4 and st.area == pytest.approx(1.0)
    assert st.maintained and st.maintenance_factor == 1.0


def test_mean_is_area_weighted_on_meshes():
    """Vertices weigh a third of their triangles' area: [1/3, 1/6, 1/3, 1/6] on this square."""
    pos = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    v = G.mesh_vertex_points(pos, [[0, 1, 2], [0, 2, 3]])
    st = R.statistics(v, [100.0, 400.0, 100.0, 400.0])
    assert st.mean == pytest.approx(200.0)  # the plain mean would be 250
    assert st.u0 == pytest.approx(0.5)
    # faces weigh their triangle's area: 1.5 m² and 0.5 m²
    pos = np.array([[0, 0, 0], [3, 0, 0], [0, 1, 0], [0, 2, 0], [1, 2, 0], [0, 3, 0]], float)
    f = G.mesh_face_points(pos, [[0, 1, 2], [3, 4, 5]])
    np.testing.assert_allclose(f.weights, [1.5, 0.5])
    assert R.statistics(f, [100.0, 400.0]).mean == pytest.approx(175.0)


def test_maintenance_factor_scales_everything_but_the_ratios():
    s = G.rectangle_grid((0, 0, 0), (1, 0, 0), (0, 1, 0), spacing=0.5,
                         maintenance_factor=G.maintenance_factor(llmf=0.9, lsf=1.0, lmf=0.9, rsmf=0.95))
    lux, se = [100.0, 200.0, 300.0, 400.0], [1.0, 2.0, 3.0, 8.0]
    m = R.statistics(s, lux, se)
    i = R.statistics(s, lux, se, maintained=False)
    assert m.maintenance_factor == pytest.approx(0.7695)
    assert m.mean == pytest.approx(0.7695 * 250) and m.minimum == pytest.approx(76.95)
    assert (i.mean, i.minimum, i.maximum) == (250.0, 100.0, 400.0) and not i.maintained
    assert m.u0 == pytest.approx(i.u0) and m.ud == pytest.approx(i.ud)
    assert m.max_rel_std_error == pytest.approx(i.max_rel_std_error)


def test_statistics_edge_cases_and_errors():
    s = _square()
    st = R.statistics(s, np.zeros(4))
    assert st.u0 is None and st.ud is None and st.max_rel_std_error is None
    with pytest.raises(LuxError, match=r"shape \(4,\)"):
        R.statistics(s, [1.0, 2.0])
    with pytest.raises(LuxError, match="finite"):
        R.statistics(s, [1.0, 2.0, np.nan, 1.0])
    with pytest.raises(LuxError, match="samples"):
        R.statistics(s, np.ones(4), samples=0)


def test_luminaire_schedule_checks():
    lums = R.check_luminaires(LUMINAIRES)
    assert lums[1]["lumens"] == 1200.0 and lums[1]["power_w"] == 11.5
    assert R.check_luminaires(None) == []
    for bad, what in [({"type": "x", "count": 0, "lumens": 1}, "count"), ({"type": "x", "count": 1}, "lumens"),
                      ({"type": "", "count": 1, "lumens": 1}, "type"),
                      ({"type": "x", "count": 1, "lumens": -5}, "lumens"),
                      ({"type": "x", "count": 1.5, "lumens": 5}, "count")]:
        with pytest.raises(LuxError, match=what):
            R.check_luminaires([bad])


def test_surface_csv_holds_maintained_values(tmp_path):
    s = G.rectangle_grid((0, 0, 0), (1, 0, 0), (0, 1, 0), spacing=0.5, maintenance_factor=0.8)
    R.write_surface_csv(tmp_path / "m.csv", s, [100.0, 200.0, 300.0, 400.0], [1.0, 2.0, 3.0, 4.0])
    d = read_results_csv(tmp_path / "m.csv")
    np.testing.assert_allclose(d["lux"], [80.0, 160.0, 240.0, 320.0])
    np.testing.assert_allclose(d["std_error"], [0.8, 1.6, 2.4, 3.2])
    np.testing.assert_allclose(np.stack([d["x"], d["y"]], axis=1), s.points[:, :2])
    R.write_surface_csv(tmp_path / "i.csv", s, [100.0, 200.0, 300.0, 400.0], [1.0, 2.0, 3.0, 4.0],
                        maintained=False)
    np.testing.assert_allclose(read_results_csv(tmp_path / "i.csv")["lux"], [100, 200, 300, 400])


def test_summary_json_round_trip(tmp_path):
    w = G.workplane([(0, 0), (4, 0), (4, 3), (0, 3)], maintenance_factor=0.8, name="office")
    lux = np.linspace(300.0, 600.0, w.n_points)
    out = tmp_path / "sum.json"
    d = R.write_summary_json(out, w, lux, lux * 0.01, samples=128, luminaires=LUMINAIRES, project="P1",
                             date="2026-12-01")
    back = R.read_summary_json(out)
    assert back == json.loads(json.dumps(d))
    assert back["statistics"]["mean"] == pytest.approx(0.8 * 450.0)
    assert back["statistics"]["samples"] == 128 and back["values"].startswith("maintained")
    assert back["surface"]["grid_shape"] == list(w.grid_shape) and back["surface"]["band"] == 0.5
    assert back["surface"]["spacing"] == pytest.approx(list(w.spacing))
    assert back["surface"]["n_points"] == w.n_points and "points" not in back["surface"]
    assert [lum["type"] for lum in back["luminaires"]] == ["Recessed panel 600", "Downlight"]
    assert (back["project"], back["date"]) == ("P1", "2026-12-01")
    # zero illuminance: U0 is null, the file stays valid JSON
    R.write_summary_json(out, w, np.zeros(w.n_points))
    assert json.loads(out.read_text())["statistics"]["u0"] is None
    # the points outside the lit geometry: null when not checked, else the record as given
    assert back["unlit_points"] is None
    unlit = {"count": 1, "indices": [3], "reasons": ["inside a solid or behind a wall"], "lux": [0.0]}
    R.write_summary_json(out, w, lux, unlit=unlit)
    assert json.loads(out.read_text())["unlit_points"] == unlit
    with pytest.raises(LuxError, match="unlit_points"):
        R.summary(w, lux, unlit=[3])
    (tmp_path / "other.json").write_text('{"format": "x"}')
    with pytest.raises(LuxError, match="not a"):
        R.read_summary_json(tmp_path / "other.json")


def _texts(fig):
    """Every text drawn on the figure, table cells included."""
    import matplotlib.table
    import matplotlib.text

    out = [t.get_text() for t in fig.findobj(matplotlib.text.Text)]
    for table in fig.findobj(matplotlib.table.Table):
        out += [cell.get_text().get_text() for cell in table.get_celld().values()]
    return out


def test_one_page_report_png_and_pdf(tmp_path):
    from PIL import Image

    w = G.workplane([(0, 0), (6, 0), (6, 3), (3, 3), (3, 6), (0, 6)], maintenance_factor=0.8, name="L office")
    xy = w.points[:, :2]
    lux = 2000.0 / (1.0 + ((xy - [1.5, 1.5]) ** 2).sum(axis=1))
    png, pdf = tmp_path / "r.png", tmp_path / "r.pdf"
    fig = R.render_report(w, lux, lux * 0.01, samples=256, luminaires=LUMINAIRES, project="Test office",
                          date="2026-12-01", png_path=png, pdf_path=pdf)
    assert R.report_size_px() == (1754, 1240)  # A4 landscape, 297 × 210 mm at 150 dpi
    with Image.open(png) as im:
        assert im.size == (1754, 1240)
        assert len(im.getcolors(1 << 20) or range(10_000)) > 50  # a picture, not a blank page
    assert png.stat().st_size > 50_000
    assert pdf.read_bytes()[:5] == b"%PDF-" and pdf.stat().st_size > 10_000
    texts = _texts(fig)
    st = R.statistics(w, lux, lux * 0.01, 256)
    for label, value in R.statistics_rows(w, st):
        assert label in texts and value in texts, label
    assert "9 × 9" in texts and "0.800" in texts and "256" in texts
    assert {"Recessed panel 600", "panel600.ies", "dl.ldt", "6", "3400"} <= set(texts)
    assert "Test office" in texts and "2026-12-01" in texts
    assert any("maintained" in t for t in texts)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.pdf", "r.png"]  # no temporary files


def test_report_of_mesh_points(tmp_path):
    pos = np.array([[x, y, 0.0] for y in range(4) for x in range(4)], float)
    tri = [[i + 4 * j, i + 1 + 4 * j, i + 5 + 4 * j] for j in range(3) for i in range(3)] + \
          [[i + 4 * j, i + 5 + 4 * j, i + 4 + 4 * j] for j in range(3) for i in range(3)]
    v = G.mesh_vertex_points(pos, tri, name="floor vertices")
    lux = 100.0 + 50.0 * v.points[:, 0]
    R.render_report(v, lux, png_path=tmp_path / "v.png")
    from PIL import Image

    with Image.open(tmp_path / "v.png") as im:
        assert im.size == R.report_size_px()
