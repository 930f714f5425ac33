"""The independent reference integrator (tests/oracles/reference) against closed forms.

The reference is what tests/integrators/test_render_reference.py holds the product to, so it is
checked on its own first: the furnace (every path length at once), an area light over a
plane (one bounce, emitter found by BSDF sampling), and emitters seen directly (its
camera conventions, pixel filter and one- and two-sided emission).
"""
import numpy as np
import pytest
from helpers import disk_over_plane_scene, flat_emission, furnace_scene, look_at
from oracles.reference import render_reference

from spectral_gi import core
from spectral_gi.core import constants as C

pytestmark = pytest.mark.statistical


def _z(ref, expected):
    return (ref.image_mean - expected) / ref.image_mean_stderr


def test_furnace_converges_to_the_closed_form():
    """A closed box whose walls emit L_e and reflect ρ everywhere: L = L_e / (1 − ρ) at
    every pixel, whatever the direction (all path lengths to max_depth 256 contribute)."""
    rho, le = 0.5, 100.0
    ref = render_reference(furnace_scene(rho, le), spp=256, seed=11, batches=32)
    expected = le / (1.0 - rho)
    assert abs(_z(ref, expected)) < 4.0, (ref.image_mean, ref.image_mean_stderr)
    assert abs(ref.image_mean / expected - 1.0) < 0.02
    # per pixel too: z-scores of the 64 pixels look standard normal
    z = (ref.luminance - expected) / ref.stderr
    assert abs(z.mean()) < 4.0 / np.sqrt(z.size) and 0.5 < np.mean(z * z) < 1.7, (z.mean(), np.mean(z * z))
    # a flat emission under a flat reflectance keeps illuminant E's chromaticity (1/3, 1/3)
    xyz = ref.XYZ.reshape(-1, 3).sum(axis=0)
    assert xyz[:2] / xyz.sum() == pytest.approx([1 / 3, 1 / 3], abs=0.01)


def test_furnace_truncated_at_max_depth():
    """With max_depth = D the path scatters at most D + 1 times: L = L_e Σ_{k=0}^{D+1} ρ^k."""
    rho, le, depth = 0.5, 100.0, 1
    ref = render_reference(furnace_scene(rho, le, max_depth=depth), spp=256, seed=12, batches=32)
    expected = le * sum(rho ** k for k in range(depth + 2))
    assert abs(_z(ref, expected)) < 4.0, (ref.image_mean, ref.image_mean_stderr, expected)


@pytest.mark.parametrize("kind", [C.LIGHT_ELLIPSE, C.LIGHT_RECT])
def test_area_light_over_plane(kind):
    """A Lambertian plane under a coaxial light (max_depth 0: one reflection): the radiance at
    the centre is ρ L F with F = E / (π L): R² / (h² + R²) for the disk, the rectangle
    formula for the square of half-side R."""
    radius, h, rho, lum = 0.5, 1.0, 0.8, 1000.0
    sc = disk_over_plane_scene(radius, h, rho, lum, kind=kind)
    if kind == C.LIGHT_ELLIPSE:
        form = radius ** 2 / (h ** 2 + radius ** 2)
    else:
        x = radius / h
        s = np.sqrt(1 + x * x)
        form = 4 * (1 / (2 * np.pi)) * 2 * (x / s) * np.arctan(x / s)
    ref = render_reference(sc, spp=256, seed=13, batches=32)
    expected = rho * lum * form
    assert abs(_z(ref, expected)) < 4.0, (ref.image_mean, ref.image_mean_stderr, expected)
    assert abs(ref.image_mean / expected - 1.0) < 0.03
    # the light's back side does not emit: turned over, it leaves the plane black
    li = sc.lights[0]
    li.axis_u, li.axis_v = li.axis_v, li.axis_u
    assert render_reference(sc, spp=32, seed=14, batches=4).luminance.max() == 0.0


