"""Denoising (OpenImageDenoise): the colour image gets closer to the converged one; the measurements do not change."""
import numpy as np
import pytest

from spectral_gi import cli
from spectral_gi.core import cornell_box, denoise, denoise_available, render
from spectral_gi.core.io.exr import read_channels

needs_oidn = pytest.mark.skipif(not denoise_available(), reason="pyoidn (OpenImageDenoise) is not installed")


def rmse(a, b):
    return float(np.sqrt(np.mean((np.asarray(a, np.float64) - np.asarray(b, np.float64)) ** 2)))


@needs_oidn
def test_denoise_checks_its_inputs():
    img = np.ones((8, 8, 3), np.float32)
    with pytest.raises(ValueError, match="albedo"):
        denoise(img, albedo=np.ones((8, 4, 3)))
    with pytest.raises(ValueError, match="only together"):
        denoise(img, normal=np.ones((8, 8, 3)))
    with pytest.raises(ValueError, match=r"\(H, W, 3\)"):
        denoise(np.ones((8, 8)))
    flat = denoise(np.full((16, 16, 3), 0.25, np.float32))
    assert float(flat.mean()) == pytest.approx(0.25, rel=0.01)  # a noise-free flat image stays itself
    np.testing.assert_allclose(flat, 0.25, atol=0.02)


@needs_oidn
@pytest.mark.slow
def test_cli_denoise_brings_the_cornell_box_closer_to_converged_and_keeps_the_measurements(tmp_path):
    size = ["--width", "64", "--height", "64", "--max-depth", "8", "--seed", "1"]
    assert cli.main(["render", "--builtin", "cornell", "--spp", "16", *size, "--out", str(tmp_path / "noisy.exr")]) == 0
    assert cli.main(["render", "--builtin", "cornell", "--spp", "16", *size, "--denoise",
                     "--out", str(tmp_path / "denoised.exr")]) == 0
    noisy, _ = read_channels(tmp_path / "noisy.exr")
    den, header = read_channels(tmp_path / "denoised.exr")
    ref_film, _ = render(cornell_box(width=64, height=64, spp=1024, max_depth=8, seed=7))
    ref = ref_film.develop().rgb
    rgb = lambda c: np.dstack([c["R"], c["G"], c["B"]])  # noqa: E731
    # over the pixels below 1 (all but the light's own face, tens of times brighter, whose
    # edge pixels would dominate any RMSE)
    lit = ref.max(axis=2) < 1.0
    assert lit.mean() > 0.9
    e_noisy, e_den = rmse(rgb(noisy)[lit], ref[lit]), rmse(rgb(den)[lit], ref[lit])
    print(f"\nCornell box 64x64, 16 spp: RMSE to 1024 spp noisy {e_noisy:.4g}, denoised {e_den:.4g}")
    assert e_den < 0.7 * e_noisy
    for name in ("Luminance.Y", "XYZ.X", "XYZ.Y", "XYZ.Z", "Variance.Y", "Lab.L", "xyY.x"):
        np.testing.assert_array_equal(den[name], noisy[name])  # measurements are never denoised
    assert "OpenImageDenoise" in str(header.get("spectralgi.denoised"))


def test_cli_denoise_without_oidn_is_a_usage_error(tmp_path, monkeypatch, capsys):
    import spectral_gi.core as core

    monkeypatch.setattr(core, "denoise_available", lambda: False)
    code = cli.main(["render", "--builtin", "cornell", "--spp", "1", "--width", "4", "--height", "4", "--denoise",
                     "--out", str(tmp_path / "x.exr")])
    assert code == 2
    assert "pip install pyoidn" in capsys.readouterr().err
    assert not (tmp_path / "x.exr").exists()
