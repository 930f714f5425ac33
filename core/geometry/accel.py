"""Python side of the BVH: build from triangles, batch queries."""
from dataclasses import dataclass

import numpy as np

from ..jit import KERNEL_LOCK
from . import bvh as K
from .simd import BLOCK_COLS


@dataclass
class BVH:
    nodes: np.ndarray  # float32 (R, 32), 64-byte aligned: packed 4-wide records (kernels/bvh.py)
    prims: np.ndarray  # leaf order → original triangle index
    tris: np.ndarray  # float32 (B, 40): leaf blocks of four triangles (kernels/bvh.py, simd.py)
    v0: np.ndarray  # float32 (T, 3), leaf order: the first corner rounded to float32 (shading)
    e1: np.ndarray  # float64 (T, 3): exact v1 - v0 of the float32-rounded corners (shading)
    e2: np.ndarray

    @property
    def links(self):
        """int32 (R, 32) view of ``nodes``: the children's references at columns C_REF..C_REF + 3
        and counts at C_CNT..C_CNT + 3."""
        return self.nodes.view(np.int32)

    @property
    def n_records(self):
        return self.nodes.shape[0]

    @property
    def n_nodes(self):
        """Nodes of the tree: the root and every child present in a record (records and leaves)."""
        return 1 + int(np.count_nonzero(self.links[:, K.C_REF:K.C_REF + 4] >= 0))

    def leaves(self):
        """(first triangle (leaf order), count, first block, box (L, 6)) of every leaf, in
        record order."""
        lk = self.links
        blocks, counts, boxes = [], [], []
        for c in range(4):
            cnt = lk[:, K.C_CNT + c]
            ref = lk[:, K.C_REF + c]
            leaf = (cnt > 0) & (ref >= 0)
            blocks.append(ref[leaf])
            counts.append(cnt[leaf])
            boxes.append(self.child_boxes(c)[leaf])
        blocks = np.concatenate(blocks)
        firsts = self.tris.view(np.int32)[blocks, K.PRIM_COL] if blocks.size else blocks
        return firsts, np.concatenate(counts), blocks, np.concatenate(boxes)

    def child_boxes(self, c):
        """float32 (R, 6): the box (min xyz, max xyz) of child ``c`` of every record."""
        return self.nodes[:, K.C_BOX + c:K.C_BOX + 24:4]

    def corners(self):
        """float32 (T, 9): every triangle's corners v0, v1, v2 in leaf order, read back from
        the leaf blocks (for tests and tools; the kernels read the blocks)."""
        ids = self.tris.view(np.int32)[:, K.PRIM_COL:K.PRIM_COL + K.BLOCK]
        coords = self.tris[:, :9 * K.BLOCK].reshape(-1, 9, K.BLOCK)
        out = np.empty((self.prims.size, 9), np.float32)
        b, ln = np.nonzero(ids >= 0)
        out[ids[b, ln]] = coords[b, :, ln]
        return out

    @property
    def nbytes(self):
        """Bytes the renderer keeps: node records, leaf blocks, leaf-order shading arrays
        and ``prims``.

        At most 128 (T - 1) + 160 T + 64 T (a record per binary node, a block per triangle,
        when every leaf holds one triangle), i.e. < 352 bytes per triangle whatever the
        tree; with the builder's leaves of about 6 triangles and records of about three
        children it is about 122 (benchmarks/scale_bench.py).
        """
        return sum(a.nbytes for a in (self.nodes, self.prims, self.tris, self.v0, self.e1, self.e2))


def _aligned_empty(shape, dtype, align=64):
    """A numpy-allocated empty array whose data start on an ``align``-byte boundary."""
    dtype = np.dtype(dtype)
    nbytes = int(np.prod(shape)) * dtype.itemsize
    buf = np.empty(nbytes + align, np.uint8)
    off = (-buf.ctypes.data) % align
    return buf[off:off + nbytes].view(dtype).reshape(shape)


