"""The radiosity solvers end on any input, and never call a solution that is not finite
converged: at most ``max_iter`` iterations, and a NaN residual (a solution with NaN or Inf
in it) stops the loop with ``converged`` False. Pure NumPy: the solvers take the matrices
directly."""
import math

import numpy as np
import pytest

from spectral_gi.core.integrators.radiosity import solvers

N = 6
F = np.full((N, N), 1.0 / (N - 1))  # a closed room: every patch sees the others, rows sum to 1
np.fill_diagonal(F, 0.0)
AREA = np.ones(N)
E = np.zeros((N, 1))
E[0] = 1.0


def _solve(method, rho, e, **kw):
    if method == "jacobi":
        return solvers.jacobi(F, rho, e, AREA, **kw)
    if method == "gauss-seidel":
        return solvers.gauss_seidel(F, rho, e, AREA, **kw)
    if method == "jacobi-power":
        return solvers.jacobi_power(F, rho, e, AREA, **kw)
    return solvers.southwell(F, rho, e, AREA, **kw)


METHODS = ["jacobi", "gauss-seidel", "jacobi-power", "southwell"]


@pytest.mark.parametrize("method", METHODS)
def test_a_lossless_room_stops_at_max_iter_unconverged(method):
    # ρ = 1 in a closed room: B = E + F B has no solution, the iterates grow without end
    B, st = _solve(method, np.ones((N, 1)), E, tol=1e-9, max_iter=200)
    assert st.iterations <= 200 and not st.converged
    assert np.isfinite(B).all()


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("poke", ["nan reflectance", "inf reflectance", "inf exitance"])
def test_a_solution_that_is_not_finite_is_never_converged(method, poke):
    rho = np.full((N, 1), 0.5)
    e = E.copy()
    if poke == "nan reflectance":
        rho[2] = np.nan
    elif poke == "inf reflectance":
        rho[2] = np.inf
    else:
        e[0] = np.inf
    with np.errstate(all="ignore"):
        B, st = _solve(method, rho, e, tol=1e-9, max_iter=10_000)
    assert not st.converged and math.isnan(st.residual), st
    assert st.iterations <= 2 * N, st  # stopped at the first residual that is not finite


def test_a_finite_room_still_converges():
    # the closed grey room's closed form: B = E + ρ F B, so the total Σ B = Σ E / (1 − ρ) when F's rows sum to 1
    for method in METHODS:
        B, st = _solve(method, np.full((N, 1), 0.5), E, tol=1e-10, max_iter=10_000)
        assert st.converged and st.residual <= 1e-10, (method, st)
        assert B.sum() == pytest.approx(E.sum() / 0.5, rel=1e-8), method
