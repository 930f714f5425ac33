"""Orthographic projection, thin lens (depth of field), pixel filters by importance sampling."""
import math

import numpy as np
import pytest
from chi2 import chi2_interval
from helpers import flat_emission

from spectral_gi.core import constants as C
from spectral_gi.core.integrators import render as R
from spectral_gi.core.film import develop
from spectral_gi.core.camera.kernel import filter_function, filter_offset, filter_table
from spectral_gi.core.scene import Camera, Light, RenderSettings, Scene, SceneError, SpectrumTable, validate

LUM = 100.0


def light_scene(lights, cam, spp=64, filt=C.FILTER_BOX, width=1.0):
    """Only visible rect/ellipse lights on black: the image shows their coverage of each pixel."""
    spectra = SpectrumTable.empty()
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    for li in lights:
        li.spectrum = e
    return Scene(spectra=spectra, lights=lights, camera=cam,
                 settings=RenderSettings(spp=spp, max_depth=0, seed=2, filter=filt, filter_width=width))


def facing_camera(kind, centre, hu, hv, z):
    """A visible light in the plane z facing +Z (towards a camera above it)."""
    return Light("l", kind, (centre[0], centre[1], z), (hu, 0.0, 0.0), (0.0, hv, 0.0), 0, LUM, visible=True)


def down_camera(width, height, **kw):
    m = np.eye(4)
    m[:3, 3] = (0.0, 0.0, 5.0)  # camera space = world space: looks down −Z, +Y up
    return Camera(m, width=width, height=height, **kw)


def _overlap(a0, a1, b0, b1):
    return np.clip(np.minimum(a1, b1) - np.maximum(a0, b0), 0, None)


@pytest.mark.statistical
def test_orthographic_projection_puts_a_rectangle_on_the_predicted_pixels():
    """ortho_scale spans the larger image side (Blender, sensor fit AUTO); shift is in units of it."""
    w, h, scale, shift = 40, 20, 4.0, 0.1
    cam = down_camera(w, h, projection=C.CAM_ORTHOGRAPHIC, ortho_scale=scale, shift_x=shift)
    sc = light_scene([facing_camera(C.LIGHT_RECT, (0.55, -0.3), 0.5, 0.3, 1.0)], cam)
    d = develop(R.render(sc)[0].sums)
    px = scale / w  # metres per pixel
    x0 = -scale / 2 + shift * scale + px * np.arange(w)
    y1 = scale * h / w / 2 - px * np.arange(h)  # top edge of each row
    cover = (_overlap(x0, x0 + px, 0.05, 1.05)[None, :] * _overlap(y1[:, None] - px, y1[:, None], -0.6, 0.0)) / px ** 2
    expected = LUM * cover
    sigma = LUM * np.sqrt(cover * (1 - cover) / sc.settings.spp) + 0.01 * LUM
    assert np.all(np.abs(d.luminance - expected) <= 5 * sigma), np.abs(d.luminance - expected).max()
    # the rectangle's x edges fall mid-pixel (9 full columns and two halves), its y edges on
    # pixel edges (6 full rows)
    assert (cover > 0.999).sum() == 54 and ((cover > 0.4) & (cover < 0.6)).sum() == 12
    assert np.all(d.luminance[cover < 1e-9] == 0.0)


def _second_moment(lum, half_w):
    """Mean squared distance from the image centre, in units of the plane z = −1 (tangents)."""
    h, w = lum.shape
    px = 2 * half_w / w
    xs = (np.arange(w) + 0.5 - w / 2) * px
    ys = (np.arange(h) + 0.5 - h / 2) * px
    r2 = xs[None, :] ** 2 + ys[:, None] ** 2
    return float((lum * r2).sum() / lum.sum()), px


@pytest.mark.statistical
@pytest.mark.parametrize("distance", [2.0, 1.0, 3.5])
def test_thin_lens_blurs_to_the_circle_of_confusion(distance):
    """A small disc at distance S2 with the lens focused at S1 spreads over a disc of radius
    a |S2 − S1| / (S1 S2) in tangent units (a = lens / (2 N)); at S2 = S1 it stays sharp.
    Second moments add: m2 = ρ0²/2 (the object) + R²/2 (the blur) + px²/6 (the pixel box)."""
    s1, lens, fstop, r = 2.0, 200.0, 2.0, 0.03
    w = 64
    cam = down_camera(w, w, lens_mm=lens, fstop=fstop, focus_distance=s1)
    sc = light_scene([facing_camera(C.LIGHT_ELLIPSE, (0, 0), r, r, 5.0 - distance)], cam, spp=256)
    lum = develop(R.render(sc)[0].sums).luminance
    half_w = 0.5 * 36.0 / lens
    m2, px = _second_moment(lum, half_w)
    a = 0.001 * lens / (2 * fstop)
    blur = a * abs(distance - s1) / (s1 * distance)
    expected = (r / distance) ** 2 / 2 + blur ** 2 / 2 + px ** 2 / 6
    assert m2 == pytest.approx(expected, rel=0.05), (m2, expected, blur / px)
    if distance == s1:
        # in focus: as sharp as a pinhole, the disc covers ~ (2 r / S2 / px)² pixels only
        assert (lum > 0).sum() < 1.3 * np.pi * (r / distance / px + 1) ** 2
    # the flux is kept: the disc's total luminance × pixel solid angle is the same as unblurred
    total = lum.sum() * px * px
    assert total == pytest.approx(LUM * np.pi * (r / distance) ** 2, rel=0.03)


