"""Properties > Object > Spectral GI Lighting Analysis: calculation surface settings and results table."""
import bpy


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
        sub.prop(s, "maintenance_factor")
        sub.prop(s, "samples")
        sub.prop(s, "rel_error")
        row = layout.row(align=True)
        row.operator("spectral_gi.lux_calculate", icon="LIGHT_SUN")
        row.operator("spectral_gi.lux_add_workplane", icon="MESH_GRID")
        layout.prop(context.scene, "spectral_gi_workplane_height")
        if s.valid:
            box = layout.box()
            box.label(text="Results (maintained, lx)", icon="GRAPH")
            grid = box.grid_flow(row_major=True, columns=2, even_columns=True)
            for name, value in (("Ē", f"{s.mean:.4g} lx"), ("Emin", f"{s.minimum:.4g} lx"),
                                ("Emax", f"{s.maximum:.4g} lx"), ("U0 = Emin/Ē", f"{s.u0:.2f}"),
                                ("Ud = Emin/Emax", f"{s.ud:.2f}"), ("Points", str(s.n_points)),
                                ("Spacing", f"{s.spacing_u:.3f} × {s.spacing_v:.3f} m"),
                                ("Band", f"{s.band_used:.2f} m"), ("MF", f"{s.mf_used:.3f}"),
                                ("Samples", str(s.samples_used)), ("Max rel. error", f"{100 * s.max_rel_error:.2f} %")):
                grid.label(text=name)
                grid.label(text=value)
            if s.result_object:
                box.label(text=f"False colour on {s.result_object!r}", icon="COLOR")
        layout.prop(context.scene, "spectral_gi_report_dir")
        layout.operator("spectral_gi.lux_export_report", icon="FILE")
        if not has_matplotlib():
            layout.label(text="The PNG/PDF page needs the 'analysis' extra (matplotlib)", icon="INFO")


classes = (SPECTRALGI_PT_lux,)
