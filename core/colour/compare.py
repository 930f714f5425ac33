"""Image comparison against a reference renderer (Cycles): numbers, ΔE00 map, side by side.

Both images are linear Rec.709 (Blender's scene-linear) on Blender's scale, where RGB
(1, 1, 1) is a luminance of 683 cd/m² (core/units.py). The report gives

* ``luminance_ratio``: mean luminance of ours / mean luminance of the reference;
* ``relative_rmse``: root-mean-square luminance difference per pixel over the
  reference's mean luminance (noise of both images included);
* ``delta_e00_mean`` / ``delta_e00_p95``: mean and 95th percentile of the per-pixel
  CIEDE2000 difference, in CIE L*a*b* against a D65 white of ``white_luminance``
  cd/m² (default 683: Blender's RGB (1, 1, 1) is L* = 100).

The false-colour map runs from dark blue (ΔE00 = 0) through green and yellow to red at
``vmax``; a legend bar with tick marks and numbers is drawn below it.
"""
from __future__ import annotations

import math

import numpy as np

from .. import constants as C
from . import XYZ_to_Lab, delta_E_CIE2000, luminance_rec709, sRGB_linear_to_XYZ

D65_XY = (0.3127, 0.3290)
DELTA_E_VMAX = 10.0  # ΔE00 at the top of the false-colour scale

# colour ramp stops (position, linear Rec.709)
_RAMP = np.array([
    [0.00, 0.02, 0.02, 0.20],
    [0.25, 0.00, 0.20, 0.80],
    [0.50, 0.05, 0.70, 0.10],
    [0.75, 0.90, 0.80, 0.00],
    [1.00, 0.90, 0.02, 0.01],
])


def _rgb_image(a, what):
    a = np.asarray(a, dtype=np.float64)
    if a.ndim != 3 or a.shape[2] not in (3, 4):
        raise ValueError(f"{what}: expected an (H, W, 3) or (H, W, 4) image, got shape {a.shape}")
    a = a[..., :3]
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{what}: contains NaN or Inf")
    return a


def image_luminance(rgb):
    """Luminance (cd/m²) of a linear Rec.709 image on Blender's scale: 683 · Y(rgb)."""
    return C.K_M * luminance_rec709(np.asarray(rgb, dtype=np.float64)[..., :3])


def image_Lab(rgb, white_luminance=C.K_M):
    """CIE L*a*b* of a linear Rec.709 image against a D65 white of ``white_luminance`` cd/m²."""
    XYZ = np.maximum(sRGB_linear_to_XYZ(np.asarray(rgb, dtype=np.float64)[..., :3]), 0.0)
    return XYZ_to_Lab(XYZ * (C.K_M / float(white_luminance)), np.array(D65_XY))


def delta_e00_map(ours, reference, white_luminance=C.K_M):
    """Per-pixel CIEDE2000 difference of two linear Rec.709 images of the same size."""
    a = _rgb_image(ours, "ours")
    b = _rgb_image(reference, "reference")
    if a.shape != b.shape:
        raise ValueError(f"images differ in size: {a.shape[1]}×{a.shape[0]} and {b.shape[1]}×{b.shape[0]}")
    return delta_E_CIE2000(image_Lab(a, white_luminance), image_Lab(b, white_luminance))


def compare_images(ours, reference, white_luminance=C.K_M):
    """(report dict, ΔE00 map (H, W)) comparing ``ours`` with ``reference`` (see the module docstring)."""
    a = _rgb_image(ours, "ours")
    b = _rgb_image(reference, "reference")
    if a.shape != b.shape:
        raise ValueError(f"images differ in size: {a.shape[1]}×{a.shape[0]} and {b.shape[1]}×{b.shape[0]}")
    if not float(white_luminance) > 0.0:
        raise ValueError(f"white luminance must be positive, got {white_luminance}")
    ya = image_luminance(a)
    yb = image_luminance(b)
    mean_a = float(ya.mean())
    mean_b = float(yb.mean())
    de = delta_e00_map(a, b, white_luminance)
    rmse = float(np.sqrt(np.mean((ya - yb) ** 2)))
    report = {
        "width": int(a.shape[1]),
        "height": int(a.shape[0]),
        "mean_luminance": mean_a,
        "mean_luminance_reference": mean_b,
        "luminance_ratio": mean_a / mean_b if mean_b > 0.0 else (1.0 if mean_a == 0.0 else math.inf),
        "relative_rmse": rmse / mean_b if mean_b > 0.0 else (0.0 if rmse == 0.0 else math.inf),
        "delta_e00_mean": float(de.mean()),
        "delta_e00_p95": float(np.percentile(de, 95.0)),
        "delta_e00_max": float(de.max()),
        "white_luminance": float(white_luminance),
        "luminance_unit": "cd/m2",
    }
    return report, de


