"""Field checks of the scene contract: each failure raises :class:`SceneError` naming the field."""
import math

import numpy as np


class SceneError(ValueError):
    """A scene (or scene file) is malformed. The message names the offending field."""


def fail(field_name, problem):
    raise SceneError(f"{field_name}: {problem}")


def check_array(name, a, dtype, shape):
    """shape: tuple with None for free dimensions."""
    if not isinstance(a, np.ndarray):
        fail(name, f"expected a numpy array, got {type(a).__name__}")
    if a.dtype != np.dtype(dtype):
        fail(name, f"expected dtype {np.dtype(dtype).name}, got {a.dtype.name}")
    if a.ndim != len(shape) or any(s is not None and s != d for s, d in zip(shape, a.shape)):
        want = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
        fail(name, f"expected shape {want}, got {a.shape}")
    if np.issubdtype(a.dtype, np.floating) and not np.all(np.isfinite(a)):
        bad = np.argwhere(~np.isfinite(a))[0]
        fail(name, f"contains NaN or Inf (first at index {tuple(int(i) for i in bad)})")


def check_number(name, v, lo=-math.inf, hi=math.inf, integer=False):
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
        fail(name, f"expected a number, got {type(v).__name__}")
    if integer and int(v) != v:
        fail(name, f"expected an integer, got {v}")
    if not math.isfinite(float(v)):
        fail(name, f"must be finite, got {v}")
    if not lo <= v <= hi:
        fail(name, f"must be in [{lo}, {hi}], got {v}")


def check_vec3(name, v):
    a = np.asarray(v, dtype=np.float64) if not isinstance(v, np.ndarray) else v
    if a.shape != (3,):
        fail(name, f"expected 3 numbers, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        fail(name, "contains NaN or Inf")
    return a
