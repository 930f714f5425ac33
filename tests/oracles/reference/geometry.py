"""Ray casting of the reference: brute force, every ray against every triangle.

Möller–Trumbore (1997) in float64 over all triangles of the scene, no acceleration
structure. With P = d × e2, T = o − v0 and Q = T × e1, Möller–Trumbore's determinant and
numerators expand, by the scalar triple product, into dot products of per-ray vectors
(d, o and m = d × o) with per-triangle vectors (n = e1 × e2, e1, e2, e2 × v0, v0 × e1):

    det = P·e1 = −d·n
    t det = Q·e2 = o·n − v0·n
    u det = T·P = −m·e2 − d·(e2 × v0)
    v det = d·Q = m·e1 − d·(v0 × e1)

so one matrix product gives them for all ray–triangle pairs at once, and the hit is
det ≠ 0, u ≥ 0, v ≥ 0, u + v ≤ 1, t > t_min as usual. Self-intersection is avoided
without moving the ray origin: a ray leaving a surface ignores the triangle it leaves (a
flat triangle cannot be met again by a ray that starts on it) and any hit closer than
``T_MIN_REL`` times the scene's size (the neighbouring triangle of a quad meets the ray at
t ≈ 0 up to rounding).

Analytic area lights (rectangles and ellipses spanned by two half-axes) are intersected
here too; as the scene contract has it, they emit but never block rays.
"""
import numpy as np

from spectral_gi.core import constants as C

T_MIN_REL = 1e-9
CHUNK = 1 << 15  # ray–triangle pairs per block of the brute-force test (its arrays stay in cache)


class Triangles:
    """All triangles of a scene's meshes, in the meshes' order, in float64."""

    def __init__(self, scene):
        v0, v1, v2, mat = [], [], [], []
        for mesh in scene.meshes:
            p = np.asarray(mesh.positions, dtype=np.float64)
            idx = np.asarray(mesh.indices)
            v0.append(p[idx[:, 0]])
            v1.append(p[idx[:, 1]])
            v2.append(p[idx[:, 2]])
            mat.append(np.asarray(mesh.material, dtype=np.int64))
        empty = [np.zeros((0, 3))]
        self.v0 = np.concatenate(v0 or empty)
        self.e1 = np.concatenate(v1 or empty) - self.v0
        self.e2 = np.concatenate(v2 or empty) - self.v0
        self.material = np.concatenate(mat or [np.zeros(0, np.int64)])
        n = np.cross(self.e1, self.e2)
        self.area = 0.5 * np.linalg.norm(n, axis=1)
        keep = self.area > 0.0
        self.normal = np.zeros_like(n)
        self.normal[keep] = n[keep] / (2.0 * self.area[keep, None])  # right-handed (v0, v1, v2): the front
        self.count = self.v0.shape[0]
        corners = np.concatenate([self.v0, self.v0 + self.e1, self.v0 + self.e2])
        self.size = float(np.max(np.abs(corners))) if corners.size else 1.0
        self.t_min = T_MIN_REL * max(self.size, 1e-300)
        # rows: the ray's d, o, m = d × o; column blocks: det, t det, u det, v det (module docstring)
        nn, e1, e2, v0 = np.cross(self.e1, self.e2), self.e1, self.e2, self.v0
        z = np.zeros_like(nn)
        blocks = [(-nn, z, z), (z, nn, z), (-np.cross(e2, v0), z, -e2), (-np.cross(v0, e1), z, e1)]
        self._weights = np.concatenate([np.concatenate(bl, axis=1).T for bl in blocks], axis=1)
        self._offsets = np.concatenate([np.zeros(self.count), -np.einsum("ij,ij->i", v0, nn),
                                        np.zeros(self.count), np.zeros(self.count)])

    def intersect(self, o, d, skip):
        """Closest hit of rays (o, d) ((N, 3) each) among the triangles other than ``skip``
        (N,) (-1: none): (t (N,), triangle (N,), -1 and inf where nothing is hit)."""
        n = o.shape[0]
        best_t = np.full(n, np.inf)
        best_i = np.full(n, -1, np.int64)
        if self.count == 0 or n == 0:
            return best_t, best_i
        step = max(1, CHUNK // self.count)
        for a in range(0, n, step):
            b = min(n, a + step)
            oo, dd = o[a:b], d[a:b]
            rays = np.concatenate([dd, oo, np.cross(dd, oo)], axis=1)
            k = rays @ self._weights + self._offsets  # (rays, 4 T): det, t det, u det, v det
            det, tn, un, vn = (k[:, j * self.count:(j + 1) * self.count] for j in range(4))
            ok = det != 0.0
            inv = 1.0 / np.where(ok, det, 1.0)
            u, v, t = un * inv, vn * inv, tn * inv
            hit = ok & (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0) & (t > self.t_min)
            rows = np.nonzero(skip[a:b] >= 0)[0]
            hit[rows, skip[a:b][rows]] = False
            t = np.where(hit, t, np.inf)
            i = np.argmin(t, axis=1)
            best_t[a:b] = t[np.arange(b - a), i]
            best_i[a:b] = np.where(np.isfinite(best_t[a:b]), i, -1)
        return best_t, best_i


class AreaLights:
    """The scene's rectangle and ellipse lights (``core.scene.Light``): centre c, half-axes
    u and v, i.e. the points c + a u + b v with |a|, |b| ≤ 1 (rectangle; a parallelogram when
    u and v are not orthogonal, which the contract allows) or a² + b² ≤ 1 (ellipse); the
    front is the side of u × v; ``two_sided`` emits from both sides."""

    def __init__(self, scene):
        self.lights = []
        for i, li in enumerate(scene.lights):
            if li.kind not in (C.LIGHT_RECT, C.LIGHT_ELLIPSE):
                raise NotImplementedError(f"reference: lights[{i}] of kind {li.kind} (only rectangles and ellipses "
                                          "can be found by BSDF sampling)")
            c = np.asarray(li.position, np.float64)
            u = np.asarray(li.axis_u, np.float64)
            v = np.asarray(li.axis_v, np.float64)
            nrm = np.cross(u, v)
            self.lights.append((li, c, u, v, nrm / np.linalg.norm(nrm)))

    def hits(self, o, d, t_max):
        """For each light, (index, t (N,), front (N,) bool) of rays meeting it before t_max
        (t = inf where they do not)."""
        out = []
        for k, (li, c, u, v, nrm) in enumerate(self.lights):
            den = d @ nrm
            with np.errstate(divide="ignore", invalid="ignore"):
                t = ((c - o) @ nrm) / den
            ok = np.isfinite(t) & (t > 0.0) & (t < t_max)
            q = o + np.where(ok, t, 0.0)[:, None] * d - c
            # the hit's coordinates (a, b) in q = a u + b v (u and v need not be orthogonal)
            gram = np.array([[u @ u, u @ v], [u @ v, v @ v]])
            a, b = np.linalg.solve(gram, np.stack([q @ u, q @ v])) if q.size else (q[:, 0], q[:, 0])
            if li.kind == C.LIGHT_RECT:
                ok &= (np.abs(a) <= 1.0) & (np.abs(b) <= 1.0)
            else:
                ok &= a * a + b * b <= 1.0
            out.append((k, np.where(ok, t, np.inf), den < 0.0))
        return out
