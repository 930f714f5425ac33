"""Unit and axis conversions between Blender data and the core scene contract.

This is the only arithmetic in the add-on. Every function is pure (plain numbers and
numpy arrays in, plain numbers and arrays out), so each one is tested without Blender.

Conventions:
* Blender units × ``unit_settings.scale_length`` = metres (the core works in metres).
* Axes stay Blender's (+Z up); matrices are 4×4, row-major as ``numpy.array(Matrix)``.
* Blender area lights emit along their local -Z axis.
"""
import math

import numpy as np

SQUARE_SHAPES = ("SQUARE", "DISK")  # one size for both axes
ELLIPSE_SHAPES = ("DISK", "ELLIPSE")
AREA_SHAPES = ("SQUARE", "RECTANGLE", "DISK", "ELLIPSE")


def matrix_to_array(matrix):
    """A 4×4 mathutils Matrix (or nested sequence) → float64 (4, 4) numpy array."""
    m = np.array([[float(matrix[r][c]) for c in range(4)] for r in range(4)], dtype=np.float64)
    return m


def points_to_world_metres(matrix, local_points, scale_length):
    """Apply a 4×4 object matrix to (N, 3) local points and convert to metres (float32)."""
    m = np.asarray(matrix, dtype=np.float64)
    p = np.asarray(local_points, dtype=np.float64).reshape(-1, 3)
    world = p @ m[:3, :3].T + m[:3, 3]
    return np.ascontiguousarray(world * float(scale_length), dtype=np.float32)


def camera_to_world_metres(matrix, scale_length):
    """Camera matrix_world → the core's ``to_world``: unit axes (scale removed), translation in metres."""
    m = np.asarray(matrix, dtype=np.float64).copy()
    norms = np.linalg.norm(m[:3, :3], axis=0)
    if np.any(norms <= 0.0):
        raise ValueError("the camera's matrix has a zero scale")
    out = np.eye(4)
    out[:3, :3] = m[:3, :3] / norms[None, :]
    out[:3, 3] = m[:3, 3] * float(scale_length)
    return out


def render_resolution(resolution_x, resolution_y, percentage):
    """Pixel size of the render as Blender computes it: resolution × percentage / 100, truncated."""
    w = int(resolution_x) * int(percentage) // 100
    h = int(resolution_y) * int(percentage) // 100
    return max(1, w), max(1, h)


def area_light_size(shape, size, size_y):
    """Full extents (local X, local Y) in Blender units: SQUARE and DISK use ``size`` for both."""
    if shape not in AREA_SHAPES:
        raise ValueError(f"unknown area light shape {shape!r}")
    sx = float(size)
    sy = sx if shape in SQUARE_SHAPES else float(size_y)
    return sx, sy


def area_light_geometry(matrix, shape, size, size_y, scale_length):
    """World-space frame of a Blender area light.

    Returns ``(position, axis_u, axis_v, is_ellipse, area_m2)``: the centre and the
    half-extent vectors in metres (object scale and rotation included), oriented so
    that ``cross(axis_u, axis_v)`` points along the light's local -Z axis in world
    space (the side Blender's area lights emit from, also under mirroring), and the
    emitting area in m².
    """
    m = np.asarray(matrix, dtype=np.float64)
    s = float(scale_length)
    sx, sy = area_light_size(shape, size, size_y)
    axis_u = m[:3, 0] * (0.5 * sx) * s
    axis_v = m[:3, 1] * (0.5 * sy) * s
    emit_dir = -m[:3, 2]
    if float(np.dot(np.cross(axis_u, axis_v), emit_dir)) < 0.0:
        axis_v = -axis_v
    cross = float(np.linalg.norm(np.cross(axis_u, axis_v)))
    is_ellipse = shape in ELLIPSE_SHAPES
    area = math.pi * cross if is_ellipse else 4.0 * cross
    position = m[:3, 3] * s
    return position, axis_u, axis_v, is_ellipse, area


def area_light_normalising_area(area_m2, normalize, scale_length):
    """The area (m²) that a Blender area light's power is spread over.

    With "Normalize" on (the default) it is the light's own area. With it off, Cycles
    does not divide by the area: the light then emits as a light of one square
    Blender unit would, whatever its size (``scale_length``² m²).
    """
    if normalize:
        return float(area_m2)
    return float(scale_length) ** 2


def light_power_watts(energy, exposure):
    """Blender's light power (W) scaled by its exposure: energy · 2^exposure, as Cycles does."""
    return float(energy) * 2.0 ** float(exposure)


