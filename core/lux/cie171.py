"""CIE 171:2006 *Test cases to assess the accuracy of lighting computer programs*: the analytic
cases as code — closed-form expected values and the scenes, points and normals to check an
illuminance integrator against them.

Lighting designers run these cases to show that a program is fit for a calculation (DIALux and
Relux publish such validations), so they live in ``core`` where a user can run them, not only
in the test suite.

Closed forms used (all photometric: I in cd, L in cd/m², Φ in lm, E in lx):

* 5.2, point source: ``E = I cos θ / d²`` at a point at distance d whose normal makes θ with
  the direction to the source (:func:`point_source_illuminance`).
* 5.3, area source: a uniform Lambertian emitter of luminance L gives ``E = π L F`` with F the
  configuration factor from the point to the emitter. :func:`polygon_factor` is Lambert's
  contour integral, exact for any planar polygon wholly in front of the point;
  :func:`parallel_corner_factor` and :func:`perpendicular_corner_factor` are the classical
  closed forms for a point facing a rectangle's corner (the rectangle parallel to the point's
  plane, or perpendicular to it with one side in that plane), as tabulated in Howell's
  catalogue of configuration factors.
* 5.4, flux conservation: an isotropic source of flux Φ (I = Φ / 4π) sends ``I Ω`` lumens onto
  a surface of solid angle Ω (:func:`polygon_solid_angle`, Van Oosterom and Strackee), so the
  six faces of a closed room receive Φ in all.
* 5.7, diffuse reflection with an internal obstruction: a uniformly lit Lambertian wall S₂ of
  reflectance ρ and illuminance E_v has exitance ρ E_v, so a point that sees the part P of S₂
  the obstruction leaves uncovered receives ``E = ρ E_v F(P)`` (:func:`obstructed_wall_factor`:
  the uncovered part is a rectangle, its factor Lambert's contour integral).
* 5.6 and 5.8, diffuse inter-reflection in a closed room of area A whose surfaces all reflect
  ρ (Lambertian): every reflected lumen lands on the room again, so the area-mean indirect
  illuminance is ``Φ ρ / (A (1 − ρ))`` (:func:`enclosure_indirect`; 1979 lx for 10 000 lm in a
  4 m cube at ρ = 0.95) and the area-mean direct illuminance is ``Φ / A``; a program that stops
  after k bounces keeps ``1 − ρ^k`` of the indirect part (:func:`truncated_indirect`). The
  inter-reflected field is not uniform (lower near the edges), so an 8 × 8 grid's mean
  overstates the area mean by 0.07 % (ρ = 0.95) to 0.64 % (ρ = 0.1); for the publication's room
  the cases also give it per point (:data:`CUBE_INDIRECT_8X8`, a converged radiosity solution).

Geometry: case 5.8's room (a 4 m cube, 10 000 lm at its centre, ρ from 0 to 0.95) is the
publication's. Case 5.7's geometry (S₂ a 4 m × 3 m wall of ρ = 0.6, a 4 m × 1 m × 0.2 m black
obstruction 1.3 m in front of it, the black measurement wall S₁-v 4 m from S₂ and the black
floor S₁-hz between them, points A–F on S₁-v and G–K on S₁-hz) is the publication's as the
validation reports of other programs describe it (the report itself was not at hand); its
Table 19 is known to be wrong (Ashdown, *CIE 171:2006 – Errata*, Lighting Analysts), and the
values here are computed, not transcribed — they agree with the corrected table of Dau's
NVIDIA Iray validation (2016) to its two decimals. The sun that lights S₂ is chosen here.
The dimensions of the other cases are parameters whose defaults are chosen
here (not transcribed from the publication); the expected values come from the closed forms
above, never from the publication's tables.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import constants as C
from ..scene import Camera, Light, Material, Mesh, Scene, SpectrumTable
from ..spectra import uplift
from .grids import rectangle_grid
from .points import LuxError

# Inter-reflected illuminance (lx) at the centres of an 8 × 8 grid on a face of a 4 m cube with
# 10 000 lm at its centre (scale by Φ / 10 000 · (4 / side)²), for each reflectance: the ten
# values of one eighth of the face, cells (i, j) with 0 ≤ i ≤ j ≤ 3 counted from a corner in the
# order (0,0) (0,1) (0,2) (0,3) (1,1) (1,2) (1,3) (2,2) (2,3) (3,3); the face's symmetry gives
# the rest. Computed here by a radiosity solution (exitance constant on N × N patches of a face,
# collocated at their centres, with exact point-to-patch configuration factors for the
# collocation and for the gather at the grid points), N = 32 and 64 extrapolated as h^1.6
# (the observed order); the N = 16/32/64 and 8/16/32 extrapolations differ by ≤ 1.5e-4.
CUBE_INDIRECT_8X8 = {
    0.1: (8.72637, 10.1717, 11.0961, 11.589, 11.4491, 12.1552, 12.5101, 12.6052, 12.8076, 12.9221),
    0.2: (20.0503, 23.1366, 25.0826, 26.1134, 25.7955, 27.2569, 27.9894, 28.1777, 28.5921, 28.8247),
    0.3: (35.1621, 40.1222, 43.2022, 44.8221, 44.2805, 46.553, 47.6886, 47.9673, 48.6045, 48.9588),
    0.4: (56.0671, 63.1801, 67.5256, 69.7935, 68.9725, 72.1198, 73.6873, 74.0528, 74.9246, 75.405),
    0.5: (86.4073, 96.0123, 101.778, 104.762, 103.594, 107.689, 109.722, 110.169, 111.289, 111.9),
    0.6: (133.523, 146.037, 153.407, 157.188, 155.588, 160.716, 163.252, 163.775, 165.159, 165.905),
    0.7: (214.646, 230.587, 239.785, 244.457, 242.32, 248.582, 251.665, 252.256, 253.92, 254.807),
    0.8: (381.684, 401.713, 413.009, 418.687, 415.88, 423.394, 427.078, 427.725, 429.691, 430.725),
    0.9: (894.822, 919.791, 933.526, 940.347, 936.7, 945.611, 949.959, 950.648, 952.94, 954.128),
    0.95: (1932.14, 1959.98, 1975.09, 1982.54, 1978.4, 1988.07, 1992.78, 1993.48, 1995.95, 1997.21),
}
CUBE_INDIRECT_CELLS = ((0, 0), (0, 1), (0, 2), (0, 3), (1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3))

CIE171_TOLERANCE = 0.05  # relative difference per point accepted against the analytic value
CASE_5_8_REFLECTANCES = (0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95)


# --------------------------------------------------------------------------- closed forms


def point_source_illuminance(intensity, source, points, normals) -> np.ndarray:
    """``E = I cos θ / d²`` (lx) at ``points`` (N, 3) facing ``normals`` from an isotropic point of
    ``intensity`` cd at ``source``; 0 where the source is behind the point's plane."""
    p = np.asarray(points, float).reshape(-1, 3)
    n = np.asarray(normals, float).reshape(-1, 3)
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    d = np.asarray(source, float).reshape(1, 3) - p
    r = np.linalg.norm(d, axis=1)
    if not (r > 0).all():
        raise LuxError("a point coincides with the point source")
    cos = np.maximum((d * n).sum(axis=1) / r, 0.0)
    return float(intensity) * cos / r**2


