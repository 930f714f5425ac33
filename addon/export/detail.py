"""The scene as a render evaluates it, for exports that run outside one.

F12 exports from the render's own depsgraph, which Blender evaluates at render detail. Render
GI, Compare with Cycles and the lighting analysis run as operators and have only the
viewport's depsgraph, which evaluates subdivision at its viewport levels, hair at its display
amounts, curves and metaballs at their viewport resolutions, and leaves out what is hidden
in the viewport but renders. ``render_detail(scene)`` is a context manager that sets those
settings to their render values (as Cycles would see them) for the time of the export and
puts every one back afterwards, also on an error or a cancel::

    with render_detail(scene, view_layer):
        result = export_scene(context.evaluated_depsgraph_get(), scene)

The depsgraph is to be taken inside the block: taking it evaluates the changed settings.
"""
from contextlib import contextmanager

PARTICLE_DETAIL = (("display_percentage", lambda s: 100), ("child_percent", lambda s: s.rendered_child_count),
                   ("display_step", lambda s: s.render_step))
LEVEL_MODIFIERS = ("SUBSURF", "MULTIRES")


class Overrides:
    """Set attributes and put every one back afterwards (also on errors), in reverse order."""

    def __init__(self):
        self._saved = []

    def set(self, owner, attr, value):
        """Set owner.attr to value (remembering the old value); False where it has no such
        attribute or refuses the value."""
        if owner is None or not hasattr(owner, attr):
            return False
        old = getattr(owner, attr)
        if old == value:
            return True
        self._saved.append((owner, attr, old))
        try:
            setattr(owner, attr, value)
        except (TypeError, ValueError, AttributeError):
            self._saved.pop()
            return False
        return True

    def unhide(self, obj, view_layer):
        """Show an object hidden in the view layer (the eye), to hide again on restore."""
        try:
            if obj.hide_get(view_layer=view_layer):
                obj.hide_set(False, view_layer=view_layer)
                self._saved.append((obj, None, view_layer))
        except (RuntimeError, TypeError, ReferenceError):
            pass

    def restore(self):
        for owner, attr, value in reversed(self._saved):
            try:
                if attr is None:
                    owner.hide_set(True, view_layer=value)
                else:
                    setattr(owner, attr, value)
            except (TypeError, ValueError, AttributeError, ReferenceError, RuntimeError):
                pass
        self._saved.clear()


def _layer_collections(lc):
    yield lc
    for child in lc.children:
        yield from _layer_collections(child)


def apply_render_detail(ov, scene, view_layer=None):
    """Set on ``ov`` (an :class:`Overrides`) the scene's render detail, as the module says."""
    view_layer = view_layer or scene.view_layers[0]
    for lc in _layer_collections(view_layer.layer_collection):
        coll = lc.collection
        if lc.exclude or coll.hide_render:
            continue
        ov.set(lc, "hide_viewport", False)
        ov.set(coll, "hide_viewport", False)
    for obj in scene.objects:
        if obj.hide_render:
            continue
        ov.set(obj, "hide_viewport", False)
        ov.unhide(obj, view_layer)
        for mod in obj.modifiers:
            ov.set(mod, "show_viewport", bool(mod.show_render))
            if mod.type in LEVEL_MODIFIERS:
                ov.set(mod, "levels", int(mod.render_levels))
            if mod.type == "PARTICLE_SYSTEM":
                settings = mod.particle_system.settings
                for attr, value in PARTICLE_DETAIL:
                    if hasattr(settings, attr):
                        ov.set(settings, attr, value(settings))
        data = obj.data
        if obj.type in ("CURVE", "SURFACE", "FONT") and data is not None:
            for axis in ("u", "v"):
                r = getattr(data, f"render_resolution_{axis}", 0)
                if r:  # 0: the render uses the viewport's resolution
                    ov.set(data, f"resolution_{axis}", int(r))
        if obj.type == "META" and data is not None and data.render_resolution > 0:
            ov.set(data, "resolution", float(data.render_resolution))


@contextmanager
def render_detail(scene, view_layer=None):
    """Within the block the viewport evaluates ``scene`` at render detail (see the module)."""
    ov = Overrides()
    try:
        apply_render_detail(ov, scene, view_layer)
        yield ov
    finally:
        ov.restore()
