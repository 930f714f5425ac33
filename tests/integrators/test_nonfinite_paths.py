"""Every path ends, and a sample that is not finite is dropped and counted, never carried.

Validated input cannot hold an infinite or NaN spectrum, but a lossless scene is valid: a
closed room of reflectance 1, where the throughput never falls and, with no depth limit
(the point measures' ``max_depth=None``), only a capped Russian roulette ends a path. The
kernels are driven here by records poked after validation (infinite and NaN reflectance,
infinite emission) through the point measures with unlimited depth and through a camera
render, in a subprocess with a time limit: a path that never ends stops that process
(faulthandler prints where) instead of the test run.

The contract (docs/user/reliability.md): the call returns; a reflectance reads clamped to
[0, 1] (Inf as 1, NaN as 0); a sample whose value is NaN or Inf is left out of the mean and
counted (the point measures' samples used, with a NonFiniteSamples warning; the film's
sample count and RenderStats.dropped_samples); the relative-error loop stops a point whose
estimate has no target to reach.
"""
import json
import math
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

PROBE = textwrap.dedent("""
    import faulthandler, json, sys, warnings
    import numpy as np
    sys.path.insert(0, sys.argv[1])
    import helpers as H
    from spectral_gi import core
    from spectral_gi.core.integrators import render
    from spectral_gi.core.integrators.illuminance import NonFiniteSamples

    real = render.prepare
    POKE = {}

    def poked(scene, **kw):
        prep = real(scene, **kw)
        m = prep.materials
        if "reflectance" in POKE:
            m.spec[m.ra[0]] = np.float32(POKE["reflectance"])
        if "emission" in POKE:
            m.spec[m.emis[0]] = np.float32(POKE["emission"])
        return prep

    render.prepare = poked
    P = np.zeros((3, 3))
    N = np.tile([0.0, 0.0, 1.0], (3, 1))
    core.point_illuminance(H.furnace_scene(rho=0.5), P[:1], N[:1], spp=1, threads=1)  # compile (or load)
    core.render(H.furnace_scene(rho=0.5, spp=1, width=2, height=2), threads=1)
    faulthandler.dump_traceback_later(int(sys.argv[2]), exit=True)  # a path that never ends: exit 1

    def lux(rho, poke=None, **kw):
        POKE.clear()
        POKE.update(poke or {})
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            e, se, n = core.point_illuminance(H.furnace_scene(rho=rho), P, N, max_depth=None, threads=1, **kw)
        warned = [str(x.message) for x in w if issubclass(x.category, NonFiniteSamples)]
        return {"lux": e.tolist(), "se": se.tolist(), "n": n.tolist(), "warned": warned}

    def camera(rho, poke=None):
        POKE.clear()
        POKE.update(poke or {})
        film, st = core.render(H.furnace_scene(rho=rho, spp=16, width=4, height=4, max_depth=1024), threads=1)
        y = film.develop().luminance
        return {"count": film.sums[..., 3].tolist(), "dropped": st.dropped_samples, "spp": st.spp,
                "finite": bool(np.isfinite(y).all()), "mean": float(y.mean())}

    def cli_lux(poke):
        import contextlib, io, tempfile
        from pathlib import Path
        from spectral_gi import cli
        from spectral_gi.core.scene import save

        d = Path(tempfile.mkdtemp())
        save(H.furnace_scene(rho=0.5), d / "box.json")
        (d / "p.pts").write_text("0 0 0 0 0 1\\n0 0 0.5 0 0 1\\n")
        POKE.clear()
        POKE.update(poke)
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            code = cli.main(["lux", str(d / "box.json"), "--sensors", str(d / "p.pts"), "--spp", "16",
                             "--threads", "1", "--out", str(d / "lux.csv")])
        return {"code": code, "stderr": err.getvalue()}

    out = {
        "white": lux(1.0, spp=64),
        "inf_reflectance": lux(0.5, {"reflectance": np.inf}, spp=64),
        "nan_reflectance": lux(0.5, {"reflectance": np.nan}, spp=256),
        "one": lux(0.5, {"reflectance": 1.0}, spp=64),
        "zero": lux(0.5, {"reflectance": 0.0}, spp=256),
        "inf_emission": lux(0.5, {"emission": np.inf}, spp=64),
        "inf_emission_rel": lux(0.5, {"emission": np.inf}, spp=1 << 20, rel_error=0.01),
        "cam_white": camera(1.0),
        "cam_one": camera(0.5, {"reflectance": 1.0}),
        "cam_inf_reflectance": camera(0.5, {"reflectance": np.inf}),
        "cam_nan_reflectance": camera(0.5, {"reflectance": np.nan}),
        "cam_inf_emission": camera(0.5, {"emission": np.inf}),
        "cli_inf_emission": cli_lux({"emission": np.inf}),
    }
    print(json.dumps(out))
""")


