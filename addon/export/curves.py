"""Particle hair and Curves objects → core meshes of tessellated curves (core/geometry/curves.py).

The strands are read as Cycles reads them (intern/cycles/blender/curves.cpp):

* Particle hair (a Hair particle system rendered as Path on a mesh): every strand Cycles
  renders — the parents, or only the children when there are children — with
  ``2^steps + 1`` keys (Render Steps in a final render, Viewport Steps otherwise, plus the
  spiral kink's extra steps) read with ``ParticleSystem.co_hair``; the viewport keeps the
  Display Amount's share of the children, as Cycles does. Radius along the strand: Cycles'
  Hair Shape, ``radius_scale · ½ · (root … tip)`` bent by Shape over the strand's
  fraction of length, zero at the last key with Close Tip; material: the settings'
  material slot.
* Curves objects: the points' positions and their ``radius`` attribute (0.005 without
  one, Cycles' default); material: the first slot.

Round curves ("3D Curves", or any Curves object of poly curves, which Cycles always
renders round) become tubes of Hair Sides faces, ribbons camera-facing strips. Between
keys the strands follow Cycles' Catmull-Rom spline in straight pieces, one per 15° of
turning (poly curves: straight between their points, as Cycles).
"""
import numpy as np

from .convert import matrix_to_array
from .mesh import slot_materials

CURVES_DEFAULT_RADIUS = 0.005  # Cycles' radius of Curves points without a radius attribute
DEFAULT_SIDES = 6
CURVE_TYPE_POLY = 1  # Blender's CurveType: CATMULL_ROM 0, POLY 1, BEZIER 2, NURBS 3
MAX_TRIANGLES = 100_000_000  # per hair system or Curves object: about 12 GB of BVH (122 B per triangle)


def hair_shape(scene):
    """The core curve shape of Cycles' curve setting (Render properties > Curves > Shape)."""
    from ...core import hair_curves as G

    settings = getattr(scene, "cycles_curves", None)
    return G.RIBBON if getattr(settings, "shape", "THICK") == "RIBBONS" else G.ROUND


def hair_sides(scene):
    s = getattr(scene, "spectral_gi", None)
    return int(getattr(s, "hair_sides", DEFAULT_SIDES)) if s is not None else DEFAULT_SIDES


def renders_hair(depsgraph):
    """Whether the view layer renders hair (View Layer > Filter > Hair), as Cycles reads it."""
    layer = getattr(depsgraph, "view_layer", None)
    return bool(getattr(layer, "use_strand", True)) if layer is not None else True


def _linear_scale(matrix):
    """The mean linear scale of a 4×4 matrix (cube root of its determinant's size)."""
    return abs(float(np.linalg.det(np.asarray(matrix, np.float64)[:3, :3]))) ** (1.0 / 3.0)


def _psys_modifier_enabled(obj, psys, render):
    for mod in getattr(obj, "modifiers", ()):
        if mod.type == "PARTICLE_SYSTEM" and mod.particle_system.name == psys.name:
            return bool(mod.show_render if render else mod.show_viewport)
    return True


def particle_strands(obj, psys, render):
    """(keys float64 (K, 3) in object space, counts int (C,), times (K,) fraction of length) of
    the strands Cycles renders of particle system ``psys`` of evaluated object ``obj``."""
    part = psys.settings
    n_parent = len(psys.particles)
    n_child = len(psys.child_particles)
    if not render:
        n_child = int(n_child * float(getattr(part, "display_percentage", 100)) / 100.0)
    first = n_parent if (part.child_type != "NONE" and n_child > 0) else 0
    total = n_parent + n_child
    steps = (1 << int(part.render_step if render else part.display_step)) + 1
    if getattr(part, "kink", "NO") == "SPIRAL":
        steps += int(getattr(part, "kink_extra_steps", 0))
    n_curves = max(total - first, 0)
    world = np.zeros((n_curves, steps, 3), np.float64)
    for c, pa in enumerate(range(first, total)):
        prev = (0.0, 0.0, 0.0)
        for s in range(steps):
            co = psys.co_hair(obj, particle_no=pa, step=s)
            # co_hair gives (0, 0, 0) past the cached path: Cycles keeps the previous key there
            prev = tuple(co) if (s == 0 or co[0] != 0.0 or co[1] != 0.0 or co[2] != 0.0) else prev
            world[c, s] = prev
    inv = np.linalg.inv(matrix_to_array(obj.matrix_world))
    local = world @ inv[:3, :3].T + inv[:3, 3]
    seg = np.linalg.norm(np.diff(local, axis=1), axis=2)
    cum = np.concatenate([np.zeros((n_curves, 1)), np.cumsum(seg, axis=1)], axis=1)
    length = cum[:, -1:]
    times = np.where(length > 0.0, cum / np.where(length > 0.0, length, 1.0), 0.0)
    return local.reshape(-1, 3), np.full(n_curves, steps, np.int64), times.reshape(-1)


def particle_radii(part, times, counts):
    """Cycles' key radii (object units) of particle settings ``part`` at fractions of length ``times``."""
    from ...core import hair_curves
    shape_radius = hair_curves.shape_radius

    half = float(part.radius_scale) * 0.5
    r = shape_radius(float(part.shape), half * float(part.root_radius), half * float(part.tip_radius), times)
    if getattr(part, "use_close_tip", True) and len(counts):
        r = np.array(r, np.float64)
        r[np.cumsum(counts) - 1] = 0.0
    return r


