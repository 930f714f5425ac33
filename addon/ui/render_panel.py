"""Properties > Render and View Layer: the Spectral GI panels.

``SPECTRALGI_PT_render`` is shown whatever the render engine (the Render GI button works
with any engine selected); the settings panels follow Blender's COMPAT_ENGINES pattern
and appear when the render engine is Spectral GI.
"""
import math

import bpy

from .. import background, render_job
from ..export.convert import render_resolution
from ..preferences import draw_status

ENGINE = "SPECTRAL_GI"


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
        is_engine = context.scene.render.engine == ENGINE

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
        if background.STATE.phase in (background.COMPILING, background.FAILED) or not state.message:
            draw_status(layout)  # the background compile (once a render has run, its outcome says more)

        if settings is not None and not is_engine:
            # with Spectral GI as the render engine, the Sampling panel below shows these
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

        row = layout.row()
        row.enabled = not running
        row.operator("spectral_gi.compare_cycles", text="Compare with Cycles", icon="IMAGE_REFERENCE")
        if settings is not None and getattr(settings, "compare_valid", False):
            box = layout.box()
            box.label(text="Spectral GI vs Cycles", icon="GRAPH")
            box.label(text=f"Mean luminance ratio: {settings.compare_luminance_ratio:.4f}")
            box.label(text=f"Relative RMSE (luminance): {settings.compare_relative_rmse:.4f}")
            box.label(text=f"ΔE00 mean {settings.compare_delta_e_mean:.2f}, "
                           f"95th percentile {settings.compare_delta_e_p95:.2f}")
            if settings.compare_report_path:
                box.label(text=f"Report: {bpy.path.basename(settings.compare_report_path)}", icon="FILE")
        layout.operator("spectral_gi.add_cornell_box", icon="MESH_CUBE")


class SpectralGIEnginePanel:
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES and getattr(context.scene, "spectral_gi", None) is not None


class SPECTRALGI_PT_sampling(SpectralGIEnginePanel, bpy.types.Panel):
    bl_idname = "SPECTRALGI_PT_sampling"
    bl_label = "Sampling"

    def draw(self, context):
        s = context.scene.spectral_gi
        col = self.layout.column()
        col.use_property_split = True
        col.use_property_decorate = False
        col.prop(s, "samples")
        col.prop(s, "viewport_samples")
        col.prop(s, "use_denoise")
        col.prop(s, "max_bounces")
        col.prop(s, "sampler")
        row = col.row(align=True)
        row.prop(s, "seed")
        row.prop(s, "use_animated_seed", text="", icon="TIME")
        col.separator()
        col.prop(s, "time_limit")
        col.prop(s, "noise_target")
        col.prop(s, "threads")


class SPECTRALGI_PT_film(SpectralGIEnginePanel, bpy.types.Panel):
    bl_idname = "SPECTRALGI_PT_film"
    bl_label = "Film"

    def draw(self, context):
        s = context.scene.spectral_gi
        col = self.layout.column()
        col.use_property_split = True
        col.use_property_decorate = False
        col.prop(s, "pixel_filter")
        col.prop(s, "filter_width")
        col.prop(s, "white_balance")
        col.prop(context.scene.render, "film_transparent", text="Transparent")
        col.label(text="Combined: linear Rec.709; RGB 1 = 683 cd/m²", icon="INFO")
        draw_colour_settings(col, s)
        col.prop(s, "hair_sides")


def draw_colour_settings(col, s):
    """Colour output, observer and Fourier order (also used by tests with a mock layout)."""
    col.separator()
    col.prop(s, "colour_space")
    if getattr(s, "colour_space", "REC709") != "REC709":
        col.label(text="Written to the Colour Output pass and EXR files", icon="INFO")
    col.prop(s, "observer")
    col.prop(s, "fourier_order")


