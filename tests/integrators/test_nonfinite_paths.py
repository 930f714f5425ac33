"""A path whose throughput or direction stops being finite ends there: validated input
cannot produce one, but the kernels never carry it further (no endless path, no index
from a NaN). Driven by records poked after validation, in a subprocess with a time limit:
with unlimited depth, a path of infinite throughput would never be ended by the roulette."""
import subprocess
import sys
import textwrap

import pytest

PROBE = textwrap.dedent("""
    import sys
    import numpy as np
    sys.path.insert(0, sys.argv[1])
    import helpers as H
    from spectral_gi import core
    from spectral_gi.core.integrators import render

    real = render.prepare

    def poked(scene, **kw):
        prep = real(scene, **kw)
        prep.materials.spec[:] = np.float32(np.inf)  # every reflectance infinite: β becomes Inf at a bounce
        return prep

    scene = H.furnace_scene(rho=0.5)
    core.point_illuminance(scene, np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), spp=1, threads=1)  # compile
    core.render(H.furnace_scene(rho=0.5, spp=1), threads=1)
    import faulthandler
    faulthandler.dump_traceback_later(300, exit=True)  # a path that never ends: the process stops, exit 1
    render.prepare = poked
    lux, se, n = core.point_illuminance(scene, np.zeros((3, 3)), np.tile([0.0, 0.0, 1.0], (3, 1)), spp=64,
                                        max_depth=None, threads=1)
    assert (n == 64).all()
    film, st = core.render(scene, threads=1)
    assert st.spp == scene.settings.spp
    print("ended")
""")


@pytest.mark.slow
def test_a_path_of_infinite_throughput_ends(tmp_path):
    from pathlib import Path

    tests = Path(__file__).resolve().parents[1]
    out = subprocess.run([sys.executable, "-c", PROBE, str(tests)], capture_output=True, text=True, timeout=2400)
    assert out.returncode == 0 and out.stdout.strip().endswith("ended"), out.stderr[-3000:]
