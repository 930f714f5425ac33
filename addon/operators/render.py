"""The "Render GI" operator: export on the main thread, render on a worker thread, show progress."""
import bpy

from .. import render_job
from ..jobs import ModalJobOperator, redraw


class SPECTRALGI_OT_render(ModalJobOperator, bpy.types.Operator):
    """Render the scene's active camera with the Spectral GI path tracer into the image "Spectral GI Result\""""

    bl_idname = "spectral_gi.render"
    bl_label = "Render GI"
    bl_options = {"REGISTER"}

    def _prepare(self, context):
        """Export the scene; returns a RenderJob or None (after reporting why)."""
        from ..export import ExportCancelled, export_scene
        from ..export.detail import render_detail

        render_job.STATE.phase = "Exporting scene"
        render_job.STATE.cancelling = False
        try:
            with render_detail(context.scene, context.view_layer):  # what F12 renders, not the viewport's detail
                result = export_scene(context.evaluated_depsgraph_get(), context.scene,
                                      should_cancel=lambda: render_job.STATE.cancelling)
        except ExportCancelled:
            self.report({"INFO"}, "Spectral GI: export cancelled")
            return None
        except Exception as exc:  # never let an export problem take Blender down
            import traceback

            traceback.print_exc()
            self.report({"ERROR"}, f"Spectral GI: cannot export the scene: {exc}")
            return None
        settings = getattr(context.scene, "spectral_gi", None)
        job = render_job.RenderJob(result.scene, threads=settings.threads if settings is not None else 0)
        job.warning = result.warning
        return job

    def _conclude(self, context, job):
        img = job.result_image()
        if img is not None:
            from ..imageio import show_in_image_editors

            show_in_image_editors(img, context.window_manager)
        redraw(context.window_manager)
        if job.error is not None:
            if job.traceback:
                print(job.traceback)
            self.report({"ERROR"}, f"Spectral GI: {job.summary()}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"Spectral GI: {job.summary()}")
        if job.dropped_warning:
            self.report({"WARNING"}, f"Spectral GI: {job.dropped_warning}")
        return {"FINISHED"}
