"""Properties > Render: the Spectral GI panel (shown whatever the render engine)."""
import bpy

from .. import render_job
from ..export.convert import render_resolution


class SPECTRALGI_PT_render(bpy.types.Panel):
    bl_idname = "SPECTRALGI_PT_render"
    bl_label = "Spectral GI"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"

    def draw(self, context):
        layout = self.layout
        settings = getattr(context.scene, "spectral_gi", None)
        state = render_job.STATE
        running = render_job.busy()

        row = layout.row(align=True)
        row.scale_y = 1.4
        row.enabled = not running
        row.operator("spectral_gi.render", text="Render GI", icon="RENDER_STILL")

        if running:
            box = layout.box()
            box.label(text=state.phase or "Rendering", icon="TIME")
            if state.total:
                box.label(text=f"Samples: {state.done} / {state.total}")
            if state.rate > 0.0:
                box.label(text=f"{state.rate / 1e6:.2f} M samples/s")
            box.label(text="Cancelling…" if state.cancelling else "Press Esc to cancel (keeps the image so far)",
                      icon="CANCEL")
        elif state.message:
            layout.label(text=state.message, icon="INFO")

        if settings is not None:
            col = layout.column()
            col.use_property_split = True
            col.use_property_decorate = False
            col.enabled = not running
            col.prop(settings, "samples")
            col.prop(settings, "max_bounces")
            col.prop(settings, "seed")
            col.prop(settings, "threads")
            r = context.scene.render
            w, h = render_resolution(r.resolution_x, r.resolution_y, r.resolution_percentage)
            col.label(text=f"Resolution: {w} × {h} px (Output properties)")
        layout.operator("spectral_gi.add_cornell_box", icon="MESH_CUBE")


classes = (SPECTRALGI_PT_render,)