def _panel_scene(two_sided, facing, filt, width=24, height=16, fw=1.5):
    """An emissive rectangle (one mesh quad, luminance 100) in front of a pinhole camera at the
    origin looking along +Y: x ∈ [-0.3, 0.5], z ∈ [-0.1, 0.25] at distance 2. ``facing``: the
    quad's front faces the camera."""
    spectra = core.SpectrumTable.empty()
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    y = 2.0
    quad = np.array([[-0.3, y, -0.1], [0.5, y, -0.1], [0.5, y, 0.25], [-0.3, y, 0.25]], np.float32)
    tris = np.array([[0, 1, 2], [0, 2, 3]] if facing else [[0, 2, 1], [0, 3, 2]], np.int32)
    mat = core.Material("panel", emission=e, emission_luminance=100.0, two_sided=two_sided)
    cam = core.Camera(look_at((0, 0, 0), (0, 1, 0)), width=width, height=height, lens_mm=50.0,
                      sensor_width_mm=36.0)
    return core.Scene(meshes=[core.Mesh("panel", quad, tris, np.zeros(2, np.int32))], spectra=spectra,
                      materials=[mat], camera=cam,
                      settings=core.RenderSettings(spp=64, max_depth=0, filter=filt, filter_width=fw))


def _box_coverage(width, height, fw):
    """Expected luminance of _panel_scene under the box filter: 100 × the part of each pixel's
    filter window (fw pixels wide, centred on the pixel) that the projected quad covers."""
    half_w = 0.5 * 36.0 / 50.0
    half_h = half_w * height / width

    def cols(x0, x1):  # window x ↦ film pixels
        return (x0 / half_w + 1) * width / 2, (x1 / half_w + 1) * width / 2

    fx0, fx1 = cols(-0.3 / 2.0, 0.5 / 2.0)
    fy0, fy1 = (1 - 0.25 / 2.0 / half_h) * height / 2, (1 + 0.1 / 2.0 / half_h) * height / 2
    cx = np.arange(width) + 0.5
    cy = np.arange(height) + 0.5
    ox = np.clip(np.minimum(cx + fw / 2, fx1) - np.maximum(cx - fw / 2, fx0), 0, None) / fw
    oy = np.clip(np.minimum(cy + fw / 2, fy1) - np.maximum(cy - fw / 2, fy0), 0, None) / fw
    return 100.0 * oy[:, None] * ox[None, :]


@pytest.mark.parametrize("two_sided, facing", [(False, True), (True, False), (False, False)])
def test_emitter_seen_directly_covers_the_predicted_pixels(two_sided, facing):
    """The camera conventions (+x right, top row up, sensor width over the wider side) and the
    box filter: each pixel is the emitter's coverage of its filter window. A one-sided emitter
    seen from behind is black; a two-sided one looks the same from both sides."""
    ref = render_reference(_panel_scene(two_sided, facing, C.FILTER_BOX), spp=256, seed=15, batches=16)
    expected = _box_coverage(24, 16, 1.5) if (two_sided or facing) else np.zeros((16, 24))
    cover = expected / 100.0
    # the batches' spread holds both the coverage's binomial noise and the spectral noise
    assert np.all(np.abs(ref.luminance - expected) <= 5 * ref.stderr + 1e-9), \
        np.max(np.abs(ref.luminance - expected) / np.maximum(ref.stderr, 1e-12))
    assert np.all(ref.luminance[cover == 0.0] == 0.0)
    if two_sided or facing:
        assert np.all(ref.luminance[cover == 1.0] > 99.0)


@pytest.mark.parametrize("filt", [C.FILTER_GAUSSIAN, C.FILTER_BLACKMAN_HARRIS])
def test_pixel_filters_weigh_the_emitter_edge(filt):
    """Along a row inside the quad each pixel is the filter's mass between the quad's edges
    (the filter's cdf at their offsets from the pixel centre): the smooth filters are sampled
    with their own densities."""
    from oracles.reference.camera import _filter_shape

    fw = 2.0
    ref = render_reference(_panel_scene(False, True, filt, fw=fw), spp=512, seed=16, batches=16)
    half_w = 0.5 * 36.0 / 50.0
    fx0, fx1 = ((np.array([-0.3, 0.5]) / 2.0 / half_w + 1) * 24 / 2)  # film x of the quad's edges
    row = 8  # a row well inside the quad in y
    g = np.linspace(0.0, 1.0, 20001)
    f = _filter_shape(filt, g)
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]))])
    cdf /= cdf[-1]
    cx = np.arange(24) + 0.5
    frac = np.interp((fx1 - cx) / fw + 0.5, g, cdf) - np.interp((fx0 - cx) / fw + 0.5, g, cdf)
    expected = 100.0 * frac
    assert np.all(np.abs(ref.luminance[row] - expected) <= 5 * ref.stderr[row] + 1e-9)
    assert np.all(ref.luminance[row][frac == 0.0] == 0.0)
