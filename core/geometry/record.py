"""The geometry record: the BVH and the per-triangle tables the path kernel reads, in the
BVH's leaf order."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..scene import SceneError


class GeometryRecord(NamedTuple):
    """The scene's triangles as the path kernel traces and shades them (T triangles, in the
    BVH's leaf order).

    nodes: float32 (N, ...) the flattened BVH nodes (core/geometry/accel.py, bvh.py).
    tris: float32 (B, ...) the leaves' triangles in SIMD blocks (core/geometry/bvh.py).
    v0: float32 (T, 3) each triangle's first corner; e1, e2: float64 (T, 3) its edges
        v1 − v0 and v2 − v0 (the geometric normal is e1 × e2).
    tri_mat: int32 (T,) material index of each triangle.
    tri_emitter: int32 (T,) index of the triangle in the emitter table, -1 if it is not one.
    tri_nrm: float32 (T, 9) the three vertex normals of each triangle, interpolated with the
        hit's barycentrics and turned to the geometric normal's side; (0, 9): flat shading.
        The geometric normal still decides ray offsets and which side a direction is on.
    tri_flag: int8 (T,) bit 1 a sensor triangle, bit 2 a holdout triangle; (0,) when no
        triangle has a flag (the kernel then skips the test).
    """

    nodes: np.ndarray
    tris: np.ndarray
    v0: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    tri_mat: np.ndarray
    tri_emitter: np.ndarray
    tri_nrm: np.ndarray
    tri_flag: np.ndarray


def triangles(scene):
    """(v0, v1, v2 float64 (T, 3), material int32 (T,)) of every mesh's triangles, concatenated
    in the scene's order (before the BVH reorders them)."""
    v0s, v1s, v2s, mats = [], [], [], []
    for mesh in scene.meshes:
        p = mesh.positions.astype(np.float64)
        idx = mesh.indices
        v0s.append(p[idx[:, 0]])
        v1s.append(p[idx[:, 1]])
        v2s.append(p[idx[:, 2]])
        mats.append(mesh.material)
    if v0s:
        v0 = np.concatenate(v0s)
        v1 = np.concatenate(v1s)
        v2 = np.concatenate(v2s)
        tri_mat_orig = np.concatenate(mats).astype(np.int32)
    else:
        v0 = v1 = v2 = np.zeros((0, 3))
        tri_mat_orig = np.zeros(0, np.int32)
    return v0, v1, v2, tri_mat_orig


def pack(scene, bvh, tri_mat, tri_emitter, tri_mat_orig, measure) -> GeometryRecord:
    """The record of ``bvh`` (built from ``triangles(scene)``), its leaf-order materials and
    emitter indices; ``measure``: an illuminance render (at least one sensor mesh)."""
    return GeometryRecord(bvh.nodes, bvh.tris, bvh.v0, bvh.e1, bvh.e2, tri_mat, tri_emitter,
                          shading_normals(scene, bvh), triangle_flags(scene, bvh, tri_mat_orig, measure))


def shading_normals(scene, bvh):
    """float32 (T, 9): each triangle's three vertex normals in leaf order (the geometric
    normal for meshes without normals), or (0, 9) when no mesh has normals."""
    if not any(m.normals is not None for m in scene.meshes):
        return np.zeros((0, 9), np.float32)
    parts = []
    for mesh in scene.meshes:
        idx = mesh.indices
        if mesh.normals is not None:
            parts.append(mesh.normals.astype(np.float64)[idx].reshape(-1, 9))
        else:
            p = mesh.positions.astype(np.float64)
            ng = np.cross(p[idx[:, 1]] - p[idx[:, 0]], p[idx[:, 2]] - p[idx[:, 0]])
            ln = np.linalg.norm(ng, axis=1, keepdims=True)
            ng = np.divide(ng, ln, out=np.zeros_like(ng), where=ln > 0)
            parts.append(np.tile(ng, 3))
    return np.ascontiguousarray(np.concatenate(parts)[bvh.prims], np.float32)


def scene_radius(v0, v1, v2):
    """Radius of a sphere around every triangle (1 m for an empty scene)."""
    if not v0.size:
        return 1.0
    pts = np.concatenate([v0, v1, v2])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    return max(0.5 * float(np.linalg.norm(hi - lo)), 1e-3)


def triangle_flags(scene, bvh, tri_mat_orig, measure):
    """int8 (T,) flags in leaf order (1: sensor, 2: holdout from the mesh or its material),
    or (0,) when nothing is flagged (the kernel then skips the test)."""
    parts = []
    hold_mat = np.array([bool(m.holdout) for m in scene.materials] or [False])
    for mesh in scene.meshes:
        n = mesh.indices.shape[0]
        parts.append(np.full(n, (1 if mesh.sensor else 0) | (2 if mesh.holdout else 0), np.int8))
    flags = np.concatenate(parts) if parts else np.zeros(0, np.int8)
    if flags.size:
        flags |= np.where(hold_mat[tri_mat_orig], 2, 0).astype(np.int8)
    if measure and not np.any(flags & 1):
        raise SceneError("meshes: an illuminance render needs at least one mesh with sensor = True")
    if not np.any(flags):
        return np.zeros(0, np.int8)
    return np.ascontiguousarray(flags[bvh.prims], np.int8)
