"""Quasi-Monte Carlo points, randomised so estimates stay unbiased (compendium item 30).

Every value is a pure function of (index, dimension, seed), so a render kernel can call
``qmc_sample`` per (pixel, sample, dimension) in any order and on any thread.

* ``radical_inverse(b, i)``: Φ_b(i) = Σ a_j b^{-j-1} for i = Σ a_j b^j, any base b ≥ 2.
  Base 2 is a 64-bit reversal; other bases sum digit / b^{k} with exact powers.
* van der Corput: Φ_2; Halton: dimension d uses the d-th prime (``PRIMES``: the first
  ``N_PRIMES`` = 256); Hammersley of n points: (i/n, Φ_2(i), Φ_3(i), ...).
* Owen scrambling (nested uniform scrambling, Owen 1995): digit k of the result is a
  permutation of digit k of Φ_b(i) chosen by a hash of the seed, the dimension and the
  k more significant digits, so points in the same elementary interval stay together
  (stratification is kept) while each point is uniform over the seeds. Base 2 uses a
  hash whose output bit k depends only on input bits 0..k (the digit order of Φ_2 is
  the bit order of i), in the manner of Laine and Karras (2011) and Burley (JCGT
  2020), built here from add / odd multiply / x ^= x·even steps keyed by the seed.
  Other bases use an affine permutation a → (m a + s) mod b per digit with m, s drawn
  from a hash of the prefix (a random digit permutation of the same nested structure);
  past the index's last digit (and below 2^-32) the scrambled zeros are i.i.d. uniform
  digits, drawn at once as one uniform tail.
* Cranley–Patterson rotation: x + r mod 1 with r a hash of (seed, dimension).

Dimensions beyond the prime table fall back to independent random numbers.
"""
import numpy as np

from ..jit import inline
from .rng import mix64, uniform
from .tags import RANDOMIZE_CP, RANDOMIZE_OWEN, SAMPLER_HALTON, SAMPLER_HAMMERSLEY


def _first_primes(n):
    out = []
    k = 2
    while len(out) < n:
        if all(k % p for p in out if p * p <= k):
            out.append(k)
        k += 1
    return np.array(out, dtype=np.int64)


N_PRIMES = 256
PRIMES = _first_primes(N_PRIMES)  # 2, 3, 5, ..., 1619

ONE_MINUS_EPS = 1.0 - 2.0 ** -53
_INV53 = 2.0 ** -53
_TWO53 = 9007199254740992.0
_MAX_EXACT = 2 ** 53
_TWO32 = 4294967296.0

_U1 = np.uint64(1)
_S1 = np.uint64(1)
_S2 = np.uint64(2)
_S4 = np.uint64(4)
_S8 = np.uint64(8)
_S11 = np.uint64(11)
_S16 = np.uint64(16)
_S32 = np.uint64(32)
_M1 = np.uint64(0x5555555555555555)
_M2 = np.uint64(0x3333333333333333)
_M4 = np.uint64(0x0F0F0F0F0F0F0F0F)
_M8 = np.uint64(0x00FF00FF00FF00FF)
_M16 = np.uint64(0x0000FFFF0000FFFF)
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_DIM_SALT = np.uint64(0xA0761D6478BD642F)
_DIG_SALT = np.uint64(0xE7037ED1A0B428DB)
# even multipliers for the x ^= x * c steps (odd * 2 ** k, k ≥ 1)
_E1 = np.uint64(0x7A4F3B6D2C81E5C6)
_E2 = np.uint64(0x1B873593C2B2AE34)
_E3 = np.uint64(0xC4CEB9FE1A85EC52)
_ODD = np.uint64(0x94D049BB133111EB)


@inline
def reverse_bits64(x):
    x = np.uint64(x)
    x = ((x >> _S1) & _M1) | ((x & _M1) << _S1)
    x = ((x >> _S2) & _M2) | ((x & _M2) << _S2)
    x = ((x >> _S4) & _M4) | ((x & _M4) << _S4)
    x = ((x >> _S8) & _M8) | ((x & _M8) << _S8)
    x = ((x >> _S16) & _M16) | ((x & _M16) << _S16)
    return (x >> _S32) | (x << _S32)


@inline
def _bits_to_unit(x):
    """Top 53 bits of a 64-bit fraction → float in [0, 1)."""
    return float(x >> _S11) * _INV53


