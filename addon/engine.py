"""The Spectral GI render engine (F12, animation renders, the compositor's passes).

The class stays thin: the render loop lives in ``render_job.render_with_engine`` and
imports ``core`` (and so numba) only when a render starts. Blender runs ``render()``
on its render thread (the UI stays responsive); the kernels release the GIL.
"""
import bpy

from .imageio import ILLUMINANCE_PASS, enabled_passes, sensors_enabled
from .properties.scene import COLOUR_OUTPUT_PASS
from .export.camera import view_camera
from .render_job import render_with_engine
from .viewport import FINAL_RENDERS, ViewportRenderer

# Blender panels (output, dimensions, colour management, …) drawn for our engine too.
# Lights are drawn by our own light panel (with their photometric units), not Blender's legacy one.
EXCLUDE_PANELS = frozenset({"DATA_PT_light", "DATA_PT_spot", "NODE_DATA_PT_light", "DATA_PT_preview"})
EXCLUDE_PREFIXES = ("VIEWLAYER_PT_freestyle", "RENDER_PT_freestyle", "MATERIAL_PT_freestyle")
# Panels of other engines that show settings the exporter reads: depth of field, the world's node tree.
EXTRA_PANELS = ("DATA_PT_camera_dof", "DATA_PT_camera_dof_aperture", "EEVEE_WORLD_PT_surface")


class SpectralGIRenderEngine(bpy.types.RenderEngine):
    """Spectral path tracer with photometric output (cd/m², lux) in real units."""

    bl_idname = "SPECTRAL_GI"
    bl_label = "Spectral GI"
    bl_use_preview = False  # no material preview renders
    bl_use_postprocess = True  # compositor and sequencer after the render
    bl_use_eevee_viewport = True  # Material Preview in the viewport uses EEVEE
    bl_use_shading_nodes_custom = False  # materials use Blender's shader nodes

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.viewport = None  # ViewportRenderer of a Rendered-mode viewport (addon/viewport.py)
        self.draw_data = None

    def __del__(self):
        vp = getattr(self, "viewport", None)
        if vp is not None:
            vp.stop(wait=0.0)

    def render(self, depsgraph):
        try:
            with FINAL_RENDERS:  # viewports pause while a final render runs
                render_with_engine(self, depsgraph)
        except Exception as exc:  # never let an exception escape into Blender's render job
            import traceback

            traceback.print_exc()
            self.report({"ERROR"}, f"Spectral GI: {type(exc).__name__}: {exc}")

    # ------------------------------------------------------------------ the viewport (Rendered mode)

    def view_update(self, context, depsgraph):
        """A depsgraph change: export what changed; the render restarts on its own thread."""
        try:
            if self.viewport is None:
                from .render_job import engine_threads

                self.viewport = ViewportRenderer(threads=engine_threads(depsgraph.scene))
            self.viewport.sync(depsgraph, region_camera(context, depsgraph.scene))
        except Exception as exc:  # never into Blender's draw loop
            self.report({"ERROR"}, f"Spectral GI: viewport: {type(exc).__name__}: {exc}")

    def view_draw(self, context, depsgraph):
        """Draw the latest image (restarting first if the view moved); redraws until it has converged."""
        vp = self.viewport
        if vp is None:
            return
        try:
            vp.view(region_camera(context, depsgraph.scene))
            frame = vp.frame()  # until the first frame after a change, the previous one stays up
            if frame is not None:
                self.draw_data = ViewportTexture.update(self.draw_data, frame)
            if self.draw_data is not None:
                self.draw_data.draw(self, depsgraph.scene, context.region.width, context.region.height)
            self.update_stats("", vp.status)
            if not vp.converged:
                self.tag_redraw()
        except Exception as exc:
            self.report({"ERROR"}, f"Spectral GI: viewport: {type(exc).__name__}: {exc}")

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        for name, channels, chan_id, kind in enabled_passes(renderlayer):
            self.register_pass(scene, renderlayer, name, channels, chan_id, kind)
        # the image in an output space other than Rec.709 (Combined stays Blender's scene-linear)
        settings = getattr(scene, "spectral_gi", None) if scene is not None else None
        if getattr(settings, "colour_space", "REC709") != "REC709":
            self.register_pass(scene, renderlayer, COLOUR_OUTPUT_PASS, 3, "RGB", "COLOR")
        if sensors_enabled(scene):
            self.register_pass(scene, renderlayer, *ILLUMINANCE_PASS)


def region_camera(context, scene):
    """The core Camera of the 3D viewport region being drawn (its view and projection matrices)."""
    from .export.convert import matrix_to_array

    region, rv3d = context.region, context.region_data
    return view_camera(matrix_to_array(rv3d.view_matrix), matrix_to_array(rv3d.window_matrix), region.width,
                       region.height, scene.unit_settings.scale_length)


class ViewportTexture:
    """The GPU texture of the latest viewport frame, drawn over the region through Blender's
    display transform (``bind_display_space_shader``: view transform, look, exposure)."""

    def __init__(self, frame):
        import gpu

        rgba = frame.rgba[::-1]  # GPU textures start at the bottom row
        h, w = rgba.shape[:2]
        pixels = gpu.types.Buffer("FLOAT", w * h * 4, rgba.ravel())
        self.texture = gpu.types.GPUTexture((w, h), format="RGBA16F", data=pixels)
        self.key = (frame.generation, frame.pixel_size, frame.spp)

    @classmethod
    def update(cls, current, frame):
        if current is not None and current.key == (frame.generation, frame.pixel_size, frame.spp):
            return current
        return cls(frame)

    def draw(self, engine, scene, width, height):
        import gpu
        from gpu_extras.presets import draw_texture_2d

        gpu.state.blend_set("ALPHA_PREMULT")
        engine.bind_display_space_shader(scene)
        draw_texture_2d(self.texture, (0, 0), width, height)  # a coarse frame is stretched over the region
        engine.unbind_display_space_shader()
        gpu.state.blend_set("NONE")


def compat_panels():
    """Blender's generic panels that list the legacy 'BLENDER_RENDER' engine as compatible."""
    panels = []
    for panel in bpy.types.Panel.__subclasses__():
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if engines is not None and "BLENDER_RENDER" in engines and panel.__name__ not in EXCLUDE_PANELS \
                and not panel.__name__.startswith(EXCLUDE_PREFIXES):
            panels.append(panel)
    for name in EXTRA_PANELS:
        panel = getattr(bpy.types, name, None)
        if panel is not None and getattr(panel, "COMPAT_ENGINES", None) is not None and panel not in panels:
            panels.append(panel)
    return panels


classes = (SpectralGIRenderEngine,)


def register_extra():
    for panel in compat_panels():
        panel.COMPAT_ENGINES.add(SpectralGIRenderEngine.bl_idname)


def unregister_extra():
    # Blender's panels only: this add-on's own panels keep their COMPAT_ENGINES (class
    # attributes of modules that stay imported), else they would stay hidden after the
    # add-on is disabled and enabled again in one session
    own = __name__.rsplit(".", 1)[0]
    for panel in bpy.types.Panel.__subclasses__():
        if panel.__module__.startswith(own):
            continue
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if engines is not None and SpectralGIRenderEngine.bl_idname in engines:
            try:
                engines.remove(SpectralGIRenderEngine.bl_idname)
            except (AttributeError, KeyError):
                pass