def _aligned_copy(a, align=64):
    """A numpy-allocated copy of ``a`` whose data start on an ``align``-byte boundary."""
    out = _aligned_empty(a.shape, a.dtype, align)
    out[...] = a
    return out


def _corners(v, name):
    v = np.asarray(v)
    if v.dtype != np.float32 and v.dtype != np.float64:
        v = v.astype(np.float64)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"accel.build: {name} must have shape (T, 3), got {v.shape}")
    return np.ascontiguousarray(v)


def build(v0, v1, v2):
    """Build a BVH over triangles given by their corners, each (T, 3) float.

    Corners are rounded to float32 (float32 input is used as is, without a copy). Raises
    ValueError for mismatched shapes or a non-finite coordinate, naming the triangle.
    """
    a, b, c = _corners(v0, "v0"), _corners(v1, "v1"), _corners(v2, "v2")
    if not (a.shape == b.shape == c.shape):
        raise ValueError(f"accel.build: corner arrays differ in shape: {a.shape}, {b.shape}, {c.shape}")
    if a.shape[0] >= 2 ** 31 - 1:
        raise ValueError(f"accel.build: {a.shape[0]} triangles exceed the int32 indices")
    n = a.shape[0]
    # numpy-allocated outputs: numpy asks the kernel for transparent huge pages on large
    # arrays, which spares traversal a TLB miss per node on big scenes
    # blocks: a leaf of n triangles takes ceil(n / 4) <= n, so n rows always suffice; the
    # rows past the blocks used are never written, so their pages are never resident
    tris = _aligned_empty((n, BLOCK_COLS), np.float32)
    tv0 = np.empty((n, 3), np.float32)
    te1 = np.empty((n, 3), K.EDGE_DTYPE)
    te2 = np.empty((n, 3), K.EDGE_DTYPE)
    nodes, prims, bad, n_blk = K.build_bvh(a, b, c, tris, tv0, te1, te2)
    if bad >= 0:
        raise ValueError(f"accel.build: triangle {bad} has a non-finite corner coordinate "
                         f"({a[bad].tolist()}, {b[bad].tolist()}, {c[bad].tolist()})")
    return BVH(_aligned_copy(nodes), prims, tris[:n_blk], tv0, te1, te2)


def _rays(origins, directions, tmax):
    o = np.ascontiguousarray(origins, np.float64)
    d = np.ascontiguousarray(directions, np.float64)
    tm = np.full(o.shape[0], np.inf) if tmax is None else \
        np.array(np.broadcast_to(tmax, o.shape[:1]), np.float64)  # a writable copy: one compiled signature
    return o, d, tm


def closest(bvh, origins, directions, tmax=None):
    """Closest hits: (t, original triangle index or -1)."""
    o, d, tm = _rays(origins, directions, tmax)
    with KERNEL_LOCK:
        t, p = K.trace_closest_batch(o, d, tm, bvh.nodes, bvh.tris)
    if bvh.prims.size == 0:
        return t, np.full(p.shape, -1, np.int32)
    tri = np.where(p >= 0, bvh.prims[np.maximum(p, 0)], -1)
    return t, tri


def occluded(bvh, origins, directions, tmax):
    o, d, tm = _rays(origins, directions, tmax)
    with KERNEL_LOCK:
        return K.trace_occluded_batch(o, d, tm, bvh.nodes, bvh.tris)


def tree_depth(bvh):
    """Levels of the tree on its longest root-to-leaf path: records, plus one for the
    leaves (1 for a tree that is a single leaf)."""
    lk = bvh.links
    inner = lk[:, K.C_REF:K.C_REF + 4]
    if bvh.tris.shape[0] == 0 or (bvh.n_records == 1 and np.count_nonzero(inner >= 0) == 1):
        return 1
    level = np.zeros(1, np.int64)
    depth = 1
    while level.size:
        depth += 1
        cnt = lk[level, K.C_CNT:K.C_CNT + 4]
        ref = lk[level, K.C_REF:K.C_REF + 4]
        level = ref[(cnt == 0) & (ref >= 0)].astype(np.int64)
    return depth
