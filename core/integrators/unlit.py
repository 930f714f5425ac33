"""Sensor points that look outside the lit geometry: inside a solid, behind a wall, in open space.

An illuminance estimate that is exactly 0 lx with a standard error of 0 means no sample found
any light, which is right for a point in the dark but is more often a point in the wrong
place: inside a desk or a wall, under the floor, outside the room. This module finds those
points so that the command line, the JSON summary and Blender can say which they are.

A point is probed with :data:`PROBE_RAYS` rays over the cosine-weighted hemisphere about its
normal (the directions its illuminance integrates over; a fixed Fibonacci spiral, so the
probe is the same for every run), cast from the point moved the scene's ray epsilon along each
ray, as the illuminance integrator casts them. A ray that hits a triangle from the side its
winding's normal faces away from (``d · n > 0``: the back of the face) counts as a back hit; a
ray that hits nothing escapes. Reported:

* every point that read 0 lx with a standard error of 0, with its most likely cause: **inside a
  solid or behind a wall** when at least half of its probe rays hit the back of a face, **in
  open space** when at least half escape, else **no light reaches it** (a closed room without
  a light that reaches the point, or a point facing away from every light with nothing to
  reflect towards it);
* a point that did read light but whose probe rays hit the back of a face at least
  :data:`BACK_FRACTION` of the time, where the median point of the same call does not (below
  one half): surfaces are two-sided to the renderer, so such a point is lit through a gap (an
  open-bottomed box, a wall with a missing face) and is almost certainly inside a solid. The
  median test keeps a room modelled with outward normals (every point inside it sees the back
  of its faces) from being reported.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..geometry import accel
from ..geometry import record as geometry_record
from .path import EPS_REL

PROBE_RAYS = 32  # directions per point
BACK_FRACTION = 0.9  # a lit point is reported when this share of its probe rays hit the back of a face
POINTS_PER_CALL = 4096  # points probed per batch of rays

INSIDE = "inside a solid or behind a wall"
OPEN = "in open space (its rays escape the scene)"
DARK = "no light reaches it"


@dataclass(frozen=True)
class UnlitPoints:
    """The points an illuminance calculation should not be trusted at: their indices (in the
    order given, ascending), the reason for each, the value each read (lx) and the shares of
    their probe rays that hit the back of a face and that escaped."""

    n_points: int
    indices: np.ndarray
    reasons: tuple
    lux: np.ndarray
    back_fraction: np.ndarray
    escape_fraction: np.ndarray

    def __len__(self):
        return int(self.indices.size)

    def warning(self, limit: int = 10, what: str = "points") -> str | None:
        """One line naming up to ``limit`` of the points and why, or None when there are none."""
        if not len(self):
            return None
        shown = ", ".join(f"{int(i)} ({r})" for i, r in zip(self.indices[:limit], self.reasons[:limit]))
        more = f" and {len(self) - limit} more" if len(self) > limit else ""
        zero = int(np.count_nonzero(self.lux == 0.0))
        head = f"{len(self)} of {self.n_points} {what} look outside the lit geometry"
        if zero:
            head += f" ({zero} read 0 lx with no sample reaching a light)"
        return f"{head}: {shown}{more}"

    def to_dict(self) -> dict:
        """A JSON-able record: count, indices, reasons, the values read and the probe's fractions."""
        return {"count": len(self), "probe_rays": PROBE_RAYS, "indices": [int(i) for i in self.indices],
                "reasons": list(self.reasons), "lux": [float(v) for v in self.lux],
                "back_fraction": [round(float(v), 4) for v in self.back_fraction],
                "escape_fraction": [round(float(v), 4) for v in self.escape_fraction]}


