"""Patches for radiosity: the scene's triangles subdivided to a target size, each side of a
triangle a patch of its own (surfaces in the renderer reflect on both sides), adaptive
refinement where the solution's gradient is large, and interpolation of per-patch values
to the vertices of a display mesh.

A triangle whose longest edge is ℓ is split into k² congruent triangles on a regular
barycentric grid, k = ⌈ℓ / max_edge⌉, so every patch's edges are at most ``max_edge``
(the grid keeps the triangle's shape). Refinement splits a patch into four at its edge
midpoints (each child half the size): ``refine`` splits the patches whose value differs
from a neighbour's (patches sharing a corner, on the same side) by more than a relative
threshold.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ... import constants as C
from ...scene import SceneError


@dataclass
class Patches:
    """n patches over T geometry triangles (all arrays in patch or triangle order).

    corners: float64 (n, 3, 3) counter-clockwise seen from the patch's front;
    normal: float64 (n, 3) unit front normals; area: float64 (n,) m²;
    tri: int32 (n,) the geometry triangle (row of ``geometry``); side: int8 (n,) 0 the front
    of the geometry triangle (its e1 × e2 side), 1 its back; material: int32 (n,);
    source: int32 (n,) the scene triangle (meshes concatenated in the scene's order);
    geometry: float64 (T, 3, 3) the triangles that occlude (every patch's own triangle);
    tri_patch: int32 (T, 2) the patch of each geometry triangle's front and back (-1 none);
    occluders: float64 (T0, 3, 3) the scene's triangles before subdivision, which cover the
    same surface as ``geometry``: shadow rays test these (a far smaller tree to traverse);
    None: ``geometry``.
    """

    corners: np.ndarray
    normal: np.ndarray
    area: np.ndarray
    tri: np.ndarray
    side: np.ndarray
    material: np.ndarray
    source: np.ndarray
    geometry: np.ndarray
    tri_patch: np.ndarray
    occluders: np.ndarray | None = None

    @property
    def n(self):
        return int(self.area.size)

    def centroids(self):
        return self.corners.mean(axis=1)

    def subset(self, keep):
        """The patches where ``keep`` (bool (n,)) holds, over the same geometry."""
        keep = np.asarray(keep, bool)
        idx = np.full(self.n, -1, np.int32)
        idx[keep] = np.arange(int(keep.sum()), dtype=np.int32)
        tp = np.where(self.tri_patch >= 0, idx[np.maximum(self.tri_patch, 0)], -1).astype(np.int32)
        return Patches(self.corners[keep], self.normal[keep], self.area[keep], self.tri[keep], self.side[keep],
                       self.material[keep], self.source[keep], self.geometry, tp, self.occluders)

    def shadow_geometry(self):
        """The triangles shadow rays test (``occluders``, else ``geometry``)."""
        return self.geometry if self.occluders is None else self.occluders


def scene_triangles(scene):
    """(corners float64 (T, 3, 3), material int32 (T,), source int32 (T,)) of the scene's
    surfaces: every mesh's triangles except those of null (volume-only) materials and
    degenerate ones."""
    parts, mats, src = [], [], []
    base = 0
    for mesh in scene.meshes:
        p = np.asarray(mesh.positions, np.float64)
        idx = np.asarray(mesh.indices)
        parts.append(p[idx])
        mats.append(np.asarray(mesh.material, np.int32))
        src.append(base + np.arange(idx.shape[0], dtype=np.int32))
        base += idx.shape[0]
    if not parts:
        return np.zeros((0, 3, 3)), np.zeros(0, np.int32), np.zeros(0, np.int32)
    tri = np.concatenate(parts)
    mat = np.concatenate(mats)
    source = np.concatenate(src)
    model = np.array([m.model for m in scene.materials] or [C.MAT_LAMBERT])
    ok = (model[mat] != C.MAT_NULL) & (np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]),
                                                      axis=1) > 0)
    return tri[ok], mat[ok], source[ok]


def subdivide(tri, max_edge):
    """Every triangle (T, 3, 3) split into k² on its barycentric grid, k = ⌈longest edge /
    max_edge⌉ (max_edge None or ≤ 0: no split). Returns (sub-triangles (S, 3, 3), parent
    int64 (S,)), the sub-triangles oriented as their parent."""
    tri = np.asarray(tri, np.float64)
    if max_edge is None or not max_edge > 0 or tri.shape[0] == 0:
        return tri.copy(), np.arange(tri.shape[0])
    edge = np.max(np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2), axis=1)
    ks = np.maximum(1, np.ceil(edge / float(max_edge) - 1e-9)).astype(np.int64)
    out, parent = [], []
    for k in np.unique(ks):
        sel = np.nonzero(ks == k)[0]
        a, b, c = tri[sel, 0], tri[sel, 1], tri[sel, 2]
        bary = []
        for i in range(k):
            for j in range(k - i):
                bary.append(((i, j), (i + 1, j), (i, j + 1)))  # upward
                if j + i + 1 < k:
                    bary.append(((i + 1, j), (i + 1, j + 1), (i, j + 1)))  # downward
        g = np.array(bary, np.float64) / k  # (k², 3 corners, (u along b, v along c))
        u = g[..., 0]
        v = g[..., 1]
        w = 1.0 - u - v
        pts = (w[None, :, :, None] * a[:, None, None, :] + u[None, :, :, None] * b[:, None, None, :]
               + v[None, :, :, None] * c[:, None, None, :])
        out.append(pts.reshape(-1, 3, 3))
        parent.append(np.repeat(sel, g.shape[0]))
    order = np.argsort(np.concatenate(parent), kind="stable")
    return np.concatenate(out)[order], np.concatenate(parent)[order]


def _assemble(geometry, mat, source, sides, occluders=None):
    """Patches over the geometry triangles for ``sides`` ("both" or "front"), shadowed by
    ``occluders`` (None: the geometry)."""
    t = geometry.shape[0]
    e1 = geometry[:, 1] - geometry[:, 0]
    e2 = geometry[:, 2] - geometry[:, 0]
    cr = np.cross(e1, e2)
    ln = np.linalg.norm(cr, axis=1)
    nrm = cr / ln[:, None]
    area = 0.5 * ln
    tri_patch = np.full((t, 2), -1, np.int32)
    tri_patch[:, 0] = np.arange(t, dtype=np.int32)
    corners = [geometry]
    normals = [nrm]
    tri_idx = [np.arange(t, dtype=np.int32)]
    side = [np.zeros(t, np.int8)]
    if sides == "both":
        tri_patch[:, 1] = t + np.arange(t, dtype=np.int32)
        corners.append(geometry[:, ::-1])
        normals.append(-nrm)
        tri_idx.append(np.arange(t, dtype=np.int32))
        side.append(np.ones(t, np.int8))
    k = len(corners)
    return Patches(np.ascontiguousarray(np.concatenate(corners)), np.concatenate(normals), np.tile(area, k),
                   np.concatenate(tri_idx), np.concatenate(side), np.tile(mat, k).astype(np.int32),
                   np.tile(source, k).astype(np.int32), np.ascontiguousarray(geometry), tri_patch,
                   None if occluders is None else np.ascontiguousarray(occluders, np.float64))


def build_patches(scene, max_edge=None, sides="both"):
    """The scene's patches: its surfaces' triangles subdivided so that no edge is longer than
    ``max_edge`` m (None: the triangles as they are); ``sides`` "both" (a patch on each side
    of every triangle, as the renderer's surfaces reflect on both) or "front" (the side of
    each triangle's e1 × e2 only)."""
    if sides not in ("both", "front"):
        raise SceneError(f"radiosity sides: expected 'both' or 'front', got {sides!r}")
    if max_edge is not None and not float(max_edge) > 0:
        raise SceneError(f"radiosity max_edge: expected a positive length in m, got {max_edge!r}")
    tri, mat, source = scene_triangles(scene)
    if tri.shape[0] == 0:
        raise SceneError("radiosity: the scene has no surfaces to mesh into patches")
    sub, parent = subdivide(tri, max_edge)
    return _assemble(sub, mat[parent], source[parent], sides, tri)


def split4(corners):
    """Each triangle (S, 3, 3) split into four at its edge midpoints, oriented as it was:
    (4S, 3, 3), the four children of triangle s at rows 4s .. 4s + 3."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    ab = 0.5 * (a + b)
    bc = 0.5 * (b + c)
    ca = 0.5 * (c + a)
    kids = np.stack([np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1), np.stack([ca, bc, c], 1),
                     np.stack([ab, bc, ca], 1)], 1)
    return kids.reshape(-1, 3, 3)


def _weld(points, tol):
    """Integer ids of points equal to within ``tol`` (by rounding to a grid of that size)."""
    q = np.round(points / tol).astype(np.int64)
    _, ids = np.unique(q, axis=0, return_inverse=True)
    return ids.reshape(-1)


def _tolerance(patches):
    span = float(np.ptp(patches.geometry.reshape(-1, 3), axis=0).max()) if patches.n else 1.0
    return max(span, 1e-9) * 1e-7


def neighbours(patches):
    """Pairs (a, b) of patches on the same side of the surfaces that share a corner."""
    tol = _tolerance(patches)
    ids = _weld(patches.corners.reshape(-1, 3), tol).reshape(-1, 3)
    key = ids * 2 + patches.side[:, None].astype(np.int64)
    owner = np.repeat(np.arange(patches.n), 3)
    order = np.argsort(key.reshape(-1), kind="stable")
    k = key.reshape(-1)[order]
    o = owner[order]
    pairs = []
    start = 0
    for end in np.append(np.nonzero(np.diff(k))[0] + 1, k.size):
        grp = o[start:end]
        if grp.size > 1:
            a, b = np.meshgrid(grp, grp, indexing="ij")
            m = a < b
            pairs.append(np.stack([a[m], b[m]], 1))
        start = end
    if not pairs:
        return np.zeros((0, 2), np.int64)
    return np.unique(np.concatenate(pairs), axis=0)


def refine(patches, values, threshold, min_area=0.0):
    """Adaptive refinement: the patches whose ``values`` (n,) differ from a neighbour's by
    more than ``threshold`` times the larger of the two (and whose area is above
    ``min_area``) are split into four; both sides of a triangle are split together.
    Returns (new patches, number split)."""
    v = np.asarray(values, np.float64)
    pairs = neighbours(patches)
    split = np.zeros(patches.n, bool)
    if pairs.size:
        a, b = pairs[:, 0], pairs[:, 1]
        big = np.maximum(np.abs(v[a]), np.abs(v[b]))
        jump = np.abs(v[a] - v[b]) > float(threshold) * np.where(big > 0, big, np.inf)
        split[a[jump]] = True
        split[b[jump]] = True
    split &= patches.area > float(min_area)
    tri_split = np.zeros(patches.geometry.shape[0], bool)
    tri_split[patches.tri[split]] = True
    if not tri_split.any():
        return patches, 0
    keep = ~tri_split
    geometry = np.concatenate([patches.geometry[keep], split4(patches.geometry[tri_split])])
    # material and source of each geometry triangle, from any of its patches
    t_mat = np.zeros(patches.geometry.shape[0], np.int32)
    t_src = np.zeros(patches.geometry.shape[0], np.int32)
    t_mat[patches.tri] = patches.material
    t_src[patches.tri] = patches.source
    mat = np.concatenate([t_mat[keep], np.repeat(t_mat[tri_split], 4)])
    src = np.concatenate([t_src[keep], np.repeat(t_src[tri_split], 4)])
    sides = "both" if np.any(patches.side == 1) else "front"
    return _assemble(geometry, mat, src, sides, patches.occluders), int(tri_split.sum())


@dataclass
class DisplayMesh:
    """A welded triangle mesh for smooth display: positions float64 (V, 3), faces int32
    (n, 3) (one per patch, oriented as the patch), side int8 (V,) the side each vertex
    belongs to (0 front, 1 back)."""

    positions: np.ndarray
    faces: np.ndarray
    side: np.ndarray


def display_mesh(patches):
    """The patches' corners welded per side and per facing direction: a vertex is shared by
    the patches of one side that meet there with the same normal (one plane), so values do
    not bleed across a crease (a block standing on the floor) or between the two sides."""
    tol = _tolerance(patches)
    pts = patches.corners.reshape(-1, 3)
    side = np.repeat(patches.side, 3).astype(np.int64)
    q = np.round(pts / tol).astype(np.int64)
    facing = np.round(np.repeat(patches.normal, 3, axis=0) * 1e4).astype(np.int64)
    key = np.concatenate([q, side[:, None], facing], axis=1)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return DisplayMesh(pts[first], inv.reshape(-1, 3).astype(np.int32), side[first].astype(np.int8))


def to_vertices(mesh, patches, values):
    """Per-patch ``values`` (n, ...) interpolated to the display mesh's vertices: the mean
    of the patches meeting at a vertex, weighted by their areas (V, ...)."""
    vals = np.asarray(values, np.float64)
    nv = mesh.positions.shape[0]
    w = np.repeat(patches.area, 3)
    flat = vals[np.repeat(np.arange(patches.n), 3)]
    ids = mesh.faces.reshape(-1)
    num = np.zeros((nv,) + vals.shape[1:])
    np.add.at(num, ids, flat * w.reshape((-1,) + (1,) * (vals.ndim - 1)))
    den = np.bincount(ids, weights=w, minlength=nv)
    return num / np.maximum(den, 1e-300).reshape((-1,) + (1,) * (vals.ndim - 1))
