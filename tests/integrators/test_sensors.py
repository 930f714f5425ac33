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
from spectral_gi.core.integrators.render import render
from spectral_gi.core.scene import (
    Camera, Light, Material, Mesh, RenderSettings, Scene, SceneError, SpectrumTable, World)
from spectral_gi.core.integrators.sensors import illuminance_stats, render_illuminance

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


# ---- partly covered pixels: a black block standing on a sensor floor under a uniform sky ----
# At the block's foot the floor sees up to half its hemisphere blocked, and the estimator
# (sky sampling + BSDF sampling) gives many samples of 0 there. A pixel straddling the
# foot has only its few samples that land on the floor to measure with; it used to set
# Emin (0 lx, U0 = 0) although every floor point sees half a sky.

L_SKY = 100.0  # cd/m²


def block_scene(half, hb=1.0, res=20, spp=256, view=2.0):
    """A large sensor floor (z = 0) under a uniform sky of L_SKY cd/m², a black box
    |x|, |y| < half, 0 < z < hb standing on it; an orthographic camera looks straight down
    over ±view/2 m (res × res pixels of view/res m: the box's sides cut pixel columns)."""
    spectra = SpectrumTable.empty()
    r = spectra.add("grey", flat_reflectance(0.5), C.SPECTRUM_BOUNDED)
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    mats = [Material("floor", reflectance=r), Material("black", reflectance=-1)]
    floor = quad("floor", 2.0, 0.0, 0, sensor=True)
    block = box_mesh("block", (-half, -half, 0.0), (half, half, hb), 1)
    cam = Camera(look_at((0, 0, 5.0), (0, 0, 0), up=(0, 1, 0)), width=res, height=res,
                 projection=C.CAM_ORTHOGRAPHIC, ortho_scale=view)
    return Scene(meshes=[floor, block], spectra=spectra, materials=mats, camera=cam,
                 world=World(background=e, luminance=L_SKY),
                 settings=RenderSettings(spp=spp, max_depth=2, seed=3))


def projected_solid_angle(poly, pts):
    """∫ cos θ dω (θ from +z) of the polygon ``poly`` (k, 3) seen from each point of ``pts``
    (N, 3) below or level with it (Lambert's polygon formula: ½ Σ edges' angle × n·edge plane normal)."""
    r = poly[None, :, :] - pts[:, None, :]
    r = r / np.linalg.norm(r, axis=2)[:, :, None]
    nxt = np.roll(r, -1, axis=1)
    c = np.cross(r, nxt)
    n = np.linalg.norm(c, axis=2)
    ok = n > 1e-15
    angle = np.arctan2(n, np.sum(r * nxt, axis=2))
    return 0.5 * np.abs(np.sum(np.where(ok, angle * c[..., 2] / np.where(ok, n, 1.0), 0.0), axis=1))


def sky_E(x, y, half, hb):
    """E (lux) on the floor at (x, y) next to the black box of block_scene: L (π − the box's
    projected solid angle, the sum over its sides facing the point); NaN under the box."""
    pts = np.stack([x, y, np.zeros_like(x)], 1)
    blocked = np.zeros(x.shape)
    h = half
    sides = (((x >= h), [[h, -h, 0], [h, h, 0], [h, h, hb], [h, -h, hb]]),
             ((x <= -h), [[-h, -h, 0], [-h, h, 0], [-h, h, hb], [-h, -h, hb]]),
             ((y >= h), [[-h, h, 0], [h, h, 0], [h, h, hb], [-h, h, hb]]),
             ((y <= -h), [[-h, -h, 0], [h, -h, 0], [h, -h, hb], [-h, -h, hb]]))
    for sel, quad_pts in sides:
        if sel.any():
            blocked[sel] += projected_solid_angle(np.array(quad_pts, float), pts[sel])
    return np.where((np.abs(x) < h) & (np.abs(y) < h), np.nan, L_SKY * (math.pi - blocked))


def test_sky_E_oracle():
    # far from the box: the whole sky, π L; at the foot of a very tall box's side: half of it
    assert sky_E(np.array([1e6]), np.array([0.0]), 0.4, 1.0)[0] == pytest.approx(math.pi * L_SKY, rel=1e-9)
    assert sky_E(np.array([0.4 + 1e-6]), np.array([0.0]), 0.4, 1e4)[0] == pytest.approx(0.5 * math.pi * L_SKY,
                                                                                        rel=1e-3)
    # against cosine-weighted rays through the box (slab test), 200 000 of them
    rng = np.random.default_rng(1)
    u1, u2 = rng.random(200_000), rng.random(200_000)
    d = np.stack([np.sqrt(u1) * np.cos(2 * np.pi * u2), np.sqrt(u1) * np.sin(2 * np.pi * u2), np.sqrt(1 - u1)], 1)
    for p in ((0.5, 0.1), (0.6, 0.7), (-0.41, -0.3)):
        o = np.array([p[0], p[1], 0.0])
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = (np.array([-0.4, -0.4, 0.0]) - o) / d
            t2 = (np.array([0.4, 0.4, 1.0]) - o) / d
        hit = np.nanmin(np.maximum(t1, t2), 1) >= np.maximum(np.nanmax(np.minimum(t1, t2), 1), 0.0)
        want = math.pi * L_SKY * (1.0 - hit.mean())
        assert sky_E(np.array([p[0]]), np.array([p[1]]), 0.4, 1.0)[0] == pytest.approx(want, abs=0.01 * want)


