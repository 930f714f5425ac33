"""Lighting analysis panels: Properties > Object > Spectral GI Lighting Analysis (a surface's settings and
its results table) and the 3D Viewport's sidebar > Spectral GI > Lighting (the scene's surfaces, the
one-click report)."""
import bpy


def _progress(layout):
    from .. import lux_job

    st = lux_job.STATE
    if st.running:
        layout.label(text=lux_job.lux_status_line(), icon="TIME")
        if st.total:
            layout.progress(factor=min(1.0, st.done / st.total), text=f"{100 * st.done / st.total:.0f} %")
        return True
    if st.message:
        layout.label(text=st.message, icon="INFO")
    return False


def result_rows(s):
    """(label, value) rows of a surface's stored result, as the report's statistics table."""
    rows = [("Ē (maintained)", f"{s.mean:.4g} lx"), ("Emin", f"{s.minimum:.4g} lx"), ("Emax", f"{s.maximum:.4g} lx"),
            ("U0 = Emin/Ē", f"{s.u0:.2f}"), ("Ud = Emin/Emax", f"{s.ud:.2f}")]
    if s.grid_cols:
        rows.append(("Grid", f"{s.grid_cols} × {s.grid_rows}"))
        rows.append(("Spacing", f"{s.spacing_u:.3f} × {s.spacing_v:.3f} m"))
    rows += [("Points", str(s.n_points)), ("Area", f"{s.area:.2f} m²"), ("Band", f"{s.band_used:.2f} m"),
             ("MF", f"{s.mf_used:.3f}"), ("Samples per point", str(s.samples_used)),
             ("Std. error max / mean", f"{100 * s.max_rel_error:.2f} / {100 * s.mean_rel_error:.2f} %"),
             ("Colour scale", f"{s.scale_min:.4g} – {s.scale_max:.4g} lx, {'log' if s.scale_log else 'linear'}, "
                              f"{s.scale_steps or 'continuous'}{' steps' if s.scale_steps else ''}")]
    if s.unlit_points:
        rows.append(("Points outside", f"{s.unlit_points} (see the report's unlit_points)"))
    return rows


def _overlay(layout, s):
    """The false-colour scale's settings."""
    col = layout.column()
    col.use_property_split = True
    col.use_property_decorate = False
    col.prop(s, "scale_auto")
    sub = col.column(align=True)
    sub.active = not s.scale_auto
    sub.prop(s, "scale_fixed_min")
    sub.prop(s, "scale_fixed_max")
    col.prop(s, "scale_log")
    col.prop(s, "scale_steps")


def radiosity_settings(layout, scene):
    """The method choice and, with Radiosity, its patch size, overlay, range and legend."""
    from ..operators.lux import radiosity_legend

    col = layout.column()
    col.use_property_split = True
    col.use_property_decorate = False
    col.prop(scene, "spectral_gi_lux_method")
    if scene.spectral_gi_lux_method != "RADIOSITY":
        return
    r = scene.spectral_gi_radiosity
    box = layout.box()
    box.label(text="Radiosity (diffuse surfaces only)", icon="LIGHT_AREA")
    sub = box.column()
    sub.use_property_split = True
    sub.use_property_decorate = False
    sub.prop(r, "max_edge")
    sub.prop(r, "quantity")
    sub.prop(r, "overlay")
    _overlay(box, scene.spectral_gi_radiosity_scale)
    if r.objects:
        box.label(text=f"{r.patches} patches, overlay on {len(r.objects.splitlines())} object(s)", icon="COLOR")
        legend = box.column(align=True)
        for k, (_colour, label) in reversed(list(enumerate(radiosity_legend(scene)))):
            legend.label(text=f"step {k + 1}: {label}")
        box.operator("spectral_gi.radiosity_recolour", icon="COLOR")
    if r.warning:
        for line in r.warning.split("; "):
            box.label(text=line, icon="ERROR")


def _images(layout, s):
    row = layout.row(align=True)
    for img, label, icon in ((s.plan_image, "Show Plan", "IMAGE_DATA"), (s.report_image, "Show Report", "FILE_IMAGE")):
        if img is not None:
            row.operator("spectral_gi.lux_show_image", text=label, icon=icon).image = img.name


