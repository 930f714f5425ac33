"""``render-blend --frames`` (addon/headless.py): a frame range, one atomic EXR per frame,
frames already written skipped on a rerun, on a LocalCluster; a frame whose .blend uses a
file missing on the machine fails naming the file."""
import json
import subprocess
import sys

import numpy as np
import pytest

from helpers import make_floor_blend
from spectral_gi.addon import headless


def test_frame_ranges_and_names(tmp_path):
    assert headless.parse_frames("3") == [3]
    assert headless.parse_frames("1-3,7,2") == [1, 2, 3, 7]
    for bad in ("a", "5-2", "1--2"):
        with pytest.raises(headless.HeadlessError, match="--frames"):
            headless.parse_frames(bad)
    assert headless.frame_path(tmp_path / "f_###.exr", 7).name == "f_007.exr"
    assert headless.frame_path(tmp_path / "shot.exr", 12).name == "shot_0012.exr"
    with pytest.raises(headless.HeadlessError, match=".exr"):
        headless.frame_path(tmp_path / "shot.png", 1)


def test_frames_already_written_are_skipped(tmp_path, monkeypatch):
    blend = tmp_path / "s.blend"
    blend.write_bytes(b"BLENDER-v500" + bytes(64))
    rendered = []

    def fake(blend, frame, out, spp=None, stream=None):
        rendered.append(frame)
        out.write_bytes(b"exr")
        return {"frame": frame, "exr": str(out), "samples": spp}

    monkeypatch.setattr(headless, "render_frame", fake)
    out = tmp_path / "out" / "f_##.exr"
    headless.render_frames(blend, out, [1, 2, 3], spp=2)
    assert rendered == [1, 2, 3] and (tmp_path / "out" / "f_02.exr").is_file()
    (tmp_path / "out" / "f_02.exr").unlink()
    rendered.clear()
    headless.render_frames(blend, out, [1, 2, 3], spp=2)
    assert rendered == [2]


BLEND_EXTRA = """
if "--missing-texture" in sys.argv:
    img = bpy.data.images.new("Wood", 4, 4)
    img.source = "FILE"
    img.filepath = sys.argv[2]
    tex = t.nodes.new("ShaderNodeTexImage")
    tex.image = img
    t.links.new(tex.outputs["Color"], d.inputs["Color"])
for frame, watts in ((1, 100.0), (2, 200.0), (3, 400.0)):  # the light doubles each frame
    light.energy = watts
    light.keyframe_insert("energy", frame=frame)
"""


def _make_blend(path, *extra):
    return make_floor_blend(path, BLEND_EXTRA, *extra, width=8, height=6)


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "spectral_gi.cli", "render-blend", *map(str, args)],
                          capture_output=True, text=True, timeout=1800)


def _luminance(path):
    return np.mean(headless.read_multilayer_exr(path)["Luminance.Y"])


@pytest.mark.slow
@pytest.mark.blender
def test_frame_range_on_a_local_cluster_and_a_rerun(tmp_path):
    pytest.importorskip("bpy")
    pytest.importorskip("distributed")
    blend = _make_blend(tmp_path / "anim.blend")
    out = tmp_path / "frames" / "f_####.exr"
    proc = _cli(blend, "--frames", "1-3", "--out", out, "--scheduler", "local:2", "--mkdir")
    assert proc.returncode == 0, proc.stderr[-3000:]
    paths = [tmp_path / "frames" / f"f_000{f}.exr" for f in (1, 2, 3)]
    assert all(p.is_file() and p.with_suffix(".png").is_file() for p in paths)
    assert not list((tmp_path / "frames").glob(".*"))  # no temporary file left behind
    lum = [_luminance(p) for p in paths]
    assert lum[1] / lum[0] == pytest.approx(2.0, rel=0.35) and lum[2] / lum[1] == pytest.approx(2.0, rel=0.35)
    assert [d["frame"] for d in json.loads(proc.stdout.strip().splitlines()[-1])["frames"]] == [1, 2, 3]
    # a rerun renders only the frame that is missing
    paths[1].unlink()
    stamps = [paths[0].stat().st_mtime_ns, paths[2].stat().st_mtime_ns]
    proc = _cli(blend, "--frames", "1-3", "--out", out, "--scheduler", "local:2", "--mkdir")
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "2 of 3 frames already written, skipped" in proc.stderr
    assert paths[1].is_file() and [paths[0].stat().st_mtime_ns, paths[2].stat().st_mtime_ns] == stamps
    assert [d["frame"] for d in json.loads(proc.stdout.strip().splitlines()[-1])["frames"]] == [2]


@pytest.mark.slow
@pytest.mark.blender
def test_a_frame_whose_file_is_missing_fails_naming_it(tmp_path):
    pytest.importorskip("bpy")
    pytest.importorskip("distributed")
    missing = tmp_path / "textures" / "wood.png"
    blend = _make_blend(tmp_path / "tex.blend", missing, "--missing-texture")
    proc = _cli(blend, "--frames", "1-2", "--out", tmp_path / "t.exr", "--scheduler", "local:2")
    assert proc.returncode == 1, proc.stderr[-3000:]
    errors = [ln for ln in proc.stderr.splitlines() if ln.startswith("spectral-gi: error:")]
    assert len(errors) == 1 and "Traceback" not in proc.stderr, proc.stderr[-3000:]
    assert str(missing) in errors[0] and "image 'Wood'" in errors[0], errors[0]
    assert not list(tmp_path.glob("t_*.exr"))
