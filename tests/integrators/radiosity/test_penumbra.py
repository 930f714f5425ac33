"""The direct light of emitting patches in a penumbra (kernel.OP_EMITTERS): a square lamp
half hidden by the edge of a plate, where the visible part of the lamp, and so the exact
illuminance π L F (Lambert's formula, compendium item 57, for the visible rectangle), is
known in closed form."""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from spectral_gi import core
from spectral_gi.core import constants as C
from spectral_gi.core.integrators.radiosity import kernel as K
from spectral_gi.core.integrators.radiosity import solve
from spectral_gi.core.scene import Material, Mesh, Scene, SpectrumTable

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from helpers import flat_emission  # noqa: E402

H = 1.0  # lamp height, m
A = 0.5  # the lamp's half-width, m
EDGE = 0.1  # the plate's edge (x), at half the lamp's height; it covers x > EDGE
LUM = 1000.0  # cd/m²


def quad(name, corners, material):
    pos = np.asarray(corners, np.float32)
    return Mesh(name, pos, np.array([[0, 1, 2], [0, 2, 3]], np.int32), np.full(2, material, np.int32))


def lamp_and_plate():
    sp = SpectrumTable.empty()
    e = sp.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    mats = [Material("lamp", emission=e, emission_luminance=LUM, two_sided=False), Material("black")]
    lamp = quad("lamp", [(-A, -A, H), (-A, A, H), (A, A, H), (A, -A, H)], 0)  # faces down
    plate = quad("plate", [(EDGE, -2, H / 2), (2, -2, H / 2), (2, 2, H / 2), (EDGE, 2, H / 2)], 1)
    floor = quad("floor", [(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)], 1)
    return Scene(meshes=[lamp, plate, floor], spectra=sp, materials=mats)


def exact_lux(x0):
    """π L F to the part of the lamp the floor point (x0, 0, 0) sees past the plate's edge,
    which hides the lamp beyond x = 2 EDGE − x0."""
    x1 = min(A, 2 * EDGE - x0)
    if x1 <= -A:
        return 0.0
    poly = np.array([(-A, -A, H), (-A, A, H), (x1, A, H), (x1, -A, H)])
    return math.pi * LUM * core.form_factor_point_polygon((x0, 0, 0), (0, 0, 1), poly)


XS = (-0.35, -0.2, 0.0, 0.12, 0.3, 0.5)  # from nearly the whole lamp seen to a sliver of it


@pytest.fixture(scope="module")
def solution():
    return core.radiosity(lamp_and_plate(), method="jacobi", n_points=1, n_vis=4)


def test_penumbra_direct_light_matches_the_closed_form(solution):
    """The lamp is two patches, as the Cornell box's lamp at 0.1 m: the illuminance at floor
    points across its penumbra is within 1 % of the closed form (16 shadow rays and the three
    corners a pair decide the penumbra, 1024 resolve it), or 0.2 % of the unshadowed value
    where the point sees a sliver of the lamp, and four shadow rays a pair are off by far
    more."""
    pts = np.array([(x, 0.0, 0.0) for x in XS])
    nrm = np.tile([0.0, 0.0, 1.0], (len(XS), 1))
    want = np.array([exact_lux(x) for x in XS])
    got = core.radiosity_illuminance(solution, pts, nrm, indirect=False)
    np.testing.assert_allclose(got, want, rtol=0.01, atol=0.002 * want[0])
    assert want[0] == pytest.approx(math.pi * LUM * core.form_factor_point_polygon(
        (XS[0], 0, 0), (0, 0, 1), np.array([(-A, -A, H), (-A, A, H), (A, A, H), (A, -A, H)])), rel=1e-12)
    coarse = core.radiosity(lamp_and_plate(), method="jacobi", n_points=1, n_vis=4, n_emit=1)
    old = core.radiosity_illuminance(coarse, pts, nrm, indirect=False)
    assert np.max(np.abs(old / want - 1)) > 0.03  # the lamp's visibility from four rays a patch


def test_fully_visible_pairs_cost_the_first_rays_only(solution):
    """A point that sees the whole lamp (or none of it) stops after the first 16 rays: the
    factor equals Lambert's formula for the whole lamp exactly, with no noise."""
    ctx = solution._ctx
    emit = np.nonzero(np.any(solution.emitted > 0, axis=1))[0].astype(np.int32)
    assert emit.size == 2
    pts = np.array([[[-1.0, 0.3, 0.0]], [[3.0, 0.0, 0.0]]])  # left of the plate; far under it
    nrm = np.tile([0.0, 0.0, 1.0], (2, 1))
    q = solve._query(pts, nrm, np.full(2, -1, np.int32), emit)
    f = solve.run_op(K.OP_EMITTERS, ctx.pat, q, ctx.lit, emit.size, 256, 0, ctx.eps, 1).sum(axis=1)
    lamp = np.array([(-A, -A, H), (-A, A, H), (A, A, H), (A, -A, H)])
    assert f[0] == pytest.approx(core.form_factor_point_polygon(pts[0, 0], nrm[0], lamp), rel=1e-5)
    assert f[1] == 0.0


def test_penumbra_on_the_patches(solution):
    """The floor's patches under the penumbra get the same adaptive visibility: the direct
    illuminance of each patch, sampled at its centroid (one point a patch), is the closed
    form there within 1 %."""
    sol = core.radiosity(lamp_and_plate(), method="jacobi", n_points=1, n_vis=4, max_edge=0.25)
    c = sol.patches.corners.mean(axis=1)
    floor = np.nonzero((np.abs(c[:, 2]) < 1e-9) & (sol.patches.normal[:, 2] > 0.5) & (np.abs(c[:, 0]) < 0.6)
                       & (np.abs(c[:, 1]) < 0.2))[0]
    assert floor.size >= 4
    # the closed form at the centroid, for centroids on the line y = 0 only by symmetry: use the general one
    want = []
    for i in floor:
        x0, y0 = c[i, 0], c[i, 1]
        x1 = min(A, 2 * EDGE - x0)
        poly = np.array([(-A, -A, H), (-A, A, H), (x1, A, H), (x1, -A, H)])
        want.append(0.0 if x1 <= -A else math.pi * LUM * core.form_factor_point_polygon((x0, y0, 0), (0, 0, 1), poly))
    np.testing.assert_allclose(sol.direct_illuminance[floor], want, rtol=0.01)


def test_n_emit_must_be_a_whole_number():
    with pytest.raises(core.SceneError, match="n_emit"):
        core.radiosity(lamp_and_plate(), n_emit=0)
