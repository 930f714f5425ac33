"""Lighting analysis: Add Work Plane, Calculate Illuminance, Export Report, Lighting Report (in lx).

Calculate Illuminance and Lighting Report export the scene on the main thread, calculate on a
worker thread (``lux_job``: progress in the status bar and the panel, Esc cancels) and store
the results on the main thread (by the path tracer, or with Method Radiosity from one radiosity solution
of the scene, which also gets a false-colour overlay on every surface, see ``radiosity_overlay``):
the statistics in ``Object.spectral_gi_lux``, the per-point
values and the surface in an ID property of the object (so reports can be written after the
.blend is reopened), the false colours as a colour attribute with a material that shows them,
and the plan and report page as packed images. In the background (scripts, ``bpy`` as a
module) they run on the calling thread.
"""
import dataclasses
import datetime
import json
import os

import bpy

from ..jobs import ModalJobOperator, redraw

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
            surface = lux.face_set_grid(pos, tri, name=obj.name, spacing=spacing, band=float(s.band),
                                        maintenance_factor=float(s.maintenance_factor))
            if s.workplane:  # reported as a work plane (EN 12464-1); the same grid
                surface = dataclasses.replace(surface, kind="workplane")
            return surface
        if s.kind == "VERTICES":
            return lux.mesh_vertex_points(pos, tri, name=obj.name, maintenance_factor=float(s.maintenance_factor))
        return lux.mesh_face_points(pos, tri, name=obj.name, maintenance_factor=float(s.maintenance_factor))
    except lux.LuxError as exc:
        raise LuxInputError(str(exc)) from None


def marked_objects(scene):
    return [o for o in scene.objects if o.type == "MESH" and getattr(o, "spectral_gi_lux", None) is not None
            and o.spectral_gi_lux.enabled]


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


def overlay_options(s, lux_m=None):
    """The false-colour scale of a surface's settings ``s`` as core's keywords (vmin, vmax, steps, scale):
    the fixed range, or (automatic) the range core finds in ``lux_m``. LuxInputError for a fixed range
    core cannot draw (minimum not below maximum; a logarithmic scale from 0)."""
    from ...core import lux

    scale = "log" if s.scale_log else "linear"
    if s.scale_auto:
        vmin, vmax = (None, None) if lux_m is None else lux.auto_range(lux_m, scale)
    else:
        vmin, vmax = float(s.scale_fixed_min), float(s.scale_fixed_max)
        if not vmax > vmin:
            raise LuxInputError(f"the fixed false-colour range needs Range Maximum ({vmax:g} lx) above Range "
                                f"Minimum ({vmin:g} lx)")
        if scale == "log" and not vmin > 0.0:
            raise LuxInputError("a logarithmic false-colour scale needs Range Minimum above 0 lx")
    return {"vmin": vmin, "vmax": vmax, "steps": int(s.scale_steps), "scale": scale}


def write_colours(obj, surface, lux_m, options=None):
    """The false colours on the result mesh: grid → a new grid object (face corners), vertices → point
    domain, faces → face corners of each triangle, on the scale ``options`` (:func:`overlay_options`;
    None: automatic, linear, 8 steps). Returns the object carrying them."""
    import numpy as np

    from ...core import lux

    rgba = lux.colour_attribute(surface, lux_m, linear=True, **(options or {}))
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


RESULT_KEY = "_spectral_gi_lux_result"  # ID property: the surface, per-point values and luminaires of the last result
PLAN_SIZE = 512  # px, the longer side of the false-colour plan image


def store_result(obj, surface, lux0, se, used, luminaires=(), unlit=None, method="PATH"):
    """The statistics into obj.spectral_gi_lux, the surface and its values into an ID property (both saved
    with the .blend), the false colours on the mesh and the plan image. ``unlit``: the dict of
    ``core.unlit_points(...).to_dict()`` (kept for the report). Returns the statistics."""
    from ...core import lux

    samples = int(used.max())
    st = lux.statistics(surface, lux0, se, samples=samples or None)  # radiosity: no samples
    s = obj.spectral_gi_lux
    s.mean, s.minimum, s.maximum = st.mean, st.minimum, st.maximum
    s.u0, s.ud = st.u0 or 0.0, st.ud or 0.0
    s.n_points = st.n_points
    s.grid_cols, s.grid_rows = (surface.grid_shape[1], surface.grid_shape[0]) if surface.grid_shape else (0, 0)
    s.spacing_u, s.spacing_v = surface.spacing if surface.spacing else (0.0, 0.0)
    s.band_used, s.mf_used = surface.band, surface.maintenance_factor
    s.samples_used = samples
    s.max_rel_error = st.max_rel_std_error or 0.0
    s.mean_rel_error = st.mean_rel_std_error or 0.0
    s.area = st.area
    s.unlit_points = 0 if unlit is None else int(unlit["count"])
    obj[RESULT_KEY] = {"surface": json.dumps(surface.to_dict()), "lux": [float(x) for x in lux0],
                       "std_error": [float(x) for x in se], "samples": samples,
                       "luminaires": json.dumps(list(luminaires)), "unlit": json.dumps(unlit),
                       "method": "radiosity" if method == "RADIOSITY" else "path"}
    apply_overlay(obj, surface, lux0)
    s.valid = True
    return st


