"""Evaluated Blender geometry → core meshes (world space, metres)."""
import numpy as np

from .convert import points_to_world_metres
from .material import export_material
from .shading import corner_attributes, program_attributes, render_uv_layer

# Object types that Blender can turn into a mesh (modifiers and geometry nodes applied).
GEOMETRY_TYPES = frozenset({"MESH", "CURVE", "SURFACE", "FONT", "META"})
# Object types that never render anything: skipped without a warning.
HELPER_TYPES = frozenset({"EMPTY", "CAMERA", "ARMATURE", "LATTICE", "LIGHT_PROBE", "SPEAKER"})


def corner_uvs(me):
    """float32 (T*3, 2) UVs of the loop triangles' corners from the render UV map, or None."""
    layer = render_uv_layer(me)
    n_t = len(me.loop_triangles)
    if layer is None or n_t == 0:
        return None
    uv = np.empty(len(layer.data) * 2, dtype=np.float32)
    layer.data.foreach_get("uv", uv)
    loops = np.empty(n_t * 3, dtype=np.int32)
    me.loop_triangles.foreach_get("loops", loops)
    return np.ascontiguousarray(uv.reshape(-1, 2)[loops], dtype=np.float32)


def local_triangles(obj):
    """(positions float32 (N, 3), triangles int32 (T, 3), material slot int32 (T,), normals, uvs) of
    an evaluated object; normals is None when every face is flat-shaded, uvs (float32 (T*3, 2),
    per triangle corner, from the render UV map) None without a UV map.

    With smooth faces the triangles are unwelded (three vertices each) so that each corner
    carries Blender's corner normal (smooth faces, sharp edges, custom normals) and flat
    faces their face normal. Uses ``to_mesh()`` (modifiers applied) and always frees it
    with ``to_mesh_clear()``. Returns None if the object yields no mesh.
    """
    try:
        me = obj.to_mesh()
    except RuntimeError:
        return None
    try:
        if me is None:
            return None
        me.calc_loop_triangles()
        n_v = len(me.vertices)
        n_t = len(me.loop_triangles)
        co = np.empty(n_v * 3, dtype=np.float32)
        tri = np.empty(n_t * 3, dtype=np.int32)
        slot = np.empty(n_t, dtype=np.int32)
        if n_v:
            me.vertices.foreach_get("co", co)
        if n_t:
            me.loop_triangles.foreach_get("vertices", tri)
            me.loop_triangles.foreach_get("material_index", slot)
        co = co.reshape(-1, 3)
        tri = tri.reshape(-1, 3)
        uvs = corner_uvs(me)
        smooth = np.zeros(n_t, dtype=bool)
        if n_t:
            me.loop_triangles.foreach_get("use_smooth", smooth)
        if not smooth.any() or not hasattr(me, "corner_normals"):
            return co, tri, slot, None, uvs
        loops = np.empty(n_t * 3, dtype=np.int32)
        me.loop_triangles.foreach_get("loops", loops)
        corner = np.empty(len(me.corner_normals) * 3, dtype=np.float32)
        me.corner_normals.foreach_get("vector", corner)
        face = np.empty(n_t * 3, dtype=np.float32)
        me.loop_triangles.foreach_get("normal", face)
        normals = corner.reshape(-1, 3)[loops].reshape(n_t, 3, 3)
        normals[~smooth] = face.reshape(-1, 3)[~smooth][:, None, :]
        return (np.ascontiguousarray(co[tri].reshape(-1, 3)), np.arange(n_t * 3, dtype=np.int32).reshape(-1, 3),
                slot, np.ascontiguousarray(normals.reshape(-1, 3)), uvs)
    finally:
        obj.to_mesh_clear()


def slot_materials(obj):
    """The Blender material of each material slot of ``obj`` (None for an empty slot)."""
    mats = [s.material for s in obj.material_slots]
    data_mats = list(getattr(obj.data, "materials", None) or [])
    for i, m in enumerate(data_mats):
        if i >= len(mats):
            mats.append(m)
        elif mats[i] is None:
            mats[i] = m
    return mats


def export_mesh(ctx, obj, matrix, name, cache=None, key=None):
    """A core Mesh for evaluated object ``obj`` placed by 4×4 ``matrix``, or None if it has no triangles.

    ``cache`` (a dict) shares the local triangles of objects instanced many times, under
    ``key`` (default: the evaluated mesh's address, valid for one export).
    """
    from ...core import Mesh

    if cache is not None and key is None and obj.data is not None:
        key = obj.data.as_pointer()
    if cache is None:
        key = None
    local = cache.get(key) if key is not None else None
    if local is None:
        local = local_triangles(obj)
        if local is None:
            return None
        if key is not None:
            cache[key] = local
    co, tri, slot, normals, uvs = local
    if tri.shape[0] == 0:
        return None
    mats = slot_materials(obj)
    lut = np.array([export_material(ctx, m) for m in mats] or [export_material(ctx, None)], dtype=np.int32)
    tri_mat = lut[np.clip(slot, 0, lut.size - 1)]
    world_normals = None
    if normals is not None:
        # normals transform by the inverse transpose of the object's linear part
        lin = np.asarray(matrix, dtype=np.float64)[:3, :3]
        try:
            nm = np.linalg.inv(lin).T
        except np.linalg.LinAlgError:
            nm = None
        if nm is not None:
            n = normals.astype(np.float64) @ nm.T
            length = np.linalg.norm(n, axis=1, keepdims=True)
            ok = length[:, 0] > 0
            n[ok] /= length[ok]
            n[~ok] = 0.0
            world_normals = np.ascontiguousarray(n, dtype=np.float32)
    # corner UVs only where a material reaches an image texture
    if not _uses_textures(ctx, set(int(k) for k in np.unique(tri_mat))):
        uvs = None
    elif uvs is None:
        ctx.note(f"{name}: no UV map, its image textures read at UV (0, 0)")
        uvs = np.zeros((tri.shape[0] * 3, 2), np.float32)
    attributes = None
    names = program_attributes(ctx, set(int(k) for k in np.unique(tri_mat)))
    if names:
        attributes = corner_attributes(ctx, obj, name, names)
    return Mesh(name=name, positions=points_to_world_metres(matrix, co, ctx.scale_length),
                indices=np.ascontiguousarray(tri, dtype=np.int32),
                material=np.ascontiguousarray(tri_mat, dtype=np.int32), normals=world_normals, corner_uvs=uvs,
                attributes=attributes)


def _uses_textures(ctx, indices):
    """True if one of the core materials ``indices`` (or a component of their mixes) has a texture."""
    from ...core import reached_materials

    return any(m.base_colour_texture >= 0 or m.roughness_texture >= 0 or m.normal_texture >= 0
               for m in (ctx.materials[i] for i in reached_materials(ctx.materials, indices)))