def parallel_corner_factor(a: float, b: float, c: float) -> float:
    """Configuration factor from a point to an a × b rectangle in a parallel plane at distance c,
    the point's normal through a corner of the rectangle:
    ``F = 1/(2π) [X/√(1+X²) atan(Y/√(1+X²)) + Y/√(1+Y²) atan(X/√(1+Y²))]``, X = a/c, Y = b/c."""
    X, Y = a / c, b / c
    sx, sy = math.sqrt(1 + X * X), math.sqrt(1 + Y * Y)
    return (X / sx * math.atan(Y / sx) + Y / sy * math.atan(X / sy)) / (2 * math.pi)


def perpendicular_corner_factor(a: float, b: float, c: float) -> float:
    """Configuration factor from a point to a rectangle in a plane perpendicular to the point's
    plane: the rectangle's side of length a lies in the point's plane at distance c from the point,
    which faces the end of that side; its other side b rises away from the plane:
    ``F = 1/(2π) [atan(1/Y) − Y/√(X²+Y²) atan(1/√(X²+Y²))]``, X = b/a, Y = c/a."""
    X, Y = b / a, c / a
    r = math.sqrt(X * X + Y * Y)
    return (math.atan(1.0 / Y) - Y / r * math.atan(1.0 / r)) / (2 * math.pi)


