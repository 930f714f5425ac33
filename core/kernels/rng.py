"""Counter-based random numbers: a pure function of (seed, pixel, sample, dimension).

Every random number a path uses is ``uniform(path_key(seed, pixel, sample), dim)``, so
an image does not depend on how pixels are split among threads or passes. The mixer
is the SplitMix64 finaliser (Steele, Lea and Flood, OOPSLA 2014), a bijection on
64-bit integers with good avalanche.
"""
import numpy as np

from ..jit import inline

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_S30 = np.uint64(30)
_S27 = np.uint64(27)
_S31 = np.uint64(31)
_S11 = np.uint64(11)
_INV53 = 1.0 / 9007199254740992.0  # 2^-53


@inline
def mix64(z):
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


@inline
def path_key(seed, pixel, sample):
    k = mix64(np.uint64(seed) * _GOLDEN + np.uint64(0x632BE59BD9B4E019))
    k = mix64(k ^ (np.uint64(pixel) * _GOLDEN))
    return mix64(k ^ (np.uint64(sample) * _M1))


@inline
def uniform(key, dim):
    """A float in [0, 1) for dimension ``dim`` of the path with ``key``."""
    return float(mix64(key + np.uint64(dim) * _GOLDEN) >> _S11) * _INV53