class SPECTRALGI_PT_sensors(SpectralGIEnginePanel, bpy.types.Panel):
    """Illuminance sensors: the option, the sensor objects and the last render's statistics (lux)."""

    bl_idname = "SPECTRALGI_PT_sensors"
    bl_label = "Sensors"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_header(self, context):
        self.layout.prop(context.scene.spectral_gi, "use_sensors", text="")

    def draw(self, context):
        s = context.scene.spectral_gi
        layout = self.layout
        col = layout.column()
        col.active = s.use_sensors
        sensors = [o.name for o in context.scene.objects if getattr(o, "spectral_gi_sensor", False)]
        if sensors:
            col.label(text=f"Sensor objects: {len(sensors)} ({', '.join(sensors[:3])}"
                           f"{', …' if len(sensors) > 3 else ''})", icon="LIGHT_SUN")
        else:
            col.label(text="No sensor objects: mark them in Object properties", icon="ERROR")
        col.label(text="Illuminance pass in lux (0 off the sensors)")
        stats = render_job.STATE.illuminance
        if stats:
            box = layout.box()
            box.label(text="Last render (pixel statistics)", icon="GRAPH")
            excluded = int(stats.get("excluded", 0))
            if stats.get("pixels"):
                box.label(text=f"Em (mean): {stats['Em']:.4g} lx")
                box.label(text=f"Emin: {stats['Emin']:.4g} lx    Emax: {stats['Emax']:.4g} lx")
                box.label(text=f"U0 = Emin / Em: {stats['U0']:.3f}    ({stats['pixels']} px)")
                if math.isfinite(stats.get("Emin_std", float("nan"))):
                    box.label(text=f"Emin pixel's standard error: {stats['Emin_std']:.2g} lx")
            elif excluded:
                box.label(text="No pixel was fully on a sensor")
            else:
                box.label(text="No sensor surface was in view")
            if excluded:
                box.label(text=f"{excluded} partly covered px (outlines, contact lines) excluded")
            box.label(text="Area-weighted only for an orthographic top view", icon="INFO")


class SPECTRALGI_PT_object(bpy.types.Panel):
    """Object properties: the illuminance-sensor flag and Blender's holdout (both read by the export)."""

    bl_idname = "SPECTRALGI_PT_object"
    bl_label = "Spectral GI"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        obj = context.object
        return (context.engine in cls.COMPAT_ENGINES and obj is not None and obj.type in
                ("MESH", "CURVE", "SURFACE", "FONT", "META", "LIGHT") and hasattr(obj, "spectral_gi_sensor"))

    def draw(self, context):
        obj = context.object
        col = self.layout.column()
        col.use_property_split = True
        col.use_property_decorate = False
        if obj.type != "LIGHT":
            col.prop(obj, "spectral_gi_sensor")
            col.prop(obj, "is_holdout")
        # Blender's ray visibility (Cycles' panel is shown for Cycles only); light linking is
        # under Object > Shading
        col.prop(obj, "visible_camera", text="Ray Visibility Camera")
        for prop, label in (("visible_diffuse", "Diffuse"), ("visible_glossy", "Glossy"),
                            ("visible_transmission", "Transmission"), ("visible_volume_scatter", "Volume Scatter")):
            col.prop(obj, prop, text=label)
        if obj.type != "LIGHT":
            col.prop(obj, "visible_shadow", text="Shadow")


class SPECTRALGI_PT_passes(bpy.types.Panel):
    bl_idname = "SPECTRALGI_PT_passes"
    bl_label = "Spectral GI Passes"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "view_layer"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES and getattr(context.view_layer, "spectral_gi", None) is not None

    def draw(self, context):
        from ..properties.scene import PASSES

        s = context.view_layer.spectral_gi
        col = self.layout.column(heading="Include", align=True)
        col.use_property_split = True
        col.use_property_decorate = False
        col.label(text="Combined (linear Rec.709 RGBA) is always written")
        for prop, *_rest in PASSES:
            col.prop(s, prop)


classes = (SPECTRALGI_PT_render, SPECTRALGI_PT_sampling, SPECTRALGI_PT_film, SPECTRALGI_PT_sensors,
           SPECTRALGI_PT_passes, SPECTRALGI_PT_object)
