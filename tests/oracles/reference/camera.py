"""Camera rays of the reference, written from the scene contract (``core.scene.Camera``).

Conventions (those the contract states, as Blender has them):

* ``to_world`` (4×4) maps camera space to world space: its first three columns are the
  camera's right (+x), up (+y) and backward (+z) axes, the camera looks along −z, and
  the fourth column is its position. The columns are normalised first, so a scaled
  camera object keeps its field of view.
* Sensor fit: AUTO fits ``sensor_width_mm`` to the larger image dimension, HORIZONTAL
  fits ``sensor_width_mm`` to the width, VERTICAL ``sensor_height_mm`` to the height.
  Perspective: the fitted axis spans ±(size / 2) / lens_mm on the plane z = −1 (a
  tangent); orthographic: ±ortho_scale / 2 metres. The other axis follows the aspect.
  Lens shift moves the window by shift × (the larger of the two full extents).
* Pixels: x to the right, y downwards from the top row (the film's row 0 is the top of
  the image). Film position (fx, fy) in [0, W] × [0, H] maps to the window point
  sx = (2 fx / W − 1) · half_w + off_x, sy = (1 − 2 fy / H) · half_h + off_y.
* Thin lens (fstop > 0): aperture radius lens_mm / (2 fstop) mm; the pinhole ray through
  the window point fixes the point in focus at depth ``focus_distance``; the ray starts
  at a uniform point of the aperture disc and passes through that point.
* Pixel filter: the position of a sample in its pixel is drawn from the filter (each
  axis independently) and the sample counts for that pixel with weight 1, so a pixel is
  the filter-weighted radiance around its centre. Box: uniform over ±width/2 pixels;
  Gaussian: σ = width/6 truncated at ±width/2; Blackman–Harris: the 4-term window over
  the width (F. J. Harris 1978). The last two are sampled by inverting their cdf,
  tabulated here on a fine grid.
* Panoramic projections (Cycles'): the film position gives (u, v) = (fx / W, 1 − fy / H)
  plus the lens shift. Equirectangular: latitude = lat_min + v (lat_max − lat_min) and
  longitude = lon_min + u (lon_max − lon_min) (0 along −z, positive towards +x), the
  direction (cos lat sin lon, sin lat, −cos lat cos lon). Fisheyes: the angle θ from −z
  with the image position's azimuth; equidistant θ = fov/2 · |(2u − 1, 2v − 1)| (no ray
  past 1), equisolid θ = 2 asin(r / 2f) with r the position on the sensor in mm (the
  fitted axis of the sensor keeps its size, the other follows the aspect; no ray past the
  field of view). No ray: a zero direction. No depth of field.
"""
import numpy as np

from spectral_gi.core import constants as C

_BH = (0.35875, 0.48829, 0.14128, 0.01168)


def _filter_shape(kind, t):
    """The filter on t ∈ [0, 1] across its width (t = 0.5 at the pixel centre)."""
    if kind == C.FILTER_BOX:
        return np.ones_like(t)
    if kind == C.FILTER_GAUSSIAN:
        return np.exp(-0.5 * ((t - 0.5) * 6.0) ** 2)
    if kind == C.FILTER_BLACKMAN_HARRIS:
        a = 2.0 * np.pi * t
        return np.maximum(_BH[0] - _BH[1] * np.cos(a) + _BH[2] * np.cos(2 * a) - _BH[3] * np.cos(3 * a), 0.0)
    raise NotImplementedError(f"reference: pixel filter {kind}")


class PixelFilter:
    """Draws offsets (pixels) from the pixel centre with a filter's density."""

    def __init__(self, kind, width, cells=1 << 14):
        self.kind = int(kind)
        self.width = float(width)
        edges = np.linspace(0.0, 1.0, cells + 1)
        f = _filter_shape(self.kind, edges)
        cdf = np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]))])
        self._edges = edges
        self._cdf = cdf / cdf[-1]

    def offsets(self, u):
        if self.kind == C.FILTER_BOX:
            t = u
        else:
            t = np.interp(u, self._cdf, self._edges)
        return (t - 0.5) * self.width


