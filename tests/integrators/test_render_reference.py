"""The path tracer (NEE + MIS) against the independent reference integrator (tests/oracles/reference).

The reference shares no transport code with the product (its own camera rays, brute-force
ray casting, random numbers, wavelength sampling, film and Russian roulette; BSDF sampling
only, no light sampling), only the scene records and the BSDF models. Both estimate the
same pixel integrals; per pixel, the difference of the two means over the standard error
of that difference must look like a standard normal variable, and the whole images must
agree within their errors.

Two scenes: the Cornell box with a rough-plastic white and an emissive ceiling (MIS
between a glossy lobe and emissive triangles), and a glossy box lit by an analytic area
light seen by the camera and a two-sided emissive panel, with an anisotropic rough gold
(measured η, κ), a Ward surface, a Gaussian pixel filter, a non-square image and a
deeper max_depth. And, cheaply, area lights seen directly (their shape on the film),
with orthogonal and with skewed half-axes.
"""
import functools

import numpy as np
import pytest
from helpers import flat_emission, flat_reflectance
from oracles.reference import render_reference

from spectral_gi import core
from spectral_gi.core import constants as C

pytestmark = pytest.mark.statistical

FULL_SPP = 256
REF_SPP = 4096


def cornell_plastic(spp, seed):
    """The Cornell box; the white surfaces a rough plastic (a GGX coat over the white base), so
    MIS between glossy BSDF sampling and light sampling is exercised, not only the diffuse
    case; the whole ceiling emits (at 1/20 of the lamp's luminance, front side only), so that
    the reference, which finds emitters only by chance, converges in a test's time."""
    sc = core.cornell_box(12, 12, spp=spp, max_depth=3, seed=seed)
    sc.materials[0] = core.Material(name="white plastic", model=C.MAT_PLASTIC, reflectance=sc.materials[0].reflectance,
                                    params=list(core.plastic_params(0.3)), ior=1.5)
    light = next(i for i, m in enumerate(sc.materials) if m.emission >= 0)
    lamp = sc.materials[light]
    sc.materials.append(core.Material(name="ceiling", reflectance=lamp.reflectance, emission=lamp.emission,
                                      emission_luminance=lamp.emission_luminance / 20, two_sided=False))
    ceiling = next(m for m in sc.meshes if m.name == "ceiling")
    ceiling.material[:] = len(sc.materials) - 1
    sc.settings.filter = C.FILTER_BOX
    return sc


def glossy_box(spp, seed):
    """The Cornell box's walls, 16 × 12 pixels, max_depth 4, the independent sampler and a
    Gaussian filter, lit by

    * a downward rectangle light (``Light``, 0.24 m × 0.2 m, 4000 cd/m²) 2 cm under the
      ceiling, visible to the camera; the lamp becomes a plain diffuser;
    * a two-sided emissive panel (mesh, 0.12 m × 0.14 m, 1500 cd/m²) 5 cm in front of the red
      wall, which it lights with its back;

    with the tall block an anisotropic rough gold (GGX α 0.12 × 0.35, η and κ of measured
    gold from Scene.ior_tables) and the short block a Ward surface (α 0.2, ρs 0.25)."""
    sc = core.cornell_box(16, 12, spp=spp, max_depth=4, seed=seed)
    lamp = next(m for m in sc.materials if m.emission >= 0)
    lamp.emission = -1
    lamp.emission_luminance = 0.0
    white = sc.materials[0].reflectance
    e = sc.spectra.add("flat emission", flat_emission(), C.SPECTRUM_UNBOUNDED)
    one = sc.spectra.add("one", flat_reflectance(1.0), C.SPECTRUM_BOUNDED)
    spec = sc.spectra.add("ward specular", flat_reflectance(0.25), C.SPECTRUM_BOUNDED)
    eta, kappa = core.metal_preset("Au")
    i_eta = sc.ior_tables.add("Au eta", eta)
    i_kappa = sc.ior_tables.add("Au kappa", kappa)
    gold = len(sc.materials)
    sc.materials.append(core.Material(name="rough gold", model=C.MAT_GGX_CONDUCTOR, reflectance=one,
                                      params=list(core.ggx_conductor_params(0.12, 0.35)), eta_table=i_eta,
                                      kappa_table=i_kappa))
    ward = len(sc.materials)
    sc.materials.append(core.Material(name="ward", model=C.MAT_WARD, reflectance=white, specular=spec,
                                      params=list(core.ward_params(0.2))))
    panel = len(sc.materials)
    sc.materials.append(core.Material(name="panel", emission=e, emission_luminance=1500.0, two_sided=True))
    for mesh in sc.meshes:
        if mesh.name == "tall_block":
            mesh.material[:] = gold
        elif mesh.name == "short_block":
            mesh.material[:] = ward
    x = -0.50
    quad = np.array([[x, 0.30, 0.12], [x, 0.42, 0.12], [x, 0.42, 0.26], [x, 0.30, 0.26]], np.float32)
    sc.meshes.append(core.Mesh("panel", quad, np.array([[0, 1, 2], [0, 2, 3]], np.int32),
                               np.full(2, panel, np.int32)))
    # cross(axis_u, axis_v) = −Z: it emits downwards
    sc.lights.append(core.Light("area", C.LIGHT_RECT, (-0.278, 0.28, 0.5288), (0.0, 0.10, 0.0), (0.12, 0.0, 0.0),
                                e, 4000.0, visible=True))
    sc.settings.sampler = C.SAMPLER_INDEPENDENT
    sc.settings.filter = C.FILTER_GAUSSIAN
    sc.settings.filter_width = 2.0
    return sc