def _curves_mesh(ctx, name, local, radii, counts, matrix, material, camera, shape, sides, spline=True):
    from ...core import Mesh
    from ...core import constants as C
    from ...core import hair_curves as G

    m = np.asarray(matrix, np.float64)
    world = (local @ m[:3, :3].T + m[:3, 3]) * ctx.scale_length
    r = np.asarray(radii, np.float64) * _linear_scale(m) * ctx.scale_length
    if spline:  # Cycles' Catmull-Rom spline through the keys, in straight pieces where it bends
        world, r, counts = G.catmull_rom_refine(world, r, counts)
    eye = view_dir = None
    if shape == G.RIBBON:
        to_world = np.asarray(camera.to_world, np.float64)
        if camera.projection == C.CAM_ORTHOGRAPHIC:
            view_dir = -to_world[:3, 2]
        else:
            eye = to_world[:3, 3]
    n_tri = G.triangle_count(counts, shape, sides)
    if n_tri > MAX_TRIANGLES:
        from .context import ExportError

        raise ExportError(f"{name}: {len(counts)} strands would make {n_tri:,} triangles (at most "
                          f"{MAX_TRIANGLES:,}); use fewer children, Render Steps or Hair Sides")
    pos, tri, nrm, _ = G.tessellate(world, r, counts, shape=shape, sides=sides, eye=eye, view_dir=view_dir)
    if tri.shape[0] == 0:
        return None
    return Mesh(name=name, positions=pos, indices=tri, material=np.full(tri.shape[0], material, np.int32),
                normals=nrm)


def _material(ctx, obj, slot, owner_name):
    from .material import export_material

    mats = slot_materials(obj)
    mat = mats[min(max(slot, 0), len(mats) - 1)] if mats else None
    if mat is not None:
        ctx.material_user(mat.name, owner_name)
    return export_material(ctx, mat)


def export_particle_hair(ctx, obj, matrix, name, camera, scene, render=True):
    """Core meshes of the hair particle systems of evaluated mesh object ``obj`` placed by ``matrix``."""

    meshes = []
    shape, sides = hair_shape(scene), hair_sides(scene)
    for psys in getattr(obj, "particle_systems", ()):
        part = psys.settings
        if part.type != "HAIR" or not _psys_modifier_enabled(obj, psys, render):
            continue
        label = f"{name}/{psys.name}"
        if part.render_type != "PATH":
            continue  # Object / Collection hair: its instances come with the depsgraph's
        local, counts, times = particle_strands(obj, psys, render)
        if len(counts) == 0:
            continue
        radii = particle_radii(part, times, counts)
        material = _material(ctx, obj, int(part.material) - 1, label)
        mesh = _curves_mesh(ctx, label, local, radii, counts, matrix, material, camera, shape, sides)
        if mesh is not None:
            meshes.append(mesh)
            ctx.note(f"{label}: hair rendered as {_shape_text(shape, sides)}; {len(counts)} strands, "
                     f"{mesh.indices.shape[0]} triangles")
    return meshes


def curves_data(curves):
    """(positions (P, 3), counts (C,), radii (P,), poly) of a Curves datablock (object space)."""
    n_points, n_curves = len(curves.points), len(curves.curves)
    pos = np.zeros(n_points * 3, np.float32)
    if n_points:
        curves.position_data.foreach_get("vector", pos)
    offsets = np.zeros(n_curves + 1, np.int32)
    if n_curves:
        curves.curve_offset_data.foreach_get("value", offsets)
    radii = np.full(n_points, CURVES_DEFAULT_RADIUS, np.float32)
    attr = curves.attributes.get("radius")
    if attr is not None and attr.domain == "POINT" and attr.data_type == "FLOAT" and n_points:
        attr.data.foreach_get("value", radii)
    poly = False
    types = curves.attributes.get("curve_type")
    if types is not None and n_curves and types.domain == "CURVE":
        poly = int(types.data[0].value) == CURVE_TYPE_POLY
    return pos.reshape(-1, 3).astype(np.float64), np.diff(offsets).astype(np.int64), radii.astype(np.float64), poly


def export_curves_object(ctx, obj, matrix, name, camera, scene):
    """A core mesh of evaluated Curves object ``obj`` placed by ``matrix``, or None without curves."""
    from ...core import hair_curves as G

    pos, counts, radii, poly = curves_data(obj.data)
    if len(counts) == 0:
        return None
    if np.any(counts < 2):
        ctx.note(f"{name}: curves of one point skipped")
    shape = G.ROUND if poly else hair_shape(scene)
    sides = hair_sides(scene)
    material = _material(ctx, obj, 0, name)
    mesh = _curves_mesh(ctx, name, pos, radii, counts, matrix, material, camera, shape, sides, spline=not poly)
    if mesh is not None:
        ctx.note(f"{name}: curves rendered as {_shape_text(shape, sides)}; {len(counts)} curves, "
                 f"{mesh.indices.shape[0]} triangles")
    return mesh


def _shape_text(shape, sides):
    from ...core import hair_curves as G

    if shape == G.RIBBON:
        return "camera-facing ribbons"
    lo, hi = G.silhouette_range(sides)
    return (f"tubes of {sides} sides (width seen from one side {100 * (lo - 1):+.0f} % "
            f"to {100 * (hi - 1):+.0f} % of the round curve's, exact on average)")
