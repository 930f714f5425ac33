"""The shared goodness-of-fit harness for samplers (and a z-test for means).

A sampler is tested by histogramming its samples and comparing with the expected
count of every cell, N × ∫_cell pdf, where the integral is computed here by adaptive
quadrature of the *supplied* density function (a quadtree of 3×3 Simpson
rules, refined where a rectangle disagrees with its four children), so the expected
table never depends on the sampler under test. Directions are histogrammed in
(cos θ, φ) cells of a chosen frame, where dω = d(cos θ) dφ, so the density in cell
coordinates is the solid-angle pdf itself; points in the plane in (x, y) cells.
Everything outside the histogram range is one more cell whose expectation is also
integrated, so a density that does not integrate to 1 fails too.

Cells whose expected count is below 5 are pooled (with the smallest other cells
until the pool reaches 5); the degrees of freedom are the pooled cells minus one. A
sample where the supplied density is 0 fails at once (checked on the samples
themselves, so a thin sliver of support that the quadrature misses cannot hide one). The significance of each
test is Šidák-corrected for the number of statistical tests in the run, so the
family-wise false-failure rate is FAMILY_ALPHA. On failure the observed and expected
tables are written as .txt files to a fresh temporary folder whose path is printed
and put in the assertion message.
"""
from dataclasses import dataclass
import math
import os
import tempfile
import zlib

import numpy as np
import pytest
from scipy import stats

FAMILY_ALPHA = 0.01
MIN_EXPECTED = 5.0

# Simpson nodes pulled in by 1e-7 of the width, so a density that jumps exactly on a
# cell border (a cone's edge placed on a cell edge) is never sampled on the wrong side
_NODES = np.array([1e-7, 0.5, 1.0 - 1e-7])
_WEIGHTS = np.outer([1.0, 4.0, 1.0], [1.0, 4.0, 1.0])[None] / 36.0  # Simpson on the unit square


def sidak_alpha(n_tests, family_alpha=FAMILY_ALPHA):
    """Per-test significance so that n independent tests fail together with probability family_alpha."""
    n = max(int(n_tests), 1)
    return 1.0 - (1.0 - family_alpha) ** (1.0 / n)


def family_size(request, marker="statistical"):
    """Number of collected tests in this run that carry ``marker`` (at least 1)."""
    items = getattr(request.session, "items", None) or [request.node]
    return max(1, sum(1 for it in items if it.get_closest_marker(marker) is not None))


@pytest.fixture
def alpha(request):
    """Šidák-corrected per-test significance for the statistical tests of this run."""
    return sidak_alpha(family_size(request))


def seed_for(name):
    """A fixed seed derived from a test's name (stable across runs and machines)."""
    return zlib.crc32(name.encode())


# -- quadrature ----------------------------------------------------------------------------

def _rects(density, x0, x1, y0, y1):
    """Simpson's 3×3 rule over each rectangle (vectorised), and whether the density is
    zero at some of the nine nodes and positive at others. The nodes include (almost) the
    corners and edge midpoints, so an edge of the support cannot hide between a
    rectangle's border and its nodes at every level of refinement (as it can with Gauss
    nodes)."""
    hx = x1 - x0
    hy = y1 - y0
    xs = x0[:, None, None] + hx[:, None, None] * _NODES[None, :, None] + 0.0 * _NODES[None, None, :]
    ys = y0[:, None, None] + hy[:, None, None] * _NODES[None, None, :] + 0.0 * _NODES[None, :, None]
    v = np.asarray(density(xs.ravel(), ys.ravel()), dtype=np.float64).reshape(xs.shape)
    pos = (v > 0).sum(axis=(1, 2))
    return (v * _WEIGHTS).sum(axis=(1, 2)) * hx * hy, (pos > 0) & (pos < 9)