SCENES = {"cornell_plastic": cornell_plastic, "glossy_box": glossy_box}


@functools.cache
def _reference(name):
    return render_reference(SCENES[name](REF_SPP, 0), spp=REF_SPP, seed=1009)


def _full(name, brighter=1.0):
    sc = SCENES[name](FULL_SPP, 1)
    for m in sc.materials:
        m.emission_luminance *= brighter
    for li in sc.lights:
        li.luminance *= brighter
    film, _ = core.render(sc, threads=2)
    return film.develop()


def _disagreements(full, ref):
    """The ways in which the product's image ``full`` (a Developed film) and the reference
    disagree beyond chance (empty: they agree), and the statistics.

    z_i = (P_i − R_i) / s_i per pixel, s_i² = var P_i + var R_i. The product's pixels are
    independent; the reference's are not quite (the pixels of a batch share its wavelength
    sets), so the spread of mean z under agreement is measured, not assumed to be 1/√n:
    var(mean z) = Σ var P_i / (n s_i)² + var over batches of (mean_i R_b,i / s_i) / B.
    """
    se = np.sqrt(full.variance + ref.variance)
    ok = se > 0
    z = (full.luminance - ref.luminance)[ok] / se[ok]
    n = z.size
    b = ref.batch_luminance.shape[0]
    ref_part = (ref.batch_luminance[:, ok] / se[ok]).mean(axis=1)
    mean_z_sd = np.sqrt(np.sum(full.variance[ok] / se[ok] ** 2) / n ** 2 + ref_part.var(ddof=1) / b)
    pixels = full.luminance.size
    image_se = np.sqrt(full.variance.sum() / pixels ** 2 + ref.image_mean_stderr ** 2)
    image_z = (full.luminance.mean() - ref.image_mean) / image_se
    stats = {"pixels": int(n), "mean z": float(z.mean()), "sd of mean z": float(mean_z_sd),
             "mean z²": float(np.mean(z * z)), "|z| > 3.5": float(np.mean(np.abs(z) > 3.5)),
             "max |z|": float(np.abs(z).max()), "image z": float(image_z)}
    bad = []
    # mean z ~ N(0, sd²); mean z² ~ 1 (a little below where the product's stratified sampler
    # makes its variance estimate conservative); few pixels in the tails
    if not abs(z.mean()) < 4.0 * mean_z_sd:
        bad.append("mean z")
    if not 0.6 < np.mean(z * z) < 1.6:
        bad.append("mean z²")
    if not np.mean(np.abs(z) > 3.5) < 0.02:
        bad.append("tails")
    # the images agree on the whole (the reference's error of the image mean from its batches)
    if not abs(image_z) < 4.0:
        bad.append("image mean")
    return bad, stats


@pytest.mark.slow
@pytest.mark.parametrize("name", list(SCENES))
def test_path_tracer_agrees_with_the_reference(name):
    ref = _reference(name)
    full = _full(name)
    assert (ref.stderr > 0).sum() > 0.9 * ref.stderr.size
    bad, stats = _disagreements(full, ref)
    assert not bad, (bad, stats)


@pytest.mark.slow
def test_the_check_can_fail():
    """A product image with every emitter 10 % brighter must be caught by the same statistics."""
    bad, stats = _disagreements(_full("cornell_plastic", brighter=1.10), _reference("cornell_plastic"))
    assert "mean z" in bad and "image mean" in bad, stats


