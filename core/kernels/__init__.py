"""Numba kernels. Entry kernels (the only ones called from Python):

* ``bvh.build_bvh``            binned-SAH BVH build
* ``bvh.trace_closest_batch``  closest-hit queries for a batch of rays (tests, tools)
* ``bvh.trace_occluded_batch`` any-hit queries for a batch of segments (tests, tools)
* ``path.render_rows``         samples of the spectral path tracer for a block of rows (serial, nogil)
* ``spectrum.eval_spectrum_batch`` spectra evaluated from their moments (tests, benchmarks)

Everything else is an inlined helper.
"""
