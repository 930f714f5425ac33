"""Fuzzing the scene format: valid scene files mutated field by field and array by array,
scenes generated from the records' grammar, and damaged archives.

The contract of :func:`core.scene.load`: it returns a scene that validates, whose derived
quantities the kernels read are finite (the camera's normalised frame, the film's memory
estimate), or it raises SceneError with one line naming the field. Never another
exception, never a scene that would drive a kernel out of bounds.
"""
import copy
import json
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from helpers import flat_emission, flat_reflectance, look_at

from spectral_gi.core import constants as C
from spectral_gi.core import scene as S
from spectral_gi.core.camera.record import camera_vector
from spectral_gi.core.integrators.render import check_render_inputs
from spectral_gi.core.scene.builtin import cornell_box

pytestmark = pytest.mark.fuzz

SPECIAL = [None, True, False, 0, -1, 1, 0.0, 0.5, -0.0, 2 ** 31, 2 ** 63, 10 ** 30, 10 ** 400, 1e308, 1.5e154,
           -1e300, 1e-320, math.inf, -math.inf, math.nan, "", "no", "1_0", "0.0", "Infinity", "x" * 70000, [], {},
           [0, 0, 0], [[1, 0, 0, 0]] * 4, [1e200, 1e200, 1e200], {"a": 1}, [[[[]]]]]
json_leaf = st.one_of(st.none(), st.booleans(), st.integers(-2 ** 70, 2 ** 70),
                      st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=12))
json_value = st.one_of(st.sampled_from(SPECIAL),
                       st.recursive(json_leaf, lambda c: st.lists(c, max_size=4) |
                                    st.dictionaries(st.text(max_size=6), c, max_size=3), max_leaves=8))


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    sc = cornell_box(width=8, height=6, spp=2)
    sc.lights.append(S.Light("spot", C.LIGHT_SPOT, (0.0, 0.0, 0.5), (1.0, 0.0, 0.0), (0.0, 0.0, 0.0),
                             sc.materials[3].emission, 0.0, intensity=10.0, direction=(0.0, 0.0, -1.0),
                             spot_angle=1.0))
    sc.metadata = {"name": "fuzz", "note": [1, 2]}
    path = S.save(sc, tmp_path_factory.mktemp("scene") / "s.json")
    with np.load(path.with_suffix(".npz")) as z:
        arrays = {k: z[k] for k in z.files}
    return path, json.loads(path.read_text()), arrays


def _paths(doc, prefix=()):
    """Every (path, value) of a JSON document."""
    out = [(prefix, doc)]
    if isinstance(doc, dict):
        for k, v in doc.items():
            out += _paths(v, prefix + (k,))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            out += _paths(v, prefix + (i,))
    return out


def _set(doc, path, value, delete=False):
    d = doc
    for k in path[:-1]:
        d = d[k]
    if delete:
        del d[path[-1]]
    else:
        d[path[-1]] = value


def check_contract(path):
    """load() gives a scene the kernels can take, or one line of SceneError."""
    try:
        sc = S.load(path)
    except S.SceneError as e:
        msg = str(e)
        assert msg and "\n" not in msg, msg
        return None
    v = camera_vector(sc.camera, sc.settings)
    assert np.all(np.isfinite(v)), v
    frame = v[0:9].reshape(3, 3)
    assert abs(np.linalg.det(frame)) > 1e-7
    for li in sc.lights:
        for vec in (li.position, li.axis_u, li.axis_v, li.direction):
            assert np.all(np.isfinite(np.asarray(vec, float)))
        assert isinstance(li.two_sided, bool) and isinstance(li.visible, bool)
    for m in sc.materials:
        assert isinstance(m.two_sided, bool) and type(m.reflectance) is int
    try:
        check_render_inputs(sc)
    except S.SceneError as e:
        assert "\n" not in str(e)
    return sc


def _write(tmp_path_factory, saved, doc, arrays=None):
    folder = tmp_path_factory.mktemp("m")
    path = folder / "s.json"
    if arrays is None:
        (folder / "s.npz").write_bytes(saved[0].with_suffix(".npz").read_bytes())
    else:
        np.savez(folder / "s.npz", **arrays)
        doc.pop("arrays_sha256", None)  # a hand-made pair: nothing to compare with
    path.write_text(json.dumps(doc, allow_nan=True))
    return path


@given(st.data())
def test_mutated_scene_json_loads_or_names_the_field(tmp_path_factory, saved, data):
    doc = copy.deepcopy(saved[1])
    for _ in range(data.draw(st.integers(1, 3))):
        paths = [p for p, _ in _paths(doc) if p]
        p = data.draw(st.sampled_from(paths))
        how = data.draw(st.sampled_from(["replace", "replace", "delete", "unknown key"]))
        if how == "replace":
            _set(doc, p, copy.deepcopy(data.draw(json_value)))  # SPECIAL holds shared lists and dicts
        elif how == "delete":
            _set(doc, p, None, delete=True)
        else:
            parent = doc
            for k in p[:-1]:
                parent = parent[k]
            if isinstance(parent, dict):
                parent[data.draw(st.text(min_size=1, max_size=6))] = copy.deepcopy(data.draw(json_value))
    check_contract(_write(tmp_path_factory, saved, doc))


