"""``spectral-gi lux``: a points file in, a CSV of lux and standard errors out (Radiance's rtrace -I)."""
import csv
import subprocess
import sys

import numpy as np
import pytest
from helpers import plane_scene

from spectral_gi.core import constants as C
from spectral_gi.core.scene import Light, save

CLI = [sys.executable, "-m", "spectral_gi.cli"]
INTENSITY = 100.0  # cd
HEIGHT = 2.0  # m


def run(args, cwd):
    return subprocess.run(CLI + args, cwd=cwd, capture_output=True, text=True, timeout=900)


@pytest.fixture
def scene_file(tmp_path):
    light = Light("lamp", C.LIGHT_POINT, (0.0, 0.0, HEIGHT), (0, 0, 0), (0, 0, 0), 0, 0.0, intensity=INTENSITY)
    sc = plane_scene([light], max_depth=0)
    return save(sc, tmp_path / "room.json")


@pytest.mark.slow
def test_lux_at_points_is_i_cos_over_d2_in_input_order(tmp_path, scene_file):
    pts = tmp_path / "grid.pts"
    rows = [(1.0, 0.0, 0.0, 0, 0, 1), (0.0, 0.0, 0.0, 0, 0, 1), (0.0, 0.0, 1.0, 0, 0, 1),
            (0.0, 0.5, 0.5, 0, -1, 0)]  # floor points, one in free space, one vertical facing the lamp's axis
    pts.write_text("# x y z nx ny nz\n" + "\n".join(" ".join(map(str, r)) for r in rows) + "\n")
    r = run(["lux", str(scene_file), "--sensors", str(pts), "--spp", "64", "--out", "lux.csv"], tmp_path)
    assert r.returncode == 0, r.stderr
    with open(tmp_path / "lux.csv", newline="") as f:
        table = list(csv.reader(f))
    assert table[0] == ["x", "y", "z", "nx", "ny", "nz", "lux", "std_error"]
    got = np.array([[float(v) for v in row] for row in table[1:]])
    np.testing.assert_allclose(got[:, :3], np.array(rows)[:, :3])
    expected = []
    for x, y, z, nx, ny, nz in rows:
        v = np.array([0.0, 0.0, HEIGHT]) - (x, y, z)
        d = np.linalg.norm(v)
        expected.append(max(0.0, INTENSITY * (v @ (nx, ny, nz)) / d ** 3))
    # the floor reflects (ρ = 0.8), but the first three points face up: they see the lamp alone; the
    # vertical point also sees the lit floor below its horizon
    np.testing.assert_allclose(got[:3, 6], expected[:3], rtol=0.01)
    assert got[3, 6] > expected[3]  # the direct part plus the floor's reflection
    assert np.all(got[:, 7] >= 0.0)


@pytest.mark.slow
def test_points_outside_the_lit_geometry_get_one_warning_line(tmp_path, scene_file):
    """Two points under the floor read 0 lx with a standard error of 0: the one facing down sees
    open space, the one facing up the back of the floor; both are named, in one line."""
    pts = tmp_path / "p.pts"
    pts.write_text("0 0 1 0 0 1\n0.2 0 -1 0 0 -1\n0 0.3 0.5 0 0 1\n0.5 0 -0.5 0 0 1\n")
    r = run(["lux", str(scene_file), "--sensors", str(pts), "--spp", "16", "--out", "lux.csv"], tmp_path)
    assert r.returncode == 0, r.stderr
    warnings = [ln for ln in r.stderr.splitlines() if ln.startswith("warning:")]
    assert len(warnings) == 1, r.stderr
    assert "2 of 4 points (0-based, in file order) look outside the lit geometry" in warnings[0]
    assert "1 (in open space" in warnings[0] and "3 (inside a solid or behind a wall)" in warnings[0]
    lines = (tmp_path / "lux.csv").read_text().splitlines()
    assert [float(ln.split(",")[6]) for ln in lines[1:]][1::2] == [0.0, 0.0]


@pytest.mark.slow
def test_lux_by_radiosity_gathers_the_lamp_exactly(tmp_path, scene_file):
    """--method radiosity: points facing the lamp get I cos θ / d² (a delta light, one exact
    sample; the floor is coplanar with the floor points, so it adds nothing to them)."""
    pts = tmp_path / "grid.pts"
    rows = [(1.0, 0.0, 0.0, 0, 0, 1), (0.0, 0.0, 0.0, 0, 0, 1), (0.5, -0.5, 0.0, 0, 0, 1)]
    pts.write_text("\n".join(" ".join(map(str, r)) for r in rows) + "\n")
    r = run(["lux", str(scene_file), "--sensors", str(pts), "--method", "radiosity", "--max-edge", "20",
             "--out", "lux.csv"], tmp_path)
    assert r.returncode == 0, r.stderr
    with open(tmp_path / "lux.csv", newline="") as f:
        got = np.array([[float(v) for v in row] for row in list(csv.reader(f))[1:]])
    expected = [INTENSITY * HEIGHT / np.linalg.norm(np.array([0.0, 0.0, HEIGHT]) - r_[:3]) ** 3 for r_ in rows]
    # the points' rays start 1e-6 of the scene's 100 m extent above them: 1e-4 closer to the lamp
    np.testing.assert_allclose(got[:, 6], expected, rtol=2e-4)
    r = run(["lux", str(scene_file), "--sensors", str(pts), "--method", "radiosity", "--max-edge", "-1"], tmp_path)
    assert r.returncode == 2 and "--max-edge" in r.stderr


