"""Fuzzing film checkpoints (Film.save / Film.load) and what a render accepts to resume from.

The contract: Film.load returns a film whose arrays the path kernel may add to (shapes,
dtypes and spp checked by core.film.check_film, every value finite) or raises ValueError
with one line naming the file; the render refuses (SceneError naming ``resume``) any film
that does not fit the scene, before a kernel runs.
"""
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from helpers import furnace_scene

from spectral_gi.core.film import AOV_CHANNELS, Film, check_film
from spectral_gi.core.integrators.render import check_render_inputs
from spectral_gi.core.scene import SceneError

pytestmark = pytest.mark.fuzz

W, H = 8, 8  # the furnace scene's resolution


@pytest.fixture(scope="module")
def members(tmp_path_factory):
    f = Film(W, H, spectral_bins=3)
    rng = np.random.default_rng(1)
    f.sums[...] = rng.random(f.sums.shape)
    f.spectral[...] = rng.random(f.spectral.shape)
    f.aov[...] = rng.random(f.aov.shape)
    f.spp = 4
    path = f.save(tmp_path_factory.mktemp("film") / "f.npz")
    with np.load(path) as z:
        return path, {k: z[k] for k in z.files}


def check_contract(path):
    try:
        film = Film.load(path)
    except ValueError as e:
        assert str(e) and "\n" not in str(e) and str(path) in str(e)
        return None
    check_film(film, film.width, film.height, film.observer)
    for a in (film.sums, film.aov, film.spectral):
        assert np.all(np.isfinite(a))
    sc = furnace_scene()
    sc.settings.spp = 64
    try:
        check_render_inputs(sc, 0, film)
    except SceneError as e:
        assert str(e).startswith("resume") and "\n" not in str(e)
    return film


VALUES = [np.nan, np.inf, -np.inf, 1e308, -1.0, 0.0]


@given(st.data())
def test_mutated_checkpoints_load_or_are_refused(tmp_path_factory, members, data):
    arrays = {k: v.copy() for k, v in members[1].items()}
    key = data.draw(st.sampled_from(sorted(arrays)))
    a = arrays[key]
    how = data.draw(st.sampled_from(["value", "dtype", "shape", "drop", "replace"]))
    if how == "value" and a.dtype.kind == "f" and a.size:
        a.reshape(-1)[data.draw(st.integers(0, a.size - 1))] = data.draw(st.sampled_from(VALUES))
    elif how == "dtype":
        with np.errstate(all="ignore"):
            try:
                arrays[key] = a.astype(data.draw(st.sampled_from([np.float32, np.int64, np.int8, np.bool_, "U4"])))
            except ValueError:  # a string member as a number
                arrays[key] = np.zeros(3, np.float32)
    elif how == "shape":
        arrays[key] = data.draw(st.sampled_from([
            np.zeros((H, W, 1000)), np.zeros((2, 2, 3)), np.zeros((H, W)), np.zeros((W, H, AOV_CHANNELS)),
            np.zeros((H + 1, W, a.shape[-1] if a.ndim else 1)), np.zeros((1, 1, 0)), np.zeros(5)]))
    elif how == "drop":
        del arrays[key]
    else:
        arrays[key] = data.draw(st.sampled_from([np.array("spectral-gi-film"), np.array(2), np.array(-1),
                                                 np.array(2 ** 40), np.array("1964"), np.array(1.5),
                                                 np.array([1, 2])]))
    path = tmp_path_factory.mktemp("m") / "m.npz"
    np.savez(path, **arrays)
    check_contract(path)


@given(st.binary(min_size=1, max_size=16), st.floats(0.0, 1.0))
def test_damaged_checkpoint_bytes_are_refused(tmp_path_factory, members, junk, where):
    data = bytearray(members[0].read_bytes())
    at = int(where * (len(data) - 1))
    data[at:at + len(junk)] = junk
    path = tmp_path_factory.mktemp("d") / "d.npz"
    path.write_bytes(bytes(data))
    check_contract(path)


def test_a_checkpoint_whose_spectral_array_does_not_fit_is_refused(tmp_path, members):
    # regression: a (2, 2, 3) spectral array with an 8 x 8 film was written out of bounds
    arrays = dict(members[1])
    arrays["spectral"] = np.zeros((2, 2, 3))
    np.savez(tmp_path / "bad.npz", **arrays)
    with pytest.raises(ValueError, match=r"spectral: expected shape \(8, 8, N\), got \(2, 2, 3\)"):
        Film.load(tmp_path / "bad.npz")
    film = Film.load(members[0])
    film.spectral = np.zeros((2, 2, 3))  # a film built in Python is checked by the render as well
    with pytest.raises(SceneError, match="resume: spectral must be"):
        check_render_inputs(furnace_scene(), 0, film)