def sky_pixel_E(half, hb=1.0, res=20, view=2.0, n_sub=64):
    """sky_E averaged over the floor part of each pixel's square, and that part's share of it."""
    px = view / res
    sub = (np.arange(n_sub) + 0.5) / n_sub
    mean = np.full((res, res), np.nan)
    share = np.zeros((res, res))
    for j in range(res):
        for i in range(res):
            x = np.repeat(-view / 2 + (i + sub) * px, n_sub)
            y = np.tile(view / 2 - (j + sub) * px, n_sub)
            inside = max(np.abs(x).max(), np.abs(y).max()) < half - px
            if inside or max(np.abs(x).min(), np.abs(y).min()) > 2 * px + half:
                continue  # well under the box, or far off it: not needed
            e = sky_E(x, y, half, hb)
            ok = np.isfinite(e)
            share[j, i] = ok.mean()
            if ok.any():
                mean[j, i] = e[ok].mean()
    return mean, share


@pytest.fixture(scope="module")
def block_results():
    # sides at ±0.3995 m: the foot lies in a 0.5 % sliver of the pixels of 0.1 m around
    # x, y = ±0.4 (about one sensor sample each); at ±0.37 m in a third of them
    return {half: render_illuminance(block_scene(half), threads=1) for half in (0.3995, 0.37)}


def test_partly_covered_pixels_do_not_set_emin(block_results):
    res = block_results[0.3995]
    img, st = res.image, res.stats
    full = img.mask & (img.coverage == 1.0)
    part = img.mask & (img.coverage < 1.0)
    assert part.sum() >= 20 and np.all(img.coverage[part] < 0.05)
    # the statistics: over the fully covered pixels, the others counted as excluded (their
    # lux stays in the image)
    assert (st.pixels, st.excluded, st.min_coverage) == (int(full.sum()), int(part.sum()), 1.0)
    assert st.Emin == pytest.approx(np.min(img.lux[full])) and st.Em == pytest.approx(np.mean(img.lux[full]))
    # the analytic minimum over those pixels: the pixel column next to the foot (0 - 0.1 m from it)
    want, _ = sky_pixel_E(0.3995)
    assert np.isfinite(want[full]).sum() >= 32  # the two rings of pixels around the foot
    e_min = np.nanmin(want[full])
    assert 0.5 * math.pi * L_SKY < e_min < 0.6 * math.pi * L_SKY
    # Emin is that value within the noise of 256 samples (pixel standard errors ~6 %)
    k = np.argmin(np.where(full, img.lux, np.inf))
    assert st.Emin_std == pytest.approx(img.std.flat[k]) and 0.0 < st.Emin_std < 0.1 * e_min
    assert st.Emin == pytest.approx(e_min, rel=0.12), (st.Emin, e_min)
    em_far = math.pi * L_SKY  # Em is below the open floor's π L, U0 near the analytic ratio
    assert st.Em < em_far and st.U0 == pytest.approx(e_min / st.Em, rel=0.12)
    # every pixel, sliver ones included, used to count: they are noisy enough to read far lower
    assert illuminance_stats(img.lux).Emin < 0.5 * e_min
    assert illuminance_stats(img.lux, coverage=img.coverage, min_coverage=0.0).pixels == int(img.mask.sum())
    with pytest.raises(ValueError, match="min_coverage"):
        illuminance_stats(img.lux, coverage=img.coverage, min_coverage=1.5)


def test_contact_line_pixels_measure_the_floor_part_of_their_footprint(block_results):
    # no light is lost at the foot of the block (shadow rays or bounces leaving the floor
    # there do not hit the block's side by mistake): the partly covered pixels, each the
    # mean over its floor part, match sky_E averaged over that part
    res = block_results[0.37]
    img = res.image
    want, share = sky_pixel_E(0.37)
    part = img.mask & (img.coverage < 1.0)
    assert part.sum() >= 20
    np.testing.assert_allclose(img.coverage[part], share[part], atol=0.1)  # the sample share of the floor part
    n_sensor = img.coverage * 256
    assert np.all(n_sensor[part] >= 30)
    z = (img.lux[part] - want[part]) / img.std[part]
    assert np.all(np.abs(z) < 4.5), z
    # all together (sample-weighted) within 3 %
    ratio = np.sum(n_sensor[part] * img.lux[part]) / np.sum(n_sensor[part] * want[part])
    assert ratio == pytest.approx(1.0, abs=0.03)
    # and the fully covered pixels around them
    near = img.mask & (img.coverage == 1.0) & np.isfinite(want)
    assert near.sum() >= 40
    assert np.all(np.abs((img.lux[near] - want[near]) / img.std[near]) < 4.5)
    assert res.stats.excluded == int(part.sum())
