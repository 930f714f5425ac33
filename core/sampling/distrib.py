"""Piecewise-constant 1D and 2D distributions sampled by inverse cdf (items 11–16).

A distribution is one flat float64 array, so a kernel takes it as a single argument.

1D block at offset ``o`` for n cells on [0, 1):

    [o]               n
    [o + 1]           ∫ f  (the mean of the cell values; 0 for an all-zero function)
    [o + 2 ...]       f_0 .. f_{n-1}          (non-negative cell values)
    [o + 2 + n ...]   cdf_0 .. cdf_n           (cdf_0 = 0, cdf_n = 1 exactly)

2D array for an (ny, nx) table f[j, i] on [0, 1)² (x ↔ i, y ↔ j):

    [0] nx  [1] ny  [2] ∫∫ f
    [3 ...]                          the marginal over rows: a 1D block of ny cells
    [3 + (2 + 2ny + 1) + j (2 + 2nx + 1) ...]   the conditional of row j: a 1D block

The density is f / ∫f; zero cells are never sampled (the search returns the last cell
whose cdf start is ≤ u, and a zero cell has the same start as its successor). An
all-zero function is treated as uniform (pdf 1) and its stored integral is 0 so that
callers can tell. ``sample_*`` return the continuous position, its pdf and the cell;
``invert_*`` returns the u that maps to a position (the cdf), so
``sample(invert(x)) == x`` and ``sample(cdf[i]) == i / n`` exactly at cell boundaries.

A guided 1D array (``build_guided_1d``) is a 1D block at offset 0 followed by a guide
table of m entries, g_k = the largest i with cdf_i ≤ k/m (the cutpoint method of Chen and
Asau, 1974): ``sample_1d_guided`` starts at g_⌊u m⌋ and steps forward to the cell, a step
or two instead of a binary search's log2 n unpredictable branches, with the same result as
``sample_1d_block``.
"""
import numpy as np

from ..jit import inline

ONE_MINUS_EPS = 1.0 - 2.0 ** -53


def _block(f):
    f = np.asarray(f, dtype=np.float64).ravel()
    n = f.size
    if n == 0:
        raise ValueError("a distribution needs at least one cell")
    if not np.all(np.isfinite(f)) or np.any(f < 0.0):
        raise ValueError("distribution values must be finite and non-negative")
    total = float(np.sum(f))
    integral = total / n
    if total > 0.0:
        cdf = np.concatenate(([0.0], np.cumsum(f) / total))
    else:
        cdf = np.arange(n + 1, dtype=np.float64) / n
    cdf[-1] = 1.0
    # rounding in cumsum can leave cdf_i slightly above 1 before the last cell
    np.minimum(cdf, 1.0, out=cdf)
    return np.concatenate(([float(n), integral], f, cdf))


def build_distribution_1d(f):
    """Flat 1D distribution array (layout in the module docstring) for cell values ``f``."""
    return np.ascontiguousarray(_block(f))


def build_guided_1d(f):
    """Flat guided 1D array (module docstring) for cell values ``f``: the block, then m = n
    guide entries."""
    block = _block(f)
    n = int(block[0])
    cdf = block[2 + n:3 + 2 * n]
    guide = np.searchsorted(cdf[:n], np.arange(n) / n, side="right") - 1
    return np.ascontiguousarray(np.concatenate((block, [float(n)], guide.astype(np.float64))))


def build_distribution_2d(f):
    """Flat 2D distribution array for a table ``f`` of shape (ny, nx) (rows: y)."""
    f = np.asarray(f, dtype=np.float64)
    if f.ndim != 2 or f.size == 0:
        raise ValueError("a 2D distribution needs a non-empty (ny, nx) table")
    ny, nx = f.shape
    rows = [_block(f[j]) for j in range(ny)]
    marginal = _block(np.array([r[1] for r in rows]))
    return np.ascontiguousarray(np.concatenate(([float(nx), float(ny), marginal[1]], marginal, *rows)))


def distribution_1d_parts(dist):
    """(func, cdf, integral) views of a 1D array, for NumPy code and tests."""
    n = int(dist[0])
    return dist[2:2 + n], dist[2 + n:3 + 2 * n], float(dist[1])


def distribution_2d_parts(dist):
    """(func (ny, nx), conditional cdf (ny, nx+1), marginal func (ny,), marginal cdf (ny+1,), integral)."""
    nx, ny = int(dist[0]), int(dist[1])
    mf, mc, _ = distribution_1d_parts(dist[3:])
    base = 3 + 2 * ny + 3
    stride = 2 * nx + 3
    rows = dist[base:base + ny * stride].reshape(ny, stride)
    return rows[:, 2:2 + nx], rows[:, 2 + nx:], mf, mc, float(dist[2])


