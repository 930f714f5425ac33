"""The film's order of additions: chunks of CHUNK_SPP samples, each summed from zero, added
in order — the definition that makes passes, threads and farm tasks give the same bits."""
import numpy as np
import pytest

from spectral_gi.core.film import CHUNK_SPP, FILM_FORMAT, Film, chunk_spans
from spectral_gi.core.integrators import render as R
from spectral_gi.core.scene.builtin import cornell_box


def test_chunk_spans_cut_at_multiples_of_the_chunk():
    assert chunk_spans(0, 40) == [(0, 16), (16, 32), (32, 40)]
    assert chunk_spans(5, 20) == [(5, 16), (16, 20)]
    assert chunk_spans(16, 16) == []


def test_film_merges_chunks_in_order_only(tmp_path):
    f = Film(2, 1)
    part = Film(2, 1)
    part.sums[...] = 1.0
    with pytest.raises(ValueError, match="one chunk"):
        f.merge_chunk(part, CHUNK_SPP + 1)  # crosses a chunk boundary
    f.merge_chunk(part, CHUNK_SPP)
    assert f.spp == CHUNK_SPP and f.tail_spp == 0
    with pytest.raises(ValueError, match="one chunk"):
        f.merge_chunk(part, CHUNK_SPP)  # no samples
    half = Film(2, 1)
    half.sums[...] = 0.25
    f.merge_chunk(half, CHUNK_SPP + 4)  # an incomplete chunk is held apart ...
    assert f.tail_spp == 4 and np.all(f.sums == 1.25)
    g = Film.load(f.save(tmp_path / "f.npz"))  # ... in the checkpoint too
    assert g.tail_spp == 4 and g.spp == CHUNK_SPP + 4 and np.all(g.sums == 1.25)


def test_local_render_is_the_sum_of_its_chunks_in_order():
    """The definition of the image: each chunk summed from zero, chunk sums added in order —
    the same bits for any split of the samples into passes."""
    sc = cornell_box(width=10, height=8, spp=2 * CHUNK_SPP + 5, seed=7, max_depth=3)
    prep = R.prepare(sc)
    chunks = []
    for a, b in chunk_spans(0, sc.settings.spp):
        c = Film(10, 8)
        R.run_pass(prep, c, a, b)
        chunks.append(c.sums)
    image = chunks[0] + chunks[1]
    image = image + chunks[2]
    f, _ = R.render(sc, threads=2)
    assert np.array_equal(f.sums, image)
    g = Film(10, 8)
    for s0, s1 in [(0, 3), (3, 20), (20, 21), (21, sc.settings.spp)]:
        R.add_samples(prep, g, s0, s1)
    assert np.array_equal(g.sums, image)
    # a sum taken sample by sample over all 37 samples is a different (equally valid) rounding
    seq = Film(10, 8)
    R.run_pass(prep, seq, 0, sc.settings.spp)
    np.testing.assert_allclose(seq.sums, image, rtol=1e-12)


def test_a_version_2_checkpoint_resumes_to_within_rounding(tmp_path):
    """Films of version 2 summed every sample into one set of arrays; resuming one (here at
    8 spp, mid-chunk) takes its sums as the samples so far and goes on chunk by chunk."""
    sc = cornell_box(width=6, height=5, spp=8, seed=2, max_depth=3)
    half, _ = R.render(sc, threads=1)
    v2 = tmp_path / "v2.npz"
    np.savez_compressed(v2, format=np.array(FILM_FORMAT), version=np.array(2), spp=np.array(8, np.int64),
                        observer=np.array("1931"), sums=half.sums, spectral=half.spectral, aov=half.aov)
    old = Film.load(v2)
    assert old.spp == 8 and old.tail_spp == 0
    sc.settings.spp = 40
    resumed, _ = R.render(sc, threads=1, resume=old)
    full, _ = R.render(sc, threads=1)
    assert resumed.spp == 40
    np.testing.assert_allclose(resumed.sums, full.sums, rtol=1e-12)

