"""Image textures: the arrays the path kernel reads (the record and its validation are the
scene contract's, :mod:`core.scene.textures`).

A :class:`Texture` is a linear float32 image (H, W, C), C = 1 or 3, row 0 at the *top*,
addressed by UV coordinates with Blender's convention: (0, 0) is the image's bottom-left
corner, u to the right, v up. Materials refer to textures by index:

* ``Material.base_colour_texture``: replaces the model's ``ra`` spectrum. Its rgb,
  clamped to [0, 1], is uplifted with the linear Mallett–Yuksel (2019) basis,
  ρ(λ) = r·B_r(λ) + g·B_g(λ) + b·B_b(λ) (in [0, 1], flat 1 for white), the basis of
  ``core.spectra.uplift``: the kernel weighs three basis rows by the texel's rgb, so no
  per-texel spectral coefficients are stored. A one-channel texture is grey (r = g = b).
* ``Material.roughness_texture`` (one channel): Blender's roughness r, giving the GGX
  α = r² of both axes (isotropic), as the add-on does for a constant roughness. Only for
  the models whose row holds a GGX α: ROUGHNESS_MODELS (GGX conductor, GGX dielectric,
  plastic).
* ``Material.normal_texture`` (three channels, non-colour): a tangent-space normal map
  with Blender's convention (OpenGL, +Y up: n = 2·rgb − 1 in the frame tangent, bitangent,
  normal), the tangent of each triangle from its UV derivatives, ``normal_strength``
  blending between the interpolated normal (0) and the mapped one (1), as Blender's
  Normal Map node.

Lookups (core/kernels/textures.py): "closest" takes the texel containing the point,
"linear" interpolates the four nearest texel centres. Extension "repeat" tiles the
image, "extend" repeats its edge texels, "clip" gives 0 outside [0, 1]² (inside, the
edge texels extend). Texel values are clamped to [0, 1] when a render is prepared.
"""
from __future__ import annotations

import numpy as np

from ..scene.textures import TEXTURE_FIELDS
from .kernel import EXT_TAGS, INTERP_TAGS
from ..io import presets
from ..spectra import moments

INFO_SIZE = 6  # columns of the kernel's info table: offset, width, height, channels, interpolation, extension


def pack(textures):
    """(data float32 (N,), info int64 (K, INFO_SIZE)) of all textures, values clamped to [0, 1].

    Texel (i, j) (column, row from the top) channel c of texture t is
    data[info[t, 0] + (j·W + i)·C + c]. An empty list gives one dummy texel and row."""

    if not textures:
        return np.zeros(1, np.float32), np.zeros((1, INFO_SIZE), np.int64)
    info = np.zeros((len(textures), INFO_SIZE), np.int64)
    parts = []
    offset = 0
    for t, tx in enumerate(textures):
        h, w, c = tx.image.shape
        info[t] = (offset, w, h, c, INTERP_TAGS[tx.interpolation], EXT_TAGS[tx.extension])
        parts.append(np.clip(np.ascontiguousarray(tx.image, np.float32).reshape(-1), 0.0, 1.0))
        offset += h * w * c
    return np.ascontiguousarray(np.concatenate(parts), np.float32), info


def material_tables(scene):
    """(mat_tex int32 (K, 3): base colour, roughness and normal texture of each material
    (-1 none), mat_nstr float64 (K,): normal strengths)."""
    n = max(1, len(scene.materials))
    mat_tex = np.full((n, 3), -1, np.int32)
    nstr = np.ones(n)
    for i, m in enumerate(scene.materials):
        mat_tex[i] = [getattr(m, k) for k in TEXTURE_FIELDS]
        nstr[i] = m.normal_strength
    return mat_tex, nstr


def corner_uvs(mesh):
    """float64 (T, 3, 2) UVs of each triangle's corners (from corner_uvs, else per-vertex uvs), or None."""
    if mesh.corner_uvs is not None:
        return mesh.corner_uvs.astype(np.float64).reshape(-1, 3, 2)
    if mesh.uvs is not None:
        return mesh.uvs.astype(np.float64)[mesh.indices]
    return None


def triangle_frames(scene, prims):
    """float32 (T, 10) per triangle in BVH leaf order (``prims``, the BVH's permutation):
    the corners' UVs (u0 v0 u1 v1 u2 v2), the tangent ∂p/∂u (3, not normalised) and the
    handedness s = ±1 of the UV map (the bitangent is s·n × t); (0, 10) when no material
    uses a texture or a program. Triangles without UVs get zeros and the tangent of an arbitrary frame."""
    from ..shading.program import uses_programs

    if not any(getattr(m, k) >= 0 for m in scene.materials for k in TEXTURE_FIELDS) and not uses_programs(scene):
        return np.zeros((0, 10), np.float32)
    parts = []
    for mesh in scene.meshes:
        p = mesh.positions.astype(np.float64)
        idx = mesh.indices
        n_t = idx.shape[0]
        e1 = p[idx[:, 1]] - p[idx[:, 0]]
        e2 = p[idx[:, 2]] - p[idx[:, 0]]
        ng = np.cross(e1, e2)
        uv = corner_uvs(mesh)
        rows = np.zeros((n_t, 10))
        # an arbitrary tangent perpendicular to the normal, for triangles without a UV frame
        ax = np.where(np.abs(ng[:, :1]) < 0.9 * np.linalg.norm(ng, axis=1, keepdims=True), [[1.0, 0, 0]],
                      [[0.0, 1, 0]])
        tan = np.cross(ax, ng)
        sign = np.ones(n_t)
        if uv is not None:
            rows[:, :6] = uv.reshape(n_t, 6)
            du1 = uv[:, 1, 0] - uv[:, 0, 0]
            dv1 = uv[:, 1, 1] - uv[:, 0, 1]
            du2 = uv[:, 2, 0] - uv[:, 0, 0]
            dv2 = uv[:, 2, 1] - uv[:, 0, 1]
            det = du1 * dv2 - du2 * dv1
            ok = np.abs(det) > 1e-20
            r = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
            t_uv = (e1 * dv2[:, None] - e2 * dv1[:, None]) * r[:, None]  # ∂p/∂u
            b_uv = (e2 * du1[:, None] - e1 * du2[:, None]) * r[:, None]  # ∂p/∂v
            t_ok = ok & (np.linalg.norm(np.cross(ng, t_uv), axis=1) > 0)
            tan[t_ok] = t_uv[t_ok]
            sign[t_ok] = np.where(np.einsum("ij,ij->i", np.cross(ng[t_ok], t_uv[t_ok]), b_uv[t_ok]) < 0, -1.0, 1.0)
        rows[:, 6:9] = tan
        rows[:, 9] = sign
        parts.append(rows)
    if not parts:
        return np.zeros((0, 10), np.float32)
    return np.ascontiguousarray(np.concatenate(parts)[prims], np.float32)


def reflectance_basis():
    """(3, N_LAMBDA) the Mallett–Yuksel reflectance basis rows B_r, B_g, B_b on the renderer's grid."""

    wl, basis = presets.mallett2019_basis()
    grid = moments.grid()
    return np.stack([np.interp(grid, wl, basis[:, k]) for k in range(3)])
