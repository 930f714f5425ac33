"""Blender scene → core scene, from the evaluated depsgraph.

``export_scene(depsgraph)`` walks ``depsgraph.object_instances`` (modifiers, geometry
nodes and instancing applied), converts Blender units to metres, and returns the
validated core scene with one warning that lists everything it could not export.
"""
from dataclasses import dataclass

from .context import ExportCancelled, ExportContext, ExportError
from .convert import matrix_to_array
from .light import export_light
from .material import export_world_volume
from .mesh import GEOMETRY_TYPES, HELPER_TYPES, export_mesh, slot_materials
from .world import export_world

__all__ = ["ExportCancelled", "ExportError", "ExportResult", "MeshCache", "export_scene", "render_settings"]

DEFAULTS = {"samples": 64, "max_bounces": 16, "seed": 0, "use_animated_seed": False, "sampler": "INDEPENDENT",
            "pixel_filter": "BLACKMAN_HARRIS", "filter_width": 1.5, "time_limit": 0.0, "noise_target": 0.0}
SAMPLER_TAGS = {"INDEPENDENT": "SAMPLER_INDEPENDENT", "HALTON": "SAMPLER_HALTON", "HAMMERSLEY": "SAMPLER_HAMMERSLEY",
                "STRATIFIED": "SAMPLER_STRATIFIED"}
COLOUR_SPACES = {"REC709": "rec709", "ACESCG": "acescg", "XYZ": "xyz"}  # add-on enum → RenderSettings
OBSERVERS = {"CIE1931": "1931", "CIE1964": "1964"}
FILTER_TAGS = {"BOX": "FILTER_BOX", "BLACKMAN_HARRIS": "FILTER_BLACKMAN_HARRIS", "GAUSSIAN": "FILTER_GAUSSIAN"}
# Blender's Pixel Filter Width, read as Cycles reads it, → the core's filter support (pixels): Cycles
# spreads its Blackman–Harris window over twice the width and gives its Gaussian σ = width/4 (the
# core: the window over the width, σ = width/6); measured from Cycles' sample offsets in bpy
FILTER_SUPPORT = {"BOX": 1.0, "BLACKMAN_HARRIS": 2.0, "GAUSSIAN": 1.5}


@dataclass
class ExportResult:
    scene: object  # core.Scene, validated
    warning: str | None  # one message listing what was not exported, or None


def render_settings(scene):
    """core.RenderSettings from ``scene.spectral_gi`` (defaults if the add-on's properties are absent)."""
    from ...core import RenderSettings, constants

    s = getattr(scene, "spectral_gi", None)
    get = (lambda k: getattr(s, k, DEFAULTS[k])) if s is not None else DEFAULTS.get
    seed = int(get("seed"))
    if get("use_animated_seed"):
        seed = (seed + int(scene.frame_current)) % (2**31)
    return RenderSettings(spp=int(get("samples")), max_depth=int(get("max_bounces")), seed=seed,
                          sampler=getattr(constants, SAMPLER_TAGS[get("sampler")]),
                          filter=getattr(constants, FILTER_TAGS[get("pixel_filter")]),
                          filter_width=FILTER_SUPPORT[get("pixel_filter")] * float(get("filter_width")),
                          time_limit=float(get("time_limit")),
                          noise_target=float(get("noise_target")),
                          colour_space=COLOUR_SPACES[str(getattr(s, "colour_space", "REC709"))],
                          observer=OBSERVERS[str(getattr(s, "observer", "CIE1931"))],
                          film_transparent=bool(getattr(scene.render, "film_transparent", False)))


def fourier_order(scene):
    """Coefficients per spectrum: the scene's Spectral GI Fourier order (the core's default without the add-on)."""
    from ...core import constants

    s = getattr(scene, "spectral_gi", None)
    return int(getattr(s, "fourier_order", constants.N_COEFFS_DEFAULT)) if s is not None else \
        constants.N_COEFFS_DEFAULT


def _instance_name(inst, obj):
    if inst.is_instance and inst.parent is not None and inst.parent.original != obj.original:
        return f"{inst.parent.name}/{obj.name}"
    return obj.name


class MeshCache:
    """The local triangles of objects across exports (the viewport's incremental export).

    Keyed by the original object's and mesh's names; :meth:`forget` drops the objects whose
    geometry changed, so the next export reads only those again (``reads`` counts them).
    Instances (particles, geometry-node instances) are read on every export. ``spectra`` keeps
    the spectra fitted to colours (the costly part of exporting materials and lights), so an
    export fits only the colours that changed.
    """

    def __init__(self):
        self.local = {}
        self.reads = 0
        self.spectra = {}

    @staticmethod
    def key(obj):
        data = getattr(obj.data, "original", obj.data)
        return (obj.original.name, getattr(data, "name", ""))

    def forget(self, object_names=None, data_names=None):
        """Drop the entries of these objects (original names) and of these meshes; all with no arguments."""
        if object_names is None and data_names is None:
            self.local.clear()
            return
        objects, datas = set(object_names or ()), set(data_names or ())
        for k in [k for k in self.local if k[0] in objects or k[1] in datas]:
            del self.local[k]


