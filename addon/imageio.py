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
