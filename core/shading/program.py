"""Shader programs in the scene contract and the record the path kernel reads.

A :class:`Program` is a flat int32 op array and a float32 constant array (layout:
core/shading/ops.py), compiled from a node graph (core/shading/compiler.py) and evaluated
per shading point by core/shading/interp.py. A material names up to three programs
(``Material.base_colour_program``, ``roughness_program``, ``emission_program``); the corner
attributes a program reads (UV maps, colour attributes, generated and object coordinates)
are named in ``Program.attributes`` and carried per mesh in ``Mesh.attributes``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from . import ops as O

PROGRAM_FIELDS = ("base_colour_program", "roughness_program", "emission_program", "normal_program")
SLOT_BASE = 0
SLOT_ROUGHNESS = 1
SLOT_EMISSION = 2
SLOT_NORMAL = 3
WORLD_POSITION = "@world"  # the corners' world positions: filled from the meshes, not from Mesh.attributes
# ops whose q parameter is an offset into the constants, or an attribute index
_Q_CONST = (O.OP_XFORM, O.OP_TABLE, O.OP_CURVES, O.OP_RAMP)


@dataclass
class Program:
    """A compiled shader program: ``ops`` int32 (N,), ``consts`` float32 (M,), the corner
    attributes it reads (OP_ATTR's q indexes ``attributes``) and its register count."""

    name: str
    ops: np.ndarray
    consts: np.ndarray
    attributes: list = field(default_factory=list)
    n_registers: int = 0


def instructions(ops):
    """(pc, op, n, out, p, q, operands) of each instruction of ``ops``, up to and with OP_END."""
    pc = 0
    ops = np.asarray(ops)
    while pc < ops.shape[0]:
        if pc + O.HEADER > ops.shape[0]:
            raise ValueError(f"instruction at {pc} is cut short")
        op, n, out, p, q = (int(x) for x in ops[pc:pc + O.HEADER])
        if n < 0 or pc + O.HEADER + n > ops.shape[0]:
            raise ValueError(f"instruction at {pc} has {n} operands past the end")
        yield pc, op, n, out, p, q, [int(x) for x in ops[pc + O.HEADER:pc + O.HEADER + n]]
        if op == O.OP_END:
            return
        pc += O.HEADER + n
    raise ValueError("no end instruction")


def check(prog, n_textures):
    """The first problem of program ``prog`` as a sentence, or None."""
    if not isinstance(prog.ops, np.ndarray) or prog.ops.dtype != np.int32 or prog.ops.ndim != 1:
        return "ops must be a one-dimensional int32 array"
    if not isinstance(prog.consts, np.ndarray) or prog.consts.dtype != np.float32 or prog.consts.ndim != 1:
        return "consts must be a one-dimensional float32 array"
    if not all(isinstance(a, str) for a in prog.attributes):
        return "attributes must be names"
    nr = int(prog.n_registers)
    if not 0 <= nr <= O.MAX_REGISTERS:
        return f"n_registers must be in [0, {O.MAX_REGISTERS}]"
    nc = prog.consts.shape[0]
    try:
        for pc, op, n, out, p, q, args in instructions(prog.ops):
            if op not in O.OUT_WIDTH:
                return f"instruction at {pc}: unknown op {op}"
            if op != O.OP_END and not 0 <= out <= nr - O.OUT_WIDTH[op]:
                return f"instruction at {pc}: output register {out} out of range"
            for k in args:
                if (k >= 0 and k >= nr) or (k < 0 and -1 - k >= nc):
                    return f"instruction at {pc}: operand {k} out of range"
            if op in _Q_CONST and not 0 <= q < nc:
                return f"instruction at {pc}: constant offset {q} out of range"
            if op == O.OP_ATTR and not 0 <= q < len(prog.attributes):
                return f"instruction at {pc}: attribute {q} out of range"
            if op == O.OP_IMAGE and not 0 <= q < n_textures:
                return f"instruction at {pc}: texture {q} out of range"
    except ValueError as e:
        return str(e)
    return None


def check_scene(scene, fail):
    """Validate ``scene.programs``, the materials' program fields and the meshes' attributes
    (``fail(field, problem)`` raises)."""
    from .. import constants as C

    n_p = len(scene.programs)
    for i, prog in enumerate(scene.programs):
        if not isinstance(prog, Program):
            fail(f"programs[{i}]", f"expected a Program, got {type(prog).__name__}")
        problem = check(prog, len(scene.textures))
        if problem:
            fail(f"programs[{i}] ({prog.name!r})", problem)
    for i, m in enumerate(scene.materials):
        for key in PROGRAM_FIELDS:
            k = getattr(m, key)
            if not isinstance(k, (int, np.integer)) or not -1 <= k < n_p:
                fail(f"materials[{i}] ({m.name!r}).{key}", f"program index {k!r} out of range [-1, {n_p})")
        if m.roughness_program >= 0 and m.model not in (C.MAT_GGX_CONDUCTOR, C.MAT_GGX_DIELECTRIC, C.MAT_PLASTIC):
            fail(f"materials[{i}] ({m.name!r}).roughness_program", f"model {m.model} has no GGX roughness")
    for i, mesh in enumerate(scene.meshes):
        attrs = mesh.attributes or {}
        if not isinstance(attrs, dict):
            fail(f"meshes[{i}].attributes", "expected a dict of name -> float32 (T*3, 3)")
        n_t = mesh.indices.shape[0]
        for name, v in attrs.items():
            if not isinstance(v, np.ndarray) or v.dtype != np.float32 or v.shape != (3 * n_t, 3):
                fail(f"meshes[{i}].attributes[{name!r}]", f"expected float32 ({3 * n_t}, 3)")


class ShadingRecord(NamedTuple):
    """The scene's shader programs as the path kernel reads them (T triangles in the BVH's
    leaf order, K materials).

    prog_ops: int32 (N,) all programs' instructions, constants and attributes relocated.
    prog_consts: float32 (M,) their constants.
    mat_prog: int32 (K, 4) the start in prog_ops of each material's base colour, roughness,
        emission and normal program (-1 none).
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


def uses_programs(scene):
    return any(getattr(m, k, -1) >= 0 for m in scene.materials for k in PROGRAM_FIELDS)


def _relocate(prog, c_base, attr_index):
    ops = prog.ops.astype(np.int32).copy()
    for pc, op, n, out, p, q, args in instructions(ops):
        for j, k in enumerate(args):
            if k < 0:
                ops[pc + O.HEADER + j] = -1 - (-1 - k + c_base)
        if op in _Q_CONST:
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