@inline
def _find_cell(dist, o, n, u):
    """Largest i in [0, n-1] with cdf_i ≤ u (binary search; u is clamped to [0, 1))."""
    c0 = o + 2 + n
    lo = 0
    hi = n - 1
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if dist[c0 + mid] <= u:
            lo = mid
        else:
            hi = mid - 1
    return lo


@inline
def _in_cell(dist, o, n, i, u):
    """(x, pdf, i): the position of u within cell i of the 1D block at offset o (n cells)."""
    c0 = o + 2 + n
    lo = dist[c0 + i]
    w = dist[c0 + i + 1] - lo
    du = (u - lo) / w if w > 0.0 else 0.0
    du = min(max(du, 0.0), 1.0)
    x = (i + du) / n
    if x >= 1.0:
        x = ONE_MINUS_EPS
    integral = dist[o + 1]
    if integral > 0.0:
        pdf = dist[o + 2 + i] / integral
    else:
        pdf = 1.0
    return x, pdf, i


@inline
def sample_1d_block(dist, o, u):
    """Sample the 1D block at offset o: returns (x in [0, 1), pdf, cell)."""
    n = int(dist[o])
    u = min(max(u, 0.0), ONE_MINUS_EPS)
    return _in_cell(dist, o, n, _find_cell(dist, o, n, u), u)


@inline
def sample_1d_guided(dist, u):
    """``sample_1d_block(dist, 0, u)`` for a guided array, the cell found from the guide."""
    n = int(dist[0])
    u = min(max(u, 0.0), ONE_MINUS_EPS)
    c0 = 2 + n
    g0 = 3 + 2 * n
    m = int(dist[g0])
    i = int(dist[g0 + 1 + min(int(u * m), m - 1)])
    while i < n - 1 and dist[c0 + i + 1] <= u:
        i += 1
    return _in_cell(dist, 0, n, i, u)


@inline
def pdf_1d_block(dist, o, x):
    n = int(dist[o])
    if not (x >= 0.0 and x < 1.0):
        return 0.0
    i = min(int(x * n), n - 1)
    integral = dist[o + 1]
    if integral > 0.0:
        return dist[o + 2 + i] / integral
    return 1.0


@inline
def invert_1d_block(dist, o, x):
    """The cdf at x: the u with sample_1d_block(dist, o, u)[0] == x."""
    n = int(dist[o])
    if not (x > 0.0):
        return 0.0
    if x >= 1.0:
        return 1.0
    i = min(int(x * n), n - 1)
    c0 = o + 2 + n
    lo = dist[c0 + i]
    return min(lo + (x * n - i) * (dist[c0 + i + 1] - lo), 1.0)


@inline
def sample_distribution_1d(dist, u):
    return sample_1d_block(dist, 0, u)


@inline
def distribution_1d_pdf(dist, x):
    return pdf_1d_block(dist, 0, x)


@inline
def invert_distribution_1d(dist, x):
    return invert_1d_block(dist, 0, x)


@inline
def _row_offset(nx, ny, j):
    return 3 + (2 * ny + 3) + j * (2 * nx + 3)


@inline
def sample_distribution_2d(dist, u1, u2):
    """(x, y, pdf): y from the marginal with u2, then x from row y's conditional with u1."""
    nx = int(dist[0])
    ny = int(dist[1])
    y, py, j = sample_1d_block(dist, 3, u2)
    x, px, i = sample_1d_block(dist, _row_offset(nx, ny, j), u1)
    return x, y, px * py


@inline
def distribution_2d_pdf(dist, x, y):
    nx = int(dist[0])
    ny = int(dist[1])
    if not (x >= 0.0 and x < 1.0 and y >= 0.0 and y < 1.0):
        return 0.0
    total = dist[2]
    if not (total > 0.0):
        return 1.0
    i = min(int(x * nx), nx - 1)
    j = min(int(y * ny), ny - 1)
    return dist[_row_offset(nx, ny, j) + 2 + i] / total


@inline
def invert_distribution_2d(dist, x, y):
    nx = int(dist[0])
    ny = int(dist[1])
    j = min(max(int(y * ny), 0), ny - 1)
    return invert_1d_block(dist, _row_offset(nx, ny, j), x), invert_1d_block(dist, 3, y)