def apply_overlay(obj, surface, lux0):
    """The false colours (viewport colour attribute, plan image) of initial values ``lux0`` on the scale of
    the object's settings; the range used into scale_min/scale_max."""
    s = obj.spectral_gi_lux
    lux_m = lux0 * surface.maintenance_factor
    options = overlay_options(s, lux_m)
    s.scale_min, s.scale_max = options["vmin"], options["vmax"]
    target = write_colours(obj, surface, lux_m, options)
    s.result_object = target.name
    s.plan_image = plan_image(obj, surface, lux_m, options)


def saved_unlit(obj):
    """The dict of the points outside the lit geometry stored with the object's last result, or None."""
    d = obj.get(RESULT_KEY)
    try:
        return None if d is None or "unlit" not in d else json.loads(d["unlit"])
    except (TypeError, ValueError):
        return None


def saved_method(obj):
    """"path" or "radiosity": how the object's last result was calculated."""
    d = obj.get(RESULT_KEY)
    try:
        return "path" if d is None or "method" not in d else str(d["method"])
    except (TypeError, ValueError):
        return "path"


def saved_result(obj):
    """(surface, lux, std_error, samples, luminaires) of the object's last calculation, from the .blend; or None."""
    import numpy as np

    from ...core import lux

    d = obj.get(RESULT_KEY)
    if d is None:
        return None
    try:
        surface = lux.CalculationSurface.from_dict(json.loads(d["surface"]))
        e = np.array(d["lux"], dtype=np.float64)
        se = np.array(d["std_error"], dtype=np.float64)
        return surface, e, se, int(d["samples"]), json.loads(d["luminaires"])
    except (KeyError, TypeError, ValueError) as exc:
        raise LuxInputError(f"{obj.name!r}: the stored result cannot be read ({exc}); calculate again") from None


def _replace_image(name, width, height):
    img = bpy.data.images.get(name)
    if img is not None:
        bpy.data.images.remove(img)
    return bpy.data.images.new(name, width, height, alpha=True)


def plan_image(obj, surface, lux_m, options=None):
    """The false-colour plan (maintained lx) as the packed image "<object> lux plan", on the scale
    ``options`` (:func:`overlay_options`; None: automatic); returns it."""
    import numpy as np

    from ...core import lux

    rgba = lux.plan_image(surface, lux_m, size=PLAN_SIZE, **(options or {}))
    h, w = rgba.shape[:2]
    img = _replace_image(f"{obj.name} lux plan", w, h)
    img.pixels.foreach_set(np.ascontiguousarray(rgba[::-1], np.float32).ravel())  # Blender: rows bottom-up
    img.update()
    img.pack()
    return img


def write_plan_png(path, img):
    """The plan image as an RGB PNG on white (NumPy and zlib only)."""
    import numpy as np

    from ...core import atomic_path, encode_png

    w, h = img.size
    a = np.empty(w * h * 4, np.float32)
    img.pixels.foreach_get(a)
    a = a.reshape(h, w, 4)[::-1]
    rgb = a[..., :3] * a[..., 3:] + (1.0 - a[..., 3:])
    with atomic_path(path) as tmp:
        tmp.write_bytes(encode_png(np.round(np.clip(rgb, 0.0, 1.0) * 255.0).astype(np.uint8)))


def has_matplotlib():
    import importlib.util

    return importlib.util.find_spec("matplotlib") is not None


NO_MATPLOTLIB = ("the PNG/PDF report page needs matplotlib, which Blender's Python does not ship "
                 "(see the lighting-analysis docs); the CSV, JSON and false-colour plan are written")


def report_folder(context):
    folder = bpy.path.abspath(context.scene.spectral_gi_report_dir) if context.scene.spectral_gi_report_dir else ""
    if not folder:
        folder = os.path.dirname(bpy.data.filepath) if bpy.data.filepath else bpy.app.tempdir
    return folder


