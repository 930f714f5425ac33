"""Solvers of the radiosity system (Dutré's Global Illumination Compendium, items 61–62).

With constant basis functions (one value per patch), Galerkin radiosity gives for every
patch i and every wavelength band (the system is linear in the radiosity at each
wavelength, so it is solved per band, see ``solve.py``)

    B_i = E_i + ρ_i Σ_j F_{i→j} B_j                              (item 61)

with E_i the patch's own exitance (emission plus the reflection of the light it receives
directly from analytic lights), or, multiplied by the areas, the power system

    P_i = P^e_i + ρ_i Σ_j F_{j→i} P_j,   P_i = A_i B_i            (item 62).

Every solver takes F (n, n) (row i: F_{i→j}), ρ (n, K) or (n, 1) and E (n, K), one column
per right-hand side, and returns (B (n, K), SolveStats). They stop when the relative
residual, Σ_i A_i |E_i + ρ_i (F B)_i − B_i| / Σ_i A_i |B_i| over all columns (the power
still out of balance over the power leaving the patches; for Southwell the unshot power),
is at most ``tol``, after
``max_iter`` iterations, or when ``should_cancel()`` returns True; ``progress(iteration,
residual)`` is called after each iteration (a sweep; for the shooting solvers a block of
shots).

* ``jacobi``: B ← E + ρ F B, the Neumann series; every sweep is one matrix product
  (which also gives the residual).
* ``gauss_seidel``: the same update row by row, using the rows already updated (in blocks
  of rows, each block's lower-triangular part solved directly); about half as many sweeps.
* ``southwell``: progressive refinement (Cohen, Chen, Wallace and Greenberg 1988): the
  patches with the most unshot power shoot it to every patch (row i of F, the share of
  its power that reaches each patch, so the power system's answer), so the first steps
  already light the scene; a batch of patches shoots per step, and the rows of F can be
  computed on demand (``RowCache``); its residual is the unshot power (see ``southwell``);
  ``ambient`` gives the ambient term of the display, the unshot power spread
  uniformly with the mean reflectance's interreflection factor 1/(1 − ρ̄).
* the matrix-free stochastic solver lives in ``solve.py`` (it needs the scene's rays).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ...scene import SceneError

METHODS = ("jacobi", "gauss-seidel", "southwell", "stochastic")


@dataclass
class SolveStats:
    """method, iterations (sweeps, or shots for Southwell), final residual, seconds, and
    whether it converged (residual ≤ tol) or was cancelled."""

    method: str
    iterations: int
    residual: float
    seconds: float
    converged: bool
    cancelled: bool = False
    ambient: np.ndarray | None = None  # Southwell: the display's ambient term per column (``ambient``)
    received: np.ndarray | None = None  # Southwell: the irradiance (n, K) each patch received from the shots
    columns: int = 0  # right-hand sides solved (core.radiosity: after the reduction of the bands)


def _check(F, rho, E, area):
    F = np.asarray(F)
    n = F.shape[0]
    if F.ndim != 2 or F.shape[1] != n:
        raise SceneError(f"radiosity: the form-factor matrix must be square, got {F.shape}")
    E = np.asarray(E, np.float64).reshape(n, -1)
    rho = np.asarray(rho, np.float64).reshape(n, -1)
    if rho.shape[1] not in (1, E.shape[1]):
        raise SceneError(f"radiosity: ρ has {rho.shape[1]} columns for {E.shape[1]} right-hand sides")
    area = np.ones(n) if area is None else np.asarray(area, np.float64).reshape(n)
    return F, rho, E, area


def _matvec(F, B):
    if F.dtype == np.float32:
        return (F @ B.astype(np.float32)).astype(np.float64)
    return F @ B


def residual(F, rho, E, B, area=None):
    """The relative residual of B (see the module text); NaN when B or its residual is not
    finite (NaN or Inf, which validated input cannot produce): such a B is never converged,
    and the loops, which go on while the residual is above ``tol``, stop at it."""
    F, rho, E, area = _check(F, rho, E, area)
    with np.errstate(invalid="ignore", over="ignore"):
        r = E + rho * _matvec(F, B) - B
        num = float(np.sum(area[:, None] * np.abs(r)))
        den = float(np.sum(area[:, None] * np.abs(B)))
    return _finite_ratio(num, den)


def _loop(name, step, F, rho, E, area, tol, max_iter, progress, should_cancel):
    t0 = time.perf_counter()
    B = E.copy()
    res = residual(F, rho, E, B, area)
    it = 0
    cancelled = False
    while res > tol and it < max_iter:
        if should_cancel is not None and should_cancel():
            cancelled = True
            break
        B = step(B)
        it += 1
        res = residual(F, rho, E, B, area)
        if progress is not None:
            progress(it, res)
    return B, SolveStats(name, it, res, time.perf_counter() - t0, res <= tol, cancelled)


def _finite_ratio(num, den):
    """num / den for the residuals: NaN when either is not finite (never converged, see
    ``residual``), 0 for a zero solution."""
    if not (math.isfinite(num) and math.isfinite(den)):
        return math.nan
    return num / den if den > 0 else 0.0


def _relative(area, r, B):
    with np.errstate(invalid="ignore", over="ignore"):
        return _finite_ratio(float(np.sum(area[:, None] * np.abs(r))), float(np.sum(area[:, None] * np.abs(B))))


def jacobi(F, rho, E, area=None, *, tol=1e-6, max_iter=10000, progress=None, should_cancel=None):
    """Jacobi iteration on the radiosity system (item 61). The product F B of a sweep gives
    both the next iterate and the residual of the current one, E + ρ F B − B: one matrix
    product per sweep."""
    F, rho, E, area = _check(F, rho, E, area)
    t0 = time.perf_counter()
    B = E.copy()
    it = 0
    cancelled = False
    while True:
        nxt = E + rho * _matvec(F, B)
        res = _relative(area, nxt - B, B)
        if it > 0 and progress is not None:
            progress(it, res)
        if not res > tol or it >= max_iter:  # a residual that is not finite (NaN) stops too
            break
        if should_cancel is not None and should_cancel():
            cancelled = True
            break
        B = nxt
        it += 1
    return B, SolveStats("jacobi", it, res, time.perf_counter() - t0, res <= tol, cancelled)


GS_BLOCK = 64  # rows per block of the Gauss–Seidel sweep


def gauss_seidel(F, rho, E, area=None, *, tol=1e-6, max_iter=10000, progress=None, should_cancel=None):
    """Gauss–Seidel iteration on the radiosity system (item 61), one sweep over the rows per
    iteration: row i takes B_i = E_i + ρ_i (Σ_{j<i} F_ij B_j' + Σ_{j≥i} F_ij B_j), B' the
    rows already updated in this sweep. The sweep is blocked: for a block of rows [a, b)
    the rows before it (updated) and after it (not yet) enter by matrix products, and the
    block's own rows by the lower-triangular system (I − ρ L) x = r of its diagonal block
    (L its strictly lower part): solved directly when every column has the same ρ, by
    forward substitution over the block's rows (every column at once) when they differ.
    The same iterate as the row-by-row sweep, to rounding; the O(n²) work is in matrix
    products, the rows' loop does O(block) work each."""
    F, rho, E, area = _check(F, rho, E, area)
    n = F.shape[0]

    def sweep(B):
        B = B.copy()
        for a in range(0, n, GS_BLOCK):
            b = min(n, a + GS_BLOCK)
            Fb = F[a:b].astype(np.float64)  # converted once per block of rows
            D = Fb[:, a:b]
            low = np.tril(D, -1)
            r = Fb[:, :a] @ B[:a] + Fb[:, b:] @ B[b:] + np.triu(D) @ B[a:b]
            rh = rho[a:b]
            rhs = E[a:b] + rh * r
            eye = np.eye(b - a)
            if rh.shape[1] == 1:
                B[a:b] = np.linalg.solve(eye - rh * low, rhs)
            else:  # ρ differs between the columns: forward substitution, every column at once
                x = rhs
                for i in range(1, b - a):
                    x[i] += rh[i] * (low[i, :i] @ x[:i])
                B[a:b] = x
        return B

    return _loop("gauss-seidel", sweep, F, rho, E, area, tol, max_iter, progress, should_cancel)


def jacobi_power(F, rho, E, area, *, tol=1e-6, max_iter=10000, progress=None, should_cancel=None):
    """Jacobi iteration on the power system (item 62): P ← P^e + ρ Fᵀ P with P = A B;
    returns the radiosities B = P / A (the same fixed point as ``jacobi``)."""
    F, rho, E, area = _check(F, rho, E, area)
    Pe = area[:, None] * E
    FT = np.ascontiguousarray(F.T)
    t0 = time.perf_counter()
    P = Pe.copy()
    it = 0
    res = residual(F, rho, E, P / area[:, None], area)
    cancelled = False
    while res > tol and it < max_iter:
        if should_cancel is not None and should_cancel():
            cancelled = True
            break
        P = Pe + rho * _matvec(FT, P)
        it += 1
        res = residual(F, rho, E, P / area[:, None], area)
        if progress is not None:
            progress(it, res)
    return P / area[:, None], SolveStats("jacobi-power", it, res, time.perf_counter() - t0, res <= tol, cancelled)


def southwell(F, rho, E, area, *, tol=1e-6, max_iter=None, weights=None, progress=None, should_cancel=None,
              batch=None):
    """Progressive refinement (Southwell shooting) on the power system (item 62).

    Each step takes the ``batch`` patches with the most unshot power ΔB_i A_i (columns
    weighted by ``weights``, e.g. the luminous weight of each band; None: summed) and each
    adds ρ_j F_{i→j} ΔB_i A_i / A_j to every patch's radiosity and unshot radiosity (the
    patches of one step shoot together, what they send each other waits for a later step).
    ``F``: the (n, n) matrix, or a callable ``rows(idx) → (len(idx), n)`` giving rows i of F
    on demand, so only the rows of patches that shoot are ever computed (``RowCache``).
    ``batch`` None: max(1, n // 64), one step's rows computed in one parallel call.
    ``max_iter``: the most shots (None: 50 n). The residual is the unshot power over the
    power leaving the patches, Σ_i A_i |ΔB_i| / Σ_i A_i |B_i| (weighted as above): the
    power system's residual of B − ΔB, a bound on that of B; it costs nothing, so it is
    checked after every step. Returns (B, stats); stats.iterations counts the shots and
    stats.received is the irradiance (n, K) each patch received from the shots, so that
    B = E + ρ · received."""
    rows = F if callable(F) else None
    if rows is None:
        F, rho, E, area = _check(F, rho, E, area)
        mat = F

        def rows(idx):
            return mat[idx]
    else:
        E = np.asarray(E, np.float64).reshape(np.asarray(area).size, -1)
        rho = np.asarray(rho, np.float64).reshape(E.shape[0], -1)
        area = np.asarray(area, np.float64).reshape(E.shape[0])
    n = E.shape[0]
    w = np.ones(E.shape[1]) if weights is None else np.asarray(weights, np.float64).reshape(-1)
    max_iter = 50 * n if max_iter is None else int(max_iter)
    k = max(1, n // 64 if batch is None else int(batch))
    t0 = time.perf_counter()
    B = E.copy()
    dB = E.copy()
    recv = np.zeros_like(E)
    unshot = area * (np.abs(dB) @ w)

    def res_now():
        with np.errstate(invalid="ignore", over="ignore"):
            return _finite_ratio(float(unshot.sum()), float(np.sum(area * (np.abs(B) @ w))))

    shots = 0
    res = res_now()
    cancelled = False
    while res > tol and shots < max_iter:
        if should_cancel is not None and should_cancel():
            cancelled = True
            break
        m = min(k, n, max_iter - shots)
        idx = np.argpartition(-unshot, m - 1)[:m] if m < n else np.arange(n)
        idx = idx[unshot[idx] > 0]
        if idx.size == 0:
            break
        shoot = dB[idx] * area[idx, None]  # (m, K) the power each shoots
        dB[idx] = 0.0
        Fi = np.asarray(rows(idx), np.float64)  # (m, n)
        got = (Fi.T @ shoot) / area[:, None]  # (n, K) irradiance received
        recv += got
        gain = rho * got
        B += gain
        dB += gain
        unshot = area * (np.abs(dB) @ w)
        shots += int(idx.size)
        res = res_now()
        if progress is not None:
            progress(shots, res)
    st = SolveStats("southwell", shots, res, time.perf_counter() - t0, res <= tol, cancelled, ambient(rho, dB, area))
    st.received = recv
    return B, st


class RowCache:
    """Rows of the form-factor matrix computed on demand by ``compute(idx) → float32
    (len(idx), n)`` and kept (an (n, n) float32 array whose untouched rows take no memory),
    for progressive refinement: a patch that shoots again reuses its row."""

    def __init__(self, n, compute):
        self.n = int(n)
        self.compute = compute
        self.F = np.empty((self.n, self.n), np.float32)
        self.have = np.zeros(self.n, bool)
        self.seconds = 0.0  # spent computing rows

    def __call__(self, idx):
        idx = np.asarray(idx, np.int64)
        need = idx[~self.have[idx]]
        if need.size:
            t0 = time.perf_counter()
            self.F[need] = self.compute(need)
            self.have[need] = True
            self.seconds += time.perf_counter() - t0
        return self.F[idx]

    @property
    def computed(self):
        return int(self.have.sum())


def ambient(rho, dB, area):
    """The ambient term of progressive refinement for display (Cohen et al. 1988): the
    unshot radiosity ``dB`` spread over the scene by area, times the interreflection factor
    1/(1 − ρ̄) of the area-weighted mean reflectance ρ̄; a patch shows B + ρ · ambient."""
    rho = np.asarray(rho, np.float64)
    a = np.asarray(area, np.float64)
    rbar = np.sum(a[:, None] * rho.reshape(a.size, -1), axis=0) / a.sum()
    mean_unshot = np.sum(a[:, None] * np.asarray(dB).reshape(a.size, -1), axis=0) / a.sum()
    return mean_unshot / np.maximum(1.0 - rbar, 1e-12)


def solve_dense(method, F, rho, E, area, **kw):
    """Dispatch to one of the dense solvers by name ("jacobi", "jacobi-power",
    "gauss-seidel", "southwell")."""
    if method == "jacobi":
        return jacobi(F, rho, E, area, **kw)
    if method == "jacobi-power":
        return jacobi_power(F, rho, E, area, **kw)
    if method == "gauss-seidel":
        return gauss_seidel(F, rho, E, area, **kw)
    if method == "southwell":
        return southwell(F, rho, E, area, **kw)
    raise SceneError(f"radiosity solver: unknown method {method!r}; use one of jacobi, jacobi-power, "
                     "gauss-seidel, southwell, stochastic")