ARRAY_VALUES = [np.nan, np.inf, -np.inf, 1e38, 3.4e38, -1e30, 1e16, -1, 2 ** 31 - 1, -(2 ** 31), 65536, 0, 1e-45]
DTYPES = [np.float16, np.float32, np.float64, np.int8, np.int32, np.int64, np.uint32, np.bool_, ">f4", ">i4"]


@given(st.data())
def test_mutated_scene_arrays_load_or_name_the_field(tmp_path_factory, saved, data):
    doc = copy.deepcopy(saved[1])
    arrays = {k: v.copy() for k, v in saved[2].items()}
    key = data.draw(st.sampled_from(sorted(arrays)))
    a = arrays[key]
    how = data.draw(st.sampled_from(["value", "value", "dtype", "shape", "drop", "empty"]))
    if how == "value" and a.size:
        flat = a.reshape(-1)
        i = data.draw(st.integers(0, flat.size - 1))
        val = data.draw(st.sampled_from(ARRAY_VALUES))
        with np.errstate(all="ignore"):
            if np.issubdtype(a.dtype, np.integer):
                val = int(np.clip(np.nan_to_num(val), np.iinfo(a.dtype).min, np.iinfo(a.dtype).max))
            flat[i] = val
    elif how == "dtype":
        with np.errstate(all="ignore"):
            arrays[key] = a.astype(data.draw(st.sampled_from(DTYPES)))
    elif how == "shape":
        arrays[key] = data.draw(st.sampled_from([a[:-1], a[..., None], a.reshape(-1), np.concatenate([a, a])]))
    elif how == "drop":
        del arrays[key]
    else:
        arrays[key] = np.zeros((0,) + a.shape[1:], a.dtype)
    check_contract(_write(tmp_path_factory, saved, doc, arrays))


@given(st.binary(min_size=1, max_size=8), st.floats(0.0, 1.0))
def test_damaged_scene_archive_is_refused(tmp_path_factory, saved, junk, where):
    folder = tmp_path_factory.mktemp("d")
    src = saved[0]
    data = bytearray(src.with_suffix(".npz").read_bytes())
    at = int(where * (len(data) - 1))
    data[at:at + len(junk)] = junk
    (folder / "s.npz").write_bytes(bytes(data))
    doc = json.loads(src.read_text())
    doc.pop("arrays_sha256")
    (folder / "s.json").write_text(json.dumps(doc))
    check_contract(folder / "s.json")


# --------------------------------------------------------------------------- generated scenes

coord = st.one_of(st.floats(-10.0, 10.0), st.sampled_from([0.0, 1e15, -1e15, 1e16, 3e38, 1e-30]))
big_lum = st.one_of(st.floats(0.0, 1e4), st.sampled_from([0.0, 1e15, 2e15, 1e30, 3.4e38, 1e300]))


@st.composite
def scenes(draw):
    spectra = S.SpectrumTable.empty()
    r = spectra.add("grey", flat_reflectance(0.5), C.SPECTRUM_BOUNDED)
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    n_v = draw(st.integers(3, 6))
    pos = np.array([[draw(coord) for _ in range(3)] for _ in range(n_v)], np.float32)
    n_t = draw(st.integers(1, 4))
    idx = np.array([[draw(st.integers(-1, n_v)) for _ in range(3)] for _ in range(n_t)], np.int32)
    mats = [S.Material("m", model=draw(st.sampled_from([C.MAT_LAMBERT, 99, -1])), reflectance=r,
                       emission=draw(st.sampled_from([-1, e, r, 7])), emission_luminance=draw(big_lum),
                       two_sided=draw(st.sampled_from([True, False, "no", 1])))]
    mesh = S.Mesh("mesh", pos, idx, np.array([draw(st.integers(-1, 1)) for _ in range(n_t)], np.int32))
    kind = draw(st.sampled_from(sorted(C.LIGHT_KINDS)))
    vec = st.tuples(coord, coord, coord)
    light = S.Light("l", kind, draw(vec), draw(vec), draw(vec), e, draw(big_lum), intensity=draw(big_lum),
                    illuminance=draw(big_lum), direction=draw(vec), spot_angle=draw(st.floats(0.0, 4.0)))
    cam = look_at((0, -3, 1), (0, 0, 0)) * draw(st.sampled_from([1.0, -1.0, 1e10, 1e15, 1.4e154, 1e-200]))
    cam[3, 3] = 1.0
    camera = S.Camera(cam, width=draw(st.sampled_from([1, 8, 65536, 65537, 0])),
                      height=draw(st.sampled_from([1, 6, 65536])), lens_mm=draw(st.sampled_from([50.0, 1e-9, 1e7])))
    settings = S.RenderSettings(spp=draw(st.sampled_from([1, 4, 0, 1 << 25])), max_depth=4)
    return S.Scene(meshes=[mesh], spectra=spectra, materials=mats, lights=[light], camera=camera, settings=settings)


@given(scenes())
def test_generated_scenes_validate_round_trip_or_name_the_field(tmp_path_factory, sc):
    try:
        S.validate(sc)
    except S.SceneError as e:
        assert "\n" not in str(e)
        return
    path = S.save(sc, tmp_path_factory.mktemp("g") / "g.json")
    back = check_contract(path)
    assert back is not None
    da, aa = S.to_dict_and_arrays(sc)
    db, ab = S.to_dict_and_arrays(back)
    assert da == db and aa.keys() == ab.keys()
