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


_LO32 = np.uint64(0xFFFFFFFF)
_S1 = np.uint64(1)
_S2 = np.uint64(2)
_S4 = np.uint64(4)
_S8 = np.uint64(8)
_S16 = np.uint64(16)
_S32 = np.uint64(32)
_B1 = np.uint64(0x55555555)
_B2 = np.uint64(0x33333333)
_B4 = np.uint64(0x0F0F0F0F)
_B8 = np.uint64(0x00FF00FF)
_TOP = np.uint64(0x80000000)
_ZERO = np.uint64(0)
_INV32 = 1.0 / 4294967296.0  # 2^-32


@inline
def sobol_02(index, second, scramble):
    """Point ``index`` of the first two dimensions of Sobol's sequence, a (0, 2)-sequence in
    base 2 (dimension 0 the van der Corput radical inverse, dimension 1 the generator
    matrix of the primitive polynomial x + 1), with a digital shift ``scramble`` (32 bits,
    XOR): every 2^m consecutive points aligned at a multiple of 2^m put one point in each
    elementary interval of area 2^-m, whatever the shift. Returns a float in [0, 1)."""
    i = np.uint64(index) & _LO32
    if second == 0:
        v = ((i >> _S1) & _B1) | ((i & _B1) << _S1)
        v = ((v >> _S2) & _B2) | ((v & _B2) << _S2)
        v = ((v >> _S4) & _B4) | ((v & _B4) << _S4)
        v = ((v >> _S8) & _B8) | ((v & _B8) << _S8)
        v = ((v >> _S16) | (v << _S16)) & _LO32
    else:
        v = _ZERO
        d = _TOP
        while i != _ZERO:
            if (i & _S1) != _ZERO:
                v ^= d
            i >>= _S1
            d ^= d >> _S1
    return float((v ^ scramble) & _LO32) * _INV32


@inline
def shift_32(pseed, dim):
    """A 32-bit digital shift for dimension ``dim`` of the pixel with seed ``pseed``."""
    return mix64(np.uint64(pseed) ^ (np.uint64(dim) * _M1 + _GOLDEN)) >> _S32
