"""The scene's active camera → the core camera."""
import numpy as np

from .context import ExportError
from .convert import camera_to_world_metres, matrix_to_array, render_resolution

SENSOR_FITS = ("AUTO", "HORIZONTAL", "VERTICAL")


def sensor_fit_tag(fit):
    """Blender's ``Camera.sensor_fit`` → ``core.constants.FIT_*``."""
    from ...core import constants

    tags = {"AUTO": constants.FIT_AUTO, "HORIZONTAL": constants.FIT_HORIZONTAL,
            "VERTICAL": constants.FIT_VERTICAL}
    try:
        return tags[fit]
    except KeyError:
        raise ExportError(f"unknown camera sensor fit {fit!r}") from None


def export_camera(ctx, scene, depsgraph):
    """The core camera: perspective, orthographic (``ortho_scale``) or panoramic (equirectangular,
    fisheye equidistant or equisolid), thin lens when depth of field is on."""
    from ...core import Camera, constants

    cam_obj = scene.camera
    if cam_obj is None:
        raise ExportError("the scene has no active camera")
    ev = cam_obj.evaluated_get(depsgraph)
    if ev.type != "CAMERA":
        raise ExportError(f"the scene's camera {cam_obj.name!r} is not a camera object")
    data = ev.data
    r = scene.render
    if r.pixel_aspect_x != r.pixel_aspect_y:
        ctx.note("non-square pixel aspect ignored")
    width, height = render_resolution(r.resolution_x, r.resolution_y, r.resolution_percentage)
    to_world = camera_to_world_metres(matrix_to_array(ev.matrix_world), ctx.scale_length)
    extra = {}
    if data.type == "ORTHO":
        extra["projection"] = constants.CAM_ORTHOGRAPHIC
        extra["ortho_scale"] = float(data.ortho_scale) * ctx.scale_length
    elif data.type == "PANO":
        extra.update(panorama_settings(cam_obj.name, data))
    elif data.type != "PERSP":
        raise ExportError(f"camera {cam_obj.name!r}: only perspective, orthographic and panoramic cameras are "
                          f"supported (it is {data.type.lower()})")
    dof = data.dof
    if dof.use_dof:
        if data.type == "ORTHO":
            ctx.note(f"{cam_obj.name}: depth of field of an orthographic camera ignored")
        elif data.type == "PANO":
            ctx.note(f"{cam_obj.name}: depth of field of a panoramic camera ignored")
        elif dof.aperture_fstop > 0.0:
            extra["fstop"] = float(dof.aperture_fstop)
            target = dof.focus_object
            if target is not None:
                target_pos = matrix_to_array(target.evaluated_get(depsgraph).matrix_world)[:3, 3] * ctx.scale_length
                extra["focus_distance"] = focus_distance_to_point(to_world, target_pos)
            else:
                extra["focus_distance"] = float(dof.focus_distance) * ctx.scale_length
            if dof.aperture_blades >= 3:
                ctx.note(f"{cam_obj.name}: polygonal aperture ({dof.aperture_blades} blades) exported as round")
            if abs(dof.aperture_ratio - 1.0) > 1e-6:
                ctx.note(f"{cam_obj.name}: anamorphic aperture ratio ignored")
    return Camera(
        to_world=to_world,
        width=width,
        height=height,
        lens_mm=float(data.lens),
        sensor_width_mm=float(data.sensor_width),
        sensor_height_mm=float(data.sensor_height),
        sensor_fit=sensor_fit_tag(data.sensor_fit),
        shift_x=float(data.shift_x),
        shift_y=float(data.shift_y),
        **extra,
    )


PANORAMA_TYPES = ("EQUIRECTANGULAR", "FISHEYE_EQUIDISTANT", "FISHEYE_EQUISOLID")


