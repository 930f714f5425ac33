"""The spectral-gi command line, run as a user runs it (a subprocess)."""
import json
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from spectral_gi.core.io.exr import read_channels
from helpers import read_png_rgb8

CLI = [sys.executable, "-m", "spectral_gi.cli"]


def run(args, cwd, **kw):
    return subprocess.run(CLI + args, cwd=cwd, capture_output=True, text=True, timeout=600, **kw)


@pytest.mark.slow
def test_render_default_scene_writes_exr_and_png(tmp_path):
    r = run(["render", "--width", "24", "--height", "20", "--spp", "4", "--out", "box.exr"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert "M samples/s" in r.stderr
    chans, header = read_channels(tmp_path / "box.exr")
    assert {"R", "G", "B", "XYZ.X", "XYZ.Y", "XYZ.Z", "Luminance.Y"} <= set(chans)
    assert chans["R"].shape == (20, 24)
    assert header["whiteLuminance"] == pytest.approx(683.0)
    np.testing.assert_allclose(chans["Luminance.Y"], 683.0 * chans["XYZ.Y"], rtol=1e-5)
    png = read_png_rgb8(tmp_path / "box.png")
    assert png.shape == (20, 24, 3) and png.max() > 100


@pytest.mark.slow
def test_default_output_name_is_cornell(tmp_path):
    r = run(["render", "--width", "8", "--height", "8", "--spp", "1"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "cornell.exr").is_file() and (tmp_path / "cornell.png").is_file()


@pytest.mark.slow
def test_scene_file_round_trip_through_cli(tmp_path):
    r = run(["save-default-scene", "scene.json"], tmp_path)
    assert r.returncode == 0, r.stderr
    r = run(["render", "scene.json", "--width", "8", "--height", "8", "--spp", "1"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "scene.exr").is_file()


@pytest.mark.parametrize("content,needle", [
    ('{"format": "spectral-gi-scene", "version": 1', "not valid JSON"),
    ('{"format": "spectral-gi-scene", "version": 7}', "version"),
    ("[1, 2, 3]", "not a spectral-gi scene"),
])
def test_malformed_scene_gives_one_line_and_status_2(tmp_path, content, needle):
    (tmp_path / "bad.json").write_text(content)
    r = run(["render", "bad.json"], tmp_path)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("spectral-gi: error:") and needle in lines[0], r.stderr
    assert "Traceback" not in r.stderr


def test_nan_vertex_in_scene_file_is_named(tmp_path):
    assert run(["save-default-scene", "s.json"], tmp_path).returncode == 0
    with np.load(tmp_path / "s.npz") as z:
        arrays = {k: z[k] for k in z.files}
    arrays["meshes.2.positions"][1, 2] = np.nan
    np.savez(tmp_path / "s.npz", **arrays)
    doc = json.loads((tmp_path / "s.json").read_text())
    del doc["arrays_sha256"]  # a hand-edited pair
    (tmp_path / "s.json").write_text(json.dumps(doc))
    (tmp_path / "out.exr").write_bytes(b"previous render")
    r = run(["render", "s.json", "--out", "out.exr"], tmp_path)
    assert r.returncode == 2
    assert "meshes[2]" in r.stderr and "positions" in r.stderr and "NaN" in r.stderr
    assert (tmp_path / "out.exr").read_bytes() == b"previous render"  # nothing written before is lost


def test_bad_arguments_exit_2(tmp_path):
    r = run(["render", "--spp", "-3"], tmp_path)
    assert r.returncode == 2
    r = run(["render", "--out", "x.png", "--spp", "1"], tmp_path)
    assert r.returncode == 2 and ".exr" in r.stderr


def test_version_and_bare_command(tmp_path):
    from importlib import metadata

    r = run(["--version"], tmp_path)
    assert r.returncode == 0 and r.stdout.strip() == f"spectral-gi {metadata.version('spectral-gi')}"
    r = run([], tmp_path)
    assert r.returncode == 0 and r.stdout.startswith("usage: spectral-gi")
    for command in ("render", "render-blend", "lux", "save-default-scene"):
        assert command in r.stdout


@pytest.mark.parametrize("args", [
    ["render", "--spp", "1", "--out", "missing/box.exr"],
    ["render-blend", "scene.blend", "--out", "missing/box.exr"],
    ["lux", "--builtin", "cornell", "--sensors", "p.pts", "--out", "missing/lux.csv"],
    ["lux", "--builtin", "cornell", "--out", "missing/deeper/lux"],
    ["save-default-scene", "missing/scene.json"],
])
def test_output_in_a_missing_folder_is_an_error_before_any_work(tmp_path, args):
    """A missing output folder is reported at once (not after the render); nothing is created."""
    (tmp_path / "p.pts").write_text("0 0 0 0 1 0\n")
    (tmp_path / "scene.blend").write_bytes(b"")
    r = run(args, tmp_path)
    assert r.returncode == 2, r.stderr
    assert r.stderr.strip().splitlines() == [
        f"spectral-gi: error: {args[0] == 'save-default-scene' and 'OUT' or '--out'}: the folder "
        f"{tmp_path / 'missing' / ('deeper' if 'deeper' in args[-1] else '')}".rstrip("/")
        + " does not exist (give --mkdir to create it)"]
    assert not (tmp_path / "missing").exists()


def test_mkdir_creates_the_output_folder(tmp_path):
    r = run(["save-default-scene", "a/b/scene.json", "--mkdir"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "a" / "b" / "scene.json").is_file() and (tmp_path / "a" / "b" / "scene.npz").is_file()


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_ctrl_c_stops_cleanly_and_writes_partial_result(tmp_path):
    p = subprocess.Popen(CLI + ["render", "--width", "64", "--height", "64", "--spp", "100000"], cwd=tmp_path,
                         stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    # wait until rendering has started
    deadline = time.time() + 300
    buf = ""
    while time.time() < deadline:
        line = p.stderr.readline()
        buf += line
        if "spp" in line and "[" in line:
            break
    time.sleep(0.5)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    assert p.returncode == 130, buf + err
    assert "Traceback" not in err
    chans, header = read_channels(tmp_path / "cornell.exr")
    spp = int(header["spectralgi.spp"])
    assert 0 < spp < 100000
    assert np.all(np.isfinite(chans["R"])) and chans["R"].mean() > 0