def polygon_factor(points, normals, vertices) -> np.ndarray:
    """Configuration factor from points (N, 3) with ``normals`` to a planar polygon (K, 3), by
    Lambert's contour integral ``F = 1/(2π) Σ γᵢ n · (Rᵢ × Rᵢ₊₁)/|Rᵢ × Rᵢ₊₁|`` (γᵢ the angle between
    the directions Rᵢ, Rᵢ₊₁ to consecutive vertices). Exact when the polygon lies wholly on the
    normal's side of each point (touching the point's plane is allowed; a polygon in the point's
    plane has factor 0)."""
    p = np.asarray(points, float).reshape(-1, 3)
    n = np.asarray(normals, float).reshape(-1, 3)
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    v = np.asarray(vertices, float).reshape(-1, 3)
    R = v[None, :, :] - p[:, None, :]
    height = (R * n[:, None, :]).sum(axis=2)
    tol = 1e-9 * np.linalg.norm(R, axis=2)
    if (height < -tol).any():
        raise LuxError("the polygon must lie wholly in front of every point (clip it first)")
    in_plane = (height <= tol).all(axis=1)  # the polygon lies in the point's plane: it sends nothing
    R1 = np.roll(R, -1, axis=1)
    cr = np.cross(R, R1)
    crn = np.linalg.norm(cr, axis=2)
    gamma = np.arctan2(crn, (R * R1).sum(axis=2))
    with np.errstate(invalid="ignore", divide="ignore"):
        term = np.where(crn > 0, gamma * (cr * n[:, None, :]).sum(axis=2) / crn, 0.0)
    return np.where(in_plane, 0.0, np.abs(term.sum(axis=1)) / (2 * math.pi))


def area_source_illuminance(luminance, points, normals, vertices) -> np.ndarray:
    """``E = π L F`` (lx) from a uniform Lambertian polygon of ``luminance`` cd/m²."""
    return math.pi * float(luminance) * polygon_factor(points, normals, vertices)


def polygon_solid_angle(point, vertices) -> float:
    """Solid angle (sr) of a planar convex polygon (K, 3) seen from ``point`` (a fan of triangles,
    each by Van Oosterom and Strackee's formula)."""
    p = np.asarray(point, float).reshape(3)
    v = np.asarray(vertices, float).reshape(-1, 3) - p
    total = 0.0
    for k in range(1, len(v) - 1):
        a, b, c = v[0], v[k], v[k + 1]
        la, lb, lc = (float(np.linalg.norm(x)) for x in (a, b, c))
        num = float(np.dot(a, np.cross(b, c)))
        den = la * lb * lc + float(np.dot(a, b)) * lc + float(np.dot(a, c)) * lb + float(np.dot(b, c)) * la
        total += 2.0 * math.atan2(num, den)
    return abs(total)


def obstructed_wall_factor(point, normal, wall_x, wall_y, wall_z, obstruction_y, obstruction_top) -> float:
    """Configuration factor from a point at x = the middle of ``wall_x`` (in the plane y < the
    obstruction) to the part of the wall ``y = wall_y``, ``x ∈ wall_x``, ``z ∈ wall_z`` that a
    full-width obstruction ``y ∈ obstruction_y``, ``z ∈ [0, obstruction_top]`` leaves uncovered.

    Seen from the point, the obstruction's top edges cast a straight line across the whole wall:
    a point below the top looks over the near edge, a point above it over the far edge, so the
    uncovered part is the rectangle above ``z_cut = z_p + (h − z_p)(y_w − y_p)/(y_e − y_p)`` with
    y_e that edge's y (the obstruction as wide as the wall, so no ray passes beside it)."""
    x0, x1 = (float(v) for v in wall_x)
    z0, z1 = (float(v) for v in wall_z)
    y_near, y_far = (float(v) for v in obstruction_y)
    px, py, pz = (float(v) for v in np.asarray(point, float).reshape(3))
    h = float(obstruction_top)
    if not (py < y_near < y_far < float(wall_y)):
        raise LuxError("the obstruction must lie between the point and the wall")
    y_edge = y_near if pz < h else y_far
    z_cut = max(z0, pz + (h - pz) * (float(wall_y) - py) / (y_edge - py))
    if z_cut >= z1:
        return 0.0
    corners = np.array([[x0, wall_y, z_cut], [x1, wall_y, z_cut], [x1, wall_y, z1], [x0, wall_y, z1]], float)
    return float(polygon_factor([(px, py, pz)], [normal], corners)[0])


