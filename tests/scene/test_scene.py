"""The scene contract: validation in both directions, save/load round trip, bad files."""
import json

import numpy as np
import pytest
from helpers import furnace_scene

from spectral_gi.core import constants as C
from spectral_gi.core import scene as S
from spectral_gi.core.scene.builtin import cornell_box


def test_cornell_box_is_valid():
    sc = cornell_box()
    S.validate(sc)
    assert sc.n_triangles == 32
    assert [m.name for m in sc.materials] == ["white", "red", "green", "light"]


def _expect(sc, field):
    with pytest.raises(S.SceneError) as e:
        S.validate(sc)
    assert str(e.value).startswith(field), str(e.value)
    return str(e.value)


def test_rejects_nan_positions():
    sc = furnace_scene()
    sc.meshes[0].positions[3, 1] = np.nan
    msg = _expect(sc, "meshes[0] ('box').positions")
    assert "NaN" in msg and "(3, 1)" in msg


def test_rejects_inf_positions():
    sc = furnace_scene()
    sc.meshes[0].positions[0, 0] = np.inf
    _expect(sc, "meshes[0] ('box').positions")


def test_rejects_wrong_dtype_and_shape():
    sc = furnace_scene()
    sc.meshes[0].positions = sc.meshes[0].positions.astype(np.float64)
    assert "dtype float32" in _expect(sc, "meshes[0] ('box').positions")
    sc = furnace_scene()
    sc.meshes[0].indices = sc.meshes[0].indices[:, :2].copy()
    assert "shape (N, 3)" in _expect(sc, "meshes[0] ('box').indices")
    sc = furnace_scene()
    sc.meshes[0].material = sc.meshes[0].material[:-1].copy()
    _expect(sc, "meshes[0] ('box').material")


def test_rejects_out_of_range_indices():
    sc = furnace_scene()
    sc.meshes[0].indices[5, 2] = 8
    assert "out of range" in _expect(sc, "meshes[0] ('box').indices")
    sc = furnace_scene()
    sc.meshes[0].indices[0, 0] = -1
    _expect(sc, "meshes[0] ('box').indices")
    sc = furnace_scene()
    sc.meshes[0].material[0] = 1
    _expect(sc, "meshes[0] ('box').material")
    sc = furnace_scene()
    sc.materials[0].reflectance = 5
    _expect(sc, "materials[0] ('wall').reflectance")


def test_rejects_negative_reflectance_and_emission():
    sc = furnace_scene()
    sc.spectra.coeffs[0, 0] = -0.2
    assert "negative reflectance" in _expect(sc, "spectra[0]")
    sc = furnace_scene()
    sc.spectra.coeffs[0, 0] = 1.3
    assert "above 1" in _expect(sc, "spectra[0]")
    sc = furnace_scene()
    sc.spectra.coeffs[1, 0] = -1.0
    assert "negative emission" in _expect(sc, "spectra[1]")
    sc = furnace_scene()
    sc.materials[0].emission_luminance = -5.0
    _expect(sc, "materials[0] ('wall').emission_luminance")
    # moments that no reflectance in [0, 1] can have
    sc = furnace_scene()
    sc.spectra.coeffs[0, :3] = [0.5, 0.5, 0.5]
    assert "no reflectance" in _expect(sc, "spectra[0]")


def test_rejects_wrong_spectrum_kind():
    sc = furnace_scene()
    sc.materials[0].reflectance = 1  # an emission spectrum
    assert "bounded" in _expect(sc, "materials[0] ('wall').reflectance")


def test_rejects_unknown_version_and_bad_settings():
    sc = furnace_scene()
    sc.version = 99
    _expect(sc, "version")
    sc = furnace_scene()
    sc.settings.spp = 0
    _expect(sc, "settings.spp")
    sc = furnace_scene()
    sc.camera.width = 0
    _expect(sc, "camera.width")
    sc = furnace_scene()
    sc.camera.lens_mm = float("nan")
    _expect(sc, "camera.lens_mm")


def test_accepts_valid_variants():
    sc = furnace_scene()
    sc.meshes[0].normals = np.zeros((8, 3), np.float32)
    sc.meshes[0].uvs = np.zeros((8, 2), np.float32)
    S.validate(sc)


def _same(a, b):
    da, aa = S.to_dict_and_arrays(a)
    db, ab = S.to_dict_and_arrays(b)
    assert da == db
    assert aa.keys() == ab.keys()
    for k in aa:
        assert aa[k].dtype == ab[k].dtype and np.array_equal(aa[k], ab[k]), k


def test_save_load_round_trip(tmp_path):
    sc = cornell_box(width=40, height=30, spp=5, seed=9)
    sc.meshes[0].uvs = np.zeros((sc.meshes[0].positions.shape[0], 2), np.float32)
    path = S.save(sc, tmp_path / "box.json")
    assert path.is_file() and path.with_suffix(".npz").is_file()
    _same(sc, S.load(path))
    # folder form
    S.save(sc, tmp_path / "folder")
    _same(sc, S.load(tmp_path / "folder"))


