"""Shader programs: Blender node graphs compiled to a small register machine (as Cycles' SVM).

* :mod:`.ops`: op codes, operand encoding, sub-op tags (stored in scene files).
* :mod:`.compiler`: a bpy-free node graph description → :class:`Program`.
* :mod:`.program`: :class:`Program` (the scene contract), its validation, and the
  :class:`ShadingRecord` the path kernel reads (``pack``).
* :mod:`.interp`: the numba interpreter ``run``, evaluated per shading point for the
  material slots a program drives (base colour, roughness, emission).
* :mod:`.procedural`: the procedural textures (Blender's algorithms).

A scene without programs packs no record (None), so the path kernel compiles none of
this code for it.
"""
from .compiler import Unsupported, compile_output
from .program import PROGRAM_FIELDS, Program, ShadingRecord

__all__ = ["PROGRAM_FIELDS", "Program", "ShadingRecord", "Unsupported", "compile_output"]
