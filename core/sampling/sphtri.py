"""Uniform directions inside a spherical triangle (compendium item 22).

Sampling follows Arvo, "Stratified sampling of spherical triangles", SIGGRAPH 1995: u1
picks the sub-triangle A B Ĉ whose area is u1·Ω (Ĉ on the arc AC, found in closed form
from the spherical law of cosines), u2 picks the point on the arc B Ĉ so that the
density is uniform. The solid angle is the Van Oosterom–Strackee formula (IEEE Trans.
Biomed. Eng. 1983):

    tan(Ω/2) = |A · (B × C)| / (1 + A·B + B·C + C·A)   for unit A, B, C,

and the vertex angles come from atan2 of the same triple product, so nothing
subtracts nearly equal numbers for small triangles. pdf = 1/Ω inside, 0 outside.

Vertices need not be unit length (pass them relative to the shading point); a
degenerate triangle (zero solid angle, or a vertex at the origin) gives pdf 0.
"""
import math

from ..jit import inline
from .frame import cross, normalize

# Below this solid angle (sr) triangles are sampled through the flat triangle (see
# sample_spherical_triangle); the density then differs from 1/Ω by a relative O(Ω).
SMALL_SOLID_ANGLE = 1e-6


@inline
def _triple(ax, ay, az, bx, by, bz, cx, cy, cz):
    return ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx)


@inline
def _det_unit(ax, ay, az, bx, by, bz, cx, cy, cz):
    """A·(B×C) computed as A·((B-A)×(C-A)): the same number, without cancellation for a
    small triangle."""
    return _triple(ax, ay, az, bx - ax, by - ay, bz - az, cx - ax, cy - ay, cz - az)


@inline
def _solid_angle_unit(ax, ay, az, bx, by, bz, cx, cy, cz):
    det = abs(_det_unit(ax, ay, az, bx, by, bz, cx, cy, cz))
    den = 1.0 + (ax * bx + ay * by + az * bz) + (bx * cx + by * cy + bz * cz) + (cx * ax + cy * ay + cz * az)
    if det == 0.0:
        return 0.0
    return 2.0 * math.atan2(det, den)


@inline
def spherical_triangle_solid_angle(ax, ay, az, bx, by, bz, cx, cy, cz):
    """Solid angle (sr) subtended at the origin by the triangle A B C (Van Oosterom–Strackee)."""
    ax, ay, az, la = normalize(ax, ay, az)
    bx, by, bz, lb = normalize(bx, by, bz)
    cx, cy, cz, lc = normalize(cx, cy, cz)
    if la == 0.0 or lb == 0.0 or lc == 0.0:
        return 0.0
    return _solid_angle_unit(ax, ay, az, bx, by, bz, cx, cy, cz)


@inline
def _half_chord2(ax, ay, az, bx, by, bz):
    """1 - A·B for unit vectors, as |A - B|²/2 (exact for nearby points)."""
    dx = ax - bx
    dy = ay - by
    dz = az - bz
    return 0.5 * (dx * dx + dy * dy + dz * dz)


@inline
def _towards(px, py, pz, qx, qy, qz):
    """Unit tangent at unit p along the great circle towards q (normalised q - (q·p) p)."""
    d = px * qx + py * qy + pz * qz
    return normalize(qx - d * px, qy - d * py, qz - d * pz)


@inline
def _edge_normal(ax, ay, az, bx, by, bz, cx, cy, cz):
    """(B-A)×(C-A): normal of the plane through the three (unit) vertices."""
    return cross(bx - ax, by - ay, bz - az, cx - ax, cy - ay, cz - az)


@inline
def _sample_flat(ax, ay, az, bx, by, bz, cx, cy, cz, det, u1, u2):
    """Small-triangle branch: a uniform point on the flat triangle through the unit
    vertices (the square-root map of warps.sample_triangle_area), projected to the sphere.
    Its exact solid-angle density is p_A r²/cos = 2 r³ / |det| (item 8: the plane lies at
    distance h = |det| / (2 area) from the origin and cos = h / r)."""
    sq = math.sqrt(u1)
    b1 = u2 * sq
    b2 = sq - b1
    x, y, z, r = normalize(ax + b1 * (bx - ax) + b2 * (cx - ax), ay + b1 * (by - ay) + b2 * (cy - ay),
                           az + b1 * (bz - az) + b2 * (cz - az))
    return x, y, z, 2.0 * r * r * r / det


