"""The BSDF library's one entry kernel, for tests and tools: every model behind its tag,
so a new model adds tests, not compile time.

``bsdf_batch(op, model, p, ra, rb, eta, kappa, wo, wi_or_u)`` with wo, wi_or_u (N, 3):

* op = OP_EVAL (0):   wi_or_u holds wi → values = f (N, NW), pdf (N,); dirs = wi
* op = OP_PDF (1):    wi_or_u holds wi → pdf (N,)
* op = OP_SAMPLE (2): wi_or_u holds (u1, u2, u3) → dirs = wi (N, 3), values = sample
  weights (N, NW), pdf (N,), flags (N,)

Returns (dirs, values, pdf, flags). The Python wrappers ``evaluate``, ``pdf`` and
``sample`` coerce dtypes and shapes (one signature per kernel).
"""
import numpy as np
from numba import prange

from .. import constants as C
from ..jit import kernel
from .dispatch import bsdf_eval, bsdf_pdf, bsdf_sample
from .params import check_row

OP_EVAL = 0
OP_PDF = 1
OP_SAMPLE = 2


@kernel(parallel=True)
def bsdf_batch(op, model, p, ra, rb, eta, kappa, wo, wi_or_u):
    n = wo.shape[0]
    nw = ra.shape[0]
    dirs = np.zeros((n, 3))
    values = np.zeros((n, nw))
    pdf = np.zeros(n)
    flags = np.zeros(n, np.int64)
    for k in prange(n):
        a = wi_or_u[k, 0]
        b = wi_or_u[k, 1]
        c = wi_or_u[k, 2]
        if op == OP_EVAL:
            pdf[k] = bsdf_eval(model, p, ra, rb, eta, kappa, wo[k, 0], wo[k, 1], wo[k, 2], a, b, c, values[k])
            dirs[k, 0] = a
            dirs[k, 1] = b
            dirs[k, 2] = c
        elif op == OP_PDF:
            pdf[k] = bsdf_pdf(model, p, ra, rb, eta, kappa, wo[k, 0], wo[k, 1], wo[k, 2], a, b, c)
            dirs[k, 0] = a
            dirs[k, 1] = b
            dirs[k, 2] = c
        else:
            x, y, z, pd, fl = bsdf_sample(model, p, ra, rb, eta, kappa, wo[k, 0], wo[k, 1], wo[k, 2], a, b, c,
                                          values[k])
            dirs[k, 0] = x
            dirs[k, 1] = y
            dirs[k, 2] = z
            pdf[k] = pd
            flags[k] = fl
    return dirs, values, pdf, flags


def spectrum(x, nw=None):
    """A contiguous float64 spectrum: a scalar is repeated over ``nw`` (default NW) wavelengths."""
    a = np.asarray(x, dtype=np.float64)
    if a.ndim == 0:
        return np.full(C.N_WAVELENGTHS if nw is None else nw, float(a))
    if a.ndim != 1 or a.size == 0:
        raise ValueError(f"a spectrum is a scalar or a 1-D array, got shape {a.shape}")
    return np.ascontiguousarray(a)


def _spectra(ra, rb, eta, kappa):
    arrays = [np.asarray(x, dtype=np.float64) for x in (ra, rb, eta, kappa)]
    sizes = {a.size for a in arrays if a.ndim == 1}
    if len(sizes) > 1:
        raise ValueError(f"spectra of different lengths: {sorted(sizes)}")
    nw = sizes.pop() if sizes else C.N_WAVELENGTHS
    return [spectrum(a, nw) for a in arrays]


def _vectors(v, name):
    v = np.asarray(v, dtype=np.float64)
    if v.ndim == 1:
        v = v[None, :]
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"{name} must have shape (N, 3), got {v.shape}")
    return np.ascontiguousarray(v)


def _run(op, model, p, ra, rb, eta, kappa, wo, x):
    ra, rb, eta, kappa = _spectra(ra, rb, eta, kappa)
    wo = _vectors(wo, "wo")
    x = _vectors(x, "wi" if op != OP_SAMPLE else "u")
    if x.shape[0] != wo.shape[0]:
        if wo.shape[0] == 1:
            wo = np.ascontiguousarray(np.broadcast_to(wo, x.shape))
        else:
            raise ValueError(f"wo has {wo.shape[0]} rows, the other input {x.shape[0]}")
    return bsdf_batch(int(op), int(model), check_row(p), ra, rb, eta, kappa, wo, x)


def evaluate(model, p, ra, rb, eta, kappa, wo, wi):
    """(f (N, NW), pdf (N,)) for directions in the local frame."""
    _, f, pd, _ = _run(OP_EVAL, model, p, ra, rb, eta, kappa, wo, wi)
    return f, pd


def pdf(model, p, ra, rb, eta, kappa, wo, wi):
    """pdf (N,) of sampling wi given wo."""
    return _run(OP_PDF, model, p, ra, rb, eta, kappa, wo, wi)[2]


def sample(model, p, ra, rb, eta, kappa, wo, u):
    """(wi (N, 3), weight (N, NW), pdf (N,), flags (N,)) for u (N, 3) in [0, 1)."""
    return _run(OP_SAMPLE, model, p, ra, rb, eta, kappa, wo, u)