class SPECTRALGI_PT_lux(bpy.types.Panel):
    bl_idname = "SPECTRALGI_PT_lux"
    bl_label = "Spectral GI Lighting Analysis"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        obj = context.object
        return obj is not None and obj.type == "MESH" and hasattr(obj, "spectral_gi_lux")

    def draw(self, context):
        from ..operators.lux import has_matplotlib

        layout = self.layout
        s = context.object.spectral_gi_lux
        col = layout.column()
        col.use_property_split = True
        col.use_property_decorate = False
        col.prop(s, "enabled")
        sub = col.column()
        sub.active = s.enabled
        sub.prop(s, "kind")
        if s.kind == "GRID":
            sub.prop(s, "spacing_mode")
            if s.spacing_mode == "USER":
                sub.prop(s, "spacing")
            sub.prop(s, "band")
            sub.prop(s, "workplane")
        sub.prop(s, "maintenance_factor")
        sub.prop(s, "samples")
        sub.prop(s, "rel_error")
        _overlay(sub, s)
        radiosity_settings(layout, context.scene)
        row = layout.row(align=True)
        row.operator("spectral_gi.lux_calculate", icon="LIGHT_SUN")
        row.operator("spectral_gi.lux_add_workplane", icon="MESH_GRID")
        col = layout.column(align=True)
        col.use_property_split = True
        col.prop(context.scene, "spectral_gi_workplane_height")
        col.prop(context.scene, "spectral_gi_use_band")
        sub = col.column()
        sub.active = context.scene.spectral_gi_use_band
        sub.prop(context.scene, "spectral_gi_workplane_band")
        _progress(layout)
        if s.valid:
            box = layout.box()
            box.label(text="Results (maintained, lx)", icon="GRAPH")
            grid = box.grid_flow(row_major=True, columns=2, even_columns=True)
            for name, value in result_rows(s):
                grid.label(text=name)
                grid.label(text=value)
            if s.unlit_points:
                box.label(text=f"{s.unlit_points} points look outside the lit geometry", icon="ERROR")
            if s.result_object:
                box.label(text=f"False colour on {s.result_object!r}", icon="COLOR")
            box.operator("spectral_gi.lux_recolour", icon="COLOR")
            _images(box, s)
        layout.prop(context.scene, "spectral_gi_report_dir")
        row = layout.row(align=True)
        row.operator("spectral_gi.lux_export_report", icon="FILE")
        row.operator("spectral_gi.lux_report", icon="DOCUMENTS")
        if not has_matplotlib():
            layout.label(text="No matplotlib in Blender: CSV, JSON and plan only (no PNG/PDF page)", icon="INFO")


class SPECTRALGI_PT_lux_view3d(bpy.types.Panel):
    bl_idname = "SPECTRALGI_PT_lux_view3d"
    bl_label = "Lighting"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Spectral GI"

    def draw(self, context):
        from ..operators.lux import marked_objects

        layout = self.layout
        layout.operator("spectral_gi.lux_report", icon="DOCUMENTS")
        radiosity_settings(layout, context.scene)
        row = layout.row(align=True)
        row.operator("spectral_gi.lux_calculate", icon="LIGHT_SUN")
        row.operator("spectral_gi.lux_add_workplane", icon="MESH_GRID")
        _progress(layout)
        for obj in marked_objects(context.scene):
            s = obj.spectral_gi_lux
            box = layout.box()
            box.label(text=obj.name, icon="MESH_GRID")
            if not s.valid:
                box.label(text="Not calculated")
                continue
            box.label(text=f"Ē {s.mean:.4g} lx   Emin {s.minimum:.4g} lx   U0 {s.u0:.2f}")
            box.label(text=f"Emax {s.maximum:.4g} lx   Emin/Emax {s.ud:.2f}   MF {s.mf_used:.2f}")
            _images(box, s)


classes = (SPECTRALGI_PT_lux, SPECTRALGI_PT_lux_view3d)
