"""The shading record: the scene's shader programs as the path kernel reads them (the
programs and their validation: core/shading/program.py)."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import ops as O
from .program import PROGRAM_FIELDS, Q_CONST, WORLD_POSITION, instructions, uses_programs


class ShadingRecord(NamedTuple):
    """The scene's shader programs as the path kernel reads them (T triangles in the BVH's
    leaf order, K materials).

    prog_ops: int32 (N,) all programs' instructions, constants and attributes relocated.
    prog_consts: float32 (M,) their constants.
    mat_prog: int32 (K, 5) the start in prog_ops of each material's base colour, roughness,
        emission, normal and mix program (-1 none).
    tri_attr: float32 (T, 9·A) each triangle's corner values (3 corners × 3) of the A attributes.
    refl_row: int, the first of the three reflectance basis rows of the spectrum table (-1 none).
    emit_row: int, the first of the three emission basis rows (-1 none).
    """

    prog_ops: np.ndarray
    prog_consts: np.ndarray
    mat_prog: np.ndarray
    tri_attr: np.ndarray
    refl_row: int
    emit_row: int


def _relocate(prog, c_base, attr_index):
    ops = prog.ops.astype(np.int32).copy()
    for pc, op, n, out, p, q, args in instructions(ops):
        for j, k in enumerate(args):
            if k < 0:
                ops[pc + O.HEADER + j] = -1 - (-1 - k + c_base)
        if op in Q_CONST:
            ops[pc + 4] = q + c_base
        elif op == O.OP_ATTR:
            ops[pc + 4] = attr_index[prog.attributes[q]]
    return ops


def pack(scene, prims, spec, cmf):
    """(record or None, spec): the programs of ``scene`` for a BVH with leaf permutation
    ``prims``, and the spectrum table with the reflectance and emission basis rows appended;
    None when no material has a program."""
    if not uses_programs(scene):
        return None, spec
    from ..lights.record import world_emission_basis
    from ..textures import reflectance_basis

    names = sorted({a for p in scene.programs for a in p.attributes})
    attr_index = {a: i for i, a in enumerate(names)}
    ops_parts, const_parts, starts = [], [], []
    o_base = c_base = 0
    for prog in scene.programs:
        ops = _relocate(prog, c_base, attr_index)
        starts.append(o_base)
        ops_parts.append(ops)
        const_parts.append(prog.consts.astype(np.float32))
        o_base += ops.shape[0]
        c_base += prog.consts.shape[0]
    n = max(1, len(scene.materials))
    mat_prog = np.full((n, len(PROGRAM_FIELDS)), -1, np.int32)
    for i, m in enumerate(scene.materials):
        for s, key in enumerate(PROGRAM_FIELDS):
            k = getattr(m, key, -1)
            if k >= 0:
                mat_prog[i, s] = starts[k]
    a = max(1, len(names))
    parts = []
    for mesh in scene.meshes:
        t = mesh.indices.shape[0]
        rows = np.zeros((t, 9 * a), np.float32)
        for name, j in attr_index.items():
            v = (mesh.attributes or {}).get(name)
            if name == WORLD_POSITION:
                v = mesh.positions[mesh.indices].astype(np.float32)
            if v is not None:
                rows[:, 9 * j:9 * j + 9] = np.asarray(v, np.float32).reshape(t, 9)
        parts.append(rows)
    tri_attr = np.concatenate(parts)[prims] if parts else np.zeros((0, 9 * a), np.float32)
    refl_row = spec.shape[0]
    emit_row = refl_row + 3
    spec = np.concatenate([spec, reflectance_basis().astype(np.float32),
                           world_emission_basis(cmf)[0].astype(np.float32)])
    rec = ShadingRecord(np.ascontiguousarray(np.concatenate(ops_parts), np.int32),
                        np.ascontiguousarray(np.concatenate(const_parts + [np.zeros(1, np.float32)]), np.float32),
                        mat_prog, np.ascontiguousarray(tri_attr, np.float32), int(refl_row), int(emit_row))
    return rec, spec


def add_sensor(rec):
    """``rec`` with the sensors' material: no programs."""
    if rec is None:
        return None
    return rec._replace(mat_prog=np.concatenate([rec.mat_prog, np.full((1, len(PROGRAM_FIELDS)), -1, np.int32)]))