@pytest.mark.statistical
@pytest.mark.parametrize("kind, width", [(C.FILTER_BOX, 1.0), (C.FILTER_BLACKMAN_HARRIS, 1.5),
                                         (C.FILTER_GAUSSIAN, 1.5), (C.FILTER_BLACKMAN_HARRIS, 3.0),
                                         # the node comparison's pixel-centre filter (within 0.01 px)
                                         (C.FILTER_GAUSSIAN, 0.02)])
def test_filter_sampling_follows_the_filter(kind, width, alpha):
    table = filter_table(kind, width)
    rng = np.random.default_rng(5)
    u = rng.random(60000)
    x = np.array([filter_offset(table, v, width) for v in u])
    assert np.all(np.abs(x) <= width / 2)
    grid = np.linspace(-width / 2, width / 2, 200001)
    f = filter_function(kind, width, grid)
    norm = np.trapz(f, grid)
    var = np.trapz(f * grid ** 2, grid) / norm
    se = math.sqrt(var / len(x))
    assert abs(x.mean()) < 4.5 * se
    # variance of the sample variance ≈ (μ4 − σ⁴)/N
    m4 = np.trapz(f * grid ** 4, grid) / norm
    assert abs(x.var() - var) < 4.5 * math.sqrt((m4 - var ** 2) / len(x)), (x.var(), var)
    res = chi2_interval((x + width / 2) / width, lambda t: width * filter_function(kind, width, (np.asarray(t) - 0.5)
                                                                                   * width) / norm,
                        alpha, f"filter {kind} {width}")
    assert res.passed, res.message


@pytest.mark.statistical
def test_blackman_harris_widens_an_edge_as_predicted():
    """Across a sharp vertical edge the image is the edge convolved with the filter: the
    pixel whose centre sits on the edge is half lit whatever the filter; with a 3 px
    Blackman–Harris the neighbours get the filter's cdf at ±1 px."""
    w = 16
    cam = down_camera(w, 4, projection=C.CAM_ORTHOGRAPHIC, ortho_scale=float(w))
    # a big rectangle covering x > 0.5 (the centre of pixel 8 is at x = 0.5)
    rect = facing_camera(C.LIGHT_RECT, (50.5, 0), 50.0, 50.0, 1.0)
    sc = light_scene([rect], cam, spp=256, filt=C.FILTER_BLACKMAN_HARRIS, width=3.0)
    lum = develop(R.render(sc)[0].sums).luminance.mean(axis=0) / LUM
    grid = np.linspace(-1.5, 1.5, 30001)
    f = filter_function(C.FILTER_BLACKMAN_HARRIS, 3.0, grid)
    cdf = np.cumsum(f) / f.sum()
    at = lambda v: float(np.interp(v, grid, cdf))  # noqa: E731
    # pixel i (centre x = i - 7.5) is lit where centre + offset > 0.5 → P(offset > 8 - i)
    for i, exp in ((8, 0.5), (9, 1 - at(-1.0)), (7, 1 - at(1.0)), (5, 0.0), (11, 1.0)):
        assert lum[i] == pytest.approx(exp, abs=0.03), (i, lum[i], exp)


@pytest.mark.parametrize("field, value", [("projection", 5), ("ortho_scale", 0.0), ("ortho_scale", float("nan")),
                                          ("fstop", -1.0), ("focus_distance", 0.0)])
def test_camera_fields_are_validated(field, value):
    sc = light_scene([facing_camera(C.LIGHT_RECT, (0, 0), 1, 1, 0)], down_camera(4, 4))
    validate(sc)
    setattr(sc.camera, field, value)
    with pytest.raises(SceneError, match=f"camera.{field}"):
        validate(sc)


@pytest.mark.parametrize("field, value", [("filter", 3), ("filter_width", 0.0), ("filter_width", float("inf"))])
def test_filter_settings_are_validated(field, value):
    sc = light_scene([facing_camera(C.LIGHT_RECT, (0, 0), 1, 1, 0)], down_camera(4, 4))
    setattr(sc.settings, field, value)
    with pytest.raises(SceneError, match=f"settings.{field}"):
        validate(sc)