def panorama_settings(name, data):
    """The core Camera fields of a panoramic Blender camera (``Camera.panorama_type`` and its
    parameters, as Cycles reads them); ExportError for the panorama types not rendered."""
    from ...core import constants

    kind = data.panorama_type
    if kind not in PANORAMA_TYPES:
        raise ExportError(f"camera {name!r}: panorama type {kind.lower().replace('_', ' ')} is not supported "
                          "(equirectangular, fisheye equidistant and fisheye equisolid are)")
    tags = {"EQUIRECTANGULAR": constants.CAM_EQUIRECTANGULAR,
            "FISHEYE_EQUIDISTANT": constants.CAM_FISHEYE_EQUIDISTANT,
            "FISHEYE_EQUISOLID": constants.CAM_FISHEYE_EQUISOLID}
    return {"projection": tags[kind], "latitude_min": float(data.latitude_min),
            "latitude_max": float(data.latitude_max), "longitude_min": float(data.longitude_min),
            "longitude_max": float(data.longitude_max), "fisheye_fov": float(data.fisheye_fov),
            "fisheye_lens_mm": float(data.fisheye_lens)}


def focus_distance_to_point(to_world, point, minimum=1e-4):
    """Focus distance (m) to ``point`` as Blender measures it: along the camera's viewing axis (-Z).

    ``to_world`` is the core camera matrix (unit axes, metres); the result is at least ``minimum``.
    """
    m = np.asarray(to_world, dtype=np.float64)
    view = -m[:3, 2] / np.linalg.norm(m[:3, 2])
    d = float(np.dot(np.asarray(point, dtype=np.float64) - m[:3, 3], view))
    return max(abs(d), float(minimum))


VIEW_SENSOR_MM = 36.0  # the sensor width the view's camera is given (any: the field of view is what matters)


def view_camera(view_matrix, window_matrix, width, height, scale_length=1.0):
    """The core Camera that sees what a 3D viewport region shows.

    view_matrix: RegionView3D.view_matrix (world → view); window_matrix: its projection
    (OpenGL convention: perspective when the last row is (0, 0, -1, 0), else orthographic);
    width, height: the region in pixels. The field of view and the off-centre window
    (Blender's camera view with zoom and offset, lens shift) come from the projection:
    perspective P₀₀ = 1/tan(half width angle), P₀₂ = the window centre's tangent × P₀₀;
    orthographic P₀₀ = 2/width (Blender units), P₀₃ = -centre × P₀₀. An orthographic view's
    eye moves back to its near clipping plane (Blender's orthographic views clip symmetrically
    about the view point), so what the viewport shows in front of the view point is seen.
    """
    from ...core import Camera, constants

    w, h = max(1, int(width)), max(1, int(height))
    v = np.asarray(view_matrix, dtype=np.float64)
    p = np.asarray(window_matrix, dtype=np.float64)
    try:
        to_world = np.linalg.inv(v)
    except np.linalg.LinAlgError:
        raise ExportError("the view matrix is singular") from None
    to_world = camera_to_world_metres(to_world, scale_length)
    perspective = abs(p[3, 3]) < 0.5
    if perspective:
        if not (p[0, 0] > 0.0 and p[1, 1] > 0.0):
            raise ExportError("the view's projection is degenerate")
        half_w = 1.0 / p[0, 0]  # tangent of half the horizontal angle
        half_h = 1.0 / p[1, 1]
        cx, cy = p[0, 2] / p[0, 0], p[1, 2] / p[1, 1]  # the window centre's tangents
        extent = 2.0 * max(half_w, half_h)
        return Camera(to_world=to_world, width=w, height=h, lens_mm=0.5 * VIEW_SENSOR_MM / half_w,
                      sensor_width_mm=VIEW_SENSOR_MM, sensor_height_mm=VIEW_SENSOR_MM * h / w,
                      sensor_fit=constants.FIT_HORIZONTAL, shift_x=cx / extent, shift_y=cy / extent)
    half_w = 1.0 / p[0, 0]  # Blender units
    half_h = 1.0 / p[1, 1]
    cx, cy = -p[0, 3] / p[0, 0], -p[1, 3] / p[1, 1]
    extent = 2.0 * max(half_w, half_h)
    near = -(p[2, 3] + 1.0) / p[2, 2]  # view-space z of the near plane (positive: behind the eye)
    if near > 0.0:
        to_world[:3, 3] += to_world[:3, 2] * near * float(scale_length)
    return Camera(to_world=to_world, width=w, height=h, sensor_fit=constants.FIT_HORIZONTAL,
                  projection=constants.CAM_ORTHOGRAPHIC, ortho_scale=2.0 * half_w * float(scale_length),
                  shift_x=cx / extent, shift_y=cy / extent)