def write_report(context, obj, folder):
    """The report files of ``obj``'s stored result into ``folder``: <name>_lux.csv, .json, _plan.png and, with
    matplotlib, the one-page .png and .pdf (loaded as the packed image "<object> lux report"). Returns
    (paths written, the report image or None)."""
    from ...core import lux

    res = saved_result(obj)
    if res is None:
        raise LuxInputError(f"{obj.name!r} has no result: calculate the illuminance first")
    surface, e, se, spp, luminaires = res
    stem = os.path.join(folder, bpy.path.clean_name(obj.name) + "_lux")
    project = os.path.splitext(bpy.path.basename(bpy.data.filepath))[0] or "Spectral GI"
    date = datetime.date.today().isoformat()
    os.makedirs(folder, exist_ok=True)
    lux.write_surface_csv(stem + ".csv", surface, e, se)
    summary = lux.write_summary_json(stem + ".json", surface, e, se, samples=spp or None, luminaires=luminaires,
                                     project=project, date=date, unlit=saved_unlit(obj))
    method = saved_method(obj)
    if method == "radiosity":  # the summary says how its values were computed
        from ...core import atomic_path

        summary["method"] = method
        summary["note"] = ("radiosity: diffuse surfaces only (other materials replaced by their diffuse albedo); "
                           "standard errors 0, the error is the mesh's")
        with atomic_path(stem + ".json") as tmp:
            tmp.write_text(json.dumps(summary, indent=2, allow_nan=False) + "\n", encoding="utf-8")
    written = [stem + ".csv", stem + ".json"]
    s = obj.spectral_gi_lux
    if s.plan_image is not None:
        write_plan_png(stem + "_plan.png", s.plan_image)
        written.append(stem + "_plan.png")
    img = None
    if has_matplotlib():
        options = overlay_options(s, e * surface.maintenance_factor)
        lux.render_report(surface, e, se, samples=spp or None, luminaires=luminaires, project=project, date=date,
                          png_path=stem + ".png", pdf_path=stem + ".pdf", **options)
        written += [stem + ".png", stem + ".pdf"]
        old = bpy.data.images.get(f"{obj.name} lux report")
        if old is not None:
            bpy.data.images.remove(old)
        img = bpy.data.images.load(stem + ".png")
        img.name = f"{obj.name} lux report"
        img.pack()
        s.report_image = img
    return written, img


def _show(context, img):
    if img is not None:
        from ..imageio import show_in_image_editors

        show_in_image_editors(img, context.window_manager)


# ----------------------------------------------------------------------------- the radiosity overlay

RADIOSITY_SUFFIX = " radiosity"  # the overlay object of mesh <name> is "<name> radiosity"
RADIOSITY_KEY = "_spectral_gi_radiosity"  # ID property of the overlay object: its per-vertex lx and cd/m²
RADIOSITY_OFFSET = 1e-3  # m, the overlay sits this far in front of its surface (no z-fighting)


def mesh_patches(solution, core_scene):
    """{mesh index: patch indices} of a radiosity solution: each patch's scene triangle
    (``patches.source``, the meshes' triangles concatenated) back to its mesh."""
    import numpy as np

    counts = np.array([m.indices.shape[0] for m in core_scene.meshes], np.int64)
    mesh_of = np.searchsorted(np.cumsum(counts), solution.patches.source, side="right")
    return {int(m): np.nonzero(mesh_of == m)[0] for m in np.unique(mesh_of)}


def overlay_mesh(solution, patch_idx, values):
    """The display mesh of the patches ``patch_idx``: (positions (V, 3) m, each vertex moved
    RADIOSITY_OFFSET along its patch's normal; faces (F, 3) into them; the per-vertex
    ``values`` (V,), taken from the solution's welded display mesh (the area-weighted mean
    of the patches meeting at a vertex with the same side and normal))."""
    import numpy as np

    faces = solution.mesh.faces[patch_idx]
    used, inv = np.unique(faces.reshape(-1), return_inverse=True)
    pos = solution.mesh.positions[used].astype(np.float64)
    nrm = np.zeros_like(pos)
    np.add.at(nrm, inv, np.repeat(solution.patches.normal[patch_idx], 3, axis=0))
    nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-300)
    return pos + RADIOSITY_OFFSET * nrm, inv.reshape(-1, 3), np.asarray(values, np.float64)[used]


def radiosity_values(solution, quantity):
    return solution.vertex_luminance if quantity == "LUMINANCE" else solution.vertex_illuminance


def _remove_overlay(scene):
    r = scene.spectral_gi_radiosity
    for name in filter(None, r.objects.split("\n")):
        old = bpy.data.objects.get(name)
        if old is not None and RADIOSITY_KEY in old:
            me = old.data
            bpy.data.objects.remove(old, do_unlink=True)
            if me is not None and me.users == 0:
                bpy.data.meshes.remove(me)
    r.objects = ""


