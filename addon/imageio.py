"""Arrays ↔ Blender images. Main thread only."""
from .export.convert import rgba_rows_bottom_up

RESULT_IMAGE = "Spectral GI Result"
SCENE_LINEAR = "Linear Rec.709"


def result_image(width, height, name=RESULT_IMAGE):
    """The float, scene-linear image ``name`` of the given size (created or resized as needed)."""
    import bpy

    img = bpy.data.images.get(name)
    if img is not None and img.source != "GENERATED":
        img = None  # a loaded file with our name: leave it alone, make a new image
    if img is None:
        img = bpy.data.images.new(name, width=width, height=height, alpha=True, float_buffer=True)
    else:
        if not img.use_generated_float:
            img.use_generated_float = True
        if tuple(img.size) != (width, height):
            img.generated_width = width
            img.generated_height = height
            if tuple(img.size) != (width, height):
                img.scale(width, height)
    try:
        img.colorspace_settings.name = SCENE_LINEAR
    except TypeError:
        pass  # a colour configuration without this name: keep the default for float images
    return img


def write_rgb(rgb, name=RESULT_IMAGE):
    """Write an (H, W, 3) linear Rec.709 array (rows top-to-bottom) into image ``name``; returns the image."""
    h, w = int(rgb.shape[0]), int(rgb.shape[1])
    img = result_image(w, h, name)
    img.pixels.foreach_set(rgba_rows_bottom_up(rgb))
    img.update()
    return img


def show_in_image_editors(img, window_manager):
    """Show ``img`` in every open Image Editor; returns how many editors now show it."""
    n = 0
    for window in getattr(window_manager, "windows", ()):
        screen = window.screen
        if screen is None:
            continue
        for area in screen.areas:
            if area.type == "IMAGE_EDITOR":
                area.spaces.active.image = img
                area.tag_redraw()
                n += 1
    return n


# ----------------------------------------------------------------------------- render passes

# Blender pass name → (channels, channel ids, type, view layer property, attribute of core's Developed)
PASS_SPECS = (
    ("XYZ", 3, "XYZ", "COLOR", "use_pass_xyz", "XYZ"),
    ("Luminance", 1, "Y", "VALUE", "use_pass_luminance", "luminance"),
    ("Lab", 3, "LAB", "COLOR", "use_pass_lab", "Lab"),
    ("Variance", 1, "V", "VALUE", "use_pass_variance", "variance"),
    ("Albedo", 3, "RGB", "COLOR", "use_pass_albedo", "albedo"),
    ("Normal", 3, "XYZ", "VECTOR", "use_pass_normal", "normal"),
    ("Depth", 1, "Z", "VALUE", "use_pass_depth", "depth"),
)
NO_HIT_DEPTH = 1e10  # metres written for camera rays that hit nothing (Blender's Depth pass convention)


def enabled_passes(view_layer):
    """[(name, channels, chan_id, type)] of the Spectral GI passes enabled on ``view_layer`` (besides Combined)."""
    settings = getattr(view_layer, "spectral_gi", None) if view_layer is not None else None
    if settings is None:
        return []
    return [(name, n, chan, kind) for name, n, chan, kind, prop, _attr in PASS_SPECS if getattr(settings, prop, False)]


def pass_arrays(developed, names):
    """{pass name: (H, W, C) float32 array, rows top-to-bottom} for Combined and the passes in ``names``.

    Combined is linear Rec.709 with the core's alpha (``developed.alpha``: the fraction of
    samples that neither saw a holdout nor, with Film > Transparent, missed everything),
    premultiplied as Cycles' (transparent samples carry no radiance). Depth is
    ``NO_HIT_DEPTH`` where no camera ray hit anything.
    """
    import numpy as np

    rgb = np.asarray(developed.rgb)
    h, w = rgb.shape[:2]
    out = {}
    combined = np.empty((h, w, 4), dtype=np.float32)
    combined[..., :3] = rgb
    combined[..., 3] = np.asarray(developed.alpha).reshape(h, w)
    out["Combined"] = combined
    specs = {s[0]: s for s in PASS_SPECS}
    for name in names:
        _n, channels, _chan, _kind, _prop, attr = specs[name]
        a = np.asarray(getattr(developed, attr), dtype=np.float32).reshape(h, w, channels)
        if name == "Depth":
            a = np.where(np.isfinite(a), a, np.float32(NO_HIT_DEPTH)).astype(np.float32)
        out[name] = a
    return out


ILLUMINANCE_PASS = ("Illuminance", 1, "X", "VALUE")  # lux on the sensor objects; 0 elsewhere


def sensors_enabled(scene):
    """True when the scene asks for the Illuminance pass (Render properties > Sensors)."""
    settings = getattr(scene, "spectral_gi", None) if scene is not None else None
    return bool(getattr(settings, "use_sensors", False))


def illuminance_pass(lux):
    """(H, W, 1) float32 of the core's lux image (NaN where no sensor was seen → 0)."""
    import numpy as np

    a = np.asarray(lux, dtype=np.float64)
    return np.where(np.isfinite(a), a, 0.0).astype(np.float32)[..., None]


def rows_bottom_up(a):
    """(H, W, C) array with rows top-to-bottom → flat float32, rows bottom-up (Blender's order)."""
    import numpy as np

    return np.ascontiguousarray(np.asarray(a, dtype=np.float32)[::-1]).reshape(-1)


def write_result_passes(layer, arrays):
    """Copy ``arrays`` ({pass name: (H, W, C)}) into the render result layer's passes that exist."""
    for name, a in arrays.items():
        rp = layer.passes.find_by_name(name, "")
        if rp is not None:
            rp.rect.foreach_set(rows_bottom_up(a))