def test_a_bad_points_file_is_one_line_and_status_2(tmp_path, scene_file):
    pts = tmp_path / "bad.pts"
    pts.write_text("0 0 0 0 0 1\n1 2 3\n")
    r = run(["lux", str(scene_file), "--sensors", str(pts)], tmp_path)
    assert r.returncode == 2
    assert r.stderr.strip().count("\n") == 0 and "bad.pts, line 2" in r.stderr, r.stderr
    assert not (tmp_path / "bad.csv").exists()


def test_missing_scene_is_a_usage_error(tmp_path):
    pts = tmp_path / "p.pts"
    pts.write_text("0 0 0 0 0 1\n")
    r = run(["lux", "--sensors", str(pts)], tmp_path)
    assert r.returncode == 2 and "give a scene file or --builtin" in r.stderr


@pytest.mark.slow
def test_without_sensors_every_calculation_surface_gets_its_csv_summary_and_report(tmp_path):
    """A work plane saved in the scene file: one CSV, one JSON summary (Ē, Emin, U0 and the
    luminaire schedule) and the report page per surface."""
    import json

    from spectral_gi.core.lux import workplane

    light = Light("lamp", C.LIGHT_POINT, (0.0, 0.0, HEIGHT), (0, 0, 0), (0, 0, 0), 0, 0.0, intensity=INTENSITY)
    sc = plane_scene([light], max_depth=0)
    sc.calculation_surfaces.append(workplane([(-1, -1), (1, -1), (1, 1), (-1, 1)], height=0.75, band=0.0,
                                             name="desk"))
    scene = save(sc, tmp_path / "office.json")
    r = run(["lux", str(scene), "--spp", "32"], tmp_path)
    assert r.returncode == 0, r.stderr
    out = tmp_path / "office_lux"
    summary = json.loads((out / "desk.json").read_text())
    pts = sc.calculation_surfaces[0].points
    v = np.array([0.0, 0.0, HEIGHT]) - pts
    d = np.linalg.norm(v, axis=1)
    exact = INTENSITY * v[:, 2] / d ** 3  # the plane is above the floor: the lamp alone
    st = summary["statistics"]
    assert st["mean"] == pytest.approx(exact.mean(), rel=0.01)
    assert st["minimum"] == pytest.approx(exact.min(), rel=0.02)
    assert summary["luminaires"] == [{"type": "point", "count": 1, "lumens": pytest.approx(4 * np.pi * INTENSITY),
                                      "profile": ""}]
    with open(out / "desk.csv", newline="") as f:
        assert sum(1 for _ in f) == pts.shape[0] + 1
    assert (out / "desk.png").stat().st_size > 10_000 and (out / "desk.pdf").read_bytes()[:5] == b"%PDF-"
    assert "desk:" in r.stderr and "U0" in r.stderr
    assert summary["unlit_points"]["count"] == 0 and "warning:" not in r.stderr


def test_without_sensors_a_scene_without_surfaces_says_so(tmp_path, scene_file):
    r = run(["lux", str(scene_file)], tmp_path)
    assert r.returncode == 2 and "calculation_surfaces" in r.stderr and "--sensors" in r.stderr


@pytest.mark.slow
def test_lux_by_radiosity_reports_its_stages_and_stops_on_ctrl_c(tmp_path):
    """--method radiosity prints its stages on stderr; Ctrl-C during the form factors ends
    the command soon with status 130 and no CSV, as with the path tracer."""
    import signal
    import time

    pts = tmp_path / "p.pts"
    pts.write_text("-0.278 0.279 0.001 0 0 1\n")
    proc = subprocess.Popen(CLI + ["lux", "--builtin", "cornell", "--sensors", str(pts), "--method", "radiosity",
                                   "--max-edge", "0.03", "--out", "lux.csv"], cwd=tmp_path,
                            stderr=subprocess.PIPE, text=True)
    lines = []
    for line in proc.stderr:
        lines.append(line)
        if "form factors" in line:
            break
    assert any("patches" in x for x in lines) and any("direct light" in x for x in lines), lines
    t0 = time.monotonic()
    proc.send_signal(signal.SIGINT)
    rest = proc.stderr.read()
    assert proc.wait(timeout=120) == 130
    assert time.monotonic() - t0 < 60, "the form factors went on after Ctrl-C"
    assert "interrupted" in rest
    assert not (tmp_path / "lux.csv").exists()