def integrate_cells(density, x_edges, y_edges, n_samples, rel_tol=0.02, min_depth=2, max_depth=10,
                    max_evals=6e7, support=None):
    """∫ density over every cell of the grid x_edges × y_edges → (ny, nx) array.

    density(x, y) takes flat arrays. Each cell is a quadtree: a rectangle at depth L is
    accepted when its four children change its integral by less than tol·2^-L and none
    of them straddles an edge of the support; tol per cell is
    rel_tol × sqrt(max(p, 5/N) / N) in probability units, from the count noise of N
    samples. A child straddles an edge when the density is 0 at some of its nodes and
    positive at others, or when it is 0 at all of them but holds one of the ``support``
    points (M, 2), where the density is known to be positive: the samples themselves,
    so a sliver of support thinner than the node spacing is still found. The points
    only steer the refinement; the integral is the density's alone.
    """
    x_edges = np.asarray(x_edges, dtype=np.float64)
    y_edges = np.asarray(y_edges, dtype=np.float64)
    nx, ny = len(x_edges) - 1, len(y_edges) - 1
    X0, Y0 = np.meshgrid(x_edges[:-1], y_edges[:-1])
    X1, Y1 = np.meshgrid(x_edges[1:], y_edges[1:])
    cell = np.arange(nx * ny)
    x0, x1, y0, y1 = X0.ravel(), X1.ravel(), Y0.ravel(), Y1.ravel()
    ri = np.zeros(cell.size, np.int64)
    rj = np.zeros(cell.size, np.int64)
    est, _ = _rects(density, x0, x1, y0, y1)
    total = np.zeros(nx * ny)
    tol = rel_tol * np.sqrt(np.maximum(np.abs(est), MIN_EXPECTED / n_samples) / n_samples)
    if support is not None and len(support):
        sp = np.asarray(support, dtype=np.float64)
        pi = np.searchsorted(x_edges, sp[:, 0], side="right") - 1
        pj = np.searchsorted(y_edges, sp[:, 1], side="right") - 1
        ok = (pi >= 0) & (pi < nx) & (pj >= 0) & (pj < ny)
        pi, pj, sp = pi[ok], pj[ok], sp[ok]
        pcell = pj * nx + pi
        # position inside the cell in [0, 1)
        fx = np.clip((sp[:, 0] - x_edges[pi]) / (x_edges[pi + 1] - x_edges[pi]), 0.0, 1.0 - 1e-16)
        fy = np.clip((sp[:, 1] - y_edges[pj]) / (y_edges[pj + 1] - y_edges[pj]), 0.0, 1.0 - 1e-16)
    else:
        pcell = None
    depth = 0
    evals = 0
    while cell.size:
        xm = 0.5 * (x0 + x1)
        ym = 0.5 * (y0 + y1)
        cx0 = np.concatenate([x0, xm, x0, xm])
        cx1 = np.concatenate([xm, x1, xm, x1])
        cy0 = np.concatenate([y0, y0, ym, ym])
        cy1 = np.concatenate([ym, ym, y1, y1])
        ci = np.concatenate([2 * ri, 2 * ri + 1, 2 * ri, 2 * ri + 1])
        cj = np.concatenate([2 * rj, 2 * rj, 2 * rj + 1, 2 * rj + 1])
        ccell = np.tile(cell, 4)
        child, mixed = _rects(density, cx0, cx1, cy0, cy1)
        evals += child.size * 9
        depth += 1
        if pcell is not None:
            scale = 2 ** depth
            pkey = (pcell * scale + (fx * scale).astype(np.int64)) * scale + (fy * scale).astype(np.int64)
            ckey = (ccell * scale + ci) * scale + cj
            mixed |= (child == 0) & np.isin(ckey, pkey)
        m = cell.size
        sums = child[:m] + child[m:2 * m] + child[2 * m:3 * m] + child[3 * m:]
        edge = mixed[:m] | mixed[m:2 * m] | mixed[2 * m:3 * m] | mixed[3 * m:]
        converged = (np.abs(sums - est) <= tol[cell] * 2.0 ** -(depth - 1)) & ~edge & (depth >= min_depth)
        done = converged | (depth >= max_depth) | (evals > max_evals)
        np.add.at(total, cell[done], sums[done])
        keep = np.tile(~done, 4)
        cell, x0, x1, y0, y1, est = ccell[keep], cx0[keep], cx1[keep], cy0[keep], cy1[keep], child[keep]
        ri, rj = ci[keep], cj[keep]
    return total.reshape(ny, nx)


# -- the test --------------------------------------------------------------------------------

@dataclass
class Chi2Result:
    statistic: float
    dof: int
    p_value: float
    alpha: float
    passed: bool
    message: str
    dump: str = ""


