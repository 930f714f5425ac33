"""Blender lights → core area lights."""
import math

from .convert import (AREA_SHAPES, area_light_geometry, area_light_normalising_area, light_power_watts,
                      light_rgb)


def export_light(ctx, obj, matrix, name):
    """A core Light for evaluated light object ``obj`` placed by ``matrix``, or None (recorded as skipped)."""
    from ...core import Light, area_light_luminance, constants

    data = obj.data
    if data.type != "AREA":
        ctx.skip(f"{data.type.lower()} lights", name)
        return None
    if data.shape not in AREA_SHAPES:
        ctx.skip("area light shapes", f"{name} ({data.shape})")
        return None
    position, axis_u, axis_v, is_ellipse, area = area_light_geometry(
        matrix, data.shape, data.size, data.size_y, ctx.scale_length)
    if not area > 0.0:
        ctx.skip("area lights of zero size", name)
        return None
    if getattr(data, "node_tree", None) is not None and getattr(data, "use_nodes", False):
        ctx.skip("light node trees", name)
    if getattr(data, "spread", math.pi) < math.pi - 1e-6:
        ctx.note(f"{name}: spread ignored (emits over the full hemisphere)")
    power = light_power_watts(data.energy, getattr(data, "exposure", 0.0))
    if power < 0.0:
        ctx.note(f"{name}: negative power treated as 0")
        power = 0.0
    rgb = light_rgb(data.color, getattr(data, "use_temperature", False),
                    getattr(data, "temperature_color", (1.0, 1.0, 1.0)))
    norm_area = area_light_normalising_area(area, getattr(data, "normalize", True), ctx.scale_length)
    return Light(
        name=name,
        kind=constants.LIGHT_ELLIPSE if is_ellipse else constants.LIGHT_RECT,
        position=tuple(float(x) for x in position),
        axis_u=tuple(float(x) for x in axis_u),
        axis_v=tuple(float(x) for x in axis_v),
        spectrum=ctx.emission(f"{name} light", rgb),
        luminance=float(area_light_luminance(power, norm_area, rgb)),
        two_sided=False,
        visible=bool(getattr(obj, "visible_camera", False)),
    )
