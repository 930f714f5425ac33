"""The visibility record: which rays see which triangles and which emitters light and
shadow which triangles (Cycles' ray visibility, light linking and shadow linking), in
the BVH's leaf order and the emitter table's order, as the path kernel reads them.

A scene whose meshes and lights keep every default (visible to every ray, casting
shadows, no links) has no record (``pack`` returns None): the path kernel then compiles
none of this code.

Ray classes, the kind of event that sent a ray (Cycles' path flags): the camera, a diffuse,
glossy or transmission bounce at a surface (from the sampled lobe: a direction on the other
side of the surface is a transmission, a diffuse lobe's a diffuse bounce, anything else, a
mirror too, glossy), or a scattering event in a medium. A hidden bit ``1 << class`` in a
triangle's mask makes rays of that class pass through it.

Emitters (the emissive triangles and analytic lights of the emitter table) carry the same
hidden bits: rays of a hidden class do not see them, and next-event estimation does not
sample them for a shading point whose scattering is of that class (judged from the
material and the side of the light: a material with both a diffuse and a glossy lobe is
hidden from a light only when both are). An emitter whose light reaches a point other than
along plain, occluded rays (a hidden class, shadow linking, or no shadows) is estimated by
next-event estimation alone (``NEE_ONLY``): BSDF-sampled rays that meet it after a non-delta
event add nothing, so that the estimator stays unbiased for what next-event estimation
integrates. After a delta event (a mirror, smooth glass), where no next-event estimation is
done, it is seen by the ray as usual.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

RAY_CAMERA = 0
RAY_DIFFUSE = 1
RAY_GLOSSY = 2
RAY_TRANSMISSION = 3
RAY_VOLUME = 4
HIDE_CAMERA = 1 << RAY_CAMERA
HIDE_DIFFUSE = 1 << RAY_DIFFUSE
HIDE_GLOSSY = 1 << RAY_GLOSSY
HIDE_TRANSMISSION = 1 << RAY_TRANSMISSION
HIDE_VOLUME = 1 << RAY_VOLUME
NEE_ONLY = 1 << 5  # an emitter estimated by next-event estimation alone
NO_SHADOW = 1 << 6  # an emitter nothing occludes (a light with cast_shadow False)


class VisibilityRecord(NamedTuple):
    """T triangles (leaf order), E emitter-table entries.

    tri_vis: int32 (T,) hidden bits of each triangle (``1 << RAY_*``).
    tri_rcv: int32 (T,) the receiver class of each triangle (its mesh's light-linking class).
    tri_blk: int32 (T,) the blocker class of each triangle (shadow linking and shadow visibility).
    emit_hide: int32 (E,) each emitter's hidden bits, ``NEE_ONLY`` and ``NO_SHADOW``.
    emit_rgrp: int32 (E,) each emitter's receiver group (0: it lights everything).
    emit_sgrp: int32 (E,) each emitter's shadow group (0: everything that casts shadows blocks it).
    rcv_ok: uint8 (C, G) 1 when receiver class c is lit by the emitters of group g.
    blk_ok: uint8 (B, H) 1 when blocker class b occludes the emitters of shadow group h.
    masked: int, 1 when some triangle does not occlude some emitter (the shadow rays then
        look past such triangles), else 0.
    """

    tri_vis: np.ndarray
    tri_rcv: np.ndarray
    tri_blk: np.ndarray
    emit_hide: np.ndarray
    emit_rgrp: np.ndarray
    emit_sgrp: np.ndarray
    rcv_ok: np.ndarray
    blk_ok: np.ndarray
    masked: int


def _hide_bits(camera, diffuse, glossy, transmission, volume):
    return ((0 if camera else HIDE_CAMERA) | (0 if diffuse else HIDE_DIFFUSE) | (0 if glossy else HIDE_GLOSSY)
            | (0 if transmission else HIDE_TRANSMISSION) | (0 if volume else HIDE_VOLUME))


def _mesh_hide(m):
    return _hide_bits(m.visible_camera, m.visible_diffuse, m.visible_glossy, m.visible_transmission,
                      m.visible_volume)


def _light_hide(li):
    return _hide_bits(True, li.visible_diffuse, li.visible_glossy, li.visible_transmission, li.visible_volume)


def uses_visibility(scene):
    """True when a mesh or light of ``scene`` leaves a visibility default or has a link."""
    for m in scene.meshes:
        if _mesh_hide(m) or not m.visible_shadow or m.receivers is not None or m.blockers is not None:
            return True
    for li in scene.lights:
        if _light_hide(li) or not li.cast_shadow or li.receivers is not None or li.blockers is not None:
            return True
    return False


def _groups(sets):
    """Group index per emitter (0: None, all) and the distinct sets (group g ≥ 1 is sets[g - 1])."""
    distinct = []
    index = []
    for s in sets:
        if s is None:
            index.append(0)
            continue
        key = frozenset(int(i) for i in s)
        if key not in distinct:
            distinct.append(key)
        index.append(distinct.index(key) + 1)
    return index, distinct


def _classes(n_meshes, table_of):
    """Class per mesh and the table (C, G) of the distinct rows ``table_of(mesh)`` (uint8)."""
    rows = []
    cls = np.zeros(n_meshes, np.int32)
    for j in range(n_meshes):
        row = tuple(table_of(j))
        if row not in rows:
            rows.append(row)
        cls[j] = rows.index(row)
    if not rows:
        rows = [tuple(table_of(-1))]
    return cls, np.ascontiguousarray(np.array(rows, np.uint8).reshape(len(rows), -1))


def pack(scene, bvh, emitters):
    """The :class:`VisibilityRecord` of ``scene`` (``bvh`` its BVH, ``emitters`` its
    EmitterRecord), or None when it uses no visibility flag nor link (``uses_visibility``)."""
    if not uses_visibility(scene):
        return None
    meshes = scene.meshes
    n_m = len(meshes)
    counts = [int(m.indices.shape[0]) for m in meshes]
    tri_mesh = np.repeat(np.arange(n_m, dtype=np.int32), counts) if n_m else np.zeros(0, np.int32)
    tri_mesh = tri_mesh[bvh.prims] if tri_mesh.size else tri_mesh
    emit_tri = emitters.emit_tri
    emit_light = emitters.emit_light
    n_e = emit_tri.shape[0]
    # the emitter of each entry: ('light', li), ('mesh', j) or None (the world image)
    owners = []
    for e in range(n_e):
        if emit_tri[e] >= 0:
            owners.append(meshes[int(tri_mesh[emit_tri[e]])])
        elif emit_light[e] >= 0:
            owners.append(scene.lights[int(emit_light[e])])
        else:
            owners.append(None)
    # groups over every emitter of the scene (so that the tables do not depend on which emit)
    emitters_all = list(scene.lights) + list(meshes)
    r_index, r_sets = _groups([o.receivers for o in emitters_all])
    s_index, s_sets = _groups([o.blockers for o in emitters_all])
    group_of = {id(o): (r_index[k], s_index[k]) for k, o in enumerate(emitters_all)}
    tri_rcv_m, rcv_ok = _classes(n_m, lambda j: [1] + [1 if j in s else 0 for s in r_sets])
    tri_blk_m, blk_ok = _classes(
        n_m, lambda j: [1 if j < 0 or meshes[j].visible_shadow else 0]
        + [1 if j >= 0 and meshes[j].visible_shadow and j in s else 0 for s in s_sets])
    mesh_hide = np.array([_mesh_hide(m) for m in meshes] or [0], np.int32)
    emit_hide = np.zeros(n_e, np.int32)
    emit_rgrp = np.zeros(n_e, np.int32)
    emit_sgrp = np.zeros(n_e, np.int32)
    for e, o in enumerate(owners):
        if o is None:
            continue
        is_light = emit_light[e] >= 0
        hide = _light_hide(o) if is_light else _mesh_hide(o) & ~HIDE_CAMERA
        no_shadow = is_light and not o.cast_shadow
        if hide or no_shadow or o.blockers is not None:
            hide |= NEE_ONLY
        if no_shadow:
            hide |= NO_SHADOW
        emit_hide[e] = hide
        emit_rgrp[e], emit_sgrp[e] = group_of[id(o)]
    return VisibilityRecord(
        np.ascontiguousarray(mesh_hide[tri_mesh] if tri_mesh.size else np.zeros(0, np.int32), np.int32),
        np.ascontiguousarray(tri_rcv_m[tri_mesh], np.int32), np.ascontiguousarray(tri_blk_m[tri_mesh], np.int32),
        emit_hide, emit_rgrp, emit_sgrp, rcv_ok, blk_ok, int(not blk_ok.all()))
