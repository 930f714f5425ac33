"""Sensor points outside the lit geometry (core/integrators/unlit.py): a closed grey room lit by a
point light at its centre, a closed box and an open-bottomed box standing in it, a second, dark
room beside it, and points in each kind of wrong place."""
import dataclasses
import json

import numpy as np
import pytest

from spectral_gi.core.integrators import unlit as U
from spectral_gi.core.integrators.illuminance import illuminance
from spectral_gi.core.lux import cie171
from spectral_gi.core.scene import Mesh


def _box(name, lo, hi, outward=True, bottom=True):
    """A box [lo, hi] as triangles, normals outwards (a solid) or inwards (a room); optionally open below."""
    m = cie171.room_mesh(name, tuple(np.subtract(hi, lo)))
    pos = m.positions + np.asarray(lo, np.float32)
    tri = m.indices[:, ::-1] if outward else m.indices
    if not bottom:
        tri = tri[2:]  # the first quad of room_mesh is the floor z = lo
    return Mesh(name, pos, np.ascontiguousarray(tri), np.zeros(len(tri), np.int32))


def _scene():
    case = cie171.case_5_8(0.5)  # a 4 m cube, ρ = 0.5, 10 000 lm at (2, 2, 2)
    meshes = list(case.scene.meshes) + [
        _box("desk", (0.5, 0.5, 0.0), (1.5, 1.5, 0.7)),
        _box("open crate", (2.5, 2.5, 0.2), (3.5, 3.5, 0.9), bottom=False),
        _box("dark room", (10.0, 0.0, 0.0), (12.0, 2.0, 2.5), outward=False),
    ]
    return dataclasses.replace(case.scene, meshes=meshes)


UP, DOWN = (0.0, 0.0, 1.0), (0.0, 0.0, -1.0)
POINTS = [  # (point, normal, expected reason or None)
    ((2.0, 1.0, 0.75), UP, None),  # on the work plane
    ((1.0, 3.0, 0.75), UP, None),
    ((3.0, 1.0, 1.5), (0.0, 1.0, 0.0), None),
    ((1.0, 1.0, 0.35), UP, U.INSIDE),  # inside the desk
    ((2.0, 2.0, -1.0), DOWN, U.OPEN),  # under the room, facing away from it
    ((2.0, 2.0, -1.0), UP, U.INSIDE),  # under the room, facing the floor's back
    ((11.0, 1.0, 1.0), UP, U.DARK),  # in the room without a light
    ((3.0, 3.0, 0.6), UP, U.INSIDE),  # inside the crate: lit through its open bottom
    ((3.5, 2.0, 3.0), DOWN, None),
]


@pytest.fixture(scope="module")
def measured():
    scene = _scene()
    p = np.array([q for q, _, _ in POINTS], float)
    n = np.array([m for _, m, _ in POINTS], float)
    lux, se, _ = illuminance(scene, p, n, spp=256, seed=3, threads=2)
    return scene, p, n, lux, se


def test_probe_directions_are_cosine_weighted_unit_vectors():
    d = U.probe_directions(4096)
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0) and (d[:, 2] > 0).all()
    # a cosine-weighted hemisphere: E[cos θ] = 2/3, E[cos² θ] = 1/2, no mean sideways
    assert d[:, 2].mean() == pytest.approx(2 / 3, abs=2e-3)
    assert (d[:, 2] ** 2).mean() == pytest.approx(0.5, abs=2e-3)
    assert np.abs(d[:, :2].mean(axis=0)).max() < 2e-3


def test_points_outside_the_lit_geometry_are_found_with_their_cause(measured):
    scene, p, n, lux, se = measured
    zero = [3, 4, 5, 6]
    assert np.all(lux[zero] == 0.0) and np.all(se[zero] == 0.0)  # the silent failure being caught
    assert lux[7] > 0.0  # the crate lets light in from below
    u = U.unlit_points(scene, p, n, lux, se)
    want = {i: why for i, (_, _, why) in enumerate(POINTS) if why is not None}
    assert dict(zip(u.indices.tolist(), u.reasons)) == want
    assert u.n_points == len(POINTS) and len(u) == len(want)
    assert u.back_fraction[list(u.indices).index(3)] == 1.0 and u.escape_fraction[list(u.indices).index(4)] == 1.0


def test_the_warning_line_and_the_record(measured):
    scene, p, n, lux, se = measured
    u = U.unlit_points(scene, p, n, lux, se)
    line = u.warning(limit=2)
    assert "\n" not in line and line.startswith(f"{len(u)} of {len(POINTS)} points look outside the lit geometry")
    assert "(4 read 0 lx" in line and f"3 ({U.INSIDE}), 4 ({U.OPEN}) and {len(u) - 2} more" in line
    d = json.loads(json.dumps(u.to_dict()))
    assert d["count"] == len(u) and d["indices"] == u.indices.tolist() and d["reasons"] == list(u.reasons)
    lit = U.unlit_points(scene, p[:3], n[:3], lux[:3], se[:3])
    assert len(lit) == 0 and lit.warning() is None and lit.to_dict()["indices"] == []


def test_a_room_modelled_with_outward_normals_is_not_reported():
    """Surfaces are two-sided: a lit room whose faces point outwards (a scaled default cube) has every
    point seeing the back of its faces, which is not a reason to report them."""
    case = cie171.case_5_8(0.5)
    scene = dataclasses.replace(case.scene, meshes=[_box("cube", (0, 0, 0), (4, 4, 4), outward=True)])
    p, n = case.points[::8], case.normals[::8]
    lux, se, _ = illuminance(scene, p, n, spp=16, seed=3, threads=2)
    back, _ = U.probe(scene, p, n)
    assert (lux > 0).all() and (back == 1.0).all()
    assert len(U.unlit_points(scene, p, n, lux, se)) == 0


def test_bad_input():
    scene = _scene()
    with pytest.raises(ValueError, match="2 points, 3 values"):
        U.unlit_points(scene, np.zeros((2, 3)), np.tile(UP, (2, 1)), np.zeros(3), np.zeros(3))