def _pool(observed, expected):
    """Pool the cells with expected < MIN_EXPECTED (see the module docstring)."""
    order = np.argsort(expected, kind="stable")
    obs = observed[order].astype(np.float64)
    exp = expected[order].astype(np.float64)
    low = exp < MIN_EXPECTED
    if not low.any():
        return obs, exp
    pool_o, pool_e = obs[low].sum(), exp[low].sum()
    obs, exp = obs[~low], exp[~low]
    k = 0
    while pool_e < MIN_EXPECTED and k < len(exp):
        pool_o += obs[k]
        pool_e += exp[k]
        k += 1
    return np.concatenate([[pool_o], obs[k:]]), np.concatenate([[pool_e], exp[k:]])


def _dump(name, observed, expected, extra=None):
    folder = tempfile.mkdtemp(prefix=f"chi2_{name}_", dir=os.environ.get("CHI2_DUMP_DIR"))
    np.savetxt(os.path.join(folder, "observed.txt"), np.atleast_2d(observed), fmt="%.6g")
    np.savetxt(os.path.join(folder, "expected.txt"), np.atleast_2d(expected), fmt="%.6g")
    for key, val in (extra or {}).items():
        np.savetxt(os.path.join(folder, f"{key}.txt"), np.atleast_2d(val), fmt="%.10g")
    print(f"chi-square tables for {name}: {folder}")
    return folder


def chi2_test(observed, expected, alpha, name="chi2", extra=None, dump=True):
    """Pearson's test of the observed counts against the expected counts (same shape);
    on failure the tables are written to a temporary folder unless ``dump`` is False."""
    observed = np.asarray(observed, dtype=np.float64)
    expected = np.asarray(expected, dtype=np.float64)
    o = observed.ravel()
    e = expected.ravel()
    n = o.sum()
    po, pe = _pool(o, e)
    dof = len(po) - 1
    if dof < 1:
        stat = 0.0
        p = 1.0
    else:
        stat = float(((po - pe) ** 2 / pe).sum())
        p = float(stats.chi2.sf(stat, dof))
    passed = p >= alpha
    msg = f"{name}: chi2 = {stat:.2f}, dof = {dof}, p = {p:.3g} (alpha = {alpha:.3g}), N = {int(n)}"
    folder = "" if passed or not dump else _dump(name, observed, expected, extra)
    if folder:
        msg += f"; tables in {folder}"
    return Chi2Result(stat, dof, p, alpha, passed, msg, folder)


def _zero_density_failure(values, name, alpha, observed, expected, dump=True):
    bad = int(np.count_nonzero(~(np.asarray(values) > 0)))
    if bad == 0:
        return None
    msg = f"{name}: {bad} samples fell where the density is 0"
    folder = _dump(name, observed, expected) if dump else ""
    return Chi2Result(math.inf, 0, 0.0, alpha, False, msg + (f"; tables in {folder}" if folder else ""), folder)


def frame_rows(axis):
    """Rows (t, b, n) of an orthonormal frame with n = axis."""
    n = np.asarray(axis, dtype=np.float64)
    n = n / np.linalg.norm(n)
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t = a - np.dot(a, n) * n
    t /= np.linalg.norm(t)
    return np.stack([t, np.cross(n, t), n])


