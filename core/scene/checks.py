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


# Bounds that keep every derived quantity representable: coordinates (metres) whose squares
# and cross products stay far inside float32, and photometric amounts (cd/m², cd, lx, lm)
# whose radiance, times any geometric factor of a valid scene, stays finite in float32.
MAX_COORDINATE = 1e15  # m (about 6700 astronomical units)
MIN_LENGTH = 1e-12  # m: shortest direction or axis vector that is normalised
MAX_PHOTOMETRIC = 1e15  # cd/m², cd, lx, lm (the sun's disc is about 1.6e9 cd/m²)
MAX_NAME = 4096  # characters of a name


def check_number(name, v, lo=-math.inf, hi=math.inf, integer=False):
    """A real (or with ``integer``, an integral: int or numpy integer, never a float or a
    bool) number, finite, in [lo, hi]."""
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer, np.floating)):
        fail(name, f"expected a number, got {type(v).__name__}")
    if integer and not isinstance(v, (int, np.integer)):
        fail(name, f"expected an integer, got {v!r}")
    try:
        f = float(v)
    except OverflowError:
        fail(name, f"must be in [{_g(lo)}, {_g(hi)}], got a number of {len(str(v))} digits")
    if not math.isfinite(f):
        fail(name, f"must be finite, got {v}")
    if not lo <= v <= hi:
        fail(name, f"must be in [{_g(lo)}, {_g(hi)}], got {_g(v)}")


def _g(x):
    return f"{x:g}" if isinstance(x, (float, np.floating)) else str(x)


def check_bool(name, v):
    if not isinstance(v, (bool, np.bool_)):
        fail(name, f"expected true or false, got {v!r}")


def check_str(name, v, max_len=MAX_NAME):
    if not isinstance(v, str):
        fail(name, f"expected a string, got {type(v).__name__}")
    if len(v) > max_len:
        fail(name, f"a string of {len(v)} characters (at most {max_len})")


def check_vec3(name, v, hi=MAX_COORDINATE):
    """Three finite numbers of magnitude at most ``hi``, as a float64 array."""
    if isinstance(v, (str, bytes, dict)) or not isinstance(v, (tuple, list, np.ndarray)):
        fail(name, f"expected 3 numbers, got {type(v).__name__}")
    if not isinstance(v, np.ndarray) and any(isinstance(x, (bool, np.bool_)) or
                                             not isinstance(x, (int, float, np.integer, np.floating)) for x in v):
        fail(name, "expected 3 numbers")
    try:
        a = np.asarray(v, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        fail(name, "expected 3 finite numbers")
    if a.shape != (3,):
        fail(name, f"expected 3 numbers, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        fail(name, "contains NaN or Inf")
    if np.abs(a).max() > hi:
        fail(name, f"a component of magnitude {np.abs(a).max():.3g} (at most {hi:g})")
    return a