def enclosure_direct(flux: float, area: float) -> float:
    """Area-mean direct illuminance on the inside of a closed room: ``Φ / A`` (lx)."""
    return float(flux) / float(area)


def enclosure_indirect(flux: float, area: float, rho: float) -> float:
    """Area-mean indirect (inter-reflected) illuminance in a closed room of uniform reflectance ρ:
    ``Φ ρ / (A (1 − ρ))`` (lx)."""
    rho = float(rho)
    if not 0.0 <= rho < 1.0:
        raise LuxError(f"the reflectance must be in [0, 1), got {rho}")
    return float(flux) * rho / (float(area) * (1.0 - rho))


def truncated_indirect(flux: float, area: float, rho: float, bounces: int) -> float:
    """The part of :func:`enclosure_indirect` carried by the first ``bounces`` reflections:
    ``Φ/A · Σ_{k=1..bounces} ρ^k``."""
    return float(flux) / float(area) * sum(float(rho) ** k for k in range(1, int(bounces) + 1))


# --------------------------------------------------------------------------- scenes


def _flat_reflectance(rho):
    return uplift.reflectance_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX], [rho, rho], C.N_COEFFS_DEFAULT)


def _flat_emission():
    return uplift.emission_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX], [1.0, 1.0], C.N_COEFFS_DEFAULT)


def _materials(rho, spectra):
    if rho <= 0.0:
        return [Material("black")]
    r = spectra.add("grey", _flat_reflectance(rho), C.SPECTRUM_BOUNDED)
    return [Material(f"grey {rho:g}", reflectance=r)]


def _look_at(eye, target):
    eye = np.asarray(eye, float)
    f = np.asarray(target, float) - eye
    f /= np.linalg.norm(f)
    up = np.array([0.0, 0.0, 1.0]) if abs(f[2]) < 0.99 else np.array([0.0, 1.0, 0.0])
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = r, np.cross(r, f), -f, eye
    return m


def _plane(name, half, z=0.0):
    s = float(half)
    return Mesh(name, np.array([[-s, -s, z], [s, -s, z], [s, s, z], [-s, s, z]], np.float32),
                np.array([[0, 1, 2], [0, 2, 3]], np.int32), np.zeros(2, np.int32))


def room_mesh(name, size, material=0):
    """A closed box [0, W] × [0, D] × [0, H] as 12 triangles whose normals point inwards."""
    W, D, H = (float(s) for s in size)
    c = np.array([[0, 0, 0], [W, 0, 0], [W, D, 0], [0, D, 0], [0, 0, H], [W, 0, H], [W, D, H], [0, D, H]])
    quads = [(0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1), (2, 6, 7, 3), (1, 5, 6, 2), (0, 3, 7, 4)]
    tris = []
    for a, b, cc, d in quads:
        tris += [(a, b, cc), (a, cc, d)]
    return Mesh(name, c.astype(np.float32), np.array(tris, np.int32), np.full(12, material, np.int32))


def room_faces(size):
    """The six inner faces of a box room as (name, origin, edge_u, edge_v, inward normal)."""
    W, D, H = (float(s) for s in size)
    return [
        ("floor", (0, 0, 0), (W, 0, 0), (0, D, 0), (0, 0, 1)),
        ("ceiling", (0, 0, H), (W, 0, 0), (0, D, 0), (0, 0, -1)),
        ("wall y=0", (0, 0, 0), (W, 0, 0), (0, 0, H), (0, 1, 0)),
        ("wall y=D", (0, D, 0), (W, 0, 0), (0, 0, H), (0, -1, 0)),
        ("wall x=0", (0, 0, 0), (0, D, 0), (0, 0, H), (1, 0, 0)),
        ("wall x=W", (W, 0, 0), (0, D, 0), (0, 0, H), (-1, 0, 0)),
    ]


