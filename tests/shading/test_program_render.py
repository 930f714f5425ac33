"""Shader programs in renders: an emission program on a plane seen by an orthographic camera
gives each pixel the emission basis' XYZ of the program's rgb; a base colour program equals
the same constant material; a scene without programs packs no record."""
import numpy as np
import pytest
from helpers import look_at

from spectral_gi.core import constants as C
from spectral_gi.core.bsdfs.params import lambert_params
from spectral_gi.core.integrators import render as R
from spectral_gi.core.lights.record import world_emission_basis
from spectral_gi.core.scene import Camera, Material, Mesh, RenderSettings, Scene, SpectrumTable, World, load, save
from spectral_gi.core.shading.compiler import compile_output

pytestmark = pytest.mark.slow


def plane_scene(materials, programs, res=8, spp=16):
    pos = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    idx = np.array([[0, 1, 2], [0, 2, 3]], np.int32)
    corners = pos[idx].reshape(-1, 3)
    gen = (corners + 1.0) / 2.0  # generated coordinates of the square
    mesh = Mesh("plane", pos, idx, np.zeros(2, np.int32), attributes={"@generated": gen.astype(np.float32)})
    cam = Camera(look_at((0, 0, 1), (0, 0, 0), up=(0, 1, 0)), width=res, height=res,
                 projection=C.CAM_ORTHOGRAPHIC, ortho_scale=2.0)
    return Scene(meshes=[mesh], spectra=SpectrumTable.empty(), materials=list(materials), programs=list(programs),
                 camera=cam, world=World(),
                 settings=RenderSettings(spp=spp, max_depth=0, seed=3, filter=C.FILTER_BOX, filter_width=1.0))


def ramp_graph():
    return {"nodes": {
        "tc": {"type": "TEX_COORD", "props": {}, "inputs": {}},
        "sep": {"type": "SEPXYZ", "props": {}, "inputs": {"Vector": ("link", "tc", "Generated")}},
        "ramp": {"type": "VALTORGB", "props": {"stops": [(0.0, (1, 0, 0, 1)), (1.0, (0, 0, 1, 1))]},
                 "inputs": {"Fac": ("link", "sep", "X")}}}}


def test_emission_program_gives_each_pixel_its_colour(tmp_path):
    prog = compile_output(ramp_graph(), ("link", "ramp", "Color"), "colour", scale=2.0)
    sc = plane_scene([Material("emit", params=lambert_params(), reflectance=-1, emission_program=0)], [prog])
    save(sc, tmp_path / "s.json")
    back = load(tmp_path / "s.json")
    film, _ = R.render(back)
    xyz = film.develop().XYZ
    basis, _ = world_emission_basis(R.prepare(sc).cmf)
    cmf = R.prepare(sc).cmf[:, :3].astype(np.float64)
    for col in range(8):
        x = (col + 0.5) / 8
        rgb = 2.0 * np.array([1 - x, 0.0, x])
        want = (rgb @ basis) @ cmf * C.LAMBDA_STEP
        np.testing.assert_allclose(xyz[:, col].mean(0), want, rtol=0.03, atol=1e-3, err_msg=str(col))


def test_scene_without_programs_has_no_record():
    sc = plane_scene([Material("grey", params=lambert_params())], [])
    prep = R.prepare(sc)
    assert prep.textures.shading is None
    assert R.kernel_records(prep)[1] is None
