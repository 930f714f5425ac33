"""Analytic lights for the path kernel: sampling (next-event estimation) and ray hits.

Each light is one row of ``light_geo`` (float64, L × LG_SIZE, layout below) and a kind
tag (constants.LIGHT_*). The renderer scales each light's spectrum shape so that
``light_scale · shape`` is, per kind:

* rect / ellipse: the radiance (cd/m² photometrically);
* point / spot of radius r > 0: the radiance of the sphere, L = I / (π r²), so that its
  intensity I (cd) is that of the point light it replaces: a uniformly radiant sphere
  seen from any direction shows a disc of area π r²;
* point / spot of radius 0: the intensity I (cd); a delta light, reached only by NEE;
* sun of angular diameter 2α > 0: the radiance of its disc, L = E / (π sin²α), so that
  a surface facing it receives E (lux): ∫_cone L cos θ dω = L π sin²α;
* sun of angle 0: the illuminance E (lux) from one direction (delta).

Spot cone (Blender's spot_size = full angle and spot_blend; Cycles, intern/cycles
scene/light.cpp and kernel/light/spot.h): with t = cos of the angle between the spot's
axis and the direction from the light's centre to the lit point, the mask is 0 for
t ≤ cos(spot_size/2) and smoothstep(0, 1, (t − cos½)/((1 − cos½)·blend)) above, 1 once
the argument exceeds 1 (blend 0: a hard edge). We use the direction from the light's
centre for both strategies (NEE and BSDF hits), so the mask depends on the lit point
only and both estimators see the same emitter.

Photometric profiles (IES / EULUMDAT, core/io/photometric.py): a point or spot light whose
``light_geo`` column LG_PROF is ≥ 0 multiplies its emission by the relative intensity
I(θ, C)/I_peak read from ``prof`` at that offset, θ from the nadir LG_N (the light's local
−Z) and C = atan2(q·U, q·V) + π with U, V the light's local +X and +Y (LG_U, LG_V): C = 0
towards local −Y, 90° towards −X, as Cycles' IES texture reads a light's direction. As the
spot mask, it depends on the direction q from the light's centre to the lit point only,
so NEE and BSDF hits of a sphere see the same factor. Table layout at offset o:
[nθ, nC, θ_0..θ_{nθ−1} (rad, ascending), C_0..C_{nC−1} (rad, 0 .. 2π), values (nC × nθ,
row per C, peak 1)], bilinear in (θ, C); 0 outside [θ_0, θ_{nθ−1}].

Sphere lights are sampled uniformly in the cone they subtend (solid-angle pdf
1/(2π(1 − cos α)), sin α = r/d), the sun uniformly in its cone. Lights are never
occluders: rays pick up their emission and go on (as in Cycles).

Every function here is a separately compiled ``function``: inlined into the path
kernel at each call site they would multiply its compile time.
"""
import math

import numpy as np

from .. import constants as C
from ..jit import function, inline
from ..sampling.sphtri import sample_spherical_triangle, spherical_triangle_solid_angle
from ..sampling.warps import cone_one_minus_cos, sample_uniform_cone

# light_geo row layout
LG_POS = 0  # 3: centre
LG_U = 3  # 3: half-axis u (rect/ellipse); a profiled point/spot's local +X
LG_V = 6  # 3: half-axis v (rect/ellipse); a profiled point/spot's local +Y
LG_N = 9  # 3: unit normal (rect/ellipse); spot axis, a profiled point's nadir; direction *towards* the sun
LG_AREA = 12  # rect/ellipse area, m²
LG_RADIUS = 13  # point/spot sphere radius, m
LG_COS_HALF = 14  # spot: cos(spot_size / 2)
LG_SMOOTH = 15  # spot: 1 / ((1 − cos½) blend), 0 for a hard edge
LG_SUN_K = 16  # sun: 1 − cos α (α = half the angular diameter), 0 for a delta sun
LG_PROF = 17  # point/spot: offset of its photometric profile in ``prof``, −1 for none
LG_SIZE = 18

