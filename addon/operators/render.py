"""The "Render GI" operator: export on the main thread, render on a worker thread, show progress."""
import bpy

from .. import render_job

TIMER_STEP = 0.2  # seconds between UI updates while rendering


def _redraw(window_manager, types=("PROPERTIES", "IMAGE_EDITOR")):
    for window in getattr(window_manager, "windows", ()):
        if window.screen is None:
            continue
        for area in window.screen.areas:
            if area.type in types:
                area.tag_redraw()


def _set_status(context, text):
    ws = getattr(context, "workspace", None)
    if ws is not None:
        try:
            ws.status_text_set(text)
        except (AttributeError, RuntimeError, TypeError):
            pass


class SPECTRALGI_OT_render(bpy.types.Operator):
    """Render the scene's active camera with the Spectral GI path tracer into the image "Spectral GI Result\""""

    bl_idname = "spectral_gi.render"
    bl_label = "Render GI"
    bl_options = {"REGISTER"}

    _timer = None
    _job = None

    @classmethod
    def poll(cls, context):
        from .. import lux_job

        return context.scene is not None and not render_job.busy() and not lux_job.busy()

    # ------------------------------------------------------------------ shared steps

    def _export(self, context):
        """Export the scene; returns a RenderJob or None (after reporting why)."""
        from ..export import ExportCancelled, export_scene

        render_job.STATE.phase = "Exporting scene"
        render_job.STATE.cancelling = False
        try:
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
        if result.warning:
            self.report({"WARNING"}, f"Spectral GI: {result.warning}")
        settings = getattr(context.scene, "spectral_gi", None)
        threads = settings.threads if settings is not None else 0
        return render_job.RenderJob(result.scene, threads=threads)

    def _conclude(self, context, job):
        img = job.result_image()
        if img is not None:
            from ..imageio import show_in_image_editors

            show_in_image_editors(img, context.window_manager)
        _redraw(context.window_manager)
        if job.error is not None:
            if job.traceback:
                print(job.traceback)
            self.report({"ERROR"}, f"Spectral GI: {job.summary()}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"Spectral GI: {job.summary()}")
        return {"FINISHED"}

    # ------------------------------------------------------------------ synchronous (scripts, background)

    def execute(self, context):
        job = self._export(context)
        if job is None:
            return {"CANCELLED"}
        job.run_sync()
        return self._conclude(context, job)

    # ------------------------------------------------------------------ interactive (modal + worker thread)

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            # No event loop (no timer events): render synchronously.
            return self.execute(context)
        job = self._export(context)
        if job is None:
            return {"CANCELLED"}
        self._job = job
        job.start()
        wm = context.window_manager
        self._timer = wm.event_timer_add(TIMER_STEP, window=context.window)
        wm.modal_handler_add(self)
        _set_status(context, render_job.status_line())
        _redraw(wm)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        job = self._job
        if event.type == "ESC" and event.value == "PRESS":
            job.request_cancel()
            _set_status(context, render_job.status_line())
            return {"RUNNING_MODAL"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        try:
            done = job.poll()
        except Exception as exc:  # an image update failed: stop cleanly, keep Blender alive
            job.request_cancel()
            job.error = job.error or f"{type(exc).__name__}: {exc}"
            done = job.finished
            if done:
                job.conclude()
        if not done:
            _set_status(context, render_job.status_line())
            _redraw(context.window_manager)
            return {"PASS_THROUGH"}
        self._cleanup(context)
        return self._conclude(context, job)

    def cancel(self, context):
        # Blender ends the modal operator (new file, quit): stop the worker after its current pass.
        if self._job is not None:
            self._job.request_cancel()
        self._cleanup(context)

    def _cleanup(self, context):
        if self._timer is not None:
            context.window_manager.event_timer_remove(self._timer)
            self._timer = None
        _set_status(context, None)
