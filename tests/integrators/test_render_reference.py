"""The path tracer (NEE + MIS) against the naive reference integrator (BSDF sampling only).

Both estimate the same integral; per pixel, the difference of the two means divided by
the standard error of that difference must look like a standard normal variable.
"""
import numpy as np
import pytest

from spectral_gi import core
from spectral_gi.core import constants as C

pytestmark = pytest.mark.statistical


def _scene(next_event, spp, seed):
    sc = core.cornell_box(12, 12, spp=spp, max_depth=3, seed=seed)
    # the white surfaces become a rough plastic (a GGX coat over the white base): MIS between
    # glossy BSDF sampling and light sampling is exercised, not only the diffuse case
    sc.materials[0] = core.Material(name="white plastic", model=C.MAT_PLASTIC, reflectance=sc.materials[0].reflectance,
                                    params=list(core.plastic_params(0.3)), ior=1.5)
    # the whole ceiling emits (at 1/20 of the lamp's luminance), so that the naive integrator,
    # which finds emitters only by chance, converges in a test's time; the lamp stays
    light = next(i for i, m in enumerate(sc.materials) if m.emission >= 0)
    lamp = sc.materials[light]
    sc.materials.append(core.Material(name="ceiling", reflectance=lamp.reflectance, emission=lamp.emission,
                                      emission_luminance=lamp.emission_luminance / 20, two_sided=False))
    ceiling = next(m for m in sc.meshes if m.name == "ceiling")
    ceiling.material[:] = len(sc.materials) - 1
    sc.settings.next_event = next_event
    sc.settings.filter = C.FILTER_BOX
    return sc


def _z(a, b):
    da, db = a.develop(), b.develop()
    diff = da.luminance - db.luminance
    se = np.sqrt(da.variance + db.variance)
    ok = se > 0
    return diff[ok] / se[ok], ok


def test_path_tracer_agrees_with_the_naive_integrator():
    full, _ = core.render(_scene(True, 256, 1), threads=2)
    naive, _ = core.render(_scene(False, 2048, 2), threads=2)
    z, ok = _z(full, naive)
    assert ok.sum() > 100
    # mean of z ~ N(0, 1/n); its spread ~ 1 (heavy tails of the naive estimator's rare light
    # hits make sample variances run a little low, so allow some slack above 1)
    assert abs(z.mean()) < 4.0 / np.sqrt(z.size), z.mean()
    assert 0.6 < np.mean(z * z) < 1.6, np.mean(z * z)
    assert np.mean(np.abs(z) > 3.5) < 0.02
    # and the images agree on the whole: the difference of the mean luminances over its
    # standard error (pixels are independent) is within 4
    da, db = full.develop(), naive.develop()
    n = da.luminance.size
    se = np.sqrt(da.variance.sum() + db.variance.sum()) / n
    assert abs(da.luminance.mean() - db.luminance.mean()) < 4.0 * se


def test_the_check_can_fail():
    """A 10 % brighter light in one image must be caught by the same statistics."""
    full, _ = core.render(_scene(True, 256, 1), threads=2)
    sc = _scene(False, 2048, 2)
    for m in sc.materials:
        if m.emission >= 0:
            m.emission_luminance *= 1.10
    naive, _ = core.render(sc, threads=2)
    z, _ = _z(full, naive)
    assert abs(z.mean()) > 4.0 / np.sqrt(z.size) or np.mean(z * z) > 1.6, (z.mean(), np.mean(z * z))


def test_next_event_must_be_a_boolean():
    sc = _scene(True, 1, 0)
    sc.settings.next_event = "yes"
    with pytest.raises(core.SceneError, match="settings.next_event"):
        core.validate(sc)