TWO_PI = 2.0 * math.pi


@inline
def _frame(nx, ny, nz):
    """Orthonormal tangents (t, b) of the unit vector n (Duff et al. 2017)."""
    sgn = 1.0 if nz >= 0.0 else -1.0
    a = -1.0 / (sgn + nz)
    b = nx * ny * a
    return (1.0 + sgn * nx * nx * a, sgn * b, -sgn * nx, b, sgn + ny * ny * a, -ny)


@inline
def spot_mask(geo, li, qx, qy, qz):
    """Blender's spot mask for the unit direction q from the light's centre to the lit point."""
    t = geo[li, LG_N] * qx + geo[li, LG_N + 1] * qy + geo[li, LG_N + 2] * qz
    ch = geo[li, LG_COS_HALF]
    if t <= ch:
        return 0.0
    k = geo[li, LG_SMOOTH]
    if k <= 0.0:
        return 1.0
    x = (t - ch) * k
    if x >= 1.0:
        return 1.0
    return x * x * (3.0 - 2.0 * x)


@inline
def _bracket(prof, lo, n, x):
    """Index i in [0, n − 2] with prof[lo + i] ≤ x ≤ prof[lo + i + 1] (ascending nodes)."""
    a = 0
    b = n - 1
    while b - a > 1:
        m = (a + b) >> 1
        if prof[lo + m] <= x:
            a = m
        else:
            b = m
    return a


@function
def profile_factor(geo, prof, li, qx, qy, qz):
    """Relative intensity (peak 1) of light ``li``'s profile along the unit direction q from
    its centre; 1 for a light without a profile."""
    o = geo[li, LG_PROF]
    if o < 0.0:
        return 1.0
    o = int(o)
    nt = int(prof[o])
    nc = int(prof[o + 1])
    # θ from the nadir LG_N (the light's local −Z, a spot's axis)
    ct = geo[li, LG_N] * qx + geo[li, LG_N + 1] * qy + geo[li, LG_N + 2] * qz
    th = math.acos(min(max(ct, -1.0), 1.0))
    t0 = o + 2
    if th < prof[t0] or th > prof[t0 + nt - 1]:
        return 0.0
    a = geo[li, LG_U] * qx + geo[li, LG_U + 1] * qy + geo[li, LG_U + 2] * qz
    b = geo[li, LG_V] * qx + geo[li, LG_V + 1] * qy + geo[li, LG_V + 2] * qz
    c = math.atan2(a, b) + math.pi
    c0 = t0 + nt
    c = min(max(c, prof[c0]), prof[c0 + nc - 1])
    if nt > 1:
        i = _bracket(prof, t0, nt, th)
        dt = prof[t0 + i + 1] - prof[t0 + i]
        ft = (th - prof[t0 + i]) / dt if dt > 0.0 else 0.0
    else:
        i = 0
        ft = 0.0
    if nc > 1:
        j = _bracket(prof, c0, nc, c)
        dc = prof[c0 + j + 1] - prof[c0 + j]
        fc = (c - prof[c0 + j]) / dc if dc > 0.0 else 0.0
    else:
        j = 0
        fc = 0.0
    v0 = c0 + nc + j * nt + i
    i1 = 1 if nt > 1 else 0
    j1 = nt if nc > 1 else 0
    lo = prof[v0] * (1.0 - ft) + prof[v0 + i1] * ft
    hi = prof[v0 + j1] * (1.0 - ft) + prof[v0 + j1 + i1] * ft
    return lo * (1.0 - fc) + hi * fc


# A rectangle that subtends at least this solid angle (sr) at the lit point is sampled
# uniformly in solid angle, as two spherical triangles (Arvo 1995, core/sampling/sphtri.py),
# else by area. Area sampling's estimate carries cos θ_y / d² of each point: near a light
# (a wall beside an area light) it scatters widely and makes fireflies, also in the light
# the wall passes on; uniform in solid angle it carries none. Cycles samples its rectangular
# lights by solid angle too (the spherical rectangle of Ureña, Fajardo and King 2013,
# intern/cycles/kernel/light/area.h). The rule depends on the point and the light only, so
# ``hit_light`` gives a BSDF-sampled hit the same pdf.
RECT_SOLID_ANGLE_MIN = 1e-4


