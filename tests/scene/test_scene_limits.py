"""Strict types and the bounds that keep what a kernel reads representable (scenes built in
Python: the add-on's exporter, scripts), and the render's up-front checks of its inputs."""
import numpy as np
import pytest
from helpers import disk_over_plane_scene, furnace_scene

from spectral_gi.core import constants as C
from spectral_gi.core import scene as S
from spectral_gi.core.camera.record import camera_vector
from spectral_gi.core.integrators.render import check_render_inputs, memory_needed


def _expect(sc, field):
    with pytest.raises(S.SceneError) as e:
        S.validate(sc)
    assert str(e.value).startswith(field) and "\n" not in str(e.value), str(e.value)
    return str(e.value)


@pytest.mark.parametrize("scale", [1.4e154, 1e200, 1e16])
def test_a_camera_frame_that_overflows_is_refused(scale):
    sc = furnace_scene()
    sc.camera.to_world[:3, :3] *= scale
    if scale > 1e154:  # what the kernel would have read: a frame of zeros or NaN (rays without direction)
        with np.errstate(all="ignore"):
            frame = camera_vector(sc.camera)[:9].reshape(3, 3)
        assert not (np.all(np.isfinite(frame)) and abs(np.linalg.det(frame)) > 1e-6)
    _expect(sc, "camera.to_world")


@pytest.mark.parametrize("record,field,value", [
    ("material", "two_sided", "no"), ("material", "reflectance", 0.0), ("material", "model", 0.0),
    ("material", "params", "abc"), ("material", "params", [1.0, "x"]), ("light", "visible", 1),
    ("light", "kind", 0.0), ("light", "two_sided", np.float64(1.0)), ("settings", "spp", 4.0),
    ("camera", "width", 8.0), ("camera", "projection", 0.0), ("scene", "metadata", ["name"]),
])
def test_each_field_has_one_type(record, field, value):
    sc = disk_over_plane_scene(spp=4)
    target = {"material": sc.materials[0], "light": sc.lights[0], "settings": sc.settings, "camera": sc.camera,
              "scene": sc}[record]
    setattr(target, field, value)
    with pytest.raises(S.SceneError, match=field):
        S.validate(sc)


@pytest.mark.parametrize("what", ["emission_luminance", "light luminance", "intensity", "illuminance",
                                  "world luminance", "coordinate", "uv"])
def test_values_that_would_overflow_float32_are_refused(what):
    sc = disk_over_plane_scene(spp=4)
    if what == "emission_luminance":
        sc.materials[0].emission = 1
        sc.materials[0].emission_luminance = 1e30
        field = "materials[0]"
    elif what == "light luminance":
        sc.lights[0].luminance = 3e38
        field = "lights[0]"
    elif what == "intensity":
        sc.lights[0].kind, sc.lights[0].intensity = C.LIGHT_POINT, 1e20
        field = "lights[0]"
    elif what == "illuminance":
        sc.lights[0].kind, sc.lights[0].illuminance = C.LIGHT_SUN, 1e300
        field = "lights[0]"
    elif what == "world luminance":
        sc.world.background, sc.world.luminance = 1, 1e16
        field = "world.luminance"
    elif what == "coordinate":
        sc.meshes[0].positions[0, 0] = 3e38
        field = "meshes[0]"
    else:
        sc.meshes[0].uvs = np.full((4, 2), 1e30, np.float32)
        field = "meshes[0]"
    _expect(sc, field)


def test_coefficients_no_spectrum_has_are_refused_without_a_linear_algebra_error():
    sc = furnace_scene()
    sc.spectra.coeffs[0, 1] = 1e38  # found by the fuzz tests: the eigenvalue test did not converge
    assert "no reflectance" in _expect(sc, "spectra[0]")
    sc = furnace_scene()
    sc.spectra.coeffs[1, :] *= 1e300
    assert "emission mean" in _expect(sc, "spectra[1]")


def test_the_render_checks_bins_memory_and_the_film_to_resume_before_it_starts():
    sc = furnace_scene()
    with pytest.raises(S.SceneError, match=r"spectral_bins: expected an integer in \[0, 471\]"):
        check_render_inputs(sc, 50000)
    with pytest.raises(S.SceneError, match="spectral_bins"):
        check_render_inputs(sc, 2.0)
    sc.camera.width = sc.camera.height = 65536  # allowed by the validator, but not by this machine's memory
    S.validate(sc)
    assert memory_needed(sc) > 2 ** 40
    with pytest.raises(S.SceneError, match=r"camera.width x camera.height: a 65536x65536 render needs about .* GiB"):
        check_render_inputs(sc)
    with pytest.raises(S.SceneError, match="resume: expected a Film"):
        check_render_inputs(furnace_scene(), 0, resume="film.npz")


@pytest.mark.parametrize("value", [float("nan"), object(), {1, 2}])
def test_metadata_that_json_cannot_hold_is_refused_by_save(tmp_path, value):
    sc = furnace_scene()
    sc.metadata = {"x": value}
    with pytest.raises(S.SceneError, match="metadata: cannot be written as JSON"):
        S.save(sc, tmp_path / "s.json")
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- scene-file sizes

def _saved_doc(tmp_path):
    import json

    path = S.save(furnace_scene(), tmp_path / "s.json")
    return path, json.loads(path.read_text())


@pytest.mark.parametrize("where", ["materials[0].name", "metadata.note", "a key of metadata"])
def test_a_string_longer_than_the_limit_is_refused_naming_where(tmp_path, where):
    import json

    path, doc = _saved_doc(tmp_path)
    long = "x" * (S.MAX_STRING + 1)
    if where == "materials[0].name":
        doc["materials"][0]["name"] = long
    elif where == "metadata.note":
        doc["metadata"] = {"note": long}
    else:
        doc["metadata"] = {long: 1}
    path.write_text(json.dumps(doc))
    with pytest.raises(S.SceneError) as e:
        S.load(path)
    msg = str(e.value)
    assert f"of {S.MAX_STRING + 1} characters (at most {S.MAX_STRING})" in msg and "\n" not in msg
    assert msg.startswith("metadata" if where == "a key of metadata" else where)
    path.write_text(json.dumps(doc).replace(long, long[:-1]))
    if where == "materials[0].name":  # within the file's limit, a name still has its own
        with pytest.raises(S.SceneError, match=r"^materials\[0\]\.name: a string of 65536 characters \(at most 4096"):
            S.load(path)
    else:  # the limit itself is allowed
        S.load(path)


def test_a_scene_file_larger_than_the_limit_is_refused_before_it_is_parsed(tmp_path, monkeypatch):
    path, _doc = _saved_doc(tmp_path)
    size = path.stat().st_size
    monkeypatch.setattr(S, "MAX_JSON_BYTES", size - 1)
    with pytest.raises(S.SceneError, match=f"has {size} bytes, more than {size - 1}"):
        S.load(path)
    monkeypatch.setattr(S, "MAX_JSON_BYTES", size)
    S.load(path)
