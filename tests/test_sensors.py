"""Illuminance sensors (core/sensors.py): the measuring render gives lux on sensor meshes.

Analytic checks: a point light of I cd at height h over a sensor floor gives
E = I h / (h² + x²)^(3/2) (averaged over each pixel's footprint), whatever the floor's
real colour or emission; inside a closed cube of reflectance ρ with the point light at its
centre the mean illuminance on a face is Φ / ((1 - ρ) A) with Φ = 4π I (all the flux,
reflected again and again, lands on the walls), 1/(1 - ρ) times the direct part.
"""
import math

import numpy as np
import pytest

from spectral_gi.core import constants as C
from spectral_gi.core.renderer import render
from spectral_gi.core.scene import Camera, Light, Material, Mesh, RenderSettings, Scene, SceneError, SpectrumTable
from spectral_gi.core.sensors import illuminance_stats, render_illuminance

from helpers import box_mesh, flat_emission, flat_reflectance, look_at

I_CD = 50.0  # cd
H = 1.0  # m


def quad(name, half, z, material, sensor=False, flip=False):
    p = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]], np.float32)
    idx = np.array([[0, 2, 1], [0, 3, 2]] if flip else [[0, 1, 2], [0, 2, 3]], np.int32)
    return Mesh(name, p, idx, np.full(2, material, np.int32), sensor=sensor)


def floor_scene(rho=0.5, emission=0.0, walls=False, res=16, spp=16, view=2.0, floor_half=0.75):
    """A sensor floor (z = 0, ±floor_half m) under a point light at (0, 0, H); an orthographic
    camera looks straight down over ±view/2 m. walls: a black box around it all."""
    spectra = SpectrumTable.empty()
    r = spectra.add("floor", flat_reflectance(rho), C.SPECTRUM_BOUNDED)
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    mats = [Material("floor", reflectance=r, emission=e if emission > 0 else -1, emission_luminance=emission),
            Material("black", reflectance=-1)]
    meshes = [quad("floor", floor_half, 0.0, 0, sensor=True)]
    if walls:  # a closed black box around the floor and the light (normals outwards: two-sided Lambert)
        meshes.append(box_mesh("walls", (-2, -2, -0.5), (2, 2, 1.8), 1))
    light = Light("point", C.LIGHT_POINT, (0.0, 0.0, H), (0, 0, 0), (0, 0, 0), e, 0.0, intensity=I_CD)
    cam = Camera(look_at((0, 0, 1.5), (0, 0, 0), up=(0, 1, 0)), width=res, height=res,
                 projection=C.CAM_ORTHOGRAPHIC, ortho_scale=view)
    return Scene(meshes=meshes, spectra=spectra, materials=mats, lights=[light], camera=cam,
                 settings=RenderSettings(spp=spp, max_depth=8, seed=5))


def pixel_average_E(res, view, n_sub=24):
    """The analytic E = I h / (h² + r²)^(3/2), averaged over each pixel's square (rows top-down)."""
    px = view / res
    sub = (np.arange(n_sub) + 0.5) / n_sub
    out = np.zeros((res, res))
    for j in range(res):
        y = view / 2 - (j + sub) * px  # image rows go down, world +y is up in the image
        for i in range(res):
            x = -view / 2 + (i + sub) * px
            r2 = x[None, :] ** 2 + y[:, None] ** 2
            out[j, i] = np.mean(I_CD * H / (H * H + r2) ** 1.5)
    return out


@pytest.fixture(scope="module")
def floor_results():
    return {key: render_illuminance(floor_scene(**kw), threads=1)
            for key, kw in (("grey", {}), ("white", {"rho": 0.95}), ("emissive", {"emission": 5.0}),
                            ("walls", {"rho": 0.2, "walls": True}))}


def test_point_light_over_sensor_floor_is_analytic(floor_results):
    res = floor_results["grey"]
    lux = res.image.lux
    want = pixel_average_E(16, 2.0)
    inside = res.image.coverage == 1.0
    assert inside.sum() >= 64
    # the foot: E = I / h²; the pixel averages around it are within a few per cent of it
    assert abs(np.nanmax(lux) - I_CD / H ** 2) < 0.04 * I_CD
    # per pixel within 4.5 standard errors (wavelength sampling makes each sample noisy) ...
    z = (lux[inside] - want[inside]) / res.image.std[inside]
    assert np.all(np.abs(z) < 4.5) and np.all(res.image.std[inside] < 0.03 * want[inside])
    # ... and all together within 0.5 %
    assert np.mean(lux[inside] / want[inside]) == pytest.approx(1.0, abs=0.005)
    # the fall-off with the offset x matches I h / (h² + x²)^(3/2) (here x up to 0.75 m: E/E0 = 0.51)
    assert want[inside].min() < 0.6 * want[inside].max()


def test_sensor_ignores_its_real_colour_and_emission(floor_results):
    base = floor_results["grey"].image.lux
    ok = np.isfinite(base)
    for key in ("white", "walls"):
        other = floor_results[key].image.lux
        assert np.array_equal(np.isnan(base), np.isnan(other))
        # no other surface sends light back: the same samples give the same numbers
        np.testing.assert_allclose(other[ok], base[ok], rtol=1e-9, err_msg=key)
    # an emissive floor joins the emitter table (the point light is then picked less often,
    # so the estimate is noisier), but its own emission adds nothing
    other = floor_results["emissive"].image.lux
    assert np.array_equal(np.isnan(base), np.isnan(other))
    assert np.mean(other[ok]) == pytest.approx(np.mean(base[ok]), rel=0.03)