def chi2_sphere(dirs, pdf, alpha, name="sphere", n_z=32, n_phi=64, z_range=(-1.0, 1.0), axis=None, dump=True):
    """Test directions (N, 3) against the solid-angle density ``pdf(w (M, 3)) → (M,)``.

    Cells are equal steps of cos θ in z_range × equal steps of φ about ``axis`` (default
    +z); the rest of the sphere is one more cell.
    """
    dirs = np.asarray(dirs, dtype=np.float64)
    n = len(dirs)
    rows = np.eye(3) if axis is None else frame_rows(axis)
    loc = dirs @ rows.T
    z = np.clip(loc[:, 2], -1.0, 1.0)
    phi = np.mod(np.arctan2(loc[:, 1], loc[:, 0]), 2 * np.pi)
    z_edges = np.linspace(z_range[0], z_range[1], n_z + 1)
    phi_edges = np.linspace(0.0, 2 * np.pi, n_phi + 1)

    def density(pp, zz):
        s = np.sqrt(np.maximum(1.0 - zz * zz, 0.0))
        local = np.stack([s * np.cos(pp), s * np.sin(pp), zz], axis=-1)
        return pdf(local @ rows)

    inside = (z >= z_range[0]) & (z <= z_range[1])
    hist, _, _ = np.histogram2d(phi[inside], z[inside], bins=[phi_edges, z_edges])
    observed = hist.T  # (n_z, n_phi)
    expected = n * integrate_cells(density, phi_edges, z_edges, n, support=np.stack([phi, z], axis=1))
    out_obs = [np.count_nonzero(~inside)]
    out_exp = []
    for lo, hi in ((-1.0, z_range[0]), (z_range[1], 1.0)):
        if hi > lo:
            out_exp.append(n * integrate_cells(density, np.linspace(0, 2 * np.pi, 9), np.linspace(lo, hi, 5), n).sum())
        else:
            out_exp.append(0.0)
    obs = np.concatenate([observed.ravel(), out_obs])
    exp = np.concatenate([expected.ravel(), [sum(out_exp)]])
    fail = _zero_density_failure(pdf(dirs), name, alpha, observed, expected, dump)
    if fail is not None:
        return fail
    return chi2_test(obs, exp, alpha, name, extra={"observed_grid": observed, "expected_grid": expected}, dump=dump)


def chi2_plane(points, pdf, alpha, name="plane", nx=32, ny=32, x_range=(0.0, 1.0), y_range=(0.0, 1.0),
               dump=True):
    """Test 2D points (N, 2) against the area density ``pdf(x, y) → (M,)`` on a rectangle
    (the points must all fall inside it; anything outside fails)."""
    pts = np.asarray(points, dtype=np.float64)
    n = len(pts)
    x_edges = np.linspace(*x_range, nx + 1)
    y_edges = np.linspace(*y_range, ny + 1)
    inside = (pts[:, 0] >= x_range[0]) & (pts[:, 0] <= x_range[1]) & (pts[:, 1] >= y_range[0]) & \
        (pts[:, 1] <= y_range[1])
    hist, _, _ = np.histogram2d(pts[inside, 0], pts[inside, 1], bins=[x_edges, y_edges])
    observed = hist.T
    expected = n * integrate_cells(pdf, x_edges, y_edges, n, support=pts)
    obs = np.concatenate([observed.ravel(), [np.count_nonzero(~inside)]])
    exp = np.concatenate([expected.ravel(), [0.0]])
    fail = _zero_density_failure(pdf(pts[:, 0], pts[:, 1]), name, alpha, observed, expected, dump)
    if fail is not None:
        return fail
    return chi2_test(obs, exp, alpha, name, extra={"observed_grid": observed, "expected_grid": expected}, dump=dump)


def chi2_interval(x, pdf, alpha, name="interval", bins=64, x_range=(0.0, 1.0)):
    """Test 1D samples against the density ``pdf(x) → (M,)`` on an interval."""
    x = np.asarray(x, dtype=np.float64)
    pts = np.stack([x, np.full_like(x, 0.5)], axis=1)
    return chi2_plane(pts, lambda a, b: pdf(a), alpha, name, nx=bins, ny=1, x_range=x_range)


# -- z-test ----------------------------------------------------------------------------------

@dataclass
class ZResult:
    z: float
    p_value: float
    alpha: float
    passed: bool
    message: str


def ztest(mean, std_error, expected, alpha, name="z"):
    """Two-sided z-test of an estimate (mean ± std_error) against the exact value."""
    if std_error == 0:
        ok = mean == expected
        return ZResult(0.0 if ok else math.inf, 1.0 if ok else 0.0, alpha, ok, f"{name}: exact {mean} vs {expected}")
    z = (mean - expected) / std_error
    p = 2.0 * stats.norm.sf(abs(z))
    ok = p >= alpha
    return ZResult(z, p, alpha, ok, f"{name}: mean {mean:.6g} ± {std_error:.3g}, expected {expected:.6g}, "
                   f"z = {z:.2f}, p = {p:.3g} (alpha = {alpha:.3g})")


def ztest_samples(samples, expected, alpha, name="z"):
    """z-test of the mean of i.i.d. samples against the exact expectation."""
    y = np.asarray(samples, dtype=np.float64).ravel()
    return ztest(float(y.mean()), float(y.std(ddof=1) / math.sqrt(len(y))), expected, alpha, name)
