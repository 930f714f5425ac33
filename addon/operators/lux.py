"""Lighting analysis: Add Work Plane, Calculate Illuminance, Export Report (calculation surfaces in lx)."""
import os

import bpy

CHUNK = 256  # points per call of the integrator, so the UI gets progress between chunks
ATTRIBUTE = "Spectral GI lux"
MATERIAL = "Spectral GI False Colour"


class LuxInputError(ValueError):
    """A calculation surface that cannot be calculated (reported, never raised to Blender)."""


def _world_mesh(obj):
    """(positions (V, 3) world metres, triangles (T, 3)) of the evaluated mesh."""
    import numpy as np

    me = obj.data
    me.calc_loop_triangles()
    v = np.empty(len(me.vertices) * 3)
    me.vertices.foreach_get("co", v)
    t = np.empty(len(me.loop_triangles) * 3, dtype=np.int64)
    me.loop_triangles.foreach_get("vertices", t)
    m = np.array(obj.matrix_world)
    pos = v.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]
    scale = bpy.context.scene.unit_settings.scale_length or 1.0
    return pos * scale, t.reshape(-1, 3)


def build_surface(obj):
    """The core CalculationSurface of a marked mesh object (world coordinates, metres)."""
    from ...core import lux

    s = obj.spectral_gi_lux
    if obj.type != "MESH":
        raise LuxInputError(f"{obj.name!r} is not a mesh")
    pos, tri = _world_mesh(obj)
    if tri.shape[0] == 0:
        raise LuxInputError(f"{obj.name!r} has no faces")
    try:
        if s.kind == "GRID":
            spacing = None if s.spacing_mode == "AUTO" else float(s.spacing)
            return lux.face_set_grid(pos, tri, name=obj.name, spacing=spacing, band=float(s.band),
                                     maintenance_factor=float(s.maintenance_factor))
        if s.kind == "VERTICES":
            return lux.mesh_vertex_points(pos, tri, name=obj.name, maintenance_factor=float(s.maintenance_factor))
        return lux.mesh_face_points(pos, tri, name=obj.name, maintenance_factor=float(s.maintenance_factor))
    except lux.LuxError as exc:
        raise LuxInputError(str(exc)) from None


def marked_objects(scene):
    return [o for o in scene.objects if o.type == "MESH" and getattr(o, "spectral_gi_lux", None) is not None
            and o.spectral_gi_lux.enabled]


def calculate_points(core_scene, surface, spp, rel_error, progress=None, seed=None):
    """Initial lux, standard errors and samples at the surface's points, CHUNK points at a time."""
    import numpy as np

    from ... import core

    lux, se, used = [], [], []
    n = surface.n_points
    for a in range(0, n, CHUNK):
        b = min(n, a + CHUNK)
        e, s, c = core.point_illuminance(core_scene, surface.points[a:b], surface.normals[a:b], spp=int(spp),
                                         rel_error=rel_error or None, seed=seed)
        lux.append(e)
        se.append(s)
        used.append(c)
        if progress is not None:
            progress(b, n)
    return np.concatenate(lux), np.concatenate(se), np.concatenate(used)


def _grid_object(obj, surface):
    """A new mesh object "<surface> lux grid" with one face per grid cell (same order as the points)."""
    import numpy as np

    du, dv = surface.spacing
    cols = surface.grid_shape[1]
    j, i = np.divmod(surface.grid_index, cols)
    scale = bpy.context.scene.unit_settings.scale_length or 1.0
    verts, faces = [], []
    for k in range(surface.n_points):
        c = surface.origin + i[k] * du * surface.axis_u + j[k] * dv * surface.axis_v
        quad = [c, c + du * surface.axis_u, c + du * surface.axis_u + dv * surface.axis_v, c + dv * surface.axis_v]
        faces.append(tuple(range(len(verts), len(verts) + 4)))
        verts.extend(tuple(float(x) / scale for x in q + 1e-3 * surface.normals[k]) for q in quad)
    name = f"{obj.name} lux grid"
    old = bpy.data.objects.get(name)
    if old is not None:
        bpy.data.objects.remove(old, do_unlink=True)
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    me.update()
    grid = bpy.data.objects.new(name, me)
    grid.hide_render = True  # a result display, not part of the lit scene
    for coll in obj.users_collection or (bpy.context.scene.collection,):
        coll.objects.link(grid)
    return grid


def _material():
    mat = bpy.data.materials.get(MATERIAL)
    if mat is None:
        mat = bpy.data.materials.new(MATERIAL)
        if mat.node_tree is None:
            mat.use_nodes = True
        tree = mat.node_tree
        tree.nodes.clear()
        out = tree.nodes.new("ShaderNodeOutputMaterial")
        attr = tree.nodes.new("ShaderNodeAttribute")
        attr.attribute_name = ATTRIBUTE
        em = tree.nodes.new("ShaderNodeEmission")
        tree.links.new(attr.outputs["Color"], em.inputs["Color"])
        tree.links.new(em.outputs["Emission"], out.inputs["Surface"])
    return mat


