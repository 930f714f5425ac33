"""``spectral-gi render --method radiosity``: a radiosity solve rendered by final gather to the
same OpenEXR and PNG outputs; options that belong to the path tracer fail in one line."""
import subprocess
import sys

import pytest

CLI = [sys.executable, "-m", "spectral_gi.cli"]


def run(args, cwd):
    return subprocess.run(CLI + args, cwd=cwd, capture_output=True, text=True, timeout=900)


@pytest.mark.slow
def test_render_by_radiosity_writes_exr_and_png(tmp_path):
    from spectral_gi.core.io.exr import read_channels

    r = run(["render", "--builtin", "cornell", "--method", "radiosity", "--max-edge", "0.25", "--width", "12",
             "--height", "12", "--spp", "1", "--gather", "4", "--out", "fg.exr"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "fg.exr").is_file() and (tmp_path / "fg.png").is_file()
    assert "patches" in r.stderr and "mean luminance" in r.stderr
    chans, header = read_channels(tmp_path / "fg.exr")
    assert header["spectralgi.method"] == "radiosity" and int(header["spectralgi.patches"]) > 0
    assert chans["Luminance.Y"].mean() > 0


@pytest.mark.parametrize("extra, msg", [(["--method", "radiosity", "--denoise"], "--denoise: not available"),
                                        (["--max-edge", "0.1"], "--max-edge applies to --method radiosity")])
def test_options_of_the_other_method_fail_in_one_line(tmp_path, extra, msg):
    r = run(["render", "--builtin", "cornell", "--width", "4", "--height", "4", "--out", "x.exr"] + extra, tmp_path)
    assert r.returncode == 2 and msg in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not (tmp_path / "x.exr").exists()