def test_non_sensor_pixels_are_masked(floor_results):
    img = floor_results["grey"].image
    # the floor covers ±0.75 m of the ±1 m view: pixel columns 0-1 and 14-15 see past it
    assert np.all(np.isnan(img.lux[:, :2])) and np.all(np.isnan(img.lux[:, 14:]))
    assert np.all(img.coverage[:, :2] == 0.0)
    assert np.all(np.isfinite(img.lux[2:14, 2:14]))
    assert not img.mask[0, 0] and img.mask[8, 8]
    # with black walls around, the walls' pixels are masked too (not measured as 0)
    walls = floor_results["walls"].image
    assert np.all(np.isnan(walls.lux[:, :2]))
    st = floor_results["grey"].stats
    assert st.pixels == int(np.isfinite(img.lux).sum())
    assert st.Emax == pytest.approx(np.nanmax(img.lux)) and st.Emin == pytest.approx(np.nanmin(img.lux))
    assert st.U0 == pytest.approx(st.Emin / st.Em)


def test_stats():
    lux = np.array([[100.0, 200.0], [np.nan, 300.0]])
    st = illuminance_stats(lux)
    assert (st.Em, st.Emin, st.Emax, st.pixels) == (200.0, 100.0, 300.0, 3)
    assert st.U0 == pytest.approx(0.5)
    st = illuminance_stats(lux, mask=np.array([[False, True], [True, True]]))
    assert (st.Em, st.Emin, st.pixels) == (250.0, 200.0, 2)
    assert illuminance_stats(np.full((2, 2), np.nan)).pixels == 0


def cube_scene(rho, max_depth, spp, res=12, a=2.0, sampler=C.SAMPLER_STRATIFIED):
    """A closed cube of side a and reflectance rho (normals inwards, one-sided walls would do
    too), a point light of I_CD at its centre; an orthographic camera at the centre looks
    down at the floor, which is the sensor, covering it exactly."""
    spectra = SpectrumTable.empty()
    r = spectra.add("wall", flat_reflectance(rho), C.SPECTRUM_BOUNDED)
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    h = a / 2
    box = box_mesh("walls", (-h, -h, -h), (h, h, h), 0)
    floor_tris = np.array([0, 1])  # box_mesh's first quad is the face z = lo
    keep = np.setdiff1d(np.arange(12), floor_tris)
    walls = Mesh("walls", box.positions, box.indices[keep], box.material[keep])
    floor = Mesh("floor", box.positions, box.indices[floor_tris], box.material[floor_tris], sensor=True)
    light = Light("point", C.LIGHT_POINT, (0.0, 0.0, 0.0), (0, 0, 0), (0, 0, 0), e, 0.0, intensity=I_CD)
    cam = Camera(look_at((0, 0, 0), (0, 0, -1), up=(0, 1, 0)), width=res, height=res,
                 projection=C.CAM_ORTHOGRAPHIC, ortho_scale=a)
    return Scene(meshes=[walls, floor], spectra=spectra, materials=[Material("wall", reflectance=r)],
                 lights=[light], camera=cam,
                 settings=RenderSettings(spp=spp, max_depth=max_depth, rr_depth=3, seed=11,
                                         sampler=sampler))


def test_interreflection_in_a_closed_cube_matches_the_energy_balance():
    a, rho = 2.0, 0.5
    direct_mean = 4 * math.pi * I_CD / (6 * a * a)  # Φ spread over the six faces, by symmetry
    d = render_illuminance(cube_scene(rho, 0, 16), threads=1)
    assert d.stats.pixels == 144
    assert d.stats.Em == pytest.approx(direct_mean, rel=0.01)
    full = render_illuminance(cube_scene(rho, 256, 96), threads=1)
    want = direct_mean / (1 - rho)
    # the mean's standard error from the pixels' own errors
    se = math.sqrt(np.sum(full.image.std ** 2)) / full.image.lux.size
    assert se < 0.02 * want
    assert abs(full.stats.Em - want) < max(4 * se, 0.005 * want), (full.stats.Em, want, se)
    assert full.stats.Em > 1.8 * d.stats.Em  # the real white-ish walls and ceiling add light


def test_measuring_needs_a_sensor_and_leaves_the_normal_render_alone():
    sc = floor_scene(res=8, spp=4)
    sc.meshes[0].sensor = False
    with pytest.raises(SceneError, match="sensor"):
        render_illuminance(sc, threads=1)
    # a normal render of a scene with sensors: the floor's real radiance ρ E / π
    sc = floor_scene(res=8, spp=4, rho=0.5)
    film, _ = render(sc, threads=1)
    dev = film.develop()
    lux = render_illuminance(sc, threads=1).image.lux
    ok = np.isfinite(lux)
    assert np.all(dev.alpha == 1.0)
    # the scene's own filter (Blackman-Harris, 1.5 px) blurs a little: compare the mean
    assert np.mean(dev.luminance[2:6, 2:6]) == pytest.approx(0.5 * np.mean(lux[2:6, 2:6]) / math.pi, rel=0.03)
    assert ok.sum() > 0


def test_lux_does_not_depend_on_the_observer():
    # photometry is V(λ) whatever the film's colour-matching functions
    sc = floor_scene(res=8, spp=8)
    base = render_illuminance(sc, threads=1).image.lux
    sc.settings.observer = "1964"
    other = render_illuminance(sc, threads=1).image.lux
    ok = np.isfinite(base)
    assert np.array_equal(ok, np.isfinite(other))
    np.testing.assert_allclose(other[ok], base[ok], rtol=1e-9)
