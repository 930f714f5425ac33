"""Ray visibility, light and shadow linking, lights that cast no shadow (Cycles' object and
light visibility, Blender 4's light linking), against closed forms.

The scene: a grey floor (z = 0, ρ 0.5) under a sun at 45° (1000 lx on a surface facing it),
a white card (ρ 0.9) 0.3 m above it, an orthographic camera looking straight down, so that
with direct light only every lit floor pixel is ρ E cos 45° / π and the card's shadow falls
0.3 m to its +x side. Each flag is switched on its own and the pixels it changes are checked
against what the flag means; a scene without flags has no visibility record (the kernel
then compiles none of its code).
"""
import math

import numpy as np
import pytest

from spectral_gi.core import constants as C
from spectral_gi.core.integrators.render import prepare, render
from spectral_gi.core.scene import (
    Camera, Light, Material, Medium, Mesh, RenderSettings, Scene, SceneError, SpectrumTable, World, load, save,
    validate)

from helpers import box_mesh, flat_emission, flat_reflectance, look_at

N = 20
VIEW = 2.5
PX = VIEW / N
FLOOR = 0.97
E_SUN = 1000.0
LIT = 0.5 * E_SUN * math.cos(math.pi / 4) / math.pi  # cd/m², the lit floor
CARD_LIT = 0.9 / 0.5 * LIT  # the card's top
FLOOR_I, CARD_I = 0, 1  # mesh indices


def quad(name, x0, x1, y0, y1, z, material, flip=False):
    p = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], np.float32)
    idx = np.array([[0, 2, 1], [0, 3, 2]] if flip else [[0, 1, 2], [0, 2, 3]], np.int32)
    return Mesh(name, p, idx, np.full(2, material, np.int32))


def scene(spp=8, max_depth=0, world=0.0, floor_material=0):
    """Materials: 0 grey floor, 1 white card, 2 mirror (0.9), 3 glass (transmittance 0.9), 4 rough metal."""
    spectra = SpectrumTable.empty()
    g = spectra.add("grey", flat_reflectance(0.5), C.SPECTRUM_BOUNDED)
    w = spectra.add("white", flat_reflectance(0.9), C.SPECTRUM_BOUNDED)
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    mats = [Material("floor", reflectance=g), Material("card", reflectance=w),
            Material("mirror", model=C.MAT_MIRROR, reflectance=w),
            Material("glass", model=C.MAT_DIELECTRIC, reflectance=w, ior=1.5),
            Material("metal", model=C.MAT_GGX_CONDUCTOR, reflectance=w, params=[1.0, 0.3, 0.3], ior=0.2)]
    meshes = [quad("floor", -FLOOR, FLOOR, -FLOOR, FLOOR, 0.0, floor_material),
              quad("card", -0.5, 0.0, -0.5, 0.0, 0.3, 1)]
    sun = Light("sun", C.LIGHT_SUN, (0, 0, 0), (0, 0, 0), (0, 0, 0), e, 0.0,
                direction=(1.0, 0.0, -1.0), illuminance=E_SUN)
    cam = Camera(look_at((0, 0, 2), (0, 0, 0), up=(0, 1, 0)), width=N, height=N,
                 projection=C.CAM_ORTHOGRAPHIC, ortho_scale=VIEW)
    return Scene(meshes=meshes, spectra=spectra, materials=mats, lights=[sun], camera=cam,
                 world=World(background=e if world > 0 else -1, luminance=world),
                 settings=RenderSettings(spp=spp, max_depth=max_depth, seed=2, filter=C.FILTER_BOX, filter_width=1.0))


def pixel_edges():
    lo = -VIEW / 2 + np.arange(N) * PX
    return lo[None, :], lo[None, :] + PX, lo[::-1, None], lo[::-1, None] + PX


def inside(rx0, rx1, ry0, ry1):
    x0, x1, y0, y1 = pixel_edges()
    return (x0 >= rx0 - 1e-9) & (x1 <= rx1 + 1e-9) & (y0 >= ry0 - 1e-9) & (y1 <= ry1 + 1e-9)


def touching(rx0, rx1, ry0, ry1):
    x0, x1, y0, y1 = pixel_edges()
    return (x1 > rx0) & (x0 < rx1) & (y1 > ry0) & (y0 < ry1)


