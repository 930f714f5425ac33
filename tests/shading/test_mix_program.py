"""Mix programs: a Mix material whose first component's weight is a program of the shading
point. A plane of two Lambert materials under a constant white world (nothing else in the
scene: the plane sees only the world) has the closed-form luminance ρ(x)·L, with
ρ = w·ρa + (1 − w)·ρb at each point, w the program's value clamped to [0, 1]."""
import numpy as np
import pytest
from helpers import flat_emission, flat_reflectance, look_at

from spectral_gi.core import constants as C
from spectral_gi.core.bsdfs.params import lambert_params
from spectral_gi.core.integrators import render as R
from spectral_gi.core.scene import (
    Camera, Material, Mesh, RenderSettings, Scene, SceneError, SpectrumTable, World, load, save, validate)
from spectral_gi.core.shading.compiler import compile_output

pytestmark = pytest.mark.slow
RES = 8
L_WORLD = 100.0


def plane_scene(materials, programs, rhos, spp=256):
    """A 2 × 2 m plane at z = 0 (generated coordinates (x, y) in [0, 1]²) seen from above by an
    orthographic camera filling the frame, under a flat white world of L_WORLD cd/m²."""
    pos = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    idx = np.array([[0, 1, 2], [0, 2, 3]], np.int32)
    gen = ((pos[idx].reshape(-1, 3) + 1.0) / 2.0).astype(np.float32)
    gen[:, 2] = 0.0
    spectra = SpectrumTable.empty()
    for k, rho in enumerate(rhos):
        spectra.add(f"rho{k}", flat_reflectance(rho), C.SPECTRUM_BOUNDED)
    w = spectra.add("white", flat_emission(), C.SPECTRUM_UNBOUNDED)
    mesh = Mesh("plane", pos, idx, np.zeros(2, np.int32), attributes={"@generated": gen})
    cam = Camera(look_at((0, 0, 1), (0, 0, 0), up=(0, 1, 0)), width=RES, height=RES,
                 projection=C.CAM_ORTHOGRAPHIC, ortho_scale=2.0)
    return Scene(meshes=[mesh], spectra=spectra, materials=list(materials), programs=list(programs), camera=cam,
                 world=World(background=w, luminance=L_WORLD),
                 settings=RenderSettings(spp=spp, max_depth=2, seed=5, filter=C.FILTER_BOX, filter_width=1.0))


def coordinate_graph(axis, scale=1.0, offset=0.0):
    """Generated ``axis`` × scale + offset (a Math node's Multiply Add)."""
    return {"nodes": {
        "tc": {"type": "TEX_COORD", "props": {}, "inputs": {}},
        "sep": {"type": "SEPXYZ", "props": {}, "inputs": {"Vector": ("link", "tc", "Generated")}},
        "ma": {"type": "MATH", "props": {"operation": "MULTIPLY_ADD"},
               "inputs": {"Value": ("link", "sep", axis), "Value_001": scale, "Value_002": offset}}}}


def lambert(name, k):
    return Material(name, params=lambert_params(), reflectance=k)


def luminance(scene):
    film, _ = R.render(scene)
    return film.develop().luminance


def centres():
    x = (np.arange(RES) + 0.5) / RES  # generated x of each column's centre
    y = 1.0 - (np.arange(RES) + 0.5) / RES  # generated y of each row's centre (row 0 at the top)
    return x, y


def test_mix_program_weights_the_components_per_point(tmp_path):
    prog = compile_output(coordinate_graph("X", 2.0, -0.5), ("link", "ma", "Value"), "value")
    mix = Material("mix", model=C.MAT_MIX, params=[0.5, 1.0, 2.0], mix_program=0)
    sc = plane_scene([mix, lambert("a", 0), lambert("b", 1)], [prog], (0.8, 0.2))
    save(sc, tmp_path / "s.json")
    back = load(tmp_path / "s.json")
    assert back.materials[0].mix_program == 0
    got = luminance(back).mean(axis=0)  # per column: the weight depends on x only
    # the two components alone, the same plane and world
    la = luminance(plane_scene([lambert("a", 0)], [], (0.8,))).mean()
    lb = luminance(plane_scene([lambert("b", 0)], [], (0.2,))).mean()
    assert la == pytest.approx(0.8 * L_WORLD, rel=0.03) and lb == pytest.approx(0.2 * L_WORLD, rel=0.03)
    x, _ = centres()
    w = np.clip(2.0 * x - 0.5, 0.0, 1.0)  # clamped as Cycles clamps the factor
    np.testing.assert_allclose(got, w * la + (1.0 - w) * lb, rtol=0.04, atol=0.01 * L_WORLD)
    # not the constant weight params[0]
    assert abs(got[0] - 0.5 * (la + lb)) > 0.2 * L_WORLD and abs(got[-1] - 0.5 * (la + lb)) > 0.2 * L_WORLD


def test_nested_mix_programs():
    px = compile_output(coordinate_graph("X"), ("link", "ma", "Value"), "value")
    py = compile_output(coordinate_graph("Y"), ("link", "ma", "Value"), "value")
    outer = Material("outer", model=C.MAT_MIX, params=[0.5, 1.0, 2.0], mix_program=0)
    inner = Material("inner", model=C.MAT_MIX, params=[0.5, 3.0, 4.0], mix_program=1)
    sc = plane_scene([outer, lambert("a", 0), inner, lambert("b", 1), lambert("c", 2)], [px, py], (0.8, 0.2, 0.5))
    got = luminance(sc)
    x, y = centres()
    wx, wy = x[None, :], y[:, None]
    want = L_WORLD * (wx * 0.8 + (1.0 - wx) * (wy * 0.2 + (1.0 - wy) * 0.5))
    # rows and columns: the mean of 8 pixels each
    np.testing.assert_allclose(got.mean(axis=0), want.mean(axis=0), rtol=0.04)
    np.testing.assert_allclose(got.mean(axis=1), want.mean(axis=1), rtol=0.04)


def test_mix_program_only_on_a_mix():
    prog = compile_output(coordinate_graph("X"), ("link", "ma", "Value"), "value")
    sc = plane_scene([Material("a", params=lambert_params(), reflectance=0, mix_program=0)], [prog], (0.8,))
    with pytest.raises(SceneError, match="mix_program"):
        validate(sc)
    sc = plane_scene([Material("m", model=C.MAT_MIX, params=[0.5, 1.0, 2.0], mix_program=1), lambert("a", 0),
                      lambert("b", 0)], [prog], (0.8,))
    with pytest.raises(SceneError, match="mix_program"):
        validate(sc)