def write_colours(obj, surface, lux_m):
    """The false colours on the result mesh: grid → a new grid object (face corners), vertices → point
    domain, faces → face corners of each triangle. Returns the object carrying them."""
    import numpy as np

    from ...core import lux

    rgba = lux.colour_attribute(surface, lux_m, linear=True)
    if surface.is_grid:
        target = _grid_object(obj, surface)
        corner = np.repeat(rgba, 4, axis=0)
        domain = "CORNER"
    else:
        target = obj
        me = obj.data
        if surface.kind == "vertices":
            domain = "POINT"
            full = np.ones((len(me.vertices), 4), np.float32)
            me.calc_loop_triangles()
            t = np.empty(len(me.loop_triangles) * 3, dtype=np.int64)
            me.loop_triangles.foreach_get("vertices", t)
            full[np.unique(t)] = rgba
            corner = full
        else:
            domain = "CORNER"
            me.calc_loop_triangles()
            loops = np.empty(len(me.loop_triangles) * 3, dtype=np.int64)
            me.loop_triangles.foreach_get("loops", loops)
            corner = np.ones((len(me.loops), 4), np.float32)
            corner[loops] = np.repeat(rgba, 3, axis=0)
    me = target.data
    if ATTRIBUTE in me.color_attributes:
        me.color_attributes.remove(me.color_attributes[ATTRIBUTE])
    attr = me.color_attributes.new(ATTRIBUTE, "FLOAT_COLOR", domain)
    attr.data.foreach_set("color", np.ascontiguousarray(corner, np.float32).ravel())
    me.color_attributes.active_color = attr
    if target is not obj or not me.materials:
        mat = _material()
        if target is not obj:
            me.materials.append(mat)
    return target


def store_result(obj, surface, lux0, se, used):
    """The statistics into obj.spectral_gi_lux (saved with the .blend); the false colours on the mesh."""
    from ...core import lux

    st = lux.statistics(surface, lux0, se, samples=int(used.max()))
    s = obj.spectral_gi_lux
    s.mean, s.minimum, s.maximum = st.mean, st.minimum, st.maximum
    s.u0, s.ud = st.u0 or 0.0, st.ud or 0.0
    s.n_points = st.n_points
    s.spacing_u, s.spacing_v = surface.spacing if surface.spacing else (0.0, 0.0)
    s.band_used, s.mf_used = surface.band, surface.maintenance_factor
    s.samples_used = int(used.max())
    s.max_rel_error = st.max_rel_std_error or 0.0
    target = write_colours(obj, surface, lux0 * surface.maintenance_factor)
    s.result_object = target.name
    s.valid = True
    return st


LAST = {}  # object name → (surface, lux, std_error, samples) of this session's last calculation (for reports)


def run_calculation(context, objects, progress=None):
    """Export, build, calculate and store every surface in ``objects``. Returns messages; raises
    LuxInputError or the exporter's errors (reported by the operator)."""
    from ..export import export_scene

    surfaces = [(o, build_surface(o)) for o in objects]
    exported = export_scene(context.evaluated_depsgraph_get(), context.scene)
    out = []
    for obj, surface in surfaces:
        s = obj.spectral_gi_lux
        lux0, se, used = calculate_points(exported.scene, surface, s.samples, s.rel_error, progress)
        st = store_result(obj, surface, lux0, se, used)
        LAST[obj.name] = (surface, lux0, se, int(used.max()))
        out.append(f"{obj.name}: Ē {st.mean:.4g} lx, Emin {st.minimum:.4g} lx, U0 {s.u0:.2f} ({st.n_points} points)")
    return out


class SPECTRALGI_OT_lux_calculate(bpy.types.Operator):
    """Calculate the illuminance (lx) on the calculation surfaces (the active one, or all marked)"""

    bl_idname = "spectral_gi.lux_calculate"
    bl_label = "Calculate Illuminance"
    bl_options = {"REGISTER", "UNDO"}

    all_surfaces: bpy.props.BoolProperty(name="All Surfaces", default=True,
                                         description="Every marked surface of the scene, not only the active object")

    def execute(self, context):
        obj = context.active_object
        objects = marked_objects(context.scene) if self.all_surfaces or obj is None else [obj]
        objects = [o for o in objects if o.spectral_gi_lux.enabled]
        if not objects:
            self.report({"ERROR"}, "Spectral GI: no calculation surface (mark a mesh in Object properties)")
            return {"CANCELLED"}
        wm = context.window_manager
        wm.progress_begin(0, 1)
        try:
            lines = run_calculation(context, objects, lambda done, n: wm.progress_update(done / max(n, 1)))
        except LuxInputError as exc:
            self.report({"ERROR"}, f"Spectral GI: {exc}")
            return {"CANCELLED"}
        except Exception as exc:  # an export or integrator problem: report it, keep Blender alive
            import traceback

            traceback.print_exc()
            self.report({"ERROR"}, f"Spectral GI: cannot calculate the illuminance: {exc}")
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        for line in lines:
            self.report({"INFO"}, "Spectral GI: " + line)
        return {"FINISHED"}


