"""Numba kernels. Entry kernels (the only ones called from Python):

* ``bvh.build_bvh``            binned-SAH BVH build
* ``bvh.trace_closest_batch``  closest-hit queries for a batch of rays (tests, tools)
* ``bvh.trace_occluded_batch`` any-hit queries for a batch of segments (tests, tools)
* ``path.render_pass``         one pass of the spectral path tracer over the film

Everything else is an inlined helper.
"""
