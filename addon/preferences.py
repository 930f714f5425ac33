"""The add-on's preferences (Edit > Preferences > Add-ons > Spectral GI) and the background compile they start.

``register_extra`` starts the background compile (``background.py``) when the add-on is
enabled, unless "Compile Kernels in the Background" is off. It is called inside Blender's
add-on registration, where ``bpy.context`` is restricted but the preferences can be read.
"""
import bpy
from bpy.props import BoolProperty

from . import background

ADDON_PACKAGE = __package__.rpartition(".")[0] or __package__  # spectral_gi, or bl_ext.<repo>.spectral_gi


def _toggled(self, context):
    if self.background_compile:
        background.start()
    else:
        background.switched_off()


class SpectralGIPreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON_PACKAGE

    background_compile: BoolProperty(
        name="Compile Kernels in the Background",
        description="Compile (or load from the cache) the render kernels on a background thread as soon as the "
                    "add-on is enabled, so the first render does not wait for them. Off: the first render "
                    "compiles them",
        default=True, update=_toggled)

    def draw(self, context):
        draw_status(self.layout)
        self.layout.prop(self, "background_compile")


def draw_status(layout):
    """The background compile's status line (preferences and render panel)."""
    layout.label(text=background.status_text(), icon=background.status_icon())


def preferences(context=None):
    """This add-on's preferences, or None (not registered, or not in the preferences yet)."""
    prefs = getattr(context or bpy.context, "preferences", None)
    addon = prefs.addons.get(ADDON_PACKAGE) if prefs is not None else None
    return getattr(addon, "preferences", None)


def background_compile_enabled():
    p = preferences()
    return True if p is None else bool(p.background_compile)


classes = (SpectralGIPreferences,)


def register_extra():
    if not background.AUTOSTART:
        return
    try:
        if background_compile_enabled():
            background.start()
        else:
            background.switched_off()
    except Exception as exc:  # noqa: BLE001 - the add-on works without it: the first render compiles
        background.STATE.phase = background.FAILED
        background.STATE.error = f"{type(exc).__name__}: {exc}"


def unregister_extra():
    background.abandon()