def floor_polygon(obj):
    """The room's floor outline (K, 3) in metres: the bounding box footprint of the mesh at its lowest
    point (the floor of a box room; an L-shaped room is covered by its bounding rectangle)."""
    import numpy as np

    pos, _ = _world_mesh(obj)
    if pos.shape[0] == 0:
        raise LuxInputError(f"{obj.name!r} has no vertices")
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    if not (hi[0] - lo[0] > 0 and hi[1] - lo[1] > 0):
        raise LuxInputError(f"{obj.name!r} has no floor area (its footprint is {hi[0]-lo[0]:.3g} × "
                            f"{hi[1]-lo[1]:.3g} m)")
    z = lo[2]
    return np.array([[lo[0], lo[1], z], [hi[0], lo[1], z], [hi[0], hi[1], z], [lo[0], hi[1], z]])


class SPECTRALGI_OT_lux_add_workplane(bpy.types.Operator):
    """Add a work plane over the active room: its bounding-box footprint at the work-plane height above its
    lowest point, marked as a grid calculation surface with a 0.5 m band"""

    bl_idname = "spectral_gi.lux_add_workplane"
    bl_label = "Add Work Plane"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        room = context.active_object
        if room is None or room.type != "MESH":
            self.report({"ERROR"}, "Spectral GI: select the room (a mesh) first")
            return {"CANCELLED"}
        try:
            floor = floor_polygon(room)
        except LuxInputError as exc:
            self.report({"ERROR"}, f"Spectral GI: {exc}")
            return {"CANCELLED"}
        scale = context.scene.unit_settings.scale_length or 1.0
        h = context.scene.spectral_gi_workplane_height
        verts = [tuple(float(c) / scale for c in (p[0], p[1], p[2] + h)) for p in floor]
        me = bpy.data.meshes.new("Work Plane")
        me.from_pydata(verts, [], [(0, 1, 2, 3)])
        me.update()
        wp = bpy.data.objects.new("Work Plane", me)
        wp.hide_render = True  # a calculation surface does not block light
        context.scene.collection.objects.link(wp)
        s = wp.spectral_gi_lux
        s.enabled, s.kind, s.band = True, "GRID", 0.5
        self.report({"INFO"}, f"Spectral GI: work plane {wp.name!r} at {h:.2f} m over {room.name!r}")
        return {"FINISHED"}


def report_folder(context):
    folder = bpy.path.abspath(context.scene.spectral_gi_report_dir) if context.scene.spectral_gi_report_dir else ""
    if not folder:
        folder = os.path.dirname(bpy.data.filepath) if bpy.data.filepath else bpy.app.tempdir
    return folder


def has_matplotlib():
    import importlib.util

    return importlib.util.find_spec("matplotlib") is not None


class SPECTRALGI_OT_lux_export_report(bpy.types.Operator):
    """Write the active surface's last result as CSV and JSON (and a PNG/PDF page with matplotlib)"""

    bl_idname = "spectral_gi.lux_export_report"
    bl_label = "Export Report"

    def execute(self, context):
        from ...core import lux

        obj = context.active_object
        if obj is None or obj.name not in LAST:
            self.report({"ERROR"}, "Spectral GI: calculate the illuminance of the active surface first "
                                   "(per-point values are not kept in the .blend)")
            return {"CANCELLED"}
        surface, e, se, spp = LAST[obj.name]
        folder = report_folder(context)
        stem = os.path.join(folder, bpy.path.clean_name(obj.name) + "_lux")
        try:
            os.makedirs(folder, exist_ok=True)
            lux.write_surface_csv(stem + ".csv", surface, e, se)
            lux.write_summary_json(stem + ".json", surface, e, se, samples=spp, project=bpy.path.basename(
                bpy.data.filepath) or "Spectral GI")
            written = [stem + ".csv", stem + ".json"]
            if has_matplotlib():
                lux.render_report(surface, e, se, samples=spp, png_path=stem + ".png", pdf_path=stem + ".pdf")
                written += [stem + ".png", stem + ".pdf"]
                img = bpy.data.images.load(stem + ".png", check_existing=True)
                img.reload()
                from ..imageio import show_in_image_editors

                show_in_image_editors(img, context.window_manager)
        except Exception as exc:
            self.report({"ERROR"}, f"Spectral GI: cannot write the report: {exc}")
            return {"CANCELLED"}
        note = "" if has_matplotlib() else " (the PNG/PDF page needs the 'analysis' extra: matplotlib)"
        self.report({"INFO"}, f"Spectral GI: wrote {', '.join(os.path.basename(p) for p in written)}{note}")
        return {"FINISHED"}


classes = (SPECTRALGI_OT_lux_calculate, SPECTRALGI_OT_lux_add_workplane, SPECTRALGI_OT_lux_export_report)
