"""Camera rays: perspective, orthographic or panoramic projection, thin lens, pixel filter.

The camera vector (float64[CAM_SIZE], packed by core/camera/record.py camera_vector): camera-to-
world rotation (row major), position, the half extents of the image on the plane
z = −1 (perspective: tangents) or in metres (orthographic), Blender's lens shift, the
projection tag, the lens radius (0: pinhole), the focus distance, the filter width and
four parameters of a panoramic projection (CAM_PANO).

Panoramic projections (Cycles' models, intern/cycles/kernel/camera/projection.h): the
pixel position gives (u, v) in [0, 1]² over the whole image (v up, plus the lens shift),
mapped to a direction in a panorama frame whose +X is the view axis and +Z the camera's
up; camera space is (−p_y, p_z, −p_x), so the image centre looks down the camera's −Z.

- equirectangular: φ = P0 u + P1, θ = P2 v + P3 (P = (lon_min − lon_max, −lon_min,
  lat_min − lat_max, π/2 − lat_min)), p = (sin θ cos φ, sin θ sin φ, cos θ);
- equidistant fisheye: (u', v') = 2 (u, v) − 1, r = |(u', v')| ≤ 1, angle from the axis
  θ = r · fov / 2 (P0 = fov);
- equisolid fisheye: (u', v') = ((u − ½) w, (v − ½) h) on the sensor (mm, fitted as
  Cycles does), r = 2 f sin(θ / 2) up to the field of view (P = (f mm, fov, w, h)).

A fisheye pixel outside its image circle gets no ray: the direction (0, 0, 0).

Pixel filter: each sample's position in the pixel is drawn from the filter (separable:
x and y independently), so every sample has weight 1 and the image is the filtered
radiance (Cycles does the same with a tabulated inverse cdf). The filter's 1D
distribution (core.sampling.distrib layout, with a guide table: sampling it costs a step
or two, not a binary search over its cells) is built once by :func:`filter_table`.

Thin lens (Cycles' model): the pinhole ray through the pixel fixes the point in focus
at depth ``focus_distance``; the ray starts at a uniform point of the lens disc of
radius lens_mm / (2 f-number) (concentric map) and passes through that point.
"""
import functools
import math

import numpy as np

from .. import constants as C
from ..jit import function, inline
from ..sampling.distrib import build_guided_1d, sample_1d_guided
from ..sampling.warps import sample_disk_concentric

CAM_R = 0  # 9 entries: camera-to-world rotation, row major
CAM_T = 9  # 3 entries: camera position
CAM_HALF_W = 12
CAM_HALF_H = 13
CAM_OFF_X = 14
CAM_OFF_Y = 15
CAM_PROJ = 16
CAM_LENS_R = 17
CAM_FOCUS = 18
CAM_FILTER_W = 19
CAM_PANO = 20  # 4 entries: the panoramic projection's parameters (module docstring)
CAM_SIZE = 24

FILTER_CELLS = 1024

# Blackman–Harris window, 4 terms (F. J. Harris, Proc. IEEE 66(1), 1978), over the filter width
_BH = (0.35875, 0.48829, 0.14128, 0.01168)


def filter_function(kind, width, x):
    """The (unnormalised) filter at offsets ``x`` (pixels) from the pixel centre; 0 outside ±width/2.

    box: 1; Blackman–Harris: the 4-term window spanning the width (Cycles' default filter,
    width 1.5 px); Gaussian: exp(−x²/(2σ²)) with σ = width/6, truncated at ±3σ = ±width/2.
    """
    x = np.asarray(x, dtype=np.float64)
    inside = np.abs(x) <= 0.5 * width
    if kind == C.FILTER_BOX:
        f = np.ones_like(x)
    elif kind == C.FILTER_BLACKMAN_HARRIS:
        a = 2.0 * np.pi * (x / width + 0.5)
        f = _BH[0] - _BH[1] * np.cos(a) + _BH[2] * np.cos(2 * a) - _BH[3] * np.cos(3 * a)
    elif kind == C.FILTER_GAUSSIAN:
        s = width / 6.0
        f = np.exp(-0.5 * (x / s) ** 2)
    else:
        raise ValueError(f"unknown pixel filter {kind}")
    return np.where(inside, np.maximum(f, 0.0), 0.0)


@functools.lru_cache(maxsize=16)
def filter_table(kind, width):
    """Guided 1D piecewise-constant distribution of the filter over [−width/2, width/2] (cell
    means). Cached: one table per (kind, width), shared by every record that holds it (read
    only); a point measure's prepare packs the camera record too."""
    n = FILTER_CELLS
    sub = 8
    x = (np.arange(n * sub) + 0.5) / (n * sub) - 0.5
    f = filter_function(kind, width, x * width).reshape(n, sub).mean(axis=1)
    return build_guided_1d(f)


