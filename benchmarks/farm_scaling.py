"""Render farms on Dask: scaling on this machine, and on paper for larger farms.

    python benchmarks/farm_scaling.py [--size 128] [--spp 256] [--threads 2]

Measured here, on the Cornell box at ``--size``² pixels and ``--spp`` samples (chunks of
16 samples, one task per chunk):

* what the chunks cost a render on one machine: the same passes (8 samples each) added
  sample by sample to one film, and chunk by chunk as the film does (one more film add
  per chunk);
* the plain local render (``render(threads=--threads)``) against ``local:1`` and
  ``local:2`` (LocalClusters of one and two worker processes, started before the clock
  runs and warmed by one render, so the figures leave out the workers' start and kernel
  load, which the table lists apart): wall time, time to the first merged batch, and
  the overhead of a batch — the farm's wall time less the local render's, spread over
  its batches (negative when the workers' own threads did better);
* the fixed cost of a task on its own: a 1×1-pixel film with 64 chunks, where the
  rendering is nothing and the wall time is the scheduler's round trip, the transfer
  and the client's merge;
* the bytes moved per batch: the pickled result of one chunk (the film's float64 sums:
  5 or 6 channels, 9 AOV channels and the spectral bins) and of the scattered scene.

On paper, for 10, 100 and 1 000 workers: the client merges batches one after another,
so a farm keeps every worker busy only while the client can take a batch as fast as
the workers finish them. With t_b the time a worker renders one batch (measured here
for one worker process at --threads threads), o the measured fixed cost of a task, B
the bytes of a batch and a client link of R bytes/s (an assumed 10 Gbit/s Ethernet,
1.25 GB/s), W workers deliver W / t_b batches a second and the client takes at most
1 / (o + B / R + m), m the measured time of the merge (one add of the film). The
speed-up is the smaller of the two times t_b; its ratio to W is the efficiency. The
figures are for a 1920×1080 film and this scene's measured rate per worker; tasks
that merge several chunks (--batch-spp) divide o, not B.
"""
import argparse
import logging
import os
import pickle
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import results  # noqa: E402  (benchmarks/results.py: the JSON record of this run)

LINK_BYTES_PER_SECOND = 1.25e9  # assumed: 10 Gbit/s Ethernet to the client


def _timed_render(render, sc, **kw):
    first = {}
    t0 = time.perf_counter()

    def progress(done, total, rate):
        first.setdefault("t", time.perf_counter() - t0)

    film, stats = render(sc, progress=progress, **kw)
    return time.perf_counter() - t0, first.get("t", float("nan")), film


def _warm():
    """Runs on each worker: load (or compile) the kernels with a 1-sample render."""
    from spectral_gi.core.integrators.render import render
    from spectral_gi.core.scene.builtin import cornell_box

    render(cornell_box(width=2, height=2, spp=1), threads=1)


