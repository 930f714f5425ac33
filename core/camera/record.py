"""The camera's record: the camera vector and the pixel filter's distribution."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .. import constants as C


class CameraRecord(NamedTuple):
    """What the path kernel's camera rays read.

    cam: float64 (CAM_SIZE,) the camera vector (layout in core/camera/kernel.py): camera-to-
        world rotation and position, half extents of the image plane, shift, projection,
        thin-lens radius and focus distance, filter width.
    filt: float64 1D distribution of the pixel filter (core/camera/kernel.py filter_table).
    """

    cam: np.ndarray
    filt: np.ndarray


def pack(scene) -> CameraRecord:
    """The record of ``scene``'s camera and its render settings' pixel filter."""
    return CameraRecord(camera_vector(scene.camera, scene.settings), filter_distribution(scene.settings))


def camera_vector(cam, settings=None):
    """Pack a Camera into the float64[CAM_SIZE] the kernel reads (Blender's sensor-fit rules;
    layout in core/camera/kernel.py)."""
    from . import kernel as K

    w, h = float(cam.width), float(cam.height)
    fit = cam.sensor_fit
    if fit == C.FIT_AUTO:
        fit = C.FIT_HORIZONTAL if w >= h else C.FIT_VERTICAL
        size = cam.sensor_width_mm  # AUTO: sensor width applies to the larger dimension
    else:
        size = cam.sensor_width_mm if fit == C.FIT_HORIZONTAL else cam.sensor_height_mm
    if cam.projection == C.CAM_ORTHOGRAPHIC:
        half = 0.5 * cam.ortho_scale  # metres along the fitted axis (AUTO: the larger side)
    else:
        half = 0.5 * size / cam.lens_mm
    if fit == C.FIT_HORIZONTAL:
        half_w, half_h = half, half * h / w
    else:
        half_w, half_h = half * w / h, half
    extent = 2.0 * max(half_w, half_h)  # Blender's shift is in units of the larger dimension
    m = np.asarray(cam.to_world, dtype=np.float64)
    rot = m[:3, :3] / np.linalg.norm(m[:3, :3], axis=0)[None, :]
    v = np.zeros(K.CAM_SIZE)
    v[0:9] = rot.reshape(-1)
    v[9:12] = m[:3, 3]
    v[K.CAM_HALF_W] = half_w
    v[K.CAM_HALF_H] = half_h
    v[K.CAM_OFF_X] = cam.shift_x * extent
    v[K.CAM_OFF_Y] = cam.shift_y * extent
    v[K.CAM_PROJ] = cam.projection
    # thin lens: aperture radius = focal length / (2 f-number), in metres (as Cycles)
    v[K.CAM_LENS_R] = 0.001 * cam.lens_mm / (2.0 * cam.fstop) if cam.fstop > 0 else 0.0
    v[K.CAM_FOCUS] = cam.focus_distance
    v[K.CAM_FILTER_W] = settings.filter_width if settings is not None else 1.0
    if cam.projection in C.CAM_PANORAMIC:
        v[K.CAM_OFF_X] = cam.shift_x  # a panorama's shift moves (u, v) over the whole image (as Cycles)
        v[K.CAM_OFF_Y] = cam.shift_y
        v[K.CAM_LENS_R] = 0.0  # no depth of field
        v[K.CAM_PANO:K.CAM_PANO + 4] = panorama_parameters(cam)
    return v


def panorama_parameters(cam):
    """The four CAM_PANO entries of a panoramic camera (core/camera/kernel.py): Cycles'
    equirectangular range, the equidistant fisheye's field of view, or the equisolid
    fisheye's lens (mm), field of view and sensor width and height (mm) fitted to the image
    as Cycles fits them (the fitted axis keeps its sensor size, the other follows the
    image's aspect)."""
    if cam.projection == C.CAM_EQUIRECTANGULAR:
        return (cam.longitude_min - cam.longitude_max, -cam.longitude_min, cam.latitude_min - cam.latitude_max,
                0.5 * math.pi - cam.latitude_min)
    if cam.projection == C.CAM_FISHEYE_EQUIDISTANT:
        return (cam.fisheye_fov, 0.0, 0.0, 0.0)
    w, h = float(cam.width), float(cam.height)
    fit = cam.sensor_fit
    if fit == C.FIT_AUTO:
        horizontal, size = w > h, cam.sensor_width_mm
    elif fit == C.FIT_HORIZONTAL:
        horizontal, size = True, cam.sensor_width_mm
    else:
        horizontal, size = False, cam.sensor_height_mm
    sw, sh = (size, size * h / w) if horizontal else (size * w / h, size)
    return (cam.fisheye_lens_mm, cam.fisheye_fov, sw, sh)


def filter_distribution(settings):
    """The pixel filter's 1D distribution (box of 1 px when ``settings`` is None)."""
    from .kernel import filter_table

    if settings is None:
        return filter_table(C.FILTER_BOX, 1.0)
    return filter_table(int(settings.filter), float(settings.filter_width))