# Blender's object ray visibility → the core's Mesh / Light flags (a light's camera visibility is Light.visible)
RAY_VISIBILITY = (("visible_camera", "visible_camera"), ("visible_diffuse", "visible_diffuse"),
                  ("visible_glossy", "visible_glossy"), ("visible_transmission", "visible_transmission"),
                  ("visible_volume_scatter", "visible_volume"), ("visible_shadow", "visible_shadow"))
LIGHT_VISIBILITY = RAY_VISIBILITY[1:5]


def ray_visibility(owners, pairs=RAY_VISIBILITY):
    """{core flag: bool} of Blender's ray visibility: off when it is off on the object or on its
    instancer (as Cycles reads instances)."""
    return {core: all(bool(getattr(o, prop, True)) for o in owners) for prop, core in pairs}


def _link_members(collection):
    """(included, excluded) names of the objects of a light-linking collection: its objects by
    their link state, and the objects anywhere inside a child collection by that child's."""
    incl, excl = set(), set()

    def walk(coll, state, seen):
        if coll.name in seen:
            return
        seen = seen | {coll.name}
        for ob, entry in zip(coll.objects, getattr(coll, "collection_objects", ())):
            st = state or entry.light_linking.link_state
            (incl if st == "INCLUDE" else excl).add(ob.original.name if ob.original else ob.name)
        for child, entry in zip(coll.children, getattr(coll, "collection_children", ())):
            walk(child, state or entry.light_linking.link_state, seen)

    walk(collection, None, set())
    return incl, excl


def link_lists(emitter, mesh_owners):
    """(receivers, blockers) of an emitter object: the indices of the exported meshes its
    light-linking and shadow-linking collections let it light and be shadowed by, or None
    (no collection: all). As Blender's light linking: an object marked Include is linked, one
    marked Exclude is not, and an object not in the collection is linked unless the
    collection includes some object."""
    link = getattr(emitter, "light_linking", None)
    out = []
    for key in ("receiver_collection", "blocker_collection"):
        coll = getattr(link, key, None) if link is not None else None
        if coll is None:
            out.append(None)
            continue
        incl, excl = _link_members(coll)
        out.append([j for j, names in enumerate(mesh_owners)
                    if (not incl or names & incl) and not names & excl])
    return tuple(out)


def object_features(ctx, obj, name, light=False):
    """Record the Cycles object settings the renderer does not follow: shadow catcher (of geometry)."""
    if not light and getattr(obj, "is_shadow_catcher", False):
        ctx.skip("shadow catchers (rendered as ordinary surfaces)", name)


def camera_window(scene):
    """(orthographic, half width, half height) of the scene camera's frame (Blender units for an
    orthographic camera, at unit distance for a perspective one), for Window coordinates."""
    cam = scene.camera.data
    r = scene.render
    xr = r.resolution_x * r.pixel_aspect_x
    yr = r.resolution_y * r.pixel_aspect_y
    fit = getattr(cam, "sensor_fit", "AUTO")
    horizontal = fit == "HORIZONTAL" or (fit == "AUTO" and xr >= yr)
    if cam.type == "ORTHO":
        size = cam.ortho_scale / 2.0
    else:
        sensor = cam.sensor_width if fit in ("AUTO", "HORIZONTAL") else cam.sensor_height
        size = sensor / 2.0 / cam.lens
    if horizontal:
        return cam.type == "ORTHO", size, size * yr / xr
    return cam.type == "ORTHO", size * xr / yr, size


