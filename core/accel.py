"""Python side of the BVH: build from triangles, batch queries, and a brute-force oracle."""
from dataclasses import dataclass

import numpy as np

from .kernels import bvh as K


@dataclass
class BVH:
    bmin: np.ndarray
    bmax: np.ndarray
    child: np.ndarray
    count: np.ndarray
    axis: np.ndarray
    prims: np.ndarray  # leaf order → original triangle index
    v0: np.ndarray  # float32 (T, 3), leaf order
    e1: np.ndarray
    e2: np.ndarray

    @property
    def n_nodes(self):
        return self.bmin.shape[0]

    @property
    def nbytes(self):
        return sum(a.nbytes for a in (self.bmin, self.bmax, self.child, self.count, self.axis,
                                      self.prims, self.v0, self.e1, self.e2))


def build(v0, v1, v2):
    """Build a BVH over triangles given by their corners, each (T, 3) float."""
    v0 = np.asarray(v0, np.float64)
    v1 = np.asarray(v1, np.float64)
    v2 = np.asarray(v2, np.float64)
    tri_min = np.minimum(np.minimum(v0, v1), v2)
    tri_max = np.maximum(np.maximum(v0, v1), v2)
    centroid = (tri_min + tri_max) * 0.5
    bmin, bmax, child, count, axis, prims = K.build_bvh(
        np.ascontiguousarray(tri_min), np.ascontiguousarray(tri_max), np.ascontiguousarray(centroid))
    a = v0[prims]
    return BVH(bmin, bmax, child, count, axis, prims,
               np.ascontiguousarray(a, np.float32),
               np.ascontiguousarray(v1[prims] - a, np.float32),
               np.ascontiguousarray(v2[prims] - a, np.float32))


def closest(bvh, origins, directions, tmax=None):
    """Closest hits: (t, original triangle index or -1)."""
    o = np.ascontiguousarray(origins, np.float64)
    d = np.ascontiguousarray(directions, np.float64)
    tm = np.full(o.shape[0], np.inf) if tmax is None else np.ascontiguousarray(
        np.broadcast_to(tmax, o.shape[:1]), np.float64)
    from .renderer import KERNEL_LOCK
    with KERNEL_LOCK:
        t, p = K.trace_closest_batch(o, d, tm, bvh.bmin, bvh.bmax, bvh.child, bvh.count, bvh.axis,
                                     bvh.v0, bvh.e1, bvh.e2)
    if bvh.prims.size == 0:
        return t, np.full(p.shape, -1, np.int32)
    tri = np.where(p >= 0, bvh.prims[np.maximum(p, 0)], -1)
    return t, tri


def occluded(bvh, origins, directions, tmax):
    o = np.ascontiguousarray(origins, np.float64)
    d = np.ascontiguousarray(directions, np.float64)
    tm = np.ascontiguousarray(np.broadcast_to(tmax, o.shape[:1]), np.float64)
    from .renderer import KERNEL_LOCK
    with KERNEL_LOCK:
        return K.trace_occluded_batch(o, d, tm, bvh.bmin, bvh.bmax, bvh.child, bvh.count,
                                      bvh.v0, bvh.e1, bvh.e2)


def brute_force_closest(v0, v1, v2, origins, directions):
    """NumPy oracle: Möller–Trumbore against every triangle (float32 corners, float64 math)."""
    a = np.asarray(v0, np.float32).astype(np.float64)
    e1 = np.asarray(v1, np.float32).astype(np.float64) - a
    e2 = np.asarray(v2, np.float32).astype(np.float64) - a
    o = np.asarray(origins, np.float64)[:, None, :]
    d = np.asarray(directions, np.float64)[:, None, :]
    p = np.cross(d, e2[None])
    det = np.sum(e1[None] * p, -1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        tv = o - a[None]
        u = np.sum(tv * p, -1) * inv
        q = np.cross(tv, e1[None])
        v = np.sum(d * q, -1) * inv
        t = np.sum(e2[None] * q, -1) * inv
    ok = (det != 0) & (u >= 0) & (u <= 1) & (v >= 0) & (u + v <= 1) & (t > 0)
    t = np.where(ok, t, np.inf)
    idx = np.argmin(t, axis=1)
    best = t[np.arange(t.shape[0]), idx]
    return best, np.where(np.isfinite(best), idx, -1)