@pytest.mark.slow
def test_nee_and_mis_agree_with_bsdf_sampling_in_the_same_kernel():
    """A cheaper consistency check inside the product: the same kernel with next_event off
    (BSDF sampling only) estimates the same image (this isolates the NEE and MIS weights
    from everything the two share)."""
    sc = cornell_plastic(2048, 2)
    sc.settings.next_event = False
    naive = core.render(sc, threads=2)[0].develop()
    full = _full("cornell_plastic")
    se = np.sqrt(full.variance + naive.variance)
    ok = se > 0
    z = (full.luminance - naive.luminance)[ok] / se[ok]
    assert ok.sum() > 100
    # heavy tails of the naive estimator's rare light hits make its sample variances run a
    # little low, so allow some slack above 1
    assert abs(z.mean()) < 4.0 / np.sqrt(z.size), z.mean()
    assert 0.6 < np.mean(z * z) < 1.6, np.mean(z * z)
    assert np.mean(np.abs(z) > 3.5) < 0.02
    n = full.luminance.size
    image_se = np.sqrt(full.variance.sum() + naive.variance.sum()) / n
    assert abs(full.luminance.mean() - naive.luminance.mean()) < 4.0 * image_se


def _light_in_view(axis_u, kind=C.LIGHT_RECT):
    """A visible area light (luminance 100, half-axes axis_u and (0.3, 0, 0)) 2 m in front of a
    pinhole camera looking along +Y, on black: the image is its coverage of the pixels."""
    spectra = core.SpectrumTable.empty()
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    to_world = np.eye(4)
    to_world[:3, 0], to_world[:3, 1], to_world[:3, 2] = (1, 0, 0), (0, 0, 1), (0, -1, 0)
    # cross(axis_u, axis_v) must point at the camera (−Y): axis_v = (0.3, 0, 0), axis_u along −Z
    light = core.Light("area", kind, (0.0, 2.0, 0.0), axis_u, (0.3, 0.0, 0.0), e, 100.0, visible=True)
    return core.Scene(spectra=spectra, lights=[light], camera=core.Camera(to_world, width=16, height=16, lens_mm=50.0),
                      settings=core.RenderSettings(spp=2048, max_depth=0, seed=4, filter=C.FILTER_BOX,
                                                   sampler=C.SAMPLER_INDEPENDENT))


@pytest.mark.parametrize("kind", [C.LIGHT_RECT, C.LIGHT_ELLIPSE])
def test_an_area_light_seen_directly_has_the_reference_shape(kind):
    """The shape of a visible rectangle or ellipse light, axes orthogonal."""
    sc = _light_in_view((0.0, 0.0, -0.2), kind)
    ref = render_reference(sc, seed=5, batches=32)
    full = core.render(sc, threads=2)[0].develop()
    bad, stats = _disagreements(full, ref)
    assert not bad, (bad, stats)


@pytest.mark.parametrize("kind", [C.LIGHT_RECT, C.LIGHT_ELLIPSE])
def test_an_area_light_with_skewed_axes_has_the_reference_shape(kind):
    """Axes that are not orthogonal (validation accepts them, and the add-on exports them for an
    area light under a sheared parent): the light is the parallelogram, or the affine image of
    a disc, spanned by its half-axes, as the product samples it for next-event estimation."""
    sc = _light_in_view((0.15, 0.0, -0.2), kind)
    ref = render_reference(sc, seed=5, batches=32)
    full = core.render(sc, threads=2)[0].develop()
    bad, stats = _disagreements(full, ref)
    assert not bad, (bad, stats)


def test_next_event_must_be_a_boolean():
    sc = cornell_plastic(1, 0)
    sc.settings.next_event = "yes"
    with pytest.raises(core.SceneError, match="settings.next_event"):
        core.validate(sc)


@pytest.mark.slow
@pytest.mark.parametrize("projection", [C.CAM_EQUIRECTANGULAR, C.CAM_FISHEYE_EQUISOLID])
def test_panoramic_camera_agrees_with_the_reference(projection):
    """The plastic Cornell box seen from its middle through a panoramic camera (the reference's
    own panoramic rays): the same pixel integrals, black outside the fisheye's circle (and
    where the box is open, behind the camera)."""
    def scene(spp, seed):
        sc = cornell_plastic(spp, seed)
        cam = sc.camera
        cam.to_world = cam.to_world.copy()
        pts = np.concatenate([m.positions for m in sc.meshes])
        cam.to_world[:3, 3] = 0.5 * (pts.min(axis=0) + pts.max(axis=0))  # in the middle of the box
        cam.width, cam.height = (32, 16) if projection == C.CAM_EQUIRECTANGULAR else (12, 12)
        cam.projection, cam.fisheye_fov, cam.fisheye_lens_mm = projection, np.radians(200.0), 8.0
        return sc

    ref = render_reference(scene(1024, 0), spp=1024, seed=1013)
    film, _ = core.render(scene(256, 1), threads=2)
    full = film.develop()
    if projection == C.CAM_FISHEYE_EQUISOLID:
        assert np.all(ref.luminance[0, :2] == 0.0) and np.all(full.luminance[0, :2] == 0.0)  # corners
    bad, stats = _disagreements(full, ref)
    assert not bad, (bad, stats)