def false_colour(values, vmax=DELTA_E_VMAX):
    """(H, W) values → (H, W, 3) linear Rec.709 false colours on [0, vmax] (clamped)."""
    v = np.asarray(values, dtype=np.float64)
    if not vmax > 0.0:
        raise ValueError(f"vmax must be positive, got {vmax}")
    t = np.clip(np.nan_to_num(v / float(vmax), nan=1.0, posinf=1.0, neginf=0.0), 0.0, 1.0)
    out = np.empty(v.shape + (3,))
    for k in range(3):
        out[..., k] = np.interp(t, _RAMP[:, 0], _RAMP[:, k + 1])
    return out


# 3×5 bitmap digits for the legend's numbers (rows top to bottom, 3 bits per row)
_DIGITS = {
    "0": (7, 5, 5, 5, 7), "1": (2, 6, 2, 2, 7), "2": (7, 1, 7, 4, 7), "3": (7, 1, 7, 1, 7),
    "4": (5, 5, 7, 1, 1), "5": (7, 4, 7, 1, 7), "6": (7, 4, 7, 5, 7), "7": (7, 1, 1, 1, 1),
    "8": (7, 5, 7, 5, 7), "9": (7, 5, 7, 1, 7), ".": (0, 0, 0, 0, 2), "+": (0, 2, 7, 2, 0),
}


def _draw_text(img, text, x0, y0, scale, colour):
    h, w = img.shape[:2]
    x = x0
    for ch in text:
        rows = _DIGITS.get(ch)
        if rows is None:
            x += 4 * scale
            continue
        for r, bits in enumerate(rows):
            for c in range(3):
                if bits & (4 >> c):
                    ys, xs = y0 + r * scale, x + c * scale
                    img[max(ys, 0):min(ys + scale, h), max(xs, 0):min(xs + scale, w)] = colour
        x += 4 * scale


def legend_bar(width, vmax=DELTA_E_VMAX, ticks=None):
    """An (h, width, 3) legend: the colour ramp, tick marks and their values (ΔE00) below."""
    width = int(width)
    if width < 1:
        raise ValueError(f"legend width must be positive, got {width}")
    scale = max(1, width // 160)
    bar_h = max(4, 6 * scale)
    text_h = 7 * scale
    h = 2 * scale + bar_h + 2 * scale + text_h
    img = np.zeros((h, width, 3))
    ramp = false_colour(np.linspace(0.0, vmax, width), vmax)
    img[2 * scale:2 * scale + bar_h] = ramp[None, :, :]
    if ticks is None:  # as many as fit without their numbers touching (at most 6)
        n = int(min(6, max(2, width // (14 * scale))))
        ticks = [vmax * i / (n - 1) for i in range(n)]
    y_tick = 2 * scale + bar_h
    for i, t in enumerate(ticks):
        x = int(round(t / vmax * (width - 1)))
        img[y_tick:y_tick + 2 * scale, max(0, x - scale // 2):x + max(1, scale // 2 + 1)] = 1.0
        label = f"{t:g}" + ("+" if i == len(ticks) - 1 and t >= vmax else "")
        tw = len(label) * 4 * scale - scale
        x0 = min(max(0, x - tw // 2), max(0, width - tw))
        _draw_text(img, label, x0, y_tick + 2 * scale, scale, 1.0)
    return img


def delta_e_image(de, vmax=DELTA_E_VMAX):
    """The false-colour ΔE00 map with its legend bar below: (H + legend, W, 3) linear Rec.709."""
    de = np.asarray(de, dtype=np.float64)
    if de.ndim != 2:
        raise ValueError(f"expected an (H, W) ΔE map, got shape {de.shape}")
    return np.concatenate([false_colour(de, vmax), legend_bar(de.shape[1], vmax)], axis=0)


def side_by_side(ours, reference, gap=2):
    """Ours on the left, the reference on the right, ``gap`` black pixels between: (H, 2W + gap, 3)."""
    a = _rgb_image(ours, "ours")
    b = _rgb_image(reference, "reference")
    if a.shape != b.shape:
        raise ValueError(f"images differ in size: {a.shape[1]}×{a.shape[0]} and {b.shape[1]}×{b.shape[0]}")
    sep = np.zeros((a.shape[0], int(gap), 3))
    return np.concatenate([a, sep, b], axis=1)