@inline
def _rect_corners(geo, li, px, py, pz):
    """The rectangle's corners A = c − u − v, B = c + u − v, C = c + u + v, D = c − u + v
    relative to p, as a 12-tuple."""
    cx = geo[li, 0] - px
    cy = geo[li, 1] - py
    cz = geo[li, 2] - pz
    ux, uy, uz = geo[li, 3], geo[li, 4], geo[li, 5]
    vx, vy, vz = geo[li, 6], geo[li, 7], geo[li, 8]
    return (cx - ux - vx, cy - uy - vy, cz - uz - vz, cx + ux - vx, cy + uy - vy, cz + uz - vz,
            cx + ux + vx, cy + uy + vy, cz + uz + vz, cx - ux + vx, cy - uy + vy, cz - uz + vz)


@inline
def _rect_solid_angles(q):
    """Solid angles of the triangles A B C and A C D of the corners ``q`` (_rect_corners)."""
    o1 = spherical_triangle_solid_angle(q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7], q[8])
    o2 = spherical_triangle_solid_angle(q[0], q[1], q[2], q[6], q[7], q[8], q[9], q[10], q[11])
    return o1, o2


@inline
def _rect_direction(q, o1, o2, ua, ub):
    """A direction uniform in the spherical rectangle: triangle A B C with probability
    Ω1 / (Ω1 + Ω2) (u1 rescaled to that interval), else A C D."""
    f = o1 / (o1 + o2)
    if ua < f:
        return sample_spherical_triangle(q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7], q[8], min(ua / f, 1.0), ub)
    u1 = min((ua - f) / (1.0 - f), 1.0)
    return sample_spherical_triangle(q[0], q[1], q[2], q[6], q[7], q[8], q[9], q[10], q[11], u1, ub)


