"""Illuminance sensors: the lux falling on flagged meshes, as a lighting designer's grid.

A mesh with ``Mesh.sensor = True`` is a sensor. :func:`render_illuminance` renders the
scene a second time in the kernel's measuring mode: where the camera ray first hits a
sensor, that surface is replaced by a white (ρ = 1 at every wavelength) two-sided
Lambertian reflector without emission; every deeper vertex keeps its real material, so
interreflections through the real surfaces (the sensor's own real colour included, for
light that bounces off it before arriving back) are counted. A Lambertian surface of
reflectance 1 sends out L = E/π in every direction, so the pixel's illuminance is

    E (lux) = π · L_v (cd/m²) = π · K_m · Y,

exactly, with the same noise as any path-traced luminance. It is the illuminance on the
side of the sensor the camera sees, with respect to its shading normal.

Pixels whose camera rays hit no sensor (another surface, or nothing) are NaN in
:attr:`IlluminanceImage.lux`; their rays end at once. A pixel straddling a sensor's edge
gives the mean illuminance over the part of its footprint on the sensor
(``coverage`` < 1). Analytic lights seen by camera rays are ignored in this mode; the
camera ray itself should run through clear air (a participating medium around the
camera would attenuate the measurement).

Statistics (:func:`illuminance_stats`): Em (mean), Emin, Emax and the uniformity
U0 = Emin / Em over the sensor pixels that are fully on a sensor (every sample's camera
ray hit one: ``coverage`` = 1; ``min_coverage`` lowers the bar). Partly covered pixels
(a sensor's outline, its contact lines with objects standing on it) keep their lux in the
image, but they are left out of the statistics and counted in ``excluded``: only the
fraction ``coverage`` of their samples measures, so their estimates are much noisier
(a pixel with one or two sensor samples at a shadowed contact line often reads 0 lx),
and they would set Emin by noise, like a calculation point placed on a wall's foot
(lighting-design practice computes Emin on a grid of points on the surface). Each
counted pixel weighs the same, so these are area-weighted means only when every pixel
covers the same area of the sensor: an orthographic camera looking straight at a flat
sensor (a top view of a work plane). Under perspective or on curved sensors they are
means over the image, not over the surface. Emin and Emax are extremes of noisy pixel
estimates, so noise widens them (and lowers U0): render enough samples that the pixel
standard error (``std``; ``Emin_std`` is the Emin pixel's) is small against the
variation being measured.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .. import constants as C
from ..scene import SceneError


@dataclass
class IlluminanceImage:
    lux: np.ndarray  # (H, W) illuminance in lux; NaN where no sample hit a sensor
    coverage: np.ndarray  # (H, W) fraction of the pixel's samples whose camera ray first hit a sensor
    std: np.ndarray  # (H, W) standard error of lux (inf with fewer than two sensor samples)

    @property
    def mask(self):
        """(H, W) bool: the pixels that measured something."""
        return np.isfinite(self.lux)


# the default share of a pixel's samples that must hit a sensor for the pixel to enter the
# statistics: all of them (partly covered pixels are measured too noisily, see the module text)
FULL_COVERAGE = 1.0


@dataclass
class IlluminanceStats:
    Em: float  # mean illuminance over the counted sensor pixels, lux
    Emin: float  # lux
    Emax: float  # lux
    U0: float  # uniformity Emin / Em (NaN when Em = 0)
    pixels: int  # the number of sensor pixels counted
    excluded: int = 0  # sensor pixels left out: coverage below min_coverage
    min_coverage: float = 0.0  # the coverage a pixel needed to be counted (0: every measured pixel)
    Emin_std: float = float("nan")  # standard error of the Emin pixel's estimate, lux (NaN: not known)

    def as_dict(self):
        return dataclasses.asdict(self)


@dataclass
class IlluminanceResult:
    image: IlluminanceImage
    stats: IlluminanceStats
    film: object  # the measuring render's Film
    render_stats: object  # its RenderStats


def has_sensors(scene) -> bool:
    """True if some mesh of ``scene`` is an illuminance sensor."""
    return any(bool(m.sensor) and m.indices.shape[0] > 0 for m in scene.meshes)


def illuminance_image(film) -> IlluminanceImage:
    """Lux per pixel from the film of a measuring render (``render(..., measure=True)``).

    The film's transparent-sample count (AOV channel 8) is the number of samples that hit
    no sensor and carry no radiance; E is π K_m times the mean Y of the other samples.
    """
    from ..film import photometric_y_sums

    n = film.sums[..., 3]
    n_sensor = n - film.aov[..., 8]
    ok = n_sensor > 0.5
    safe = np.where(ok, n_sensor, 1.0)
    mean_y = photometric_y_sums(film.sums) / safe  # V(λ)-weighted Y, whatever the film's observer
    lux = np.where(ok, math.pi * C.K_M * mean_y, np.nan)
    # only sensor samples carry Y, so Σ Y² over them is the film's (photometric) Y² sum
    var = np.maximum(film.sums[..., 4] / safe - mean_y * mean_y, 0.0) / np.maximum(safe - 1.0, 1.0)
    std = np.where(n_sensor > 1.5, math.pi * C.K_M * np.sqrt(var), np.inf)
    coverage = np.where(n > 0, n_sensor / np.maximum(n, 1.0), 0.0)
    return IlluminanceImage(lux=lux, coverage=coverage, std=std)


def _check_min_coverage(min_coverage):
    if not 0.0 <= min_coverage <= 1.0:
        raise ValueError(f"min_coverage: expected a fraction in [0, 1], got {min_coverage}")


def illuminance_stats(lux, mask=None, coverage=None, min_coverage=FULL_COVERAGE, std=None) -> IlluminanceStats:
    """Em, Emin, Emax and U0 = Emin / Em over the finite pixels of ``lux`` (and ``mask``).

    With ``coverage`` (the image's per-pixel sensor coverage) only pixels whose coverage is
    at least ``min_coverage`` (default: fully covered) count; the other finite pixels are
    reported as ``excluded``. ``std`` (the per-pixel standard error) gives ``Emin_std``.
    """
    lux = np.asarray(lux, np.float64)
    sel = np.isfinite(lux)
    if mask is not None:
        sel &= np.asarray(mask, bool)
    measured = int(sel.sum())
    if coverage is not None:
        _check_min_coverage(min_coverage)
        sel &= np.asarray(coverage, np.float64) >= min_coverage
    else:
        min_coverage = 0.0
    v = lux[sel]
    excluded = measured - int(v.size)
    if v.size == 0:
        nan = float("nan")
        return IlluminanceStats(nan, nan, nan, nan, 0, excluded, float(min_coverage))
    em = float(v.mean())
    k = int(np.argmin(v))
    emin = float(v[k])
    emin_std = float(np.asarray(std, np.float64)[sel][k]) if std is not None else float("nan")
    return IlluminanceStats(Em=em, Emin=emin, Emax=float(v.max()), U0=emin / em if em > 0 else float("nan"),
                            pixels=int(v.size), excluded=excluded, min_coverage=float(min_coverage),
                            Emin_std=emin_std)


def measuring_scene(scene, box_filter=True):
    """A shallow copy of ``scene`` for the measuring render: its own settings, with a
    1-pixel box filter when ``box_filter`` (each pixel then measures its own footprint)."""
    st = dataclasses.replace(scene.settings)
    if box_filter:
        st.filter = C.FILTER_BOX
        st.filter_width = 1.0
    return dataclasses.replace(scene, settings=st)


def render_illuminance(scene, *, threads=None, progress=None, should_cancel=None, on_pass=None, status=None,
                       box_filter=True, resume=None, min_coverage=FULL_COVERAGE) -> IlluminanceResult:
    """Render the illuminance (lux) on the sensor meshes of ``scene`` (see the module text).

    Takes the scene's camera, samples and stopping rules; with ``box_filter`` (default) the
    pixel filter is a 1-pixel box. The statistics count the pixels whose sensor coverage is
    at least ``min_coverage`` (default 1: fully covered). Raises SceneError if no mesh is a
    sensor. The other arguments are those of :func:`core.renderer.render`.
    """
    from .render import render

    if not has_sensors(scene):
        raise SceneError("meshes: no mesh is an illuminance sensor (set Mesh.sensor = True)")
    _check_min_coverage(min_coverage)  # before the render, not after it
    film, rstats = render(measuring_scene(scene, box_filter), threads=threads, progress=progress,
                          should_cancel=should_cancel, on_pass=on_pass, status=status, resume=resume, measure=True)
    img = illuminance_image(film)
    stats = illuminance_stats(img.lux, coverage=img.coverage, min_coverage=min_coverage, std=img.std)
    return IlluminanceResult(image=img, stats=stats, film=film, render_stats=rstats)