def store_radiosity(scene, solution, core_scene, warnings=()):
    """The radiosity overlay (main thread): one object "<mesh> radiosity" per mesh of the solved
    scene, the mesh's patches with per-vertex false colours (the display mesh's values,
    see ``overlay_mesh``), each object keeping its per-vertex illuminance and luminance (so
    the overlay can be recoloured after the .blend is reopened). Replaces the earlier
    overlay. Returns the objects' names."""
    import numpy as np

    _remove_overlay(scene)
    r = scene.spectral_gi_radiosity
    scale = scene.unit_settings.scale_length or 1.0
    names = []
    for m, idx in mesh_patches(solution, core_scene).items():
        if idx.size == 0:
            continue
        pos, faces, lux_v = overlay_mesh(solution, idx, solution.vertex_illuminance)
        _, _, lum_v = overlay_mesh(solution, idx, solution.vertex_luminance)
        name = core_scene.meshes[m].name + RADIOSITY_SUFFIX
        old = bpy.data.objects.get(name)
        if old is not None:
            bpy.data.objects.remove(old, do_unlink=True)
        me = bpy.data.meshes.new(name)
        me.vertices.add(pos.shape[0])
        me.vertices.foreach_set("co", np.ascontiguousarray(pos / scale, np.float32).ravel())
        me.loops.add(faces.size)
        me.loops.foreach_set("vertex_index", np.ascontiguousarray(faces, np.int32).ravel())
        me.polygons.add(faces.shape[0])
        me.polygons.foreach_set("loop_start", np.arange(0, faces.size, 3, dtype=np.int32))
        me.polygons.foreach_set("loop_total", np.full(faces.shape[0], 3, np.int32))
        me.update()
        me.validate()
        me.materials.append(_material())
        obj = bpy.data.objects.new(name, me)
        obj.hide_render = True  # a result display, not part of the lit scene
        obj[RADIOSITY_KEY] = {"lux": lux_v.astype(np.float32).tolist(), "luminance": lum_v.astype(np.float32).tolist()}
        src = bpy.data.objects.get(core_scene.meshes[m].name)
        for coll in (src.users_collection if src is not None else ()) or (scene.collection,):
            coll.objects.link(obj)
        names.append(name)
    r.objects = "\n".join(names)
    r.patches = int(solution.patches.n)
    r.warning = "; ".join(warnings)
    recolour_radiosity(scene)
    return names


def recolour_radiosity(scene):
    """Colour the radiosity overlay objects by the scene's overlay settings (quantity, range,
    steps, scale): the same false colours (core/lux/falsecolour.py) and range rules as a
    calculation surface's. Returns (vmin, vmax) or None without an overlay."""
    import numpy as np

    from ...core import lux
    fc = lux.falsecolour

    r = scene.spectral_gi_radiosity
    key = "luminance" if r.quantity == "LUMINANCE" else "lux"
    objs = [o for o in (bpy.data.objects.get(n) for n in filter(None, r.objects.split("\n")))
            if o is not None and RADIOSITY_KEY in o]
    if not objs:
        return None
    values = {o.name: np.asarray(o[RADIOSITY_KEY][key], np.float64) for o in objs}
    s = scene.spectral_gi_radiosity_scale
    options = overlay_options(s, np.concatenate(list(values.values())))
    s.scale_min, s.scale_max = options["vmin"], options["vmax"]
    for o in objs:
        rgba = np.ones((values[o.name].size, 4), np.float32)
        rgba[:, :3] = fc.srgb_to_linear(fc.false_colour(values[o.name], **options))
        me = o.data
        if ATTRIBUTE in me.color_attributes:
            me.color_attributes.remove(me.color_attributes[ATTRIBUTE])
        attr = me.color_attributes.new(ATTRIBUTE, "FLOAT_COLOR", "POINT")
        attr.data.foreach_set("color", np.ascontiguousarray(rgba).ravel())
        me.color_attributes.active_color = attr
        o.hide_viewport = not r.overlay
    s.valid = True
    return options["vmin"], options["vmax"]


def radiosity_legend(scene):
    """The overlay's legend: (colour (r, g, b) sRGB, label) per step from the bottom up, in the
    quantity's unit; [] without an overlay."""
    import numpy as np

    from ...core import lux
    fc = lux.falsecolour

    r = scene.spectral_gi_radiosity
    s = scene.spectral_gi_radiosity_scale
    if not r.objects or not s.valid or not s.scale_max > s.scale_min:
        return []
    unit = "cd/m²" if r.quantity == "LUMINANCE" else "lx"
    scale = "log" if s.scale_log else "linear"
    levels = fc.legend_levels(s.scale_min, s.scale_max, int(s.scale_steps), scale)
    mid = np.sqrt(levels[:-1] * levels[1:]) if scale == "log" else 0.5 * (levels[:-1] + levels[1:])
    colours = fc.false_colour(mid, s.scale_min, s.scale_max, int(s.scale_steps), scale)
    return [(tuple(float(x) for x in c), f"{fc.format_value(a)} – {fc.format_value(b)} {unit}")
            for c, a, b in zip(colours, levels[:-1], levels[1:])]