@function
def sample_light(kind, geo, prof, li, two_sided, px, py, pz, ua, ub):
    """Sample a direction from (px, py, pz) towards analytic light ``li``.

    Returns (wx, wy, wz, dist, pdf, fac): unit direction, distance to the emitting point
    (inf for the sun), solid-angle pdf (inf for a delta light), and the factor that
    multiplies ``light_scale · spectrum``: facing / spot mask, and 1/d² for a delta point
    or spot. fac = 0 means no contribution.
    """
    if kind == C.LIGHT_RECT:
        q = _rect_corners(geo, li, px, py, pz)
        o1, o2 = _rect_solid_angles(q)
        if o1 + o2 >= RECT_SOLID_ANGLE_MIN:
            wx, wy, wz, tpdf = _rect_direction(q, o1, o2, ua, ub)
            nx = geo[li, LG_N]
            ny = geo[li, LG_N + 1]
            nz = geo[li, LG_N + 2]
            den = wx * nx + wy * ny + wz * nz
            if not (tpdf > 0.0) or den == 0.0:
                return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0
            dist = ((geo[li, 0] - px) * nx + (geo[li, 1] - py) * ny + (geo[li, 2] - pz) * nz) / den
            if not (dist > 0.0) or (den > 0.0 and not two_sided):
                return wx, wy, wz, max(dist, 0.0), 0.0, 0.0
            return wx, wy, wz, dist, 1.0 / (o1 + o2), 1.0
    if kind == C.LIGHT_RECT or kind == C.LIGHT_ELLIPSE:
        if kind == C.LIGHT_RECT:
            a = 2.0 * ua - 1.0
            b = 2.0 * ub - 1.0
        else:
            r = math.sqrt(ua)
            ph = TWO_PI * ub
            a = r * math.cos(ph)
            b = r * math.sin(ph)
        qx = geo[li, 0] + a * geo[li, 3] + b * geo[li, 6]
        qy = geo[li, 1] + a * geo[li, 4] + b * geo[li, 7]
        qz = geo[li, 2] + a * geo[li, 5] + b * geo[li, 8]
        wx = qx - px
        wy = qy - py
        wz = qz - pz
        d2 = wx * wx + wy * wy + wz * wz
        dist = math.sqrt(d2)
        if dist == 0.0:
            return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0
        wx /= dist
        wy /= dist
        wz /= dist
        cos_y = -(geo[li, LG_N] * wx + geo[li, LG_N + 1] * wy + geo[li, LG_N + 2] * wz)
        if cos_y < 0.0 and two_sided:
            cos_y = -cos_y
        if cos_y <= 0.0:
            return wx, wy, wz, dist, 0.0, 0.0
        return wx, wy, wz, dist, d2 / (geo[li, LG_AREA] * cos_y), 1.0
    if kind == C.LIGHT_SUN:
        nx = geo[li, LG_N]
        ny = geo[li, LG_N + 1]
        nz = geo[li, LG_N + 2]
        k = geo[li, LG_SUN_K]
        if k <= 0.0:
            return nx, ny, nz, np.inf, np.inf, 1.0
        theta = 2.0 * math.asin(min(math.sqrt(0.5 * k), 1.0))
        lx, ly, lz, pdf = sample_uniform_cone(theta, ua, ub)
        tx, ty, tz, bx, by, bz = _frame(nx, ny, nz)
        wx = lx * tx + ly * bx + lz * nx
        wy = lx * ty + ly * by + lz * ny
        wz = lx * tz + ly * bz + lz * nz
        return wx, wy, wz, np.inf, pdf, 1.0
    # point / spot
    cx = geo[li, 0] - px
    cy = geo[li, 1] - py
    cz = geo[li, 2] - pz
    d2 = cx * cx + cy * cy + cz * cz
    d = math.sqrt(d2)
    if d == 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0
    cx /= d
    cy /= d
    cz /= d
    fac = 1.0
    if kind == C.LIGHT_SPOT:
        fac = spot_mask(geo, li, -cx, -cy, -cz)
        if fac == 0.0:
            return cx, cy, cz, d, 0.0, 0.0
    if geo[li, LG_PROF] >= 0.0:
        fac *= profile_factor(geo, prof, np.int64(li), -cx, -cy, -cz)
        if fac <= 0.0:
            return cx, cy, cz, d, 0.0, 0.0
    r = geo[li, LG_RADIUS]
    if r <= 0.0:
        return cx, cy, cz, d, np.inf, fac / d2
    if d <= r:
        return cx, cy, cz, d, 0.0, 0.0  # inside the sphere: no sample
    s = r / d
    theta = math.asin(s)
    lx, ly, lz, pdf = sample_uniform_cone(theta, ua, ub)
    tx, ty, tz, bx, by, bz = _frame(cx, cy, cz)
    wx = lx * tx + ly * bx + lz * cx
    wy = lx * ty + ly * by + lz * cy
    wz = lx * tz + ly * bz + lz * cz
    # distance to the sphere along w: d cos θ − sqrt(r² − d² sin² θ)
    sin2 = lx * lx + ly * ly
    disc = r * r - d2 * sin2
    t = d * lz - math.sqrt(max(disc, 0.0))
    return wx, wy, wz, max(t, 0.0), pdf, fac


