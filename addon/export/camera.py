"""The scene's active camera → the core camera."""
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
    from ...core import Camera

    cam_obj = scene.camera
    if cam_obj is None:
        raise ExportError("the scene has no active camera")
    ev = cam_obj.evaluated_get(depsgraph)
    if ev.type != "CAMERA":
        raise ExportError(f"the scene's camera {cam_obj.name!r} is not a camera object")
    data = ev.data
    if data.type != "PERSP":
        raise ExportError(f"camera {cam_obj.name!r}: only perspective cameras are supported "
                          f"(it is {data.type.lower()})")
    if data.dof.use_dof:
        ctx.note(f"{cam_obj.name}: depth of field ignored")
    r = scene.render
    if r.pixel_aspect_x != r.pixel_aspect_y:
        ctx.note("non-square pixel aspect ignored")
    width, height = render_resolution(r.resolution_x, r.resolution_y, r.resolution_percentage)
    return Camera(
        to_world=camera_to_world_metres(matrix_to_array(ev.matrix_world), ctx.scale_length),
        width=width,
        height=height,
        lens_mm=float(data.lens),
        sensor_width_mm=float(data.sensor_width),
        sensor_height_mm=float(data.sensor_height),
        sensor_fit=sensor_fit_tag(data.sensor_fit),
        shift_x=float(data.shift_x),
        shift_y=float(data.shift_y),
    )