def probe_directions(n: int = PROBE_RAYS) -> np.ndarray:
    """``n`` unit directions (n, 3) about +z, cosine-weighted: a Fibonacci spiral on the unit disc
    (equal areas) lifted to the hemisphere (Malley's method)."""
    k = np.arange(n, dtype=np.float64) + 0.5
    r = np.sqrt(k / n)
    phi = k * math.pi * (3.0 - math.sqrt(5.0))
    x, y = r * np.cos(phi), r * np.sin(phi)
    return np.stack([x, y, np.sqrt(np.maximum(0.0, 1.0 - x * x - y * y))], axis=1)


def _frames(normals):
    """Tangents t, b (N, 3) completing each unit normal to a right-handed frame."""
    n = normals
    a = np.where(np.abs(n[:, :1]) > 0.9, np.array([[0.0, 1.0, 0.0]]), np.array([[1.0, 0.0, 0.0]]))
    t = np.cross(a, n)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    return t, np.cross(n, t)


def probe(scene, points, normals, rays: int = PROBE_RAYS) -> tuple[np.ndarray, np.ndarray]:
    """(back fraction (N,), escape fraction (N,)) of ``rays`` cosine-weighted probe rays per point."""
    p = np.asarray(points, np.float64).reshape(-1, 3)
    nrm = np.asarray(normals, np.float64).reshape(-1, 3)
    nrm = nrm / np.linalg.norm(nrm, axis=1, keepdims=True)
    n = p.shape[0]
    v0, v1, v2, _ = geometry_record.triangles(scene)
    if v0.shape[0] == 0:
        return np.zeros(n), np.ones(n)
    bvh = accel.build(v0, v1, v2)
    face_n = np.cross(v1 - v0, v2 - v0)
    eps = EPS_REL * max(1.0, float(np.abs(np.concatenate([v0, v1, v2])).max()))
    local = probe_directions(rays)
    back = np.zeros(n)
    escape = np.zeros(n)
    for a in range(0, n, POINTS_PER_CALL):
        b = min(n, a + POINTS_PER_CALL)
        t, bt = _frames(nrm[a:b])
        d = (local[None, :, :1] * t[:, None] + local[None, :, 1:2] * bt[:, None]
             + local[None, :, 2:] * nrm[a:b, None]).reshape(-1, 3)
        o = np.repeat(p[a:b], rays, axis=0) + eps * d
        _, tri = accel.closest(bvh, o, d)
        hit = tri >= 0
        is_back = np.zeros(tri.shape, bool)
        is_back[hit] = np.einsum("ij,ij->i", d[hit], face_n[tri[hit]]) > 0.0
        back[a:b] = is_back.reshape(b - a, rays).mean(axis=1)
        escape[a:b] = (~hit).reshape(b - a, rays).mean(axis=1)
    return back, escape


def unlit_points(scene, points, normals, lux, std_error, rays: int = PROBE_RAYS) -> UnlitPoints:
    """The points of an illuminance calculation (``lux`` and ``std_error`` (N,) at ``points``
    facing ``normals``) that read nothing, or read light while inside a solid (see the module
    text)."""
    e = np.asarray(lux, np.float64).reshape(-1)
    se = np.asarray(std_error, np.float64).reshape(-1)
    p = np.asarray(points, np.float64).reshape(-1, 3)
    if not (e.shape == se.shape == (p.shape[0],)):
        raise ValueError(f"unlit_points: {p.shape[0]} points, {e.size} values, {se.size} standard errors")
    back, escape = probe(scene, p, normals, rays)
    zero = (e == 0.0) & (se == 0.0)
    median_back = float(np.median(back)) if back.size else 0.0
    enclosed = ~zero & (back >= BACK_FRACTION) & (median_back < 0.5)
    idx = np.flatnonzero(zero | enclosed)
    reasons = tuple(INSIDE if (back[i] >= 0.5 or not zero[i]) else OPEN if escape[i] >= 0.5 else DARK for i in idx)
    return UnlitPoints(int(p.shape[0]), idx.astype(np.int64), reasons, e[idx], back[idx], escape[idx])
