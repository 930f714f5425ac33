"""Shader programs: node graphs compiled to programs the kernels evaluate at each shading point."""
