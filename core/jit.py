"""The project's single Numba decorator policy.

Every kernel in core is compiled with ``cache=True`` (the on-disk cache makes the
second start fast) and ``nogil=True`` (so Blender's UI thread keeps running while a
kernel works). Fast-math flags are off: NaN and Inf must behave as IEEE says, because the
renderer tests for them. No other module calls ``numba.njit`` directly; a test
enforces it.
"""
import os

import numba

_POLICY = dict(cache=True, nogil=True, error_model="numpy")


def kernel(fn=None, *, parallel=False):
    """Compile ``fn`` with the project policy. ``parallel=True`` for prange kernels."""

    def wrap(f):
        return numba.njit(parallel=parallel, **_POLICY)(f)

    if fn is not None:
        return wrap(fn)
    return wrap


def inline(fn):
    """Small scalar helper: compiled with the same policy and inlined into callers."""
    return numba.njit(inline="always", **_POLICY)(fn)


def set_threads(n):
    """Set the number of threads used by parallel kernels (None: all cores)."""
    if n is None or n <= 0:
        n = numba.config.NUMBA_NUM_THREADS
    n = max(1, min(int(n), numba.config.NUMBA_NUM_THREADS))
    numba.set_num_threads(n)
    return n


def cache_dir():
    return os.environ.get("NUMBA_CACHE_DIR") or "(next to the sources)"