def room_points(size, per_side=8):
    """Cell-centre points on the six inner faces (``per_side`` × ``per_side`` each), inward normals,
    cell areas as weights: ``(points, normals, weights, face_index)``."""
    pts, nrm, w, idx = [], [], [], []
    for k, (name, o, eu, ev, n) in enumerate(room_faces(size)):
        s = rectangle_grid(o, eu, ev, name=name, normal=n,
                           spacing=(np.linalg.norm(eu) / per_side, np.linalg.norm(ev) / per_side))
        pts.append(s.points)
        nrm.append(s.normals)
        w.append(s.weights)
        idx.append(np.full(s.n_points, k))
    return np.concatenate(pts), np.concatenate(nrm), np.concatenate(w), np.concatenate(idx)


def _face_corners(o, eu, ev):
    o, eu, ev = (np.asarray(x, float) for x in (o, eu, ev))
    return np.array([o, o + eu, o + eu + ev, o + ev])


@dataclass
class ReferenceCase:
    """One analytic case: a scene, the points (N, 3) and normals where illuminance is wanted, the
    expected values, and notes on where the numbers come from.

    ``expected_direct``: per-point direct illuminance (lx); ``expected_total``: per-point total
    (direct + inter-reflected), given where it has a closed form; ``expected_mean_indirect``: the
    area-mean inter-reflected illuminance over the whole room (lx); ``expected_flux``: the flux
    (lm) that the weighted sum ``Σ wᵢ Eᵢ`` must give."""

    name: str
    title: str
    scene: Scene
    points: np.ndarray
    normals: np.ndarray
    weights: np.ndarray
    expected_direct: np.ndarray | None = None
    expected_total: np.ndarray | None = None
    expected_mean_indirect: float | None = None
    expected_flux: float | None = None
    tolerance: float = CIE171_TOLERANCE
    notes: str = ""
    extra: dict = field(default_factory=dict)


def case_5_2(intensity=1000.0, height=3.0, half_width=4.0, n=9) -> ReferenceCase:
    """5.2 point source: an isotropic point of ``intensity`` cd ``height`` m above a black floor;
    points on the floor along a line from below the source to ``half_width`` m (``n`` points),
    and the same points on a vertical plane facing the source."""
    spectra = SpectrumTable.empty()
    e = spectra.add("flat", _flat_emission(), C.SPECTRUM_UNBOUNDED)
    src = np.array([0.0, 0.0, float(height)])
    light = Light("point", C.LIGHT_POINT, tuple(src), (0, 0, 0), (0, 0, 0), e, 0.0, intensity=float(intensity))
    x = np.linspace(0.0, float(half_width), n)
    floor_p = np.stack([x, np.zeros(n), np.zeros(n)], axis=1)
    floor_n = np.tile([0.0, 0.0, 1.0], (n, 1))
    wall_p = np.stack([np.full(n, float(half_width)), np.zeros(n), np.linspace(0.0, float(height), n)], axis=1)
    wall_n = np.tile([-1.0, 0.0, 0.0], (n, 1))
    p, nn = np.concatenate([floor_p, wall_p]), np.concatenate([floor_n, wall_n])
    scene = Scene(meshes=[_plane("floor", 4 * half_width)], spectra=spectra, materials=_materials(0.0, spectra),
                  lights=[light], camera=Camera(_look_at((0, -2 * half_width, height), (0, 0, 0))))
    ed = point_source_illuminance(intensity, src, p, nn)
    return ReferenceCase("5.2", "point source: E = I cos θ / d²", scene, p, nn, np.ones(len(p)),
                         expected_direct=ed, expected_total=ed.copy(),
                         notes="geometry chosen here; values from the closed form")