def test_load_errors_name_the_problem(tmp_path):
    path = S.save(furnace_scene(), tmp_path / "s.json")
    doc = json.loads(path.read_text())

    def write(d):
        path.write_text(json.dumps(d))

    with pytest.raises(S.SceneError, match="version"):
        write({**doc, "version": 2})
        S.load(path)
    with pytest.raises(S.SceneError, match="not a spectral-gi scene"):
        write({**doc, "format": "something"})
        S.load(path)
    with pytest.raises(S.SceneError, match="camera: unknown keys"):
        write({**doc, "camera": {**doc["camera"], "fov": 3}})
        S.load(path)
    with pytest.raises(S.SceneError, match="settings"):
        write({k: v for k, v in doc.items() if k != "settings"})
        S.load(path)
    write(doc)
    S.load(path)
    path.with_suffix(".npz").write_bytes(b"not a zip")
    with pytest.raises(S.SceneError, match="arrays: s.npz is not the array file s.json was saved with"):
        S.load(path)
    write({k: v for k, v in doc.items() if k != "arrays_sha256"})  # a hand-made pair: no digest to compare
    with pytest.raises(S.SceneError, match="arrays: cannot read"):
        S.load(path)


def test_pickled_arrays_are_refused(tmp_path):
    path = S.save(furnace_scene(), tmp_path / "s.json")
    with np.load(path.with_suffix(".npz")) as z:
        arrays = {k: z[k] for k in z.files}
    arrays["spectra.coeffs"] = np.array([object()], dtype=object)
    np.savez(path.with_suffix(".npz"), **arrays)
    doc = json.loads(path.read_text())
    del doc["arrays_sha256"]  # a hand-made pair
    path.write_text(json.dumps(doc))
    with pytest.raises(S.SceneError, match=r"spectra.coeffs: .*not a plain number type"):
        S.load(path)


def test_failed_save_keeps_previous_file(tmp_path):
    good = furnace_scene()
    path = S.save(good, tmp_path / "s.json")
    before = path.read_bytes(), path.with_suffix(".npz").read_bytes()
    bad = furnace_scene()
    bad.meshes[0].positions[0, 0] = np.nan
    with pytest.raises(S.SceneError):
        S.save(bad, path)
    assert (path.read_bytes(), path.with_suffix(".npz").read_bytes()) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.json", "s.npz"]


def test_constants_are_stable():
    # tags are stored in files: they must never change
    assert (C.SPECTRUM_BOUNDED, C.SPECTRUM_UNBOUNDED, C.MAT_LAMBERT, C.LIGHT_RECT, C.LIGHT_ELLIPSE) == (0, 1, 0, 0, 1)
    assert C.N_LAMBDA == 471


def test_calculation_surfaces_survive_save_and_load(tmp_path):
    from spectral_gi.core.lux import rectangle_grid, workplane

    sc = furnace_scene()
    sc.calculation_surfaces = [workplane([(-1, -1), (1, -1), (1, 1), (-1, 1)], height=0.75, band=0.2, name="desk"),
                               rectangle_grid((-1, 1, 0), (2, 0, 0), (0, 0, 1.5), name="wall", maintenance_factor=0.8)]
    back = S.load(S.save(sc, tmp_path / "s.json"))
    assert [s.name for s in back.calculation_surfaces] == ["desk", "wall"]
    for a, b in zip(sc.calculation_surfaces, back.calculation_surfaces):
        np.testing.assert_array_equal(a.points, b.points)
        np.testing.assert_array_equal(a.normals, b.normals)
        assert (a.kind, a.band, a.maintenance_factor, a.grid_shape) == (b.kind, b.band, b.maintenance_factor,
                                                                         b.grid_shape)


def test_calculation_surfaces_are_validated():
    from spectral_gi.core.lux import workplane

    sc = furnace_scene()
    desk = workplane([(-1, -1), (1, -1), (1, 1), (-1, 1)], name="desk")
    sc.calculation_surfaces = [desk, desk]
    with pytest.raises(S.SceneError, match=r"calculation_surfaces\[1\].*second surface named 'desk'"):
        S.validate(sc)
    sc.calculation_surfaces = ["desk"]
    with pytest.raises(S.SceneError, match=r"calculation_surfaces\[0\]: expected a CalculationSurface"):
        S.validate(sc)


def test_plastic_layering_entries_are_checked():
    """The plastic row's layering (entry 3: 0 physical, 1 cycles) and multiscatter (entry 4:
    only with cycles) take those values only; the error names the material and the entry."""
    from spectral_gi.core import bsdfs as B

    sc = furnace_scene(0.5, 1.0)
    sc.materials[0].model = C.MAT_PLASTIC
    for row in (B.plastic_params(0.3), B.plastic_params(0.3, layering="cycles", multiscatter=True)):
        sc.materials[0].params = list(row)
        S.validate(sc)
    for entry, value, match in ((3, 2.0, "layering \\(entry 3\\)"), (3, 0.5, "layering"),
                                (4, 1.0, "multiscatter \\(entry 4\\)")):
        row = B.plastic_params(0.3)
        row[entry] = value
        sc.materials[0].params = list(row)
        with pytest.raises(S.SceneError, match=f"materials\\[0\\].*params: plastic {match}"):
            S.validate(sc)