@inline
def filter_offset(filt, u, width):
    """Offset (pixels) from the pixel centre drawn from the filter with the uniform u."""
    x, _, _ = sample_1d_guided(filt, u)
    return (x - 0.5) * width


@inline
def panorama_direction(cam, u, v):
    """Camera-space direction (x, y, z) of the image position (u, v) (v up) of a panoramic
    projection; (0, 0, 0) outside a fisheye's image circle."""
    proj = cam[CAM_PROJ]
    p0 = cam[CAM_PANO]
    p1 = cam[CAM_PANO + 1]
    p2 = cam[CAM_PANO + 2]
    p3 = cam[CAM_PANO + 3]
    if proj == C.CAM_EQUIRECTANGULAR:
        phi = p0 * u + p1
        theta = p2 * v + p3
        st = math.sin(theta)
        return -st * math.sin(phi), math.cos(theta), -st * math.cos(phi)
    if proj == C.CAM_FISHEYE_EQUIDISTANT:
        a = 2.0 * u - 1.0
        b = 2.0 * v - 1.0
        r = math.sqrt(a * a + b * b)
        if r > 1.0:
            return 0.0, 0.0, 0.0
        theta = 0.5 * r * p0
    else:  # equisolid
        a = (u - 0.5) * p2
        b = (v - 0.5) * p3
        r = math.sqrt(a * a + b * b)
        if r > 2.0 * p0 * math.sin(0.25 * p1):
            return 0.0, 0.0, 0.0
        theta = 2.0 * math.asin(min(r / (2.0 * p0), 1.0))
    if r == 0.0:
        return 0.0, 0.0, -1.0
    st = math.sin(theta) / r
    return a * st, b * st, -math.cos(theta)


@function
def camera_ray(cam, filt, x, y, width, height, u1, u2, u3, u4):
    """World-space ray (ox, oy, oz, dx, dy, dz) through pixel (x, y) with samples u1..u4
    (u1, u2: the filter; u3, u4: the lens); a zero direction where a fisheye sees nothing."""
    fw = cam[CAM_FILTER_W]
    fx = x + 0.5 + filter_offset(filt, u1, fw)
    fy = y + 0.5 + filter_offset(filt, u2, fw)
    if cam[CAM_PROJ] >= C.CAM_EQUIRECTANGULAR:
        cx, cy, cz = panorama_direction(cam, fx / width + cam[CAM_OFF_X], 1.0 - fy / height + cam[CAM_OFF_Y])
        dx = cam[0] * cx + cam[1] * cy + cam[2] * cz
        dy = cam[3] * cx + cam[4] * cy + cam[5] * cz
        dz = cam[6] * cx + cam[7] * cy + cam[8] * cz
        n = math.sqrt(dx * dx + dy * dy + dz * dz)
        if n > 0.0:
            dx /= n
            dy /= n
            dz /= n
        return cam[CAM_T], cam[CAM_T + 1], cam[CAM_T + 2], dx, dy, dz
    sx = (fx / width * 2.0 - 1.0) * cam[CAM_HALF_W] + cam[CAM_OFF_X]
    sy = (1.0 - fy / height * 2.0) * cam[CAM_HALF_H] + cam[CAM_OFF_Y]
    if cam[CAM_PROJ] == C.CAM_ORTHOGRAPHIC:
        px = sx
        py = sy
        cx = 0.0
        cy = 0.0
    else:
        px = 0.0
        py = 0.0
        cx = sx
        cy = sy
    cz = -1.0
    lr = cam[CAM_LENS_R]
    if lr > 0.0:
        fd = cam[CAM_FOCUS]
        fpx = px + cx * fd
        fpy = py + cy * fd
        lx, ly, _ = sample_disk_concentric(u3, u4)
        px += lr * lx
        py += lr * ly
        cx = fpx - px
        cy = fpy - py
        cz = -fd
    dx = cam[0] * cx + cam[1] * cy + cam[2] * cz
    dy = cam[3] * cx + cam[4] * cy + cam[5] * cz
    dz = cam[6] * cx + cam[7] * cy + cam[8] * cz
    inv = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
    ox = cam[CAM_T] + cam[0] * px + cam[1] * py
    oy = cam[CAM_T + 1] + cam[3] * px + cam[4] * py
    oz = cam[CAM_T + 2] + cam[6] * px + cam[7] * py
    return ox, oy, oz, dx * inv, dy * inv, dz * inv