def case_5_3(luminance=1000.0, size=(1.0, 2.0), height=2.0, n=7) -> ReferenceCase:
    """5.3 area source: a uniform Lambertian rectangle of ``luminance`` cd/m² and ``size`` (a along X,
    b along Y) facing down at ``height`` m above a black floor (a parallel plane), corner at the
    origin; points on the floor along X from the corner's foot outward, and points on a vertical
    plane x = -1 m (perpendicular to the source) facing +X."""
    a, b = (float(s) for s in size)
    c = float(height)
    spectra = SpectrumTable.empty()
    e = spectra.add("flat", _flat_emission(), C.SPECTRUM_UNBOUNDED)
    centre = (a / 2, b / 2, c)
    light = Light("panel", C.LIGHT_RECT, centre, (0.0, b / 2, 0.0), (a / 2, 0.0, 0.0), e, float(luminance))
    corners = np.array([[0, 0, c], [a, 0, c], [a, b, c], [0, b, c]], float)
    x = np.linspace(-1.0, a + 1.0, n)
    floor_p = np.stack([x, np.full(n, b / 2), np.zeros(n)], axis=1)
    floor_n = np.tile([0.0, 0.0, 1.0], (n, 1))
    zz = np.linspace(0.0, c - 0.25, n)
    wall_p = np.stack([np.full(n, -1.0), np.full(n, b / 2), zz], axis=1)
    wall_n = np.tile([1.0, 0.0, 0.0], (n, 1))
    p, nn = np.concatenate([floor_p, wall_p]), np.concatenate([floor_n, wall_n])
    scene = Scene(meshes=[_plane("floor", 10.0)], spectra=spectra, materials=_materials(0.0, spectra),
                  lights=[light], camera=Camera(_look_at((a / 2, -3.0, c), (a / 2, b / 2, 0))))
    ed = area_source_illuminance(luminance, p, nn, corners)
    corner = math.pi * luminance * parallel_corner_factor(a, b, c)
    return ReferenceCase("5.3", "area source: E = π L F", scene, p, nn, np.ones(len(p)),
                         expected_direct=ed, expected_total=ed.copy(),
                         notes="geometry chosen here; values from the configuration factors",
                         extra={"corner_point": (0.0, 0.0, 0.0), "corner_lux": corner})


def case_5_4(flux=10000.0, size=(4.0, 5.0, 3.0), source=(1.0, 2.0, 2.5), per_side=8) -> ReferenceCase:
    """5.4 flux conservation: an isotropic source of ``flux`` lm in a black box room; points on the
    six inner faces. The faces receive ``I Ω`` each, Φ in all."""
    spectra = SpectrumTable.empty()
    e = spectra.add("flat", _flat_emission(), C.SPECTRUM_UNBOUNDED)
    I = float(flux) / (4 * math.pi)
    light = Light("point", C.LIGHT_POINT, tuple(float(s) for s in source), (0, 0, 0), (0, 0, 0), e, 0.0, intensity=I)
    p, nn, w, face = room_points(size, per_side)
    scene = Scene(meshes=[room_mesh("room", size)], spectra=spectra, materials=_materials(0.0, spectra),
                  lights=[light], camera=Camera(_look_at((0.2, 0.2, 1.5), (size[0], size[1], 1.0))))
    ed = point_source_illuminance(I, source, p, nn)
    face_flux = [I * polygon_solid_angle(source, _face_corners(o, eu, ev)) for _, o, eu, ev, _ in room_faces(size)]
    return ReferenceCase("5.4", "flux conservation: Σ w E = Φ", scene, p, nn, w, expected_direct=ed,
                         expected_total=ed.copy(), expected_flux=float(flux),
                         notes="geometry chosen here; the faces' fluxes from their solid angles",
                         extra={"face_flux": face_flux, "face_index": face})


def _quad(name, corners, material):
    """A quadrilateral (4, 3), counter-clockwise seen from the side its normal points to."""
    return Mesh(name, np.asarray(corners, np.float32), np.array([[0, 1, 2], [0, 2, 3]], np.int32),
                np.full(2, material, np.int32))


CASE_5_7_POINTS = {  # the publication's points, on the centre line x = 2 m of S₁-v (A–F) and S₁-hz (G–K)
    "A": (2.0, 0.0, 2.75), "B": (2.0, 0.0, 2.25), "C": (2.0, 0.0, 1.75), "D": (2.0, 0.0, 1.25),
    "E": (2.0, 0.0, 0.75), "F": (2.0, 0.0, 0.25),
    "G": (2.0, 0.25, 0.0), "H": (2.0, 0.75, 0.0), "I": (2.0, 1.25, 0.0), "J": (2.0, 1.75, 0.0), "K": (2.0, 2.25, 0.0),
}


