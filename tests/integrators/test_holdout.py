"""Holdout and transparent film (Cycles' conventions), and the film's alpha.

* A holdout (Mesh.holdout, Blender's object Holdout; or Material.holdout, the Holdout
  shader) seen by the camera leaves a hole: zero radiance, alpha 0. Deeper rays see the
  object's real material (object holdout) or a black absorber (Holdout shader); both cast
  shadows.
* settings.film_transparent: camera rays that miss give alpha 0 and no world radiance; the
  world still lights the scene.
"""
import math

import numpy as np
import pytest

from spectral_gi.core import constants as C
from spectral_gi.core.film import Film
from spectral_gi.core.integrators.render import render
from spectral_gi.core.scene import Camera, Light, Material, Mesh, RenderSettings, Scene, SpectrumTable, World

from helpers import flat_emission, flat_reflectance, look_at


def quad(name, x0, x1, y0, y1, z, material):
    p = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], np.float32)
    return Mesh(name, p, np.array([[0, 1, 2], [0, 2, 3]], np.int32), np.full(2, material, np.int32))


def card_scene(card_mesh_holdout=False, card_material=1, world=0.0, transparent=False, floor=True, spp=8):
    """A grey floor (z = 0, ±1 m) lit by an oblique sun, a white card (x, y in [-0.5, 0], z = 0.3)
    above it; an orthographic camera looks straight down over ±1.25 m (the floor's border
    pixels see past it). Materials: 0 floor, 1 white card, 2 holdout shader, 3 black."""
    spectra = SpectrumTable.empty()
    g = spectra.add("grey", flat_reflectance(0.5), C.SPECTRUM_BOUNDED)
    w = spectra.add("white", flat_reflectance(0.9), C.SPECTRUM_BOUNDED)
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    mats = [Material("floor", reflectance=g), Material("card", reflectance=w), Material("hold", holdout=True),
            Material("black", reflectance=-1)]
    meshes = [quad("floor", -FLOOR, FLOOR, -FLOOR, FLOOR, 0.0, 0)] if floor else []
    card = quad("card", -0.5, 0.0, -0.5, 0.0, 0.3, card_material)
    card.holdout = card_mesh_holdout
    meshes.append(card)
    # the sun travels down and towards +x: the card's shadow falls 0.3 m to its +x side
    sun = Light("sun", C.LIGHT_SUN, (0, 0, 0), (0, 0, 0), (0, 0, 0), e, 0.0,
                direction=(1.0, 0.0, -1.0), illuminance=1000.0)
    cam = Camera(look_at((0, 0, 2), (0, 0, 0), up=(0, 1, 0)), width=N, height=N,
                 projection=C.CAM_ORTHOGRAPHIC, ortho_scale=VIEW)
    return Scene(meshes=meshes, spectra=spectra, materials=mats, lights=[sun], camera=cam,
                 world=World(background=e if world > 0 else -1, luminance=world),
                 settings=RenderSettings(spp=spp, max_depth=4, seed=2, film_transparent=transparent,
                                         filter=C.FILTER_BOX, filter_width=1.0))


N = 20
VIEW = 2.5
PX = VIEW / N
FLOOR = 0.97  # m: not on a pixel edge, so the floor's border pixels are partly covered


def pixel_edges():
    lo = -VIEW / 2 + np.arange(N) * PX
    x0, x1 = lo[None, :], lo[None, :] + PX
    y0, y1 = lo[::-1, None], lo[::-1, None] + PX  # rows go down the image, +y up
    return x0, x1, y0, y1


def inside(rx0, rx1, ry0, ry1):
    """Pixels lying wholly in the rectangle."""
    x0, x1, y0, y1 = pixel_edges()
    return (x0 >= rx0 - 1e-9) & (x1 <= rx1 + 1e-9) & (y0 >= ry0 - 1e-9) & (y1 <= ry1 + 1e-9)


def touching(rx0, rx1, ry0, ry1):
    """Pixels overlapping the rectangle."""
    x0, x1, y0, y1 = pixel_edges()
    return (x1 > rx0) & (x0 < rx1) & (y1 > ry0) & (y0 < ry1)


def regions():
    card = inside(-0.5, 0.0, -0.5, 0.0)
    floor = inside(-FLOOR, FLOOR, -FLOOR, FLOOR) & ~touching(-0.5, 0.0, -0.5, 0.0)
    # the shadow: the card moved 0.3 m along +x (sun at 45°)
    shadow = inside(-0.2, 0.3, -0.5, 0.0) & floor
    lit = floor & ~touching(-0.2, 0.3, -0.5, 0.0)
    return card, floor, shadow, lit


@pytest.fixture(scope="module")
def renders():
    out = {}
    for key, kw in (("plain", {}), ("object", {"card_mesh_holdout": True}), ("shader", {"card_material": 2}),
                    ("black", {"card_material": 3})):
        film, _ = render(card_scene(**kw), threads=1)
        out[key] = film.develop()
    return out


