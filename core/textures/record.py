"""The textures record: the image textures and per-triangle UV frames the path kernel reads."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np


class TextureRecord(NamedTuple):
    """Image textures as the path kernel reads them (lookups in core/textures/kernel.py);
    T triangles in the BVH's leaf order, K materials.

    tri_tex: float32 (T, 10) each triangle's corner UVs (u0 v0 u1 v1 u2 v2), tangent ∂p/∂u
        and UV handedness; (0, 10) when no material has a texture (then none of the
        texture code runs).
    tex_data: float32 (N,) the texels of all textures, clamped to [0, 1] (``pack``).
    tex_info: int64 (X, INFO_SIZE) per texture: offset, width, height, channels,
        interpolation, extension.
    mat_tex: int32 (K, 3) each material's base colour, roughness and normal texture (-1 none).
    mat_nstr: float64 (K,) each material's normal-map strength.
    tex_row: int, the first of the three reflectance basis rows of the spectrum table a base
        colour texel's rgb weighs (-1: no material has a base colour texture).
    shading: the shader programs (core/shading/record.py ShadingRecord), None when no
        material has one (then none of the program code is compiled).
    """

    tri_tex: np.ndarray
    tex_data: np.ndarray
    tex_info: np.ndarray
    mat_tex: np.ndarray
    mat_nstr: np.ndarray
    tex_row: int
    shading: object = None


def pack(scene, prims, spec, cmf=None):
    """(record, spec): ``scene``'s textures for a BVH with leaf permutation ``prims``, and the
    spectrum table ``spec`` with the reflectance basis rows appended when a material has a
    base colour texture."""
    from . import material_tables, pack as pack_texels, reflectance_basis, triangle_frames

    tri_tex = triangle_frames(scene, prims)
    tex_data, tex_info = pack_texels(scene.textures)
    mat_tex, mat_nstr = material_tables(scene)
    tex_row = -1
    if np.any(mat_tex[:, 0] >= 0):
        tex_row = spec.shape[0]
        spec = np.concatenate([spec, reflectance_basis().astype(np.float32)])
    from ..shading import record as shading_record

    shading, spec = shading_record.pack(scene, prims, spec, cmf)
    return TextureRecord(tri_tex, tex_data, tex_info, mat_tex, mat_nstr, int(tex_row), shading), spec


def add_sensor(rec) -> TextureRecord:
    """``rec`` with the sensors' material (core/bsdfs/record.py add_sensor): untextured."""
    from ..shading import record as shading_record

    return rec._replace(mat_tex=np.concatenate([rec.mat_tex, np.full((1, 3), -1, np.int32)]),
                        mat_nstr=np.append(rec.mat_nstr, 1.0), shading=shading_record.add_sensor(rec.shading))