def case_5_7(rho=0.6, wall_illuminance=1000.0, sun_elevation=45.0) -> ReferenceCase:
    """5.7 diffuse reflection with an internal obstruction: S₂ (x ∈ [0, 4], y = 4, z ∈ [0, 3] m,
    reflectance ``rho``, facing −Y) lit by a sun of ``sun_elevation`` degrees shining along +Y so
    that S₂ receives ``wall_illuminance`` lx; a black box x ∈ [0, 4], y ∈ [2.5, 2.7], z ∈ [0, 1]
    between S₂ and the black measurement wall S₁-v (y = 0, facing +Y) and floor S₁-hz
    (y ∈ [0, 2.5], z = 0). At elevations below atan(3 / 2.25) ≈ 53° S₁-v shades every floor
    point from the sun and nothing shades S₂, so every point receives only light reflected by
    S₂: ``E = ρ E_v F`` (:func:`obstructed_wall_factor`). ``extra["factor_percent"]`` holds
    E / (ρ E_v) in percent, the form of the publication's Table 19."""
    e = math.radians(float(sun_elevation))
    if not 0.0 < e < math.atan2(3.0, 2.25):
        raise LuxError(f"the sun's elevation must be in (0°, 53.1°) so that only S₂ is lit, got {sun_elevation}")
    spectra = SpectrumTable.empty()
    flat = spectra.add("flat", _flat_emission(), C.SPECTRUM_UNBOUNDED)
    grey = spectra.add("grey", _flat_reflectance(rho), C.SPECTRUM_BOUNDED)
    materials = [Material("black"), Material(f"grey {rho:g}", reflectance=grey)]
    direction = (0.0, math.cos(e), -math.sin(e))
    sun = Light("sun", C.LIGHT_SUN, (0.0, 0.0, 0.0), (0, 0, 0), (0, 0, 0), flat, 0.0, direction=direction,
                illuminance=float(wall_illuminance) / math.cos(e))
    y0, y1, h = 2.5, 2.7, 1.0
    meshes = [
        _quad("S2", [(0, 4, 0), (4, 4, 0), (4, 4, 3), (0, 4, 3)], 1),
        _quad("S1-v", [(4, 0, 0), (0, 0, 0), (0, 0, 3), (4, 0, 3)], 0),
        _quad("S1-hz", [(0, 0, 0), (4, 0, 0), (4, 2.5, 0), (0, 2.5, 0)], 0),
        _quad("obstruction front", [(0, y0, 0), (4, y0, 0), (4, y0, h), (0, y0, h)], 0),
        _quad("obstruction back", [(4, y1, 0), (0, y1, 0), (0, y1, h), (4, y1, h)], 0),
        _quad("obstruction top", [(0, y0, h), (4, y0, h), (4, y1, h), (0, y1, h)], 0),
        _quad("obstruction end x=0", [(0, y1, 0), (0, y0, 0), (0, y0, h), (0, y1, h)], 0),
        _quad("obstruction end x=4", [(4, y0, 0), (4, y1, 0), (4, y1, h), (4, y0, h)], 0),
    ]
    names = list(CASE_5_7_POINTS)
    p = np.array([CASE_5_7_POINTS[k] for k in names], float)
    nn = np.array([(0.0, 1.0, 0.0) if k in "ABCDEF" else (0.0, 0.0, 1.0) for k in names])
    F = np.array([obstructed_wall_factor(pt, n, (0, 4), 4.0, (0, 3), (y0, y1), h) for pt, n in zip(p, nn)])
    ed = float(rho) * float(wall_illuminance) * F
    scene = Scene(meshes=meshes, spectra=spectra, materials=materials, lights=[sun],
                  camera=Camera(_look_at((2.0, -1.0, 2.0), (2.0, 4.0, 1.0))))
    return ReferenceCase("5.7", "diffuse reflection with an internal obstruction: E = ρ E_v F", scene, p, nn,
                         np.ones(len(p)), expected_direct=np.zeros(len(p)), expected_total=ed,
                         notes="the publication's geometry (as validation reports describe it), the sun chosen "
                               "here; values from the configuration factors, not from Table 19",
                         extra={"rho": float(rho), "wall_illuminance": float(wall_illuminance),
                                "sun_elevation": float(sun_elevation), "labels": names,
                                "factor_percent": dict(zip(names, 100.0 * F))})