class SPECTRALGI_OT_radiosity_recolour(bpy.types.Operator):
    """Colour the radiosity overlay again with the current quantity, range and steps (no new solve)"""

    bl_idname = "spectral_gi.radiosity_recolour"
    bl_label = "Update Radiosity Overlay"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        try:
            got = recolour_radiosity(context.scene)
        except LuxInputError as exc:
            self.report({"ERROR"}, f"Spectral GI: {exc}")
            return {"CANCELLED"}
        if got is None:
            self.report({"ERROR"}, "Spectral GI: no radiosity overlay: Calculate Illuminance with Method Radiosity")
            return {"CANCELLED"}
        _redraw(context)
        return {"FINISHED"}


# ----------------------------------------------------------------------------- the job, shared by the operators


def prepare_job(context, objects):
    """Build the surfaces and export the scene (main thread); returns a LuxJob. Raises LuxInputError or the
    exporter's errors. The export's warning, if any, is in ``job.warning``."""
    from ...core import luminaire_schedule
    from .. import lux_job
    from ..export import export_scene
    from ..export.detail import render_detail

    tasks = []
    for o in objects:
        s = o.spectral_gi_lux
        try:
            overlay_options(s)  # a fixed range that cannot be drawn fails before the calculation
        except LuxInputError as exc:
            raise LuxInputError(f"{o.name!r}: {exc}") from None
        tasks.append(lux_job.SurfaceTask(o.name, build_surface(o), s.samples, s.rel_error or None))
    with render_detail(context.scene, context.view_layer):  # the geometry a render sees, not the viewport's
        exported = export_scene(context.evaluated_depsgraph_get(), context.scene)
    settings = getattr(context.scene, "spectral_gi", None)
    method = context.scene.spectral_gi_lux_method
    scale = context.scene.unit_settings.scale_length or 1.0
    job = lux_job.LuxJob(exported.scene, tasks, threads=getattr(settings, "threads", 0),
                         luminaires=luminaire_schedule(exported.scene), method=method,
                         max_edge=float(context.scene.spectral_gi_radiosity.max_edge) * scale or None)
    job.warning = exported.warning
    return job


def store_job(job):
    """Store a finished job's results on their objects (main thread). Returns one line per surface."""
    out = []
    for task in job.tasks:
        obj = bpy.data.objects.get(task.name)
        if obj is None or task.name not in job.results:
            continue
        e, se, used = job.results[task.name]
        unlit = job.unlit.get(task.name)
        st = store_result(obj, task.surface, e, se, used, job.luminaires,
                          None if unlit is None else unlit.to_dict(), method=job.method)
        u0 = "–" if st.u0 is None else f"{st.u0:.2f}"
        out.append(f"{obj.name}: Ē {st.mean:.4g} lx, Emin {st.minimum:.4g} lx, U0 {u0} ({st.n_points} points)")
    if job.radiosity is not None:
        names = store_radiosity(bpy.context.scene, job.radiosity, job.scene, job.radiosity_warnings)
        out.append(f"radiosity: {job.radiosity.patches.n} patches, false colours on {len(names)} object(s)")
    return out


UNLIT_SHOWN = 10  # point indices named in a warning


def unlit_warnings(job):
    """One warning line per surface of a finished job with points outside the lit geometry."""
    out = []
    for task in job.tasks:
        unlit = job.unlit.get(task.name)
        line = None if unlit is None else unlit.warning(UNLIT_SHOWN, f"points of {task.name!r}")
        if line:
            out.append(line)
    return out


def _redraw(context):
    redraw(context.window_manager, _LuxJobOperator.redraw_areas)


class _LuxJobOperator(ModalJobOperator):
    """Shared by Calculate Illuminance and Lighting Report: ``_objects`` picks the surfaces, the job runs
    (modal with a worker thread when there is a window, else on the calling thread), ``_finish`` follows."""

    progress_bar = True
    redraw_areas = ("PROPERTIES", "IMAGE_EDITOR", "VIEW_3D")

    def _objects(self, context):
        raise NotImplementedError

    def _prepare(self, context):
        try:
            objects = self._objects(context)
            job = prepare_job(context, objects)
        except LuxInputError as exc:
            self.report({"ERROR"}, f"Spectral GI: {exc}")
            return None
        except Exception as exc:  # an export problem: report it, keep Blender alive
            import traceback

            traceback.print_exc()
            self.report({"ERROR"}, f"Spectral GI: cannot calculate the illuminance: {exc}")
            return None
        return job

    def _conclude(self, context, job):
        from .. import lux_job

        _redraw(context)
        if job.error is not None:
            if job.traceback:
                print(job.traceback)
            self.report({"ERROR"}, f"Spectral GI: {job.summary()}")
            return {"CANCELLED"}
        if job.cancelled:
            self.report({"WARNING"}, f"Spectral GI: {job.summary()}")
            return {"CANCELLED"}
        try:
            lines = store_job(job)
            lines += self._finish(context, job)
        except Exception as exc:  # writing a result or a report failed: say why
            import traceback

            traceback.print_exc()
            lux_job.STATE.message = f"Failed: {exc}"
            self.report({"ERROR"}, f"Spectral GI: {exc}")
            return {"CANCELLED"}
        for line in lines:
            self.report({"INFO"}, "Spectral GI: " + line)
        for line in unlit_warnings(job):
            self.report({"WARNING"}, "Spectral GI: " + line)
        for line in job.radiosity_warnings:
            self.report({"WARNING"}, "Spectral GI: radiosity: " + line)
        lux_job.STATE.message = job.summary()
        _redraw(context)
        return {"FINISHED"}

    def _finish(self, context, job):
        return []