@inline
def radical_inverse(base, i):
    """Φ_b(i) for an integer base b ≥ 2 and index i ≥ 0, correctly rounded while b^digits ≤ 2^53
    (the reversed digits and the power are exact integers, divided once)."""
    if base == 2:
        return _bits_to_unit(reverse_bits64(np.uint64(i)))
    if base < 2:
        return 0.0
    b = int(base)
    n = int(i)
    rev = 0
    bpow = 1
    while n > 0 and bpow <= _MAX_EXACT // b:
        rev = rev * b + n % b
        bpow *= b
        n //= b
    result = rev / bpow
    # digits beyond 2^53 (huge indices only) add below the last bit of rev / bpow
    scale = 1.0 / bpow
    while n > 0 and scale > 1e-300:
        scale /= b
        result += (n % b) * scale
        n //= b
    return min(result, ONE_MINUS_EPS)


@inline
def van_der_corput(i):
    return radical_inverse(2, i)


@inline
def halton(i, dim):
    """Dimension ``dim`` (0-based) of Halton point i: Φ of the dim-th prime."""
    return radical_inverse(PRIMES[dim], i)


@inline
def hammersley(i, dim, n):
    """Dimension ``dim`` of point i of the n-point Hammersley set: i/n, then Φ_2, Φ_3, ..."""
    if dim == 0:
        return min(i / n, ONE_MINUS_EPS)
    return radical_inverse(PRIMES[dim - 1], i)


@inline
def dimension_key(seed, dim):
    """64-bit key of (seed, dimension) for the scramblers."""
    k = mix64(np.uint64(seed) * _GOLDEN + _DIM_SALT)
    return mix64(k ^ (np.uint64(dim) * _DIG_SALT + _GOLDEN))


@inline
def nested_hash_base2(x, key):
    """Bijection of 64-bit x whose output bit k is input bit k XOR a function of the key
    and input bits 0..k-1: a nested (Owen) scramble of the binary digits of Φ_2(x)."""
    k1 = mix64(key + _GOLDEN)
    k2 = mix64(key + _DIM_SALT)
    x = np.uint64(x) + key
    x ^= x * _E1
    x *= (k1 | _U1)
    x ^= x * _E2
    x += k2
    x ^= x * _E3
    x *= _ODD
    x ^= x * _E1
    return x


@inline
def owen_scrambled_base2(i, key):
    return _bits_to_unit(reverse_bits64(nested_hash_base2(np.uint64(i), key)))


@inline
def owen_scrambled_radical_inverse(base, i, key):
    """Φ_b(i) with every digit permuted by a hash of (key, the more significant digits)."""
    if base == 2:
        return owen_scrambled_base2(i, key)
    if base < 2:
        return 0.0
    b = int(base)
    bu = np.uint64(b)
    n = int(i)
    h = key
    result = 0.0
    bpow = 1.0
    while (n > 0 or bpow < _TWO32) and bpow < _TWO53:
        d = n % b
        n //= b
        r = mix64(h)
        # affine permutation of the digit: m in [1, b-1], s in [0, b-1]
        m = np.uint64(1) + (r >> _S32) % (bu - np.uint64(1))
        s = (r & np.uint64(0xFFFFFFFF)) % bu
        pd = (m * np.uint64(d) + s) % bu
        bpow *= b
        result += float(pd) / bpow
        # the prefix for the next (less significant) output digit includes this input digit
        h = mix64(h ^ ((np.uint64(d) + np.uint64(1)) * _DIG_SALT))
    # The remaining digits of i are 0; scrambled by permutations that depend on the whole
    # prefix, they are i.i.d. uniform digits: one uniform tail drawn in one go. Every index
    # scrambles at least the digits down to b^-k < 2^-32, so the first b^k points stay
    # stratified for any b^k ≤ 2^32.
    result += uniform(h, 0) / bpow
    return min(result, ONE_MINUS_EPS)


@inline
def cranley_patterson_shift(key):
    return uniform(key, 0)


@inline
def rotate(x, r):
    """Cranley–Patterson rotation x + r mod 1, kept in [0, 1)."""
    y = x + r
    if y >= 1.0:
        y -= 1.0
    return min(max(y, 0.0), ONE_MINUS_EPS)