def cube_indirect_8x8(rho, points, size, flux=10000.0):
    """Per-point inter-reflected illuminance (lx) from :data:`CUBE_INDIRECT_8X8` at the cell
    centres of an 8 × 8 grid on each face of a cube room of ``size`` (side, side, side)."""
    side = float(size[0])
    values = CUBE_INDIRECT_8X8[float(rho)]
    lookup = dict(zip(CUBE_INDIRECT_CELLS, values))
    p = np.asarray(points, float)
    out = np.full(len(p), np.nan)
    for _, o, eu, ev, _ in room_faces(size):
        o, eu, ev = (np.asarray(x, float) for x in (o, eu, ev))
        n = np.cross(eu, ev) / side**2
        on = np.abs((p - o) @ n) < 1e-9 * side
        i = np.rint((p[on] - o) @ eu / side**2 * 8 - 0.5).astype(int)
        j = np.rint((p[on] - o) @ ev / side**2 * 8 - 0.5).astype(int)
        a, b = np.minimum(i, 7 - i), np.minimum(j, 7 - j)
        out[on] = [lookup[(min(x, y), max(x, y))] for x, y in zip(a, b)]
    if np.isnan(out).any():
        raise LuxError("a point is not at a cell centre of the cube's 8 × 8 face grids")
    return out * float(flux) / 10000.0 * (4.0 / side) ** 2


def _cube_case(name, title, rho, flux, side, per_side, notes):
    spectra = SpectrumTable.empty()
    e = spectra.add("flat", _flat_emission(), C.SPECTRUM_UNBOUNDED)
    size = (side, side, side)
    src = (side / 2, side / 2, side / 2)
    I = float(flux) / (4 * math.pi)
    light = Light("point", C.LIGHT_POINT, src, (0, 0, 0), (0, 0, 0), e, 0.0, intensity=I)
    p, nn, w, face = room_points(size, per_side)
    cam = Camera(_look_at((0.1 * side, 0.1 * side, 0.5 * side), (side, side, 0.4 * side)))
    scene = Scene(meshes=[room_mesh("cube", size)], spectra=spectra, materials=_materials(rho, spectra),
                  lights=[light], camera=cam)
    area = 6.0 * side * side
    ed = point_source_illuminance(I, src, p, nn)
    if rho == 0:
        total = ed.copy()
    elif per_side == 8 and float(rho) in CUBE_INDIRECT_8X8:
        total = ed + cube_indirect_8x8(rho, p, size, flux)
    else:
        total = None
    return ReferenceCase(name, title, scene, p, nn, w, expected_direct=ed, expected_total=total,
                         expected_mean_indirect=enclosure_indirect(flux, area, rho), expected_flux=float(flux),
                         notes=notes, extra={"rho": float(rho), "area": area, "face_index": face,
                                             "mean_direct": enclosure_direct(flux, area)})


def case_5_6(rho=0.5, flux=10000.0, side=4.0, per_side=8) -> ReferenceCase:
    """5.6 diffuse inter-reflection: an isotropic source at the centre of a closed cube whose faces
    all reflect ``rho``; direct illuminance per point and the area-mean indirect Φρ/(A(1−ρ))."""
    return _cube_case("5.6", "diffuse inter-reflection in a closed cube", rho, flux, side, per_side,
                      "geometry chosen here; values from the closed forms")


def case_5_8(rho, flux=10000.0, side=4.0, per_side=8) -> ReferenceCase:
    """5.8 internal reflected component: a 4 m cube, 10 000 lm at its centre, reflectance ``rho``
    (the publication runs ρ from 0 to 0.95); mean indirect Φρ/(A(1−ρ)), 1979 lx at ρ = 0.95."""
    return _cube_case(f"5.8 rho={rho:g}", f"internal reflected component, ρ = {rho:g}", rho, flux, side,
                      per_side, "the publication's room and flux; values from the closed forms")


def reference_cases() -> list[ReferenceCase]:
    """Every case: 5.2, 5.3, 5.4, 5.6, 5.7 and 5.8 at each of its reflectances."""
    return [case_5_2(), case_5_3(), case_5_4(), case_5_6(), case_5_7()] + [case_5_8(r) for r in CASE_5_8_REFLECTANCES]