def export_scene(depsgraph, scene=None, should_cancel=None, mesh_cache=None, camera=None):
    """Export the scene evaluated by ``depsgraph``. ``should_cancel()`` is checked between objects.

    mesh_cache: a :class:`MeshCache` whose entries are used instead of reading the meshes again;
    camera: a core Camera used instead of the scene's camera (the viewport's view).
    Raises ExportCancelled, ExportError, or core.SceneError; never returns a partial scene.
    """
    import bpy

    from ...core import Scene, validate

    scene = scene if scene is not None else depsgraph.scene
    ctx = ExportContext(scene.unit_settings.scale_length, should_cancel, n_coeffs=fourier_order(scene),
                        uplift_cache=mesh_cache.spectra if mesh_cache is not None else None)
    from .camera import export_camera
    from .curves import export_curves_object, export_particle_hair, renders_hair

    if camera is None:
        camera = export_camera(ctx, scene, depsgraph)
    if scene.camera is not None:  # Texture Coordinate's Camera output: world (metres) -> Cycles' camera space
        import numpy as np

        m = np.linalg.inv(np.asarray(scene.camera.matrix_world, np.float64))
        m[:3, :3] /= ctx.scale_length
        m[2] *= -1.0  # Cycles' camera space looks down +z (Blender's camera looks down −z)
        ctx.camera_from_world = m
        ctx.camera_window = camera_window(scene)
    meshes, lights = [], []
    mesh_owners, emitters = [], []  # the names of each mesh's objects; (core record, linking object)
    cache = {}
    surfaced, unsurfaced = set(), []
    hair = renders_hair(depsgraph)
    render = getattr(depsgraph, "mode", "VIEWPORT") == "RENDER"
    for inst in depsgraph.object_instances:
        ctx.check_cancel()
        obj = inst.object
        if not inst.is_instance and obj.original.hide_render:
            continue
        if inst.is_instance and inst.parent is not None and inst.parent.original.hide_render:
            continue  # the instances of a hidden object (also the mesh of a hidden curve, text or metaball)
        name = _instance_name(inst, obj)
        kind = obj.type
        matrix = matrix_to_array(inst.matrix_world)
        if hair and kind == "MESH" and getattr(inst, "show_particles", True) and len(obj.particle_systems):
            # particle hair renders also when its emitter does not (Show Emitter off)
            for mesh in export_particle_hair(ctx, obj, matrix, name, camera, scene, render=render):
                mesh.holdout = bool(getattr(obj, "is_holdout", False))
                meshes.append(mesh)
        if not inst.is_instance and not inst.show_self:
            continue
        if kind in GEOMETRY_TYPES:
            if not isinstance(obj.data, bpy.types.Mesh):
                # curves, text, metaballs, surfaces: Blender lists their evaluated mesh as an instance of
                # theirs (a mesh object), exported there as Cycles does; converting this too doubled them
                unsurfaced.append(obj.original.name)
                continue
            object_features(ctx, obj.original, name)
            if inst.is_instance or mesh_cache is None:
                mesh = export_mesh(ctx, obj, matrix, name, cache if inst.is_instance else None)
            else:
                key = MeshCache.key(obj)
                mesh_cache.reads += key not in mesh_cache.local
                mesh = export_mesh(ctx, obj, matrix, name, mesh_cache.local, key=key)
            if mesh is not None:
                # the illuminance-sensor flag (our object property) and Blender's object holdout, of the
                # object or of its instancer (a curve or text whose mesh this is; as Cycles reads holdout)
                owners = (obj, inst.parent) if inst.is_instance and inst.parent is not None else (obj,)
                mesh.sensor = any(bool(getattr(o, "spectral_gi_sensor", False)) for o in owners)
                mesh.holdout = any(bool(getattr(o, "is_holdout", False)) for o in owners)
                for key, value in ray_visibility(owners).items():
                    setattr(mesh, key, value)
                meshes.append(mesh)
                mesh_owners.append({o.original.name if o.original else o.name for o in owners})
                emitters.append((mesh, obj.original))
                surfaced.add(obj.original.name)
                for mat in slot_materials(obj):
                    if mat is not None:
                        ctx.material_user(mat.name, name)
        elif kind == "LIGHT":
            object_features(ctx, obj.original, name, light=True)
            light = export_light(ctx, obj, matrix, name)
            if light is not None:
                for key, value in ray_visibility((obj,), LIGHT_VISIBILITY).items():
                    setattr(light, key, value)
                light.cast_shadow = bool(getattr(obj.data, "use_shadow", True))
                lights.append(light)
                emitters.append((light, obj.original))
        elif kind == "CURVES":
            if hair:
                object_features(ctx, obj.original, name)
                mesh = export_curves_object(ctx, obj, matrix, name, camera, scene)
                if mesh is not None:
                    mesh.holdout = bool(getattr(obj, "is_holdout", False))
                    meshes.append(mesh)
        elif kind not in HELPER_TYPES:
            ctx.skip(f"{kind.lower()} objects", obj.name)
    for rec, ob in emitters:
        rec.receivers, rec.blockers = link_lists(ob, mesh_owners)
    for obj_name in unsurfaced:
        if obj_name not in surfaced:
            ctx.skip("objects with no surface", obj_name)
    if getattr(scene.render, "use_motion_blur", False):
        ctx.skip("motion blur (rendered at the frame's instant)", scene.name)
    ctx.check_cancel()
    world = scene.world.evaluated_get(depsgraph) if scene.world is not None else None
    core_world = export_world(ctx, world)
    lights.extend(getattr(ctx, "world_lights", []))  # a Sky Texture's sun disc
    export_world_volume(ctx, world)
    if not ctx.materials:
        ctx.default_material()
    result = Scene(meshes=meshes, spectra=ctx.spectra, materials=ctx.materials, ior_tables=ctx.ior_tables,
                   media=ctx.media, textures=ctx.textures, programs=ctx.programs, lights=lights, camera=camera,
                   profiles=getattr(ctx, "profiles", []),
                   world=core_world, settings=render_settings(scene),
                   metadata={"source": "Blender " + bpy.app.version_string, "scene": scene.name,
                             "blend_file": bpy.data.filepath,
                             "unit_scale_length": ctx.scale_length})
    validate(result)
    return ExportResult(scene=result, warning=ctx.warning())