class SPECTRALGI_OT_lux_calculate(_LuxJobOperator, bpy.types.Operator):
    """Calculate the illuminance (lx) on the calculation surfaces (all marked, or the active one) in the
    background; Esc cancels and keeps the earlier results"""

    bl_idname = "spectral_gi.lux_calculate"
    bl_label = "Calculate Illuminance"
    bl_options = {"REGISTER"}

    all_surfaces: bpy.props.BoolProperty(name="All Surfaces", default=True,
                                         description="Every marked surface of the scene, not only the active object")

    def _objects(self, context):
        obj = context.active_object
        objects = marked_objects(context.scene) if self.all_surfaces or obj is None else [obj]
        objects = [o for o in objects if o.type == "MESH" and o.spectral_gi_lux.enabled]
        if not objects and context.scene.spectral_gi_lux_method != "RADIOSITY":  # radiosity: the overlay alone
            raise LuxInputError("no calculation surface (mark a mesh in Object properties, or Add Work Plane)")
        return objects

    def _finish(self, context, job):
        obj = context.active_object
        if obj is not None and obj.name in job.results:
            _show(context, obj.spectral_gi_lux.plan_image)
        return []


# ----------------------------------------------------------------------------- work planes


def _outline_loops(edges):
    """Closed vertex loops of a set of boundary edges [(a, b), …] (each vertex on two of them)."""
    from collections import defaultdict

    nbr = defaultdict(list)
    for a, b in edges:
        nbr[a].append(b)
        nbr[b].append(a)
    unused = {tuple(sorted(e)) for e in edges}
    loops = []
    while unused:
        a, b = unused.pop()
        loop = [a, b]
        while True:
            nxt = next((c for c in nbr[loop[-1]] if tuple(sorted((loop[-1], c))) in unused), None)
            if nxt is None:
                break
            unused.discard(tuple(sorted((loop[-1], nxt))))
            if nxt == loop[0]:
                break
            loop.append(nxt)
        if len(loop) >= 3:
            loops.append(loop)
    return loops


def _signed_area(xy):
    """The shoelace area of a polygon (K, 2): positive when counter-clockwise."""
    import numpy as np

    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float((x * np.roll(y, -1) - np.roll(x, -1) * y).sum())


def _clean_loop(xy):
    """A loop (K, 2) counter-clockwise, its vertices on straight edges dropped."""
    import numpy as np

    if _signed_area(xy) < 0.0:
        xy = xy[::-1]
    keep = []
    for k in range(len(xy)):  # drop vertices on a straight edge
        a, b, c = xy[k - 1], xy[k], xy[(k + 1) % len(xy)]
        cross = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
        if abs(cross) > 1e-9 * max(np.hypot(*(b - a)) * np.hypot(*(c - b)), 1e-300):
            keep.append(k)
    return xy[keep]


def _inside_loop(p, xy):
    """Even-odd rule: is the 2-D point p inside the loop xy (K, 2)?"""
    inside = False
    for (ax, ay), (bx, by) in zip(xy, list(xy[1:]) + [xy[0]]):
        if (ay > p[1]) != (by > p[1]) and p[0] < ax + (p[1] - ay) * (bx - ax) / (by - ay):
            inside = not inside
    return inside


def floor_polygon(obj):
    """The room's floor outline (K, 3) in metres, counter-clockwise seen from above: the outer boundary of
    the mesh's horizontal faces at its lowest level (an L-shaped room gives its L), collinear vertices
    dropped."""
    return floor_outline(obj)[0]