@pytest.fixture(scope="module")
def probe():
    tests = Path(__file__).resolve().parents[1]
    r = subprocess.run([sys.executable, "-c", PROBE, str(tests), "300"], capture_output=True, text=True, timeout=2400)
    assert r.returncode == 0, r.stderr[-3000:]
    return json.loads(r.stdout.strip().splitlines()[-1])


@pytest.mark.slow
def test_a_lossless_room_ends_every_path_with_no_depth_limit(probe):
    # reflectance 1 in a closed box: the throughput never falls, only the capped roulette ends paths
    w = probe["white"]
    assert w["n"] == [64] * 3 and not w["warned"]
    assert all(math.isfinite(v) and v > 0 for v in w["lux"])


@pytest.mark.slow
def test_a_poked_reflectance_reads_clamped(probe):
    # Inf reads as 1 and NaN as 0: the same paths, bit for bit, as a reflectance of 1 or 0
    assert probe["inf_reflectance"] == probe["one"]
    assert probe["nan_reflectance"] == probe["zero"]
    # walls that emit L = 100 cd/m² all round and reflect nothing: E = π L
    z = probe["zero"]
    assert all(abs(e - math.pi * 100.0) <= 4.0 * se for e, se in zip(z["lux"], z["se"])), z


@pytest.mark.slow
def test_infinite_samples_are_dropped_counted_and_said(probe):
    e = probe["inf_emission"]
    assert e["n"] == [0] * 3  # every sample saw an infinite emitter: none used
    assert all(math.isnan(v) for v in e["lux"])
    assert len(e["warned"]) == 1 and "192 of 192 samples were not finite" in e["warned"][0]
    # the relative-error loop stops such a point at its first check instead of running to the cap
    r = probe["inf_emission_rel"]
    assert r["n"] == [0] * 3 and "96 of 96 samples" in r["warned"][0]


@pytest.mark.slow
def test_a_camera_render_ends_and_counts_what_it_drops(probe):
    for case in ("cam_white", "cam_inf_reflectance", "cam_nan_reflectance"):
        c = probe[case]
        assert c["spp"] == 16 and c["dropped"] == 0 and c["finite"], case
    assert probe["cam_inf_reflectance"] == probe["cam_one"]
    c = probe["cam_inf_emission"]
    assert c["spp"] == 16 and c["dropped"] == 16 * 4 * 4
    assert c["count"] == [[0.0] * 4] * 4  # no pixel holds a sample: it develops as black, not NaN
    assert c["finite"] and c["mean"] == 0.0


@pytest.mark.slow
def test_the_command_line_says_what_it_dropped_and_refuses_no_result_in_one_line_each(probe):
    c = probe["cli_inf_emission"]
    assert c["code"] == 2, c["stderr"]  # every sample dropped: no value to write, no CSV
    lines = [line for line in c["stderr"].splitlines() if line.startswith("spectral-gi: ")]
    assert lines == ["spectral-gi: warning: 32 of 32 samples were not finite (NaN or Inf) and were dropped, at 2 "
                     "point(s) from index 0; the samples used are returned per point",
                     "spectral-gi: error: the integrator's lux must be finite (value 0 is not)"], c["stderr"]
    assert "Traceback" not in c["stderr"] and "NonFiniteSamples:" not in c["stderr"]