CARD = inside(-0.5, 0.0, -0.5, 0.0)
FLOORPIX = inside(-FLOOR, FLOOR, -FLOOR, FLOOR) & ~touching(-0.5, 0.0, -0.5, 0.0)
SHADOW = inside(-0.2, 0.3, -0.5, 0.0) & FLOORPIX  # the card's shadow beside it
LITPIX = FLOORPIX & ~touching(-0.2, 0.3, -0.5, 0.0)
UNDER_LIT = inside(-0.5, -0.2, -0.5, 0.0)  # floor under the card, outside its shadow
UNDER_SHADOW = inside(-0.2, 0.0, -0.5, 0.0)  # floor under the card, in its shadow


def lum(sc):
    return render(sc, threads=1)[0].develop()


@pytest.fixture(scope="module")
def plain():
    return lum(scene())


def test_regions_and_the_plain_scene(plain):
    assert CARD.sum() == 16 and SHADOW.sum() == 8 and UNDER_LIT.sum() == 8 and UNDER_SHADOW.sum() == 4
    assert prepare(scene()).visibility is None  # no flags: no record, the kernel without that code
    assert np.mean(plain.luminance[LITPIX]) == pytest.approx(LIT, rel=0.03)
    assert np.mean(plain.luminance[CARD]) == pytest.approx(CARD_LIT, rel=0.03)
    assert np.all(plain.luminance[SHADOW] == 0.0)


def test_camera_visibility(plain):
    sc = scene()
    sc.meshes[CARD_I].visible_camera = False
    d = lum(sc)
    assert prepare(sc).visibility is not None
    # the camera sees the floor through the card, which still casts its shadow
    assert np.mean(d.luminance[UNDER_LIT]) == pytest.approx(LIT, rel=0.03)
    assert np.all(d.luminance[UNDER_SHADOW] == 0.0) and np.all(d.luminance[SHADOW] == 0.0)
    assert np.all(d.alpha == 1.0)
    # the pixels that never see the card: the same light, sample for sample
    np.testing.assert_array_equal(d.XYZ[LITPIX], plain.XYZ[LITPIX])


def test_shadow_visibility(plain):
    sc = scene()
    sc.meshes[CARD_I].visible_shadow = False
    d = lum(sc)
    assert np.mean(d.luminance[SHADOW]) == pytest.approx(LIT, rel=0.03)  # no shadow
    assert np.mean(d.luminance[CARD]) == pytest.approx(CARD_LIT, rel=0.03)  # still seen
    np.testing.assert_array_equal(d.XYZ[LITPIX], plain.XYZ[LITPIX])


def test_light_cast_shadow_and_shadow_linking():
    sc = scene()
    sc.lights[0].cast_shadow = False
    d = lum(sc)
    assert np.mean(d.luminance[SHADOW]) == pytest.approx(LIT, rel=0.03)
    assert np.mean(d.luminance[CARD]) == pytest.approx(CARD_LIT, rel=0.03)
    # shadow linking: an empty blocker set casts no shadow; the card in it casts its shadow
    sc = scene()
    sc.lights[0].blockers = []
    assert np.mean(lum(sc).luminance[SHADOW]) == pytest.approx(LIT, rel=0.03)
    sc.lights[0].blockers = [CARD_I]
    d = lum(sc)
    assert np.all(d.luminance[SHADOW] == 0.0)
    assert np.mean(d.luminance[LITPIX]) == pytest.approx(LIT, rel=0.03)
    # the floor as the only blocker: the card's shadow is gone
    sc.lights[0].blockers = [FLOOR_I]
    assert np.mean(lum(sc).luminance[SHADOW]) == pytest.approx(LIT, rel=0.03)


def test_light_linking():
    sc = scene()
    sc.lights[0].receivers = [CARD_I]
    d = lum(sc)
    assert np.mean(d.luminance[CARD]) == pytest.approx(CARD_LIT, rel=0.03)
    assert np.all(d.luminance[FLOORPIX] == 0.0)
    sc.lights[0].receivers = [FLOOR_I]
    d = lum(sc)
    assert np.all(d.luminance[CARD] == 0.0)
    assert np.mean(d.luminance[LITPIX]) == pytest.approx(LIT, rel=0.03)
    assert np.all(d.luminance[SHADOW] == 0.0)  # the card, unlit, still casts its shadow