def floor_outline(obj):
    """(outline (K, 3), holes [(K_i, 3), ...]) of the room's floor in metres, each counter-clockwise seen
    from above, collinear vertices dropped: the outer boundary of the mesh's horizontal faces at its
    lowest level and the boundaries inside it (a courtyard, a column standing in a hole of the floor)."""
    import numpy as np

    me = obj.data
    pos, _ = _world_mesh(obj)
    if pos.shape[0] == 0:
        raise LuxInputError(f"{obj.name!r} has no vertices")
    zmin = float(pos[:, 2].min())
    tol = 1e-5 * max(float(np.ptp(pos, axis=0).max()), 1.0)
    low = np.abs(pos[:, 2] - zmin) <= tol
    edges = {}
    for poly in me.polygons:
        vs = list(poly.vertices)
        if len(vs) >= 3 and low[vs].all():
            for a, b in zip(vs, vs[1:] + vs[:1]):
                key = (min(a, b), max(a, b))
                edges[key] = edges.get(key, 0) + 1
    boundary = [e for e, n in edges.items() if n == 1]
    loops = _outline_loops(boundary)
    if not loops:
        raise LuxInputError(f"{obj.name!r} has no floor: no horizontal faces at its lowest point "
                            f"(z = {zmin:.3g} m)")
    loop = max(loops, key=lambda lp: abs(_signed_area(pos[lp, :2])))
    xy = _clean_loop(pos[loop, :2])
    if len(xy) < 3 or not abs(_signed_area(xy)) > 0.0:
        raise LuxInputError(f"{obj.name!r}: its floor has no area")
    holes = []
    for lp in loops:
        if lp is loop or not all(_inside_loop(q, xy) for q in pos[lp, :2]):
            continue  # another floor outside this one
        h = _clean_loop(pos[lp, :2])
        if len(h) >= 3 and abs(_signed_area(h)) > 0.0:
            holes.append(np.concatenate([h, np.full((len(h), 1), zmin)], axis=1))
    return np.concatenate([xy, np.full((len(xy), 1), zmin)], axis=1), holes


def _workplane_faces(floor, holes):
    """Faces over the outline ``floor`` less its ``holes`` (loops of 2-D or 3-D points, counter-clockwise
    from above): the outline as one face without holes, else Blender's polygon fill of all the loops,
    every triangle wound counter-clockwise from above. Indices into the loops' vertices in order."""
    if not holes:
        return [tuple(range(len(floor)))]
    from mathutils.geometry import tessellate_polygon

    loops = [[(float(p[0]), float(p[1]), 0.0) for p in lp] for lp in [floor, *holes]]
    flat = [p for lp in loops for p in lp]
    faces = []
    for a, b, c in tessellate_polygon(loops):
        (ax, ay, _), (bx, by, _), (cx, cy, _) = flat[a], flat[b], flat[c]
        up = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay) > 0.0
        faces.append((a, b, c) if up else (a, c, b))
    return faces


def add_workplane(context, room, height, band):
    """A work plane mesh over ``room``'s floor outline, ``height`` m above it, marked as a grid calculation
    surface (a work plane) with ``band`` m left out at the walls and, the same, around holes in the floor
    (EN 12464-1 leaves the band at columns and other obstacles to the designer: set the surface's Band).
    Returns the new object."""
    floor, holes = floor_outline(room)
    scale = context.scene.unit_settings.scale_length or 1.0
    verts = [tuple(float(c) / scale for c in (p[0], p[1], p[2] + height)) for lp in [floor, *holes] for p in lp]
    me = bpy.data.meshes.new("Work Plane")
    me.from_pydata(verts, [], _workplane_faces(floor, holes))
    me.update()
    wp = bpy.data.objects.new("Work Plane", me)
    wp.hide_render = True  # a calculation surface does not block light
    for coll in room.users_collection or (context.scene.collection,):
        coll.objects.link(wp)
    s = wp.spectral_gi_lux
    s.enabled, s.kind, s.workplane, s.band = True, "GRID", True, float(band)
    return wp


class SPECTRALGI_OT_lux_add_workplane(bpy.types.Operator):
    """Add a work plane over the active room: its floor outline (the lowest horizontal faces) at the
    work-plane height, marked as a grid calculation surface with a band at the walls"""

    bl_idname = "spectral_gi.lux_add_workplane"
    bl_label = "Add Work Plane"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        room = context.active_object
        if room is None or room.type != "MESH":
            self.report({"ERROR"}, "Spectral GI: select the room (a mesh) first")
            return {"CANCELLED"}
        sc = context.scene
        try:
            wp = add_workplane(context, room, sc.spectral_gi_workplane_height,
                               sc.spectral_gi_workplane_band if sc.spectral_gi_use_band else 0.0)
        except LuxInputError as exc:
            self.report({"ERROR"}, f"Spectral GI: {exc}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"Spectral GI: work plane {wp.name!r} at {sc.spectral_gi_workplane_height:.2f} m "
                              f"over {room.name!r} ({len(wp.data.vertices)} corners)")
        return {"FINISHED"}


# ----------------------------------------------------------------------------- reports


