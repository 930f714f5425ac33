"""Shader programs: Blender node graphs compiled to a small register machine (as Cycles' SVM).

* :mod:`.ops`: op codes, operand encoding, sub-op tags (stored in scene files).
* :mod:`.program`: :class:`Program` (the scene contract) and its validation.
* :mod:`.compiler`: a bpy-free node graph description → :class:`Program` (``compile_output``).
* :mod:`.record`: the :class:`ShadingRecord` the path kernel reads (``pack``): None for a
  scene without programs, so the path kernel compiles none of this code for it.
* :mod:`.interp`: the numba interpreter ``run``, evaluated per shading point for the
  material slots a program drives (base colour, roughness, emission, normal).
* :mod:`.procedural`: the procedural textures (Blender's algorithms).

The package imports only the scene contract's part here (the compiler, record and kernels
are imported where they are used), so that core.scene can depend on it.
"""
from .program import PROGRAM_FIELDS, Program

__all__ = ["PROGRAM_FIELDS", "Program"]