def test_diffuse_visibility():
    """With bounces the card's white underside lights its shadow (the floor beside it lights
    the underside); hidden from diffuse rays it lights nothing there (no world: exactly 0)."""
    on = lum(scene(max_depth=2))
    assert np.mean(on.luminance[SHADOW]) > 0.01 * LIT
    sc = scene(max_depth=2)
    sc.meshes[CARD_I].visible_diffuse = False
    off = lum(sc)
    assert np.all(off.luminance[SHADOW] == 0.0)
    assert np.mean(off.luminance[CARD]) == pytest.approx(np.mean(on.luminance[CARD]), rel=0.05)


def test_glossy_visibility():
    """A mirror floor under a uniform world of 100 cd/m² and no sun; the camera, blind to the
    card, sees the card's underside in the mirror, or through it (hidden from glossy rays)
    the world, as every other mirror pixel does."""
    sc = scene(world=100.0, floor_material=2, max_depth=3)
    sc.lights = []
    sc.meshes[CARD_I].visible_camera = False
    sc.meshes[CARD_I].material[:] = 0  # grey
    seen = lum(sc)
    sc.meshes[CARD_I].visible_glossy = False
    hidden = lum(sc)
    mirror = np.mean(hidden.luminance[LITPIX])
    assert mirror == pytest.approx(90.0, rel=0.03)  # the mirror (0.9) of the world
    assert np.mean(hidden.luminance[CARD]) == pytest.approx(mirror, rel=0.03)
    assert np.mean(seen.luminance[CARD]) < 0.75 * mirror  # the grey underside, lit by the world in the mirror


def test_transmission_visibility():
    """A glass pane between the camera and the card (casting no shadow, so that the sun lights
    the floor through it): hidden from transmission rays the card is not seen through the
    pane, which shows the lit floor under the card as where there is no card (one bounce
    after the pane: the floor's direct light only, which the card's underside would add to)."""
    pane = quad("pane", -FLOOR, FLOOR, -FLOOR, FLOOR, 0.6, 3)
    pane.visible_shadow = False
    sc = scene(max_depth=1)
    sc.meshes.append(pane)
    sc.meshes[CARD_I].visible_transmission = False
    d = lum(sc)
    ref = scene(max_depth=1)
    ref.meshes[CARD_I] = pane  # the pane, no card
    r = lum(ref)
    # the lit floor under the card, through the pane, as where there is no card at all
    assert np.mean(d.luminance[UNDER_LIT]) == pytest.approx(np.mean(r.luminance[UNDER_LIT]), rel=0.05)
    # into the glass through one interface: (1 − F(0)) · 0.9 / η², F(0) = 0.04 at η = 1.5
    assert np.mean(d.luminance[UNDER_LIT]) == pytest.approx(LIT * 0.96 * 0.9 / 1.5 ** 2, rel=0.05)
    sc.meshes[CARD_I].visible_transmission = True
    assert np.mean(lum(sc).luminance[UNDER_LIT]) > 1.2 * np.mean(r.luminance[UNDER_LIT])  # the white card


def test_light_ray_visibility():
    """A light hidden from diffuse rays lights no Lambert surface, but a glossy metal; hidden
    from glossy rays, the Lambert floor as before."""
    sc = scene()
    sc.lights[0].visible_diffuse = False
    d = lum(sc)
    assert np.all(d.luminance == 0.0)
    sc = scene(floor_material=4)
    sc.lights[0].visible_diffuse = False
    assert np.mean(lum(sc).luminance[LITPIX]) > 0.0
    sc = scene()
    sc.lights[0].visible_glossy = False
    assert np.mean(lum(sc).luminance[LITPIX]) == pytest.approx(LIT, rel=0.03)


