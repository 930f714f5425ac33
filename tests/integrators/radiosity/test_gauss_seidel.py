"""The blocked Gauss–Seidel sweep (core/integrators/radiosity/solvers.py) against the
row-by-row sweep (tests/oracles/radiosity.py), and its converged answer against Jacobi's."""
import sys
from pathlib import Path

import numpy as np
import pytest

from spectral_gi.core.integrators.radiosity import solvers

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from oracles.radiosity import gauss_seidel_sweep  # noqa: E402


def system(n, k, seed=0):
    """A random closed-scene-like system: rows of F sum to 1, zero diagonal, float32."""
    rng = np.random.default_rng(seed)
    F = rng.random((n, n)) ** 3
    np.fill_diagonal(F, 0.0)
    F /= F.sum(axis=1, keepdims=True)
    rho = rng.uniform(0.1, 0.9, (n, k))
    lit = rng.random((n, 1)) < 0.2
    lit[0] = True
    E = rng.random((n, k)) * lit
    return F.astype(np.float32), rho, E, rng.uniform(0.5, 2.0, n)


@pytest.mark.parametrize("n, k, wide", [(150, 3, True), (150, 3, False), (64, 1, False), (7, 2, True)])
def test_one_sweep_is_the_row_by_row_sweep_item_61(n, k, wide):
    F, rho, E, area = system(n, k)
    if not wide:
        rho = rho[:, :1]
    got, st = solvers.gauss_seidel(F, rho, E, area, tol=0.0, max_iter=1)
    assert st.iterations == 1
    # the solver starts from E: one sweep from E
    ref = gauss_seidel_sweep(F, rho, E, E)
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-14)
    two, _ = solvers.gauss_seidel(F, rho, E, area, tol=0.0, max_iter=2)
    np.testing.assert_allclose(two, gauss_seidel_sweep(F, rho, E, ref), rtol=1e-12, atol=1e-14)


def test_converged_answer_agrees_with_jacobi_and_the_direct_solve_item_61():
    F, rho, E, area = system(300, 4, seed=1)
    F = F.astype(np.float64)  # a float32 matrix leaves a residual floor of about 1e-8
    gs, st_gs = solvers.gauss_seidel(F, rho, E, area, tol=1e-10)
    ja, st_ja = solvers.jacobi(F, rho, E, area, tol=1e-10)
    assert st_gs.converged and st_ja.converged
    assert st_gs.iterations < st_ja.iterations
    direct = np.stack([np.linalg.solve(np.eye(300) - rho[:, c:c + 1] * F, E[:, c]) for c in range(4)], axis=1)
    np.testing.assert_allclose(gs, direct, rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(ja, direct, rtol=1e-8, atol=1e-12)
