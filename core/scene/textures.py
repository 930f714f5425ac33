"""The scene contract's image textures: the :class:`Texture` record and its validation.

How a texture is addressed and looked up is described in :mod:`..textures` (the
arrays the kernel reads and the lookups).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import constants as C
from .checks import check_array as _check_array, check_number as _check_number

INTERPOLATIONS = ("closest", "linear")
EXTENSIONS = ("repeat", "extend", "clip")
# models whose parameter row holds a GGX α in slots 1 (α_x) and 2 (α_y), see core/bsdfs/params.py
ROUGHNESS_MODELS = (C.MAT_GGX_CONDUCTOR, C.MAT_GGX_DIELECTRIC, C.MAT_PLASTIC)
# models without their own reflectance (a base colour texture means nothing for them)
NO_BASE_MODELS = (C.MAT_MIX, C.MAT_ADD, C.MAT_NULL)
TEXTURE_FIELDS = ("base_colour_texture", "roughness_texture", "normal_texture")


@dataclass
class Texture:
    """A linear image (float32 (H, W, C), C in {1, 3}, row 0 at the top) read through UVs."""

    name: str
    image: np.ndarray
    interpolation: str = "linear"  # "closest" or "linear"
    extension: str = "repeat"  # "repeat", "extend" or "clip"
    colour: bool = True  # colour data (base colour) or not (roughness, normal map): informative


def reached_materials(materials, indices):
    """The indices of ``materials`` that ``indices`` reach: themselves and, through mix and add
    materials, their components (out-of-range indices are left out)."""
    seen, stack = set(), list(indices)
    while stack:
        j = stack.pop()
        if j in seen or not 0 <= j < len(materials):
            continue
        seen.add(j)
        mj = materials[j]
        if mj.model in (C.MAT_MIX, C.MAT_ADD) and mj.params is not None and len(mj.params) >= 3:
            stack += [int(mj.params[1]), int(mj.params[2])]
    return seen


def check(scene, fail):
    """Validate ``scene.textures``, the materials' texture fields and the UVs they need.

    ``fail(field, problem)`` raises (core.scene's SceneError)."""

    textures = scene.textures
    if not isinstance(textures, list):
        fail("textures", f"expected a list, got {type(textures).__name__}")
    for i, tx in enumerate(textures):
        if not isinstance(tx, Texture):
            fail(f"textures[{i}]", f"expected a Texture, got {type(tx).__name__}")
        nm = f"textures[{i}] ({tx.name!r})"
        _check_array(f"{nm}.image", tx.image, np.float32, (None, None, None))
        h, w, c = tx.image.shape
        if h < 1 or w < 1:
            fail(f"{nm}.image", f"expected at least one texel, got shape {tx.image.shape}")
        if c not in (1, 3):
            fail(f"{nm}.image", f"expected 1 or 3 channels (H, W, C), got {c}")
        if tx.interpolation not in INTERPOLATIONS:
            fail(f"{nm}.interpolation", f"must be one of {INTERPOLATIONS}, got {tx.interpolation!r}")
        if tx.extension not in EXTENSIONS:
            fail(f"{nm}.extension", f"must be one of {EXTENSIONS}, got {tx.extension!r}")
        if not isinstance(tx.colour, (bool, np.bool_)):
            fail(f"{nm}.colour", f"expected true or false, got {tx.colour!r}")
    n_tex = len(textures)
    textured = set()
    for i, m in enumerate(scene.materials):
        nm = f"materials[{i}] ({m.name!r})"
        for key in TEXTURE_FIELDS:
            idx = getattr(m, key)
            _check_number(f"{nm}.{key}", idx, integer=True)
            if not -1 <= idx < n_tex:
                fail(f"{nm}.{key}", f"texture index {idx} out of range [-1, {n_tex})")
            if idx >= 0:
                textured.add(i)
        _check_number(f"{nm}.normal_strength", m.normal_strength, lo=0.0, hi=1e3)
        if m.base_colour_texture >= 0 and m.model in NO_BASE_MODELS:
            fail(f"{nm}.base_colour_texture", f"model {m.model} has no base colour (give it to a component)")
        if m.roughness_texture >= 0:
            if m.model not in ROUGHNESS_MODELS:
                fail(f"{nm}.roughness_texture", f"model {m.model} has no GGX roughness; supported models: "
                                                f"{ROUGHNESS_MODELS} (GGX conductor, GGX dielectric, plastic)")
            if textures[m.roughness_texture].image.shape[2] != 1:
                fail(f"{nm}.roughness_texture", f"texture {m.roughness_texture} must have one channel")
        if m.normal_texture >= 0:
            if m.model in (C.MAT_MIX, C.MAT_ADD, C.MAT_NULL):
                fail(f"{nm}.normal_texture", f"model {m.model} has no surface normal of its own "
                                             f"(give it to a component)")
            if textures[m.normal_texture].image.shape[2] != 3:
                fail(f"{nm}.normal_texture", f"texture {m.normal_texture} must have three channels")
    # a mix reaches its components: a mesh using a mix of textured materials needs UVs too
    reach = {i: reached_materials(scene.materials, [i]) for i in range(len(scene.materials))}
    for i, mesh in enumerate(scene.meshes):
        nm = f"meshes[{i}] ({mesh.name!r})"
        n_t = mesh.indices.shape[0]
        if mesh.corner_uvs is not None:
            _check_array(f"{nm}.corner_uvs", mesh.corner_uvs, np.float32, (3 * n_t, 2))
        if textured and n_t and mesh.uvs is None and mesh.corner_uvs is None:
            used = {int(k) for k in np.unique(mesh.material)}
            hit = sorted(k for k in used if reach.get(k, set()) & textured)
            if hit:
                fail(f"{nm}.uvs", f"material {hit[0]} ({scene.materials[hit[0]].name!r}) uses textures, "
                                  f"but the mesh has neither uvs nor corner_uvs")
