"""Geometry: the 4-wide BVH over triangles, its build (binned SAH) and traversal, Python side
(accel.py) and kernels (bvh.py; simd.py, the 4-wide vector tests; prefetch.py). Compendium
items 2–4: ray casting r(x, Θ) and visibility V(x, y).
"""
