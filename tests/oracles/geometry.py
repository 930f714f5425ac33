"""NumPy oracle for the BVH's closest-hit queries (tests only)."""
import numpy as np


def brute_force_closest(v0, v1, v2, origins, directions, chunk=256):
    """NumPy oracle: the watertight test (the kernel's arithmetic, step for step) against
    every triangle, float32 corners, float64 math. Returns (t, triangle index or -1)."""
    a = np.asarray(v0, np.float32).astype(np.float64)
    b = np.asarray(v1, np.float32).astype(np.float64)
    c = np.asarray(v2, np.float32).astype(np.float64)
    origins = np.asarray(origins, np.float64)
    directions = np.asarray(directions, np.float64)
    n = origins.shape[0]
    best = np.full(n, np.inf)
    idx = np.full(n, -1, np.int64)
    if a.shape[0] == 0:
        return best, idx
    for s in range(0, n, chunk):
        o = origins[s:s + chunk]
        d = directions[s:s + chunk]
        r = np.arange(o.shape[0])
        kz = np.argmax(np.abs(d), axis=1)
        kx = (kz + 1) % 3
        ky = (kx + 1) % 3
        flip = d[r, kz] < 0
        kx, ky = np.where(flip, ky, kx), np.where(flip, kx, ky)
        sz = 1.0 / d[r, kz]
        sx = (d[r, kx] * sz)[:, None]
        sy = (d[r, ky] * sz)[:, None]
        sz = sz[:, None]
        okx, oky, okz = o[r, kx][:, None], o[r, ky][:, None], o[r, kz][:, None]
        pax, pay, paz = a[:, kx].T, a[:, ky].T, a[:, kz].T
        az = paz - okz
        ax = (pax - okx) - sx * az
        ay = (pay - oky) - sy * az
        bz = b[:, kz].T - okz
        bx = (b[:, kx].T - okx) - sx * bz
        by = (b[:, ky].T - oky) - sy * bz
        cz = c[:, kz].T - okz
        cx = (c[:, kx].T - okx) - sx * cz
        cy = (c[:, ky].T - oky) - sy * cz
        u = cx * by - cy * bx
        v = ax * cy - ay * cx
        w = bx * ay - by * ax
        det = u + v + w
        with np.errstate(divide="ignore", invalid="ignore"):
            t = sz * (u * az + v * bz + w * cz) / det
        inside = ~(((u < 0) | (v < 0) | (w < 0)) & ((u > 0) | (v > 0) | (w > 0)))
        ok = inside & (det != 0) & (t > 0)
        t = np.where(ok, t, np.inf)
        k = np.argmin(t, axis=1)
        tb = t[r, k]
        best[s:s + chunk] = tb
        idx[s:s + chunk] = np.where(np.isfinite(tb), k, -1)
    return best, idx
