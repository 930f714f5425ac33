"""Render farms on Dask (core/farm): a farm's image, lux values and frames are those of one
machine, bit for bit, whatever the workers, the batches and the faults.

The LocalCluster tests share one cluster of two worker processes (each loads the compiled
kernels once); the killed-worker test runs last, since it restarts a worker.
"""
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from spectral_gi.core.film import CHUNK_SPP, Film
from spectral_gi.core.integrators import render as R
from spectral_gi.core.scene.builtin import cornell_box

distributed = pytest.importorskip("distributed")


def _same(a, b):
    for name in ("sums", "aov", "spectral"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert a.spp == b.spp


# --------------------------------------------------------------------------- LocalCluster

@pytest.fixture(scope="module")
def cluster():
    import logging

    cl = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=logging.ERROR)
    client = distributed.Client(cl)
    yield client
    client.close()
    cl.close()


@pytest.mark.slow
def test_farm_image_is_bit_identical_to_a_local_render(cluster, tmp_path):
    sc = cornell_box(width=12, height=10, spp=3 * CHUNK_SPP + 5, seed=3, max_depth=4)
    local, _ = R.render(sc, threads=1, spectral_bins=3)
    seen = []
    for batch in (None, 2 * CHUNK_SPP):
        farm, stats = R.render(sc, client=cluster, spectral_bins=3, batch_spp=batch,
                               progress=lambda done, total, rate: seen.append((done, total)))
        _same(farm, local)
        assert stats.spp == sc.settings.spp and stats.stop_reason == "spp" and not stats.cancelled
    assert seen[:4] == [(16, 53), (32, 53), (48, 53), (53, 53)]  # one call per merged batch, in order
    # a killed client resumes from the checkpoint of the merged film, mid-chunk too
    sc.settings.spp = CHUNK_SPP + 4
    ckpt = tmp_path / "ckpt.npz"
    R.render(sc, client=cluster, spectral_bins=3, checkpoint=ckpt)
    part = Film.load(ckpt)
    assert part.spp == CHUNK_SPP + 4 and part.tail_spp == 4
    sc.settings.spp = 3 * CHUNK_SPP + 5
    resumed, _ = R.render(sc, client=cluster, resume=part)
    _same(resumed, local)


@pytest.mark.slow
def test_farm_lux_values_are_those_of_one_machine(cluster):
    from spectral_gi.core.integrators.illuminance import illuminance

    sc = cornell_box()
    rng = np.random.default_rng(1)
    pts = np.column_stack([rng.uniform(-0.2, 0.2, 7), rng.uniform(-0.2, 0.2, 7), np.full(7, 0.01)])
    nrm = np.tile([0.0, 0.0, 1.0], (7, 1))
    for kw in ({"spp": 48}, {"spp": 512, "rel_error": 0.05}):
        here = illuminance(sc, pts, nrm, threads=1, seed=4, **kw)
        there = illuminance(sc, pts, nrm, client=cluster, seed=4, **kw)
        for a, b in zip(here, there):
            assert np.array_equal(a, b)
    assert 0 < here[2].min() < 512  # the noise target stopped points at different counts


def test_without_dask_the_flag_says_how_to_install_it(tmp_path):
    code = ("import sys; sys.modules['distributed'] = None; from spectral_gi.cli import main; "
            "sys.exit(main(['render', '--width', '4', '--height', '4', '--spp', '1', '--scheduler', 'local:2', "
            f"'--out', {str(tmp_path / 'x.exr')!r}]))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 1, proc.stderr[-2000:]
    errors = [ln for ln in proc.stderr.splitlines() if ln.startswith("spectral-gi: error:")]
    assert len(errors) == 1 and 'pip install "spectral-gi[farm]"' in errors[0], proc.stderr[-2000:]


def test_a_bad_scheduler_address_is_one_line(capsys):
    from spectral_gi.core import Farm, FarmError

    with pytest.raises(FarmError, match="local:N"):
        Farm("local:0")


def test_workers_with_other_sources_refuse_the_task():
    from spectral_gi.core import FarmError
    from spectral_gi.core.farm import _check_worker, source_key

    _check_worker(source_key())
    with pytest.raises(FarmError, match="same version on every machine"):
        _check_worker("0000")


@pytest.mark.slow
def test_a_killed_worker_costs_only_its_batch(cluster):
    """One worker process is killed while it renders a batch: Dask reruns the batch on a
    worker that lives, and the image is still bit-identical."""
    sc = cornell_box(width=96, height=96, spp=8 * CHUNK_SPP, seed=9)
    result = {}

    def farm_render():
        result["film"], result["stats"] = R.render(sc, client=cluster)

    th = threading.Thread(target=farm_render)
    th.start()
    pids = cluster.run(os.getpid)
    victim = None
    deadline = time.monotonic() + 300
    while victim is None and time.monotonic() < deadline and th.is_alive():
        for addr, keys in cluster.processing().items():
            if any(str(k).startswith("spectral-gi-batch-") for k in keys) and addr in pids:
                victim = addr
                break
        time.sleep(0.02)
    assert victim is not None, "no batch was seen running"
    os.kill(pids[victim], signal.SIGKILL)
    th.join(600)
    assert not th.is_alive()
    assert pids[victim] not in cluster.run(os.getpid).values()  # the process is gone (its nanny started another)
    local, _ = R.render(sc, threads=2)
    _same(result["film"], local)
