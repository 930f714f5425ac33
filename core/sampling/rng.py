"""Counter-based random numbers: a pure function of (seed, pixel, sample, dimension).

Every random number a path uses is ``uniform(path_key(seed, pixel, sample), dim)``, so
an image does not depend on how pixels are split among threads or passes. The mixer
is the SplitMix64 finaliser (Steele, Lea and Flood, OOPSLA 2014), a bijection on
64-bit integers with good avalanche.
"""
import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic

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
_B16 = np.uint64(0x0000FFFF)
_INV32 = 1.0 / 4294967296.0  # 2^-32


@intrinsic
def _bitreverse32(typingctx, x):
    """LLVM's ``bitreverse`` of the low 32 bits of an unsigned 64-bit integer, zero-extended:
    a few instructions where the shift-and-mask ladder takes some twenty. Compiled into
    each caller, like ``prefetch``."""
    if not isinstance(x, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        i32 = ir.IntType(32)
        fn = builder.module.declare_intrinsic("llvm.bitreverse", [i32])
        r = builder.call(fn, [builder.trunc(args[0], i32)])
        return builder.zext(r, ir.IntType(64))

    return types.uint64(x), codegen


@inline
def rev32(x):
    """The 32 low bits of x in reverse order."""
    return _bitreverse32(np.uint64(x))


@inline
def pascal32(i):
    """The 32 low bits of ``i`` times Pascal's matrix mod 2, bit m of the result the XOR of
    the bits k ⊇ m of ``i`` (binom(k, m) is odd iff the bits of m are among those of k, by
    Lucas' theorem): the subset-sum transform over the five bits of a bit position, one
    shift-and-mask step per bit. Reversed, it is the second dimension of Sobol's sequence
    (sobol_bits), whose direction numbers are the rows of that matrix."""
    w = np.uint64(i) & _LO32
    w ^= (w >> _S1) & _B1
    w ^= (w >> _S2) & _B2
    w ^= (w >> _S4) & _B4
    w ^= (w >> _S8) & _B8
    w ^= (w >> _S16) & _B16
    return w


@inline
def sobol_bits(index, second):
    """The 32-bit binary fraction of point ``index`` of the (0, 2)-sequence (see sobol_02):
    the index's bits reversed (van der Corput), or for the second dimension the XOR of the
    direction numbers d_0 = 1/2, d_(k+1) = d_k ^ (d_k >> 1) picked by the index's bits,
    computed as rev32(pascal32(index))."""
    i = np.uint64(index) & _LO32
    if second == 0:
        return rev32(i)
    return rev32(pascal32(i))


@inline
def sobol_02(index, second, scramble):
    """Point ``index`` of the first two dimensions of Sobol's sequence, a (0, 2)-sequence in
    base 2 (dimension 0 the van der Corput radical inverse, dimension 1 the generator
    matrix of the primitive polynomial x + 1), with a digital shift ``scramble`` (32 bits,
    XOR): every 2^m consecutive points aligned at a multiple of 2^m put one point in each
    elementary interval of area 2^-m, whatever the shift. Returns a float in [0, 1)."""
    return float((sobol_bits(index, second) ^ scramble) & _LO32) * _INV32


@inline
def shift_32(pseed, dim):
    """A 32-bit digital shift for dimension ``dim`` of the pixel with seed ``pseed``."""
    return mix64(np.uint64(pseed) ^ (np.uint64(dim) * _M1 + _GOLDEN)) >> _S32


# ----------------------------------------------------------- padded, scrambled Sobol pairs
#
# The "stratified" sampler gives every pair of path dimensions its own randomised copy of
# the (0, 2)-sequence above (the padding idea of Kollig & Keller 2002, as in Cycles'
# Sobol–Burley and pbrt-v4's PaddedSobolSampler): pair k of sample i is point π_k(i) of the
# sequence, Owen-scrambled. π_k permutes the sample indices per pixel and pair, so pairs
# are not correlated with each other; it maps every block [0, 2^m) onto itself, so the
# first 2^m samples of every pair form a whole (0, m, 2)-net whatever the total sample
# count (a time-limited render is stratified at every power of two it passes).

_LK1 = np.uint64(0x6C50B47C)
_LK2 = np.uint64(0xB82F1E52)
_LK3 = np.uint64(0xC7AFE638)
_LK4 = np.uint64(0x8D22F6E6)


@inline
def _shuffle_rev(index, h):
    """The bit-reversed image of ``index`` under the index shuffle (see nested_index)."""
    x = rev32(np.uint64(index) & _LO32)
    x ^= (x * ((h << _S1) & _LO32)) & _LO32
    x ^= (x * ((h >> _S31) & np.uint64(0xFFFFFFFE))) & _LO32
    x ^= (x * _LK2) & _LO32
    return x


@inline
def nested_index(index, h):
    """A permutation of 32-bit sample indices that maps each [0, 2^m) onto itself: on the
    bit-reversed index, x ^= x·c with even c only lets a bit depend on the bits below it
    (above it in the index) and keeps trailing zeros, so high zero bits stay zero. Three
    rounds with multipliers from the hash h."""
    return rev32(_shuffle_rev(index, h))


@inline
def _lk(x, seed):
    """The Laine–Karras hash on bit-reversed digits: x + seed, then x ^= x·c for four even
    constants (Burley, "Practical Hash-based Owen Scrambling", JCGT 2020)."""
    x = (x + seed) & _LO32
    x ^= (x * _LK1) & _LO32
    x ^= (x * _LK2) & _LO32
    x ^= (x * _LK3) & _LO32
    x ^= (x * _LK4) & _LO32
    return x


@inline
def owen32(v, seed):
    """Nested uniform (Owen) scrambling of a 32-bit binary fraction: each digit flipped by a
    hash of the digits before it."""
    return rev32(_lk(rev32(v), seed))


@inline
def sobol_pair_both(index, pseed, pair):
    """Both components of ``sobol_pair`` at once, (comp 0, comp 1): the pair's hash and
    shuffled index are computed once; the same two values as two ``sobol_pair`` calls."""
    h = mix64(np.uint64(pseed) ^ (np.uint64(pair) * _GOLDEN + _M2))
    j = rev32(_shuffle_rev(index, h))
    u = float(rev32(_lk(j, h >> _S32))) * _INV32
    # owen32(sobol_bits(j, 1), s) with the two reversals that cancel left out
    v = float(rev32(_lk(pascal32(j), (h >> _S32) ^ np.uint64(0x9E3779B9)))) * _INV32
    return u, v


@inline
def sobol_pair(index, comp, pseed, pair):
    """Component ``comp`` (0, 1) of sample ``index`` for dimension pair ``pair`` of the
    pixel with seed ``pseed``: a float in [0, 1). The value of
    owen32(sobol_bits(nested_index(index, h), comp), seed), with the bit reversals that
    cancel left out (the first component's digits are the reversed shuffled index)."""
    h = mix64(np.uint64(pseed) ^ (np.uint64(pair) * _GOLDEN + _M2))
    seed = (h >> _S32) ^ (np.uint64(comp) * np.uint64(0x9E3779B9))
    j = rev32(_shuffle_rev(index, h))
    if comp == 0:
        return float(rev32(_lk(j, seed))) * _INV32
    return float(rev32(_lk(pascal32(j), seed))) * _INV32
