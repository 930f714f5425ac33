"""Shader programs in the scene contract and the record the path kernel reads.

A :class:`Program` is a flat int32 op array and a float32 constant array (layout:
core/shading/ops.py), compiled from a node graph (core/shading/compiler.py) and evaluated
per shading point by core/shading/interp.py. A material names up to five programs
(``Material.base_colour_program``, ``roughness_program``, ``emission_program``,
``normal_program`` and, on a MAT_MIX, ``mix_program``: the weight of its first component,
x clamped to [0, 1], in place of params[0]); the corner
attributes a program reads (UV maps, colour attributes, generated and object coordinates)
are named in ``Program.attributes`` and carried per mesh in ``Mesh.attributes``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import ops as O

PROGRAM_FIELDS = ("base_colour_program", "roughness_program", "emission_program", "normal_program", "mix_program")
SLOT_BASE = 0
SLOT_ROUGHNESS = 1
SLOT_EMISSION = 2
SLOT_NORMAL = 3
SLOT_MIX = 4
WORLD_POSITION = "@world"  # the corners' world positions: filled from the meshes, not from Mesh.attributes
# ops whose q parameter is an offset into the constants, or an attribute index
Q_CONST = (O.OP_XFORM, O.OP_TABLE, O.OP_CURVES, O.OP_RAMP, O.OP_PROC)


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
            if op in Q_CONST and not 0 <= q < nc:
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
        if m.mix_program >= 0 and m.model != C.MAT_MIX:
            fail(f"materials[{i}] ({m.name!r}).mix_program", f"model {m.model} is not a mix (MAT_MIX {C.MAT_MIX})")
    for i, mesh in enumerate(scene.meshes):
        attrs = mesh.attributes or {}
        if not isinstance(attrs, dict):
            fail(f"meshes[{i}].attributes", "expected a dict of name -> float32 (T*3, 3)")
        n_t = mesh.indices.shape[0]
        for name, v in attrs.items():
            if not isinstance(v, np.ndarray) or v.dtype != np.float32 or v.shape != (3 * n_t, 3):
                fail(f"meshes[{i}].attributes[{name!r}]", f"expected float32 ({3 * n_t}, 3)")


def uses_programs(scene):
    return any(getattr(m, k, -1) >= 0 for m in scene.materials for k in PROGRAM_FIELDS)