class SPECTRALGI_OT_lux_export_report(bpy.types.Operator):
    """Write the active surface's last result: CSV, JSON and the false-colour plan (and the one-page PNG/PDF
    report with matplotlib) into the report folder"""

    bl_idname = "spectral_gi.lux_export_report"
    bl_label = "Export Report"

    def execute(self, context):
        obj = context.active_object
        if obj is None or obj.get(RESULT_KEY) is None:
            self.report({"ERROR"}, "Spectral GI: calculate the illuminance of the active surface first")
            return {"CANCELLED"}
        try:
            written, img = write_report(context, obj, report_folder(context))
        except Exception as exc:
            self.report({"ERROR"}, f"Spectral GI: cannot write the report: {exc}")
            return {"CANCELLED"}
        _show(context, img or obj.spectral_gi_lux.plan_image)
        note = "" if has_matplotlib() else f" ({NO_MATPLOTLIB})"
        self.report({"INFO"}, f"Spectral GI: wrote {', '.join(os.path.basename(p) for p in written)}{note}")
        return {"FINISHED"}


class SPECTRALGI_OT_lux_recolour(bpy.types.Operator):
    """Draw the active surface's last result again on its false-colour scale (range, logarithmic, steps):
    the viewport colours and the plan image, without calculating"""

    bl_idname = "spectral_gi.lux_recolour"
    bl_label = "Update False Colours"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        obj = context.active_object
        try:
            res = None if obj is None else saved_result(obj)
            if res is None:
                raise LuxInputError("calculate the illuminance of the active surface first")
            apply_overlay(obj, res[0], res[1])
        except LuxInputError as exc:
            self.report({"ERROR"}, f"Spectral GI: {exc}")
            return {"CANCELLED"}
        s = obj.spectral_gi_lux
        _show(context, s.plan_image)
        _redraw(context)
        self.report({"INFO"}, f"Spectral GI: false colours {s.scale_min:.4g} – {s.scale_max:.4g} lx "
                              f"({'log' if s.scale_log else 'linear'}, {s.scale_steps or 'continuous'} steps)")
        return {"FINISHED"}


class SPECTRALGI_OT_lux_report(_LuxJobOperator, bpy.types.Operator):
    """One click from the scene to the lighting report: calculate every calculation surface (adding a work
    plane over the active room when there is none) and write each one's report (CSV, JSON, plan, and the
    PNG/PDF page with matplotlib) into the report folder, showing the report in the Image Editor"""

    bl_idname = "spectral_gi.lux_report"
    bl_label = "Lighting Report"
    bl_options = {"REGISTER"}

    def _objects(self, context):
        objects = marked_objects(context.scene)
        if objects:
            return objects
        room = context.active_object
        if room is None or room.type != "MESH":
            raise LuxInputError("no calculation surface: select the room (a mesh) for a work plane over it, "
                                "or mark a surface")
        sc = context.scene
        wp = add_workplane(context, room, sc.spectral_gi_workplane_height,
                           sc.spectral_gi_workplane_band if sc.spectral_gi_use_band else 0.0)
        self.report({"INFO"}, f"Spectral GI: added the work plane {wp.name!r} over {room.name!r}")
        return [wp]

    def _finish(self, context, job):
        folder = report_folder(context)
        lines, first = [], None
        for task in job.tasks:
            obj = bpy.data.objects.get(task.name)
            if obj is None or task.name not in job.results:
                continue
            written, img = write_report(context, obj, folder)
            first = first or img or obj.spectral_gi_lux.plan_image
            lines.append(f"wrote {', '.join(os.path.basename(p) for p in written)} in {folder}")
        if not has_matplotlib():
            self.report({"WARNING"}, f"Spectral GI: {NO_MATPLOTLIB}")
        _show(context, first)
        return lines


class SPECTRALGI_OT_lux_show_image(bpy.types.Operator):
    """Show a lighting-analysis image (the false-colour plan or the report page) in the Image Editor"""

    bl_idname = "spectral_gi.lux_show_image"
    bl_label = "Show Image"

    image: bpy.props.StringProperty(name="Image", description="Name of the image to show (no unit)")

    def execute(self, context):
        img = bpy.data.images.get(self.image)
        if img is None:
            self.report({"ERROR"}, f"Spectral GI: no image {self.image!r}")
            return {"CANCELLED"}
        from ..imageio import show_in_image_editors

        if not show_in_image_editors(img, context.window_manager):
            self.report({"INFO"}, f"Spectral GI: open an Image Editor to see {img.name!r}")
        return {"FINISHED"}


classes = (SPECTRALGI_OT_lux_calculate, SPECTRALGI_OT_lux_add_workplane, SPECTRALGI_OT_lux_export_report,
           SPECTRALGI_OT_lux_recolour, SPECTRALGI_OT_lux_report, SPECTRALGI_OT_lux_show_image,
           SPECTRALGI_OT_radiosity_recolour)