@function
def hit_light(kind, geo, prof, li, two_sided, ox, oy, oz, dx, dy, dz, tmax):
    """A ray against analytic light ``li`` (not the sun): (t, fac, pdf).

    t = inf on a miss (or for a delta light); fac multiplies ``light_scale · spectrum``
    (0 for the back of a one-sided light); pdf is the solid-angle density with which
    :func:`sample_light` would have produced this direction from the ray's origin.
    """
    if kind == C.LIGHT_RECT or kind == C.LIGHT_ELLIPSE:
        nx = geo[li, LG_N]
        ny = geo[li, LG_N + 1]
        nz = geo[li, LG_N + 2]
        den = dx * nx + dy * ny + dz * nz
        if den == 0.0:
            return np.inf, 0.0, 0.0
        t = ((geo[li, 0] - ox) * nx + (geo[li, 1] - oy) * ny + (geo[li, 2] - oz) * nz) / den
        if t <= 0.0 or t >= tmax:
            return np.inf, 0.0, 0.0
        hx = ox + t * dx - geo[li, 0]
        hy = oy + t * dy - geo[li, 1]
        hz = oz + t * dz - geo[li, 2]
        uu = geo[li, 3] * geo[li, 3] + geo[li, 4] * geo[li, 4] + geo[li, 5] * geo[li, 5]
        vv = geo[li, 6] * geo[li, 6] + geo[li, 7] * geo[li, 7] + geo[li, 8] * geo[li, 8]
        uv = geo[li, 3] * geo[li, 6] + geo[li, 4] * geo[li, 7] + geo[li, 5] * geo[li, 8]
        hu = hx * geo[li, 3] + hy * geo[li, 4] + hz * geo[li, 5]
        hv = hx * geo[li, 6] + hy * geo[li, 7] + hz * geo[li, 8]
        if uv == 0.0:
            a = hu / uu
            b = hv / vv
        else:  # skewed axes (a light under a sheared parent): solve h = a u + b v
            g = uu * vv - uv * uv
            a = (hu * vv - hv * uv) / g
            b = (hv * uu - hu * uv) / g
        if kind == C.LIGHT_RECT:
            if abs(a) > 1.0 or abs(b) > 1.0:
                return np.inf, 0.0, 0.0
        elif a * a + b * b > 1.0:
            return np.inf, 0.0, 0.0
        if den > 0.0 and not two_sided:
            return t, 0.0, 0.0
        if kind == C.LIGHT_RECT:
            o1, o2 = _rect_solid_angles(_rect_corners(geo, li, ox, oy, oz))
            if o1 + o2 >= RECT_SOLID_ANGLE_MIN:
                return t, 1.0, 1.0 / (o1 + o2)
        return t, 1.0, t * t / (geo[li, LG_AREA] * abs(den))
    if kind == C.LIGHT_SUN:
        return np.inf, 0.0, 0.0
    r = geo[li, LG_RADIUS]
    if r <= 0.0:
        return np.inf, 0.0, 0.0
    cx = geo[li, 0] - ox
    cy = geo[li, 1] - oy
    cz = geo[li, 2] - oz
    d2 = cx * cx + cy * cy + cz * cz
    if d2 <= r * r:
        return np.inf, 0.0, 0.0  # the ray starts inside the sphere
    b = cx * dx + cy * dy + cz * dz
    if b <= 0.0:
        return np.inf, 0.0, 0.0
    disc = b * b - (d2 - r * r)
    if disc < 0.0:
        return np.inf, 0.0, 0.0
    t = b - math.sqrt(disc)
    if t <= 0.0 or t >= tmax:
        return np.inf, 0.0, 0.0
    d = math.sqrt(d2)
    fac = 1.0
    if kind == C.LIGHT_SPOT:
        fac = spot_mask(geo, li, -cx / d, -cy / d, -cz / d)
    if fac > 0.0 and geo[li, LG_PROF] >= 0.0:
        fac *= profile_factor(geo, prof, np.int64(li), -cx / d, -cy / d, -cz / d)
    k = cone_one_minus_cos(math.asin(min(r / d, 1.0)))
    return t, fac, 1.0 / (TWO_PI * k)


@inline
def sun_hit(geo, li, dx, dy, dz):
    """(fac, pdf) of a ray escaping along d towards sun ``li``: inside its cone or not."""
    k = geo[li, LG_SUN_K]
    if k <= 0.0:
        return 0.0, 0.0
    c = dx * geo[li, LG_N] + dy * geo[li, LG_N + 1] + dz * geo[li, LG_N + 2]
    if 1.0 - c > k:
        return 0.0, 0.0
    return 1.0, 1.0 / (TWO_PI * k)