def disk_scene(spp=64, res=7):
    """A Lambert plane (ρ 0.8) under a coaxial downward disk light of radius R = 0.5 at h = 1:
    the radiance at the centre is ρ L R² / (h² + R²)."""
    spectra = SpectrumTable.empty()
    r = spectra.add("grey", flat_reflectance(0.8), C.SPECTRUM_BOUNDED)
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    s = 50.0
    plane = Mesh("plane", np.array([[-s, -s, 0], [s, -s, 0], [s, s, 0], [-s, s, 0]], np.float32),
                 np.array([[0, 1, 2], [0, 2, 3]], np.int32), np.zeros(2, np.int32))
    light = Light("disk", C.LIGHT_ELLIPSE, (0.0, 0.0, 1.0), (0.0, 0.5, 0.0), (0.5, 0.0, 0.0), e, 1000.0)
    cam = Camera(look_at((0, 0, 0.5), (0, 0, 0), up=(0, 1, 0)), width=res, height=res, lens_mm=2000.0)
    return Scene(meshes=[plane], spectra=spectra, materials=[Material("plane", reflectance=r)], lights=[light],
                 camera=cam, settings=RenderSettings(spp=spp, max_depth=0, seed=3))


def test_nee_only_lights_are_unbiased():
    """An area light estimated by next-event estimation alone (no shadows, or hidden from
    glossy rays) gives the closed form, as the MIS-weighted estimate does."""
    want = 0.8 * 1000.0 * 0.25 / 1.25
    for flag in ("cast_shadow", "visible_glossy"):
        sc = disk_scene()
        setattr(sc.lights[0], flag, False)
        assert np.mean(lum(sc).luminance) == pytest.approx(want, rel=0.02), flag


def test_emissive_mesh_linking():
    """An emissive mesh linked to the floor only: the floor as without links (NEE and
    BSDF-sampled hits agree), the card unlit by it."""
    sc = scene(spp=16)
    sc.lights = []
    e = sc.spectra.names.index("flat")
    sc.materials.append(Material("lamp", emission=e, emission_luminance=2000.0, two_sided=True))
    sc.meshes.append(quad("lamp", -0.6, 0.6, -0.6, 0.6, 1.2, 5, flip=True))
    sc.meshes[2].visible_camera = False
    base = lum(sc)
    sc.meshes[2].receivers = [FLOOR_I]
    d = lum(sc)
    assert np.mean(d.luminance[FLOORPIX]) == pytest.approx(np.mean(base.luminance[FLOORPIX]), rel=0.03)
    assert np.mean(base.luminance[CARD]) > 0.0 and np.all(d.luminance[CARD] == 0.0)


@pytest.mark.slow  # compiles the illuminance kernel with a visibility record
def test_illuminance_points_follow_shadow_flags():
    from spectral_gi.core.integrators.illuminance import illuminance

    p = np.array([[0.1, -0.25, 0.0]])  # in the card's shadow
    n = np.array([[0.0, 0.0, 1.0]])
    sc = scene()
    assert illuminance(sc, p, n, spp=64, max_depth=0)[0][0] == 0.0
    want = E_SUN * math.cos(math.pi / 4)
    sc.meshes[CARD_I].visible_shadow = False
    assert illuminance(sc, p, n, spp=64, max_depth=0)[0][0] == pytest.approx(want, rel=0.03)
    sc = scene()
    sc.lights[0].cast_shadow = False
    assert illuminance(sc, p, n, spp=64, max_depth=0)[0][0] == pytest.approx(want, rel=0.03)


def test_flags_survive_save_load_and_are_validated(tmp_path):
    sc = scene()
    sc.meshes[CARD_I].visible_glossy = False
    sc.meshes[CARD_I].visible_shadow = False
    sc.meshes[FLOOR_I].receivers = [1]
    sc.lights[0].cast_shadow = False
    sc.lights[0].visible_diffuse = False
    sc.lights[0].receivers = [0, 1]
    sc.lights[0].blockers = []
    back = load(save(sc, tmp_path / "s.json"))
    m = back.meshes[CARD_I]
    assert (m.visible_camera, m.visible_glossy, m.visible_shadow) == (True, False, False)
    assert back.meshes[FLOOR_I].receivers == [1] and back.meshes[CARD_I].receivers is None
    li = back.lights[0]
    assert (li.cast_shadow, li.visible_diffuse, li.visible_glossy, li.receivers, li.blockers) == \
        (False, False, True, [0, 1], [])
    sc.lights[0].receivers = [2]
    with pytest.raises(SceneError, match=r"lights\[0\].*receivers\[0\].*out of range"):
        validate(sc)
    sc.lights[0].receivers = [1, 1]
    with pytest.raises(SceneError, match=r"receivers.*twice"):
        validate(sc)
    sc.lights[0].receivers = None
    sc.meshes[0].visible_diffuse = 0
    with pytest.raises(SceneError, match=r"meshes\[0\].*visible_diffuse"):
        validate(sc)