@inline
def sample_spherical_triangle(ax, ay, az, bx, by, bz, cx, cy, cz, u1, u2):
    """Uniform direction in the spherical triangle A B C: returns (x, y, z, pdf = 1/Ω).

    Below SMALL_SOLID_ANGLE the triangle is sampled through its flat counterpart
    (``_sample_flat``), whose density equals 1/Ω to a relative O(Ω) and is returned
    exactly, because Arvo's construction loses its accuracy to cancellation there.
    """
    ax, ay, az, la = normalize(ax, ay, az)
    bx, by, bz, lb = normalize(bx, by, bz)
    cx, cy, cz, lc = normalize(cx, cy, cz)
    if la == 0.0 or lb == 0.0 or lc == 0.0:
        return 0.0, 0.0, 1.0, 0.0
    det = abs(_det_unit(ax, ay, az, bx, by, bz, cx, cy, cz))
    area = _solid_angle_unit(ax, ay, az, bx, by, bz, cx, cy, cz)
    if not (area > 0.0) or det == 0.0:
        return 0.0, 0.0, 1.0, 0.0
    if area < SMALL_SOLID_ANGLE:
        return _sample_flat(ax, ay, az, bx, by, bz, cx, cy, cz, det, u1, u2)
    ab = ax * bx + ay * by + az * bz
    # angle at A between the arcs AB and AC: tan α = |det| / ((A×B)·(A×C)); the cross
    # products of nearby unit vectors are exact enough, B·C - (A·B)(A·C) would cancel
    n1x, n1y, n1z = cross(ax, ay, az, bx - ax, by - ay, bz - az)
    n2x, n2y, n2z = cross(ax, ay, az, cx - ax, cy - ay, cz - az)
    alpha = math.atan2(det, n1x * n2x + n1y * n2y + n1z * n2z)
    sa = math.sin(alpha)
    cosa = math.cos(alpha)
    # Arvo's construction of Ĉ: the sub-triangle A B Ĉ has area u1·Ω
    area_hat = u1 * area
    s = math.sin(area_hat - alpha)
    t = math.cos(area_hat - alpha)
    uu = t - cosa
    vv = s + sa * ab  # ab = cos of the arc c = AB
    den = (vv * s + uu * t) * sa
    if den == 0.0:
        q = 1.0
    else:
        q = ((vv * t - uu * s) * cosa - vv) / den
    q = min(max(q, -1.0), 1.0)
    tx, ty, tz, tl = _towards(ax, ay, az, cx, cy, cz)
    if tl == 0.0:
        return 0.0, 0.0, 1.0, 0.0
    sq = math.sqrt(max(1.0 - q * q, 0.0))
    chx, chy, chz, _ = normalize(q * ax + sq * tx, q * ay + sq * ty, q * az + sq * tz)
    # along the arc B Ĉ: 1 - cos(θ) uniform in [0, 1 - B·Ĉ]
    h = u2 * _half_chord2(bx, by, bz, chx, chy, chz)  # 1 - z
    z = 1.0 - h
    r = math.sqrt(max(h * (2.0 - h), 0.0))
    ex, ey, ez, el = _towards(bx, by, bz, chx, chy, chz)
    if el == 0.0:  # u2 = 0 or Ĉ = B
        ex = ey = ez = 0.0
    x, y, w, _ = normalize(z * bx + r * ex, z * by + r * ey, z * bz + r * ez)
    pdf = 1.0 / area
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(w)) or pdf == math.inf:
        return 0.0, 0.0, 1.0, 0.0
    return x, y, w, pdf


@inline
def _edge_side(px, py, pz, qx, qy, qz, s, x, y, z):
    """s · sin of the angular distance of the unit direction from the great circle through
    the unit vertices p, q (positive on the triangle's side)."""
    nx, ny, nz = cross(px, py, pz, qx - px, qy - py, qz - pz)  # = p × q, accurately
    n = math.sqrt(nx * nx + ny * ny + nz * nz)
    if n == 0.0:
        return -1.0
    return s * (nx * x + ny * y + nz * z) / n


@inline
def _inside_unit(det, ax, ay, az, bx, by, bz, cx, cy, cz, x, y, z):
    """Inside test for unit vertices (det = A·(B×C) ≠ 0) and a unit direction: on the inner
    side of the three edge planes, with an angular tolerance of 1e-12 rad."""
    s = 1.0 if det > 0.0 else -1.0
    e0 = _edge_side(ax, ay, az, bx, by, bz, s, x, y, z)
    e1 = _edge_side(bx, by, bz, cx, cy, cz, s, x, y, z)
    e2 = _edge_side(cx, cy, cz, ax, ay, az, s, x, y, z)
    return min(e0, min(e1, e2)) >= -1e-12


@inline
def spherical_triangle_contains(ax, ay, az, bx, by, bz, cx, cy, cz, x, y, z):
    """True if the direction (x, y, z) is inside the cone of the triangle (edges included,
    with an angular tolerance of 1e-12 rad)."""
    ax, ay, az, la = normalize(ax, ay, az)
    bx, by, bz, lb = normalize(bx, by, bz)
    cx, cy, cz, lc = normalize(cx, cy, cz)
    x, y, z, lp = normalize(x, y, z)
    det = _det_unit(ax, ay, az, bx, by, bz, cx, cy, cz)
    if det == 0.0 or la * lb * lc * lp == 0.0:
        return False
    return _inside_unit(det, ax, ay, az, bx, by, bz, cx, cy, cz, x, y, z)