def _chunk_cost(sc, threads, reps=3):
    """The local render's cost of its chunks: the same passes of 8 samples added to one film
    sample by sample (run_pass) and chunk by chunk (add_samples), best of ``reps`` each."""
    from concurrent.futures import ThreadPoolExecutor

    from spectral_gi.core.film import Film
    from spectral_gi.core.integrators.render import add_samples, prepare, run_pass

    prep = prepare(sc)
    spp = sc.settings.spp
    best = {"one film": float("inf"), "chunks": float("inf")}
    with ThreadPoolExecutor(threads) as pool:
        for _ in range(reps):
            for name, fn in (("one film", run_pass), ("chunks", add_samples)):
                film = Film(sc.camera.width, sc.camera.height)
                t0 = time.perf_counter()
                for s0 in range(0, spp, 8):
                    fn(prep, film, s0, min(spp, s0 + 8), pool)
                best[name] = min(best[name], time.perf_counter() - t0)
    return best


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args(argv)

    import distributed

    from spectral_gi.core import Farm
    from spectral_gi.core.film import CHUNK_SPP, Film
    from spectral_gi.core.integrators.render import render
    from spectral_gi.core.scene.builtin import cornell_box

    sc = cornell_box(width=args.size, height=args.size, spp=args.spp, seed=1)
    render(cornell_box(width=4, height=4, spp=1), threads=1)  # kernels compiled or loaded here
    chunked = _chunk_cost(sc, args.threads)
    n_batches = -(-args.spp // CHUNK_SPP)
    t_local, first_local, ref = _timed_render(render, sc, threads=args.threads)
    rows = [["local render", args.threads, round(t_local, 2), round(first_local, 3), "—", "—", "yes"]]
    task_cost = {}
    for n in (1, 2):
        t0 = time.perf_counter()
        farm = Farm(f"local:{n}")
        farm.threads = max(1, args.threads // n)
        farm.client.run(_warm)  # every worker loads the kernels
        start = time.perf_counter() - t0
        t, first, film = _timed_render(render, sc, client=farm)
        same = all(np.array_equal(getattr(film, a), getattr(ref, a)) for a in ("sums", "aov"))
        tiny = cornell_box(width=1, height=1, spp=64 * CHUNK_SPP, seed=1)
        tt, _, _ = _timed_render(render, tiny, client=farm)
        task_cost[n] = tt / 64
        rows.append([f"local:{n}", f"{n} × {farm.threads}", round(t, 2), round(first, 3),
                     round(1e3 * (t - t_local) / n_batches, 1), round(start, 1), "yes" if same else "NO"])
        farm.close()
    print(f"{args.size}×{args.size} px, {args.spp} spp, {n_batches} batches; chunks {chunked}")
    for r in rows:
        print(r)

    # bytes of a batch and of the scene, and the client's merge, at this size and at 1080p
    chunk = Film(args.size, args.size)
    batch_bytes = len(pickle.dumps([(0, CHUNK_SPP, chunk)], protocol=5))
    scene_bytes = len(pickle.dumps(sc, protocol=5))
    hd = Film(1920, 1080)
    hd_bytes = len(pickle.dumps([(0, CHUNK_SPP, hd)], protocol=5))
    acc = Film(1920, 1080)
    first = Film(1920, 1080)
    part = Film(1920, 1080)
    for a in (first.sums, first.aov, part.sums, part.aov):  # touched, as unpickled arrays are
        a.fill(1.0)
    acc.merge_chunk(first, CHUNK_SPP)
    t0 = time.perf_counter()
    acc.merge_chunk(part, 2 * CHUNK_SPP)
    merge_hd = time.perf_counter() - t0
    print(f"batch {batch_bytes} B at {args.size}², {hd_bytes / 1e6:.0f} MB at 1080p; scene {scene_bytes} B; "
          f"1080p merge {1e3 * merge_hd:.0f} ms; task cost {1e3 * task_cost[2]:.1f} ms")

    # on paper: a 1080p film, each worker rendering at this machine's measured rate (threads per worker)
    rate = args.size * args.size * args.spp / t_local  # samples/s of one machine at --threads threads
    t_b = 1920 * 1080 * CHUNK_SPP / rate
    o = task_cost[2]
    client_rate = 1.0 / (o + hd_bytes / LINK_BYTES_PER_SECOND + merge_hd)
    paper = []
    for w in (10, 100, 1000):
        demand = w / t_b
        speedup = min(w, client_rate * t_b)
        paper.append([w, round(t_b, 2), round(demand, 2), round(client_rate, 2), round(speedup, 1),
                      f"{100 * speedup / w:.0f} %"])
        print(paper[-1])
    results.write("farm_scaling", tables=[
        results.table(f"Cornell box {args.size}×{args.size}, {args.spp} spp, {n_batches} batches of {CHUNK_SPP} "
                      "spp (measured)",
                      ["render", "workers × threads", "wall s", "first batch merged s", "overhead ms / batch",
                       "cluster start + kernel load s", "bit-identical"], rows),
        results.table("The film's chunks on one machine: passes of 8 spp, best of 3 (measured)",
                      ["accumulation", "wall s", "relative"],
                      [["every sample into one film (no chunks)", round(chunked["one film"], 3), 1.0],
                       ["chunks of 16 spp added in order", round(chunked["chunks"], 3),
                        round(chunked["chunks"] / chunked["one film"], 3)]]),
        results.table("Bytes moved and fixed costs (measured)", ["quantity", "value"], [
            ["result of one batch at this size, bytes", batch_bytes],
            ["result of one batch, 1920×1080 film, MB", round(hd_bytes / 1e6, 1)],
            ["scene scattered once to each worker, bytes", scene_bytes],
            ["fixed cost of a task (1×1 px, local:1), ms", round(1e3 * task_cost[1], 1)],
            ["fixed cost of a task (1×1 px, local:2), ms", round(1e3 * task_cost[2], 1)],
            ["client merge of a 1920×1080 batch, ms", round(1e3 * merge_hd, 1)]]),
        results.table("On paper: a 1920×1080 film, 16-spp batches, a 10 Gbit/s client link (assumed)",
                      ["workers", "batch time per worker s", "batches/s the workers deliver",
                       "batches/s the client merges", "speed-up", "efficiency"], paper),
    ], conditions={"size": args.size, "spp": args.spp, "threads": args.threads, "chunk_spp": CHUNK_SPP,
                   "link_bytes_per_second": LINK_BYTES_PER_SECOND, "dask": distributed.__version__})
    logging.shutdown()


if __name__ == "__main__":
    main()
