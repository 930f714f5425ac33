"""A spectral renderer's reason to exist: the same ColorChecker under a 3000 K blackbody and
under F11 renders different colours, each the one colour-science predicts from the
measured spectra."""
import numpy as np
import pytest

from spectral_gi.core.integrators import render as renderer
from spectral_gi.core.scene.builtin import colorchecker
from spectral_gi.core.spectra import library

colour = pytest.importorskip("colour")

W, H = 120, 80


def _patch_pixels(i):
    """Pixel block at the centre of patch i (camera 1 m away, 50 mm lens, 36 mm sensor)."""
    size, gap = 0.06, 0.012
    row, col = divmod(i, 6)
    x = (col - 3) * (size + gap) + gap / 2 + size / 2
    z = (1 - row) * (size + gap) + gap / 2 + size / 2
    half_w = 0.018 / 0.050
    half_h = half_w * H / W
    px = (x / half_w + 1) / 2 * W
    py = (1 - z / half_h) / 2 * H
    return slice(int(py) - 3, int(py) + 4), slice(int(px) - 3, int(px) + 4)


def _expected_xy(light):
    wl = np.arange(360.0, 831.0)
    s = library.blackbody(3000.0, wl) if light.startswith("blackbody") else library.illuminant(light, wl)
    ill = colour.SpectralDistribution(s, wl)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    out = []
    for name, sd in colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"].items():
        XYZ = colour.sd_to_XYZ(sd.copy().align(colour.SpectralShape(360, 830, 1)), cmfs, ill, method="Integration")
        out.append(colour.XYZ_to_xy(XYZ))
    return np.array(out)


def _rendered_xy(light):
    film, _ = renderer.render(colorchecker(light, width=W, height=H, spp=512, max_depth=0))
    XYZ = film.develop().XYZ
    return np.array([colour.XYZ_to_xy(XYZ[_patch_pixels(i)].reshape(-1, 3).mean(0)) for i in range(24)])


@pytest.mark.slow
@pytest.mark.statistical
def test_colorchecker_under_3000K_and_F11_matches_colour_science():
    got = {light: _rendered_xy(light) for light in ("blackbody:3000", "FL11")}
    want = {light: _expected_xy(light) for light in got}
    for light in got:
        # noise (F11's lines make wavelength sampling noisier) plus the 16-coefficient
        # representation's own error (ΔE00 ≈ 0.07 under F11)
        err = np.linalg.norm(got[light] - want[light], axis=1)
        assert err.mean() < 0.003 and err.max() < 0.007, (light, err.round(4))
    # the two lights give different colours, and by the amount the spectra predict
    shift_got = got["FL11"] - got["blackbody:3000"]
    shift_want = want["FL11"] - want["blackbody:3000"]
    assert np.linalg.norm(shift_want, axis=1).min() > 0.02
    assert np.abs(shift_got - shift_want).max() < 0.008