def light_rgb(color, use_temperature=False, temperature_color=(1.0, 1.0, 1.0)):
    """The light's linear colour: colour, times the blackbody tint when temperature is used."""
    c = np.asarray(color, dtype=np.float64).reshape(-1)[:3]
    if use_temperature:
        c = c * np.asarray(temperature_color, dtype=np.float64).reshape(-1)[:3]
    return tuple(float(x) for x in c)


def rgb_of(rgba):
    """The first three components of a colour (drops alpha) as floats."""
    v = tuple(float(x) for x in rgba)
    return v[:3]


def rgba_rows_bottom_up(rgb):
    """(H, W, 3) image with rows top-to-bottom → flat float32 RGBA with rows bottom-up (Blender's order)."""
    a = np.asarray(rgb)
    if a.ndim != 3 or a.shape[2] != 3:
        raise ValueError(f"expected an (H, W, 3) image, got shape {a.shape}")
    h, w, _ = a.shape
    out = np.empty((h, w, 4), dtype=np.float32)
    out[..., :3] = a[::-1]
    out[..., 3] = 1.0
    return out.reshape(-1)



# ----------------------------------------------------------------------------- materials
#
# Cycles' roughness conventions (Blender 4.x/5.x): α = roughness². The Principled BSDF
# stretches α by aspect = √(1 − 0.9·anisotropic) (αx = α/aspect, αy = α·aspect); the Glossy
# BSDF's anisotropy a ∈ [−0.99, 0.99] gives αx = α(1 − a), αy = α/(1 − a) for a ≥ 0 and
# αx = α/(1 + a), αy = α(1 + a) for a < 0.

SMOOTH_ALPHA = 1e-3  # α at or below which a microfacet model is exported as its smooth (delta) model


def _clamp01(x):
    x = float(x)
    return 0.0 if not x > 0.0 else 1.0 if x > 1.0 else x


def principled_alpha(roughness, anisotropic=0.0):
    """(αx, αy) of the Principled BSDF's specular lobes, each clamped to [0, 1]."""
    a = _clamp01(roughness) ** 2
    ax = ay = a
    aniso = _clamp01(anisotropic)
    if aniso > 0.0:
        aspect = math.sqrt(1.0 - 0.9 * aniso)
        ax, ay = a / aspect, a * aspect
    return min(ax, 1.0), min(ay, 1.0)


def glossy_alpha(roughness, anisotropy=0.0):
    """(αx, αy) of the Glossy BSDF (its Anisotropy input in [−1, 1]), each clamped to [0, 1]."""
    a = _clamp01(roughness) ** 2
    k = min(max(float(anisotropy), -0.99), 0.99)
    if abs(k) <= 1e-4:
        return a, a
    if k < 0.0:
        ax, ay = a / (1.0 + k), a * (1.0 + k)
    else:
        ax, ay = a * (1.0 - k), a / (1.0 - k)
    return min(ax, 1.0), min(ay, 1.0)


def is_smooth(alpha_x, alpha_y):
    """True when both roughnesses are small enough for the smooth (delta) model."""
    return alpha_x <= SMOOTH_ALPHA and alpha_y <= SMOOTH_ALPHA


def specular_level_ior(ior, level):
    """The IOR whose normal-incidence reflectance is F0(ior) · 2·level (the Principled BSDF's
    Specular IOR Level: 0.5 leaves the IOR unchanged, 0 removes the reflection, 1 doubles F0)."""
    ior = float(ior)
    level = max(float(level), 0.0)
    if level == 0.5:
        return ior
    r = (ior - 1.0) / (ior + 1.0)
    f0 = min(r * r * 2.0 * level, 0.999)
    s = math.sqrt(f0)
    eff = (1.0 + s) / (1.0 - s)
    return eff if ior >= 1.0 else 1.0 / eff


def mix_first_weight(factor):
    """Probability of the Mix Shader's first input: (1 − fac), with fac clamped to [0, 1]."""
    return 1.0 - _clamp01(factor)


def combine_emission(terms):
    """Sum of weighted emitters ``[(rgb, strength), ...]`` → one ``(rgb, strength)`` with max(rgb) = 1.

    Returns the single term unchanged when there is one (so a plain emitter keeps its
    colour exactly), and ``((0, 0, 0), 0.0)`` when nothing emits.
    """
    live = [(tuple(float(c) for c in rgb[:3]), float(s)) for rgb, s in terms
            if s > 0.0 and max(float(c) for c in rgb[:3]) > 0.0]
    if not live:
        return (0.0, 0.0, 0.0), 0.0
    if len(live) == 1:
        return live[0]
    total = np.zeros(3)
    for rgb, s in live:
        total += np.maximum(np.asarray(rgb), 0.0) * s
    peak = float(total.max())
    return tuple(float(c) for c in total / peak), peak