class CameraModel:
    """The camera of a scene, as a function from film positions and lens samples to rays."""

    def __init__(self, cam, settings):
        w, h = float(cam.width), float(cam.height)
        self.width, self.height = int(cam.width), int(cam.height)
        fit = cam.sensor_fit
        if fit == C.FIT_AUTO:
            horizontal = w >= h
            size = cam.sensor_width_mm
        elif fit == C.FIT_HORIZONTAL:
            horizontal, size = True, cam.sensor_width_mm
        else:
            horizontal, size = False, cam.sensor_height_mm
        self.ortho = cam.projection == C.CAM_ORTHOGRAPHIC
        half = 0.5 * cam.ortho_scale if self.ortho else 0.5 * size / cam.lens_mm
        if horizontal:
            self.half_w, self.half_h = half, half * h / w
        else:
            self.half_w, self.half_h = half * w / h, half
        extent = 2.0 * max(self.half_w, self.half_h)
        self.off_x, self.off_y = cam.shift_x * extent, cam.shift_y * extent
        m = np.asarray(cam.to_world, dtype=np.float64)
        self.rot = m[:3, :3] / np.linalg.norm(m[:3, :3], axis=0)
        self.pos = m[:3, 3].copy()
        self.lens_radius = 0.001 * cam.lens_mm / (2.0 * cam.fstop) if cam.fstop > 0 else 0.0
        self.focus = float(cam.focus_distance)
        self.filter = PixelFilter(settings.filter, settings.filter_width)
        self.pano = cam.projection if cam.projection in C.CAM_PANORAMIC else None
        if self.pano is not None:
            self.lens_radius = 0.0
            self.shift = (float(cam.shift_x), float(cam.shift_y))
            self.lat = (cam.latitude_min, cam.latitude_max)
            self.lon = (cam.longitude_min, cam.longitude_max)
            self.fov, self.flens = float(cam.fisheye_fov), float(cam.fisheye_lens_mm)
            sw, sh = (size, size * h / w) if (w > h if fit == C.FIT_AUTO else horizontal) else (size * w / h, size)
            self.sensor = (sw, sh)

    def panorama(self, fx, fy):
        """Camera-space unit directions (N, 3) of film positions of a panoramic camera (zero: no ray)."""
        u = fx / self.width + self.shift[0]
        v = 1.0 - fy / self.height + self.shift[1]
        if self.pano == C.CAM_EQUIRECTANGULAR:
            lat = self.lat[0] + v * (self.lat[1] - self.lat[0])
            lon = self.lon[0] + u * (self.lon[1] - self.lon[0])
            return np.stack([np.cos(lat) * np.sin(lon), np.sin(lat), -np.cos(lat) * np.cos(lon)], axis=1)
        if self.pano == C.CAM_FISHEYE_EQUIDISTANT:
            a, b = 2 * u - 1, 2 * v - 1
            r = np.hypot(a, b)
            ok = r <= 1.0
            theta = r * self.fov / 2
        else:
            a, b = (u - 0.5) * self.sensor[0], (v - 0.5) * self.sensor[1]
            r = np.hypot(a, b)
            ok = r <= 2 * self.flens * np.sin(self.fov / 4)
            theta = 2 * np.arcsin(np.minimum(r / (2 * self.flens), 1.0))
        az = np.arctan2(b, a)
        d = np.stack([np.sin(theta) * np.cos(az), np.sin(theta) * np.sin(az), -np.cos(theta)], axis=1)
        return np.where(ok[:, None], d, 0.0)

    def rays(self, px, py, rng):
        """World-space rays (origins (N, 3), unit directions (N, 3)) for pixels (px, py)."""
        n = px.shape[0]
        fx = px + 0.5 + self.filter.offsets(rng.random(n))
        fy = py + 0.5 + self.filter.offsets(rng.random(n))
        if self.pano is not None:
            return np.broadcast_to(self.pos, (n, 3)).copy(), self.panorama(fx, fy) @ self.rot.T
        sx = (2.0 * fx / self.width - 1.0) * self.half_w + self.off_x
        sy = (1.0 - 2.0 * fy / self.height) * self.half_h + self.off_y
        o = np.zeros((n, 3))
        d = np.zeros((n, 3))
        if self.ortho:
            o[:, 0], o[:, 1] = sx, sy
            d[:, 2] = -1.0
        else:
            d[:, 0], d[:, 1], d[:, 2] = sx, sy, -1.0
        if self.lens_radius > 0.0:
            focus = o + d * self.focus  # d has z = −1: this point lies at depth focus_distance
            r = self.lens_radius * np.sqrt(rng.random(n))
            phi = 2.0 * np.pi * rng.random(n)
            o[:, 0] += r * np.cos(phi)
            o[:, 1] += r * np.sin(phi)
            d = focus - o
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        return o @ self.rot.T + self.pos, d @ self.rot.T