@inline
def spherical_triangle_pdf(ax, ay, az, bx, by, bz, cx, cy, cz, x, y, z):
    """1/Ω inside the triangle, 0 outside or for a degenerate triangle (for Ω below
    SMALL_SOLID_ANGLE the exact density of the flat-triangle branch, 2 det² / |n·w|³)."""
    ax, ay, az, la = normalize(ax, ay, az)
    bx, by, bz, lb = normalize(bx, by, bz)
    cx, cy, cz, lc = normalize(cx, cy, cz)
    x, y, z, lp = normalize(x, y, z)
    det = _det_unit(ax, ay, az, bx, by, bz, cx, cy, cz)
    if det == 0.0 or la * lb * lc * lp == 0.0:
        return 0.0
    area = _solid_angle_unit(ax, ay, az, bx, by, bz, cx, cy, cz)
    if not (area > 0.0) or not _inside_unit(det, ax, ay, az, bx, by, bz, cx, cy, cz, x, y, z):
        return 0.0
    if area < SMALL_SOLID_ANGLE:
        nx, ny, nz = _edge_normal(ax, ay, az, bx, by, bz, cx, cy, cz)
        nw = abs(nx * x + ny * y + nz * z)
        if nw == 0.0:
            return 0.0
        return 2.0 * det * det / (nw * nw * nw)
    return 1.0 / area


@inline
def invert_spherical_triangle(ax, ay, az, bx, by, bz, cx, cy, cz, x, y, z):
    """(u1, u2) with sample_spherical_triangle(..., u1, u2) = (x, y, z) for an inside direction.

    Ĉ is where the great circle through B and the direction meets the arc AC; u1 is
    the area of A B Ĉ over Ω and u2 = (1 - B·P) / (1 - B·Ĉ).
    """
    ax, ay, az, la = normalize(ax, ay, az)
    bx, by, bz, lb = normalize(bx, by, bz)
    cx, cy, cz, lc = normalize(cx, cy, cz)
    px, py, pz, lp = normalize(x, y, z)
    if la == 0.0 or lb == 0.0 or lc == 0.0 or lp == 0.0:
        return 0.0, 0.0
    area = _solid_angle_unit(ax, ay, az, bx, by, bz, cx, cy, cz)
    if not (area > 0.0):
        return 0.0, 0.0
    if area < SMALL_SOLID_ANGLE:
        # barycentrics of the ray's hit on the flat triangle, then the square-root map's inverse
        nx, ny, nz = _edge_normal(ax, ay, az, bx, by, bz, cx, cy, cz)
        nn = nx * nx + ny * ny + nz * nz
        nw = nx * px + ny * py + nz * pz
        if nw == 0.0 or nn == 0.0:
            return 0.0, 0.0
        t = (nx * ax + ny * ay + nz * az) / nw
        dx = t * px - ax
        dy = t * py - ay
        dz = t * pz - az
        e1x, e1y, e1z = bx - ax, by - ay, bz - az
        e2x, e2y, e2z = cx - ax, cy - ay, cz - az
        c1x, c1y, c1z = cross(dx, dy, dz, e2x, e2y, e2z)
        c2x, c2y, c2z = cross(e1x, e1y, e1z, dx, dy, dz)
        b1 = (c1x * nx + c1y * ny + c1z * nz) / nn
        b2 = (c2x * nx + c2y * ny + c2z * nz) / nn
        sq = b1 + b2
        if not (sq > 0.0):
            return 0.0, 0.0
        return min(sq * sq, 1.0), min(max(b1 / sq, 0.0), 1.0)
    # plane through B and P, plane through A and C: their intersection line holds Ĉ
    n1x = by * pz - bz * py
    n1y = bz * px - bx * pz
    n1z = bx * py - by * px
    n2x = ay * cz - az * cy
    n2y = az * cx - ax * cz
    n2z = ax * cy - ay * cx
    chx = n1y * n2z - n1z * n2y
    chy = n1z * n2x - n1x * n2z
    chz = n1x * n2y - n1y * n2x
    chx, chy, chz, lch = normalize(chx, chy, chz)
    if lch == 0.0:  # P = B: any Ĉ, u2 = 0
        return 0.0, 0.0
    # choose the intersection on the arc AC (the side of the bisector of A and C)
    if chx * (ax + cx) + chy * (ay + cy) + chz * (az + cz) < 0.0:
        chx = -chx
        chy = -chy
        chz = -chz
    sub = _solid_angle_unit(ax, ay, az, bx, by, bz, chx, chy, chz)
    u1 = min(max(sub / area, 0.0), 1.0)
    hc = _half_chord2(bx, by, bz, chx, chy, chz)
    if hc == 0.0:
        return u1, 0.0
    u2 = min(max(_half_chord2(bx, by, bz, px, py, pz) / hc, 0.0), 1.0)
    return u1, u2