# --------------------------------------------------------------------------- world image
#
# An equirectangular map as Cycles lays it out (intern/cycles/kernel/geom: direction_to_
# equirectangular): u = 1/2 − atan2(y, x)/(2π) across the columns (u = 1/2, the image's
# centre, looks along +X), and θ = acos z down the rows (row 0 at the zenith), after
# turning the direction by −rotation about +Z. ``par`` = [cos ρ, sin ρ, scale, active].
# The map is looked up bilinearly between texel centres (Cycles' default Linear
# interpolation), periodic in u and, as Cycles has it, in v. It is importance sampled by a piecewise-
# constant 2D distribution over (u, v = θ/π), one cell a texel, of the filtered map's
# luminance averaged over the cell × sin θ (core/lights/record.py world_image): positive
# wherever the filtered map is; dω = 2π² sin θ du dv.

from ..sampling.distrib import distribution_2d_pdf, sample_distribution_2d  # noqa: E402

TWO_PI2 = 2.0 * math.pi * math.pi


@inline
def env_texel(img, u, v):
    """The map's bilinear rgb at (u, v) in [0, 1]²: texel centres at ((i + ½)/w, (j + ½)/h),
    periodic on both axes as Cycles' image lookups are (within half a texel of a pole the
    first and last rows blend, as in Cycles' render of the same map)."""
    h = img.shape[0]
    w = img.shape[1]
    x = u * w - 0.5
    y = v * h - 0.5
    xf = math.floor(x)
    yf = math.floor(y)
    tx = x - xf
    ty = y - yf
    i0 = int(xf) % w
    i1 = i0 + 1
    if i1 == w:
        i1 = 0
    j0 = int(yf) % h
    j1 = j0 + 1
    if j1 == h:
        j1 = 0
    a = (1.0 - tx) * (1.0 - ty)
    b = tx * (1.0 - ty)
    c = (1.0 - tx) * ty
    d = tx * ty
    r = a * img[j0, i0, 0] + b * img[j0, i1, 0] + c * img[j1, i0, 0] + d * img[j1, i1, 0]
    g = a * img[j0, i0, 1] + b * img[j0, i1, 1] + c * img[j1, i0, 1] + d * img[j1, i1, 1]
    bl = a * img[j0, i0, 2] + b * img[j0, i1, 2] + c * img[j1, i0, 2] + d * img[j1, i1, 2]
    return r, g, bl


@function
def env_lookup(img, dist, par, dx, dy, dz):
    """The map's bilinear rgb seen along the unit direction d, and the solid-angle pdf of
    env_sample: (r, g, b, pdf)."""
    x = par[0] * dx + par[1] * dy
    y = -par[1] * dx + par[0] * dy
    z = min(max(dz, -1.0), 1.0)
    u = 0.5 - math.atan2(y, x) / TWO_PI
    if u >= 1.0:
        u -= 1.0
    if not u >= 0.0:  # also NaN (a non-finite direction): never an index out of the image
        u = 0.0
    v = math.acos(z) / math.pi
    if not v >= 0.0:
        v = 0.0
    r, g, b = env_texel(img, u, v)
    sin_t = math.sqrt(max(0.0, 1.0 - z * z))
    if sin_t <= 0.0:
        return r, g, b, 0.0
    return r, g, b, distribution_2d_pdf(dist, u, v) / (TWO_PI2 * sin_t)


@function
def env_sample(img, dist, par, ua, ub):
    """A direction from the world image's distribution and the map's bilinear rgb there:
    (x, y, z, solid-angle pdf, r, g, b)."""
    u, v, p = sample_distribution_2d(dist, ua, ub)
    theta = v * math.pi
    sin_t = math.sin(theta)
    if sin_t <= 0.0 or p <= 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0
    r, g, b = env_texel(img, u, v)
    phi = (0.5 - u) * TWO_PI
    xl = sin_t * math.cos(phi)
    yl = sin_t * math.sin(phi)
    x = par[0] * xl - par[1] * yl
    y = par[1] * xl + par[0] * yl
    return x, y, math.cos(theta), p / (TWO_PI2 * sin_t), r, g, b