def test_record_tables():
    """The record's classes and groups: who lights and who shadows whom, and which emitters
    are estimated by NEE alone."""
    from spectral_gi.core.geometry.visibility import HIDE_DIFFUSE, NEE_ONLY, NO_SHADOW

    sc = scene()
    e = sc.spectra.names.index("flat")
    sc.lights.append(Light("lamp", C.LIGHT_POINT, (0, 0, 1), (0, 0, 0), (0, 0, 0), e, 0.0, intensity=10.0,
                           receivers=[FLOOR_I], blockers=[CARD_I], visible_diffuse=False))
    sc.lights[0].cast_shadow = False
    sc.meshes[FLOOR_I].visible_shadow = False
    prep = prepare(sc)
    vis = prep.visibility
    emt = prep.emitters
    sun_e, lamp_e = emt.emit_light.tolist().index(0), emt.emit_light.tolist().index(1)
    assert vis.emit_hide[sun_e] == NEE_ONLY | NO_SHADOW
    assert vis.emit_hide[lamp_e] == NEE_ONLY | HIDE_DIFFUSE
    tri_mesh = np.repeat([0, 1], 2)[prep.bvh.prims]
    floor_t, card_t = int(np.flatnonzero(tri_mesh == 0)[0]), int(np.flatnonzero(tri_mesh == 1)[0])
    lit = vis.rcv_ok[vis.tri_rcv, :][:, [vis.emit_rgrp[sun_e], vis.emit_rgrp[lamp_e]]]
    assert lit[floor_t].tolist() == [1, 1] and lit[card_t].tolist() == [1, 0]
    blocks = vis.blk_ok[vis.tri_blk, :][:, [vis.emit_sgrp[sun_e], vis.emit_sgrp[lamp_e]]]
    assert blocks[floor_t].tolist() == [0, 0] and blocks[card_t].tolist() == [1, 1]
    assert vis.masked == 1


def test_volume_visibility():
    """A box of scattering fog over a black background, lit by a sun and by an emissive card
    above it that the camera does not see: the fog glows with both; a sun hidden from volume
    scattering and a card hidden from it (rays scattered in the fog pass through it, and the
    fog's NEE skips it) leave the fog black (no other light: exactly 0)."""
    spectra = SpectrumTable.empty()
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    mats = [Material("fog", model=C.MAT_NULL, interior=0),
            Material("lamp", emission=e, emission_luminance=500.0, two_sided=True)]
    card = quad("lamp", -0.5, 0.5, -0.5, 0.5, 1.0, 1)
    card.visible_camera = False
    sun = Light("sun", C.LIGHT_SUN, (0, 0, 0), (0, 0, 0), (0, 0, 0), e, 0.0, direction=(1.0, 0.0, -1.0),
                illuminance=E_SUN)
    cam = Camera(look_at((0, 0, 2), (0, 0, 0), up=(0, 1, 0)), width=8, height=8, projection=C.CAM_ORTHOGRAPHIC,
                 ortho_scale=0.8)

    def fog(sun_volume=True, card_volume=True):
        c = Mesh(card.name, card.positions, card.indices, card.material, visible_camera=False,
                 visible_volume=card_volume)
        li = Light(**{**sun.__dict__, "visible_volume": sun_volume})
        return Scene(meshes=[box_mesh("fog", (-1, -1, -0.5), (1, 1, 0.5), 0), c], spectra=spectra, materials=mats,
                     media=[Medium("fog", scattering_density=1.0)], lights=[li], camera=cam,
                     settings=RenderSettings(spp=8, max_depth=2, seed=1))

    assert np.mean(lum(fog()).luminance) > 1.0
    sun_only = lum(fog(card_volume=False)).luminance
    card_only = lum(fog(sun_volume=False)).luminance
    assert np.mean(sun_only) > 1.0 and np.mean(card_only) > 1.0
    assert np.all(lum(fog(sun_volume=False, card_volume=False)).luminance == 0.0)