def test_holdout_leaves_a_hole(renders):
    card, floor, shadow, lit = regions()
    assert card.sum() == 16 and shadow.sum() == 8 and lit.sum() > 100
    plain = renders["plain"]
    assert np.all(plain.alpha == 1.0)
    assert np.all(plain.luminance[card] > 0.0)
    for key in ("object", "shader"):
        d = renders[key]
        assert np.all(d.alpha[card] == 0.0), key
        assert np.all(d.rgb[card] == 0.0) and np.all(d.luminance[card] == 0.0), key
        assert np.all(d.alpha[floor] == 1.0), key
        # still casts its shadow: the shadowed floor sees only light reflected by the card's underside
        assert np.mean(d.luminance[shadow]) < 0.25 * np.mean(d.luminance[lit]), key
    # lit floor: ρ E cos45° / π
    want = 0.5 * 1000.0 * math.cos(math.pi / 4) / math.pi
    assert np.mean(renders["shader"].luminance[lit]) == pytest.approx(want, rel=0.03)


def test_holdout_seen_by_deeper_rays(renders):
    card, floor, shadow, lit = regions()
    # object holdout: other rays see the card's real material; the pixels that never see
    # the card are the very same samples as without the holdout
    np.testing.assert_array_equal(renders["object"].XYZ[floor], renders["plain"].XYZ[floor])
    # Holdout shader: a black absorber to every other ray, sample for sample
    np.testing.assert_array_equal(renders["shader"].XYZ[floor], renders["black"].XYZ[floor])
    # and the difference is real: the white card's underside lights its shadow, the black one not at all
    assert np.all(renders["shader"].luminance[shadow] == 0.0)
    assert np.mean(renders["object"].luminance[shadow]) > 0.02 * np.mean(renders["object"].luminance[lit])


def test_transparent_film():
    miss = ~touching(-FLOOR, FLOOR, -FLOOR, FLOOR)
    hit = inside(-FLOOR, FLOOR, -FLOOR, FLOOR)
    edge = ~miss & ~hit
    opaque = render(card_scene(world=100.0), threads=1)[0].develop()
    clear = render(card_scene(world=100.0, transparent=True), threads=1)[0].develop()
    assert miss.sum() == N * N - 16 * 16 and edge.sum() == 16 * 16 - 14 * 14
    assert np.all(opaque.alpha == 1.0)
    assert np.mean(opaque.luminance[miss]) == pytest.approx(100.0, rel=0.02)  # the world, seen directly
    assert np.all(clear.alpha[miss] == 0.0) and np.all(clear.rgb[miss] == 0.0)
    assert np.all(clear.alpha[hit] == 1.0)
    # where geometry is hit the colour is unchanged, sample for sample: the world still lights it
    np.testing.assert_array_equal(clear.XYZ[hit], opaque.XYZ[hit])
    # the floor's border pixels: partly transparent (0.76 of an edge pixel is floor, 0.58 of a corner), premultiplied
    assert np.all((clear.alpha[edge] > 0.3) & (clear.alpha[edge] < 1.0))
    assert np.mean(clear.alpha[edge]) == pytest.approx(0.76, abs=0.05)
    assert np.all(clear.luminance[edge] < opaque.luminance[edge])
    # an empty scene under a transparent film: all transparent, and nothing else
    empty = card_scene(world=100.0, transparent=True)
    empty.meshes = []
    d = render(empty, threads=1)[0].develop()
    assert np.all(d.alpha == 0.0) and np.all(d.XYZ == 0.0)


def test_alpha_survives_save_load_and_resume(tmp_path):
    sc = card_scene(card_mesh_holdout=True, world=50.0, transparent=True, spp=4)
    full, _ = render(sc, threads=1)
    sc.settings.spp = 2
    half, _ = render(sc, threads=1)
    path = half.save(tmp_path / "half.npz")
    loaded = Film.load(path)
    assert np.array_equal(loaded.aov, half.aov)
    sc.settings.spp = 4
    resumed, _ = render(sc, threads=1, resume=loaded)
    assert np.array_equal(resumed.aov, full.aov) and np.array_equal(resumed.sums, full.sums)
    a = full.develop().alpha
    assert a.min() == 0.0 and a.max() == 1.0
    # a version-1 film (8 AOV channels) loads as opaque
    v1 = tmp_path / "v1.npz"
    np.savez_compressed(v1, format=np.array("spectral-gi-film"), version=np.array(1), spp=np.array(4, np.int64),
                        sums=full.sums, spectral=full.spectral, aov=full.aov[..., :8])
    old = Film.load(v1)
    assert np.all(old.develop().alpha == 1.0)


def test_flags_survive_scene_save_load_and_are_validated(tmp_path):
    from spectral_gi.core.scene import SceneError, load, save, validate

    sc = card_scene(card_mesh_holdout=True, transparent=True)
    sc.meshes[0].sensor = True
    back = load(save(sc, tmp_path / "s.json"))
    assert [(m.sensor, m.holdout) for m in back.meshes] == [(True, False), (False, True)]
    assert back.settings.film_transparent and back.materials[2].holdout and not back.materials[1].holdout
    sc.meshes[0].sensor = 1
    with pytest.raises(SceneError, match=r"meshes\[0\].*sensor"):
        validate(sc)