@inline
def independent_sample(index, dim, seed):
    """Pseudo-random reference: uniform(key(seed, index), dim)."""
    k = mix64(np.uint64(seed) * _GOLDEN + _DIM_SALT)
    k = mix64(k ^ (np.uint64(index) * _GOLDEN))
    return uniform(k, dim)


@inline
def scrambled_halton(i, dim, seed):
    if dim >= N_PRIMES:
        return independent_sample(i, dim, seed)
    return owen_scrambled_radical_inverse(PRIMES[dim], i, dimension_key(seed, dim))


@inline
def rotated_halton(i, dim, seed):
    if dim >= N_PRIMES:
        return independent_sample(i, dim, seed)
    return rotate(halton(i, dim), cranley_patterson_shift(dimension_key(seed, dim)))


@inline
def _log2_exact(n):
    """m with n = 2^m, or -1."""
    if n <= 0:
        return -1
    m = 0
    k = 1
    while k < n:
        k *= 2
        m += 1
    return m if k == n else -1


@inline
def scrambled_hammersley(i, dim, n, seed):
    """Owen-scrambled Hammersley; dimension 0 is scrambled in base 2 as the digits of i/n
    when n is a power of two (keeping the (0, m, 2)-net structure with dimension 1), and
    Cranley–Patterson rotated otherwise."""
    if dim - 1 >= N_PRIMES:
        return independent_sample(i, dim, seed)
    key = dimension_key(seed, dim)
    if dim == 0:
        m = _log2_exact(n)
        if m > 0:
            # i/n = Φ_2(j) with j the m-bit reversal of i
            j = reverse_bits64(np.uint64(i)) >> np.uint64(64 - m)
            return owen_scrambled_base2(j, key)
        return rotate(hammersley(i, 0, n), cranley_patterson_shift(key))
    return owen_scrambled_radical_inverse(PRIMES[dim - 1], i, key)


@inline
def rotated_hammersley(i, dim, n, seed):
    if dim - 1 >= N_PRIMES:
        return independent_sample(i, dim, seed)
    return rotate(hammersley(i, dim, n), cranley_patterson_shift(dimension_key(seed, dim)))


@inline
def qmc_sample(sampler, randomize, index, dim, seed, n):
    """Dimension ``dim`` of sample ``index`` (of ``n`` for Hammersley) as a float in [0, 1).

    sampler: SAMPLER_INDEPENDENT / SAMPLER_HALTON / SAMPLER_HAMMERSLEY;
    randomize: RANDOMIZE_NONE / RANDOMIZE_OWEN / RANDOMIZE_CP (ignored by the
    independent sampler). For a render, pass seed = pixel_seed(scene seed, pixel) so each
    pixel gets its own randomisation of the same low-discrepancy set. Written with one
    call of each primitive so that it inlines into kernels cheaply; equal to the
    scrambled_* / rotated_* / halton / hammersley functions above.
    """
    # which radical inverse: base (0: independent), and the index it is applied to
    base = 0
    j = np.uint64(index)
    if sampler == SAMPLER_HALTON and dim < N_PRIMES:
        base = PRIMES[dim]
    elif sampler == SAMPLER_HAMMERSLEY and dim - 1 < N_PRIMES:
        if dim == 0:
            m = _log2_exact(n)
            if randomize == RANDOMIZE_OWEN and m > 0:
                base = 2
                j = reverse_bits64(j) >> np.uint64(64 - m)
            else:
                base = 1  # i / n
        else:
            base = PRIMES[dim - 1]
    if base == 0:
        return independent_sample(index, dim, seed)
    key = dimension_key(seed, dim)
    if base == 1:
        x = min(index / n, ONE_MINUS_EPS)
    elif randomize == RANDOMIZE_OWEN:
        return owen_scrambled_radical_inverse(base, j, key)
    else:
        x = radical_inverse(base, j)
    if randomize == RANDOMIZE_CP or (randomize == RANDOMIZE_OWEN and base == 1):
        x = rotate(x, cranley_patterson_shift(key))
    return x


@inline
def pixel_seed(seed, pixel):
    """Per-pixel randomisation seed (uint64) for qmc_sample."""
    return mix64(mix64(np.uint64(seed) + _DIG_SALT) ^ (np.uint64(pixel) * _GOLDEN))

