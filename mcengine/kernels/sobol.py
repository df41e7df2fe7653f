"""Owen-scrambled, shuffled Sobol points (Burley 2020), the sampler Cycles renders with.

Brent Burley, "Practical Hash-based Owen Scrambling", JCGT 9(4), 2020, which
Cycles implements as its Sobol-Burley pattern (``kernel/sample/sobol_burley.h``;
its tabulated and blue-noise patterns give the same stratification per pixel):

* **Points.**  Only the first four dimensions of the Sobol sequence are used
  (van der Corput, then the Joe-Kuo direction numbers of x + 1, x^2 + x + 1 and
  x^3 + x + 1).  Any two of the first two form a (0, 2)-sequence: every
  power-of-two prefix of 2^m points puts exactly one point in each elementary
  interval of area 2^-m; the first three are a (1, 3)-sequence and all four a
  (3, 4)-sequence.
* **Owen scrambling.**  Each dimension of each point is scrambled by a nested
  uniform random digit permutation, computed by a hash in which every bit
  depends only on the bits above it (Laine-Karras style, with the multipliers
  of N. Vegdahl, "Building a better LK hash", 2021).  Scrambled points are
  uniform on [0, 1) one by one (so every estimate stays unbiased) and keep the
  net properties above.
* **Shuffling and padding.**  Higher dimensions come from *dimension sets*:
  every set draws up to four numbers from the same four Sobol dimensions, with
  the sample index itself Owen-scrambled by a seed of that set (a random
  permutation that maps each aligned block of 2^m indices onto one), and its
  own scrambling seeds.  Numbers of one set are stratified together; numbers
  of different sets (the pixel filter, then each bounce's light and BSDF
  samples) are independent, as if drawn from independent sequences.

The caller (``sampling.sample_1d/2d/4d``) gives the scrambling seeds, from a
64-bit hash of (render seed, pixel, dimension set), so every pixel and every
seed has its own independent scrambling: renders with different seeds are
independent replicates (randomised quasi-Monte Carlo).

``index_mask`` limits the shuffled index to the next power of two of the
render's sample count (Cycles does the same): all indices a render uses then
lie in one aligned block.  A point is computed from byte tables of the
direction numbers (three lookups per dimension).  Everything is 32-bit
arithmetic carried in uint64 and masked, as numba's integer typing widens.
"""
from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from ..jit import device

DIMENSIONS = 4
BITS = 32
INDEX_BITS = 24          # sample indices below 2^24 (Cycles' sample limit)
_M32 = np.uint64(0xFFFFFFFF)
_INV_2_32 = 1.0 / 4294967296.0


def _direction_numbers() -> np.ndarray:
    """(DIMENSIONS, BITS) uint64: v[d, b] is the Sobol value of index 2^b in dimension d,
    bit-reversed (so the first digit after the binary point is bit 0)."""
    # Joe & Kuo's (degree, coefficients a, initial m) for dimensions 2..4.
    params = ((1, 0, (1,)), (2, 1, (1, 3)), (3, 1, (1, 3, 1)))
    table = np.zeros((DIMENSIONS, BITS), np.uint64)
    table[0] = [1 << b for b in range(BITS)]          # van der Corput, already reversed
    for d, (s, a, m0) in enumerate(params, start=1):
        m = list(m0)
        for k in range(s, BITS):
            value = m[k - s] ^ (m[k - s] << s)
            for j in range(1, s):
                if (a >> (s - 1 - j)) & 1:
                    value ^= m[k - j] << j
            m.append(value)
        for b in range(BITS):
            v = m[b] << (BITS - 1 - b)                # the value, 32-bit fixed point
            table[d, b] = int(f"{v:032b}"[::-1], 2)   # bit-reversed
    return table


def _byte_tables(directions: np.ndarray) -> np.ndarray:
    """(DIMENSIONS, INDEX_BITS / 8, 256) uint32 tables of the points, indexed by the bytes
    of the bit-reversed index: [d, k, v] is the bit-reversed value in dimension d of the
    index whose reversed byte k (from the top) is v.  A point is three lookups per
    dimension, not a loop over the index's bits."""
    tables = np.zeros((DIMENSIONS, INDEX_BITS // 8, 256), np.uint32)
    for d in range(DIMENSIONS):
        for k in range(INDEX_BITS // 8):
            for v in range(256):
                x = 0
                for t in range(8):
                    if v >> t & 1:                 # reversed bit t is index bit 8 k + 7 - t
                        x ^= int(directions[d, 8 * k + 7 - t])
                tables[d, k, v] = x
    return tables


DIRECTIONS = _direction_numbers()
TABLES = _byte_tables(DIRECTIONS)


@intrinsic
def reverse_bits(typingctx, x):
    """The 32 low bits of the uint64 x in reverse order (LLVM's bitreverse: a byte swap
    and three mask steps, against five by hand)."""
    if x != types.uint64:
        return None

    def codegen(context, builder, signature, args):
        low = builder.trunc(args[0], ir.IntType(32))
        return builder.zext(builder.bitreverse(low), ir.IntType(64))
    return types.uint64(types.uint64), codegen


@device
def owen_reversed(n, seed):
    """Owen scrambling of a bit-reversed 32-bit value: each bit is flipped by a hash of
    the seed and the bits below it (the digits before it, in the unreversed value)."""
    n ^= (n * np.uint64(0x3D20ADEA)) & _M32
    n = (n + seed) & _M32
    n = (n * ((seed >> np.uint64(16)) | np.uint64(1))) & _M32
    n ^= (n * np.uint64(0x05526C56)) & _M32
    n ^= (n * np.uint64(0x53A22864)) & _M32
    return n


@device
def _to_unit(reversed_value, seed):
    """Scramble a bit-reversed Sobol value and map it to [0, 1) (32 bits, below 1 exactly)."""
    return float(reverse_bits(owen_reversed(reversed_value, seed))) * _INV_2_32


@device
def reversed_index(sample):
    """The sample index bit-reversed in INDEX_BITS bits (how a path key carries it)."""
    return reverse_bits(np.uint64(sample)) >> np.uint64(BITS - INDEX_BITS)


@device
def shuffled_index(rev_index, seed, mask):
    """A dimension set's own order of the samples: the (INDEX_BITS-bit reversed) index
    Owen-scrambled with the set's seed, which maps each aligned block of 2^m indices
    onto one, and masked with ``index_mask``; returned bit-reversed in 32 bits."""
    return owen_reversed(rev_index << np.uint64(BITS - INDEX_BITS), seed) & mask


@device
def _value(j, d):
    """Bit-reversed Sobol value in dimension d of the index whose reversal is j."""
    return np.uint64(TABLES[d, 0, j >> np.uint64(24)]
                     ^ TABLES[d, 1, (j >> np.uint64(16)) & np.uint64(0xFF)]
                     ^ TABLES[d, 2, (j >> np.uint64(8)) & np.uint64(0xFF)])


@device
def sobol_4d(j, s0, s1, s2, s3):
    """The first four dimensions of the point of shuffled index ``j``, each scrambled with
    its own 32-bit seed, in [0, 1)."""
    return (_to_unit(_value(j, 0), s0), _to_unit(_value(j, 1), s1),
            _to_unit(_value(j, 2), s2), _to_unit(_value(j, 3), s3))


@device
def sobol_2d(j, s0, s1):
    """The first two dimensions (a (0, 2)-sequence) of the point of shuffled index ``j``."""
    return _to_unit(_value(j, 0), s0), _to_unit(_value(j, 1), s1)


@device
def sobol_1d(j, s0):
    """The first dimension (van der Corput) of the point of shuffled index ``j``."""
    return _to_unit(_value(j, 0), s0)


def index_mask(samples: int) -> int:
    """The kernels' mask of the shuffled index for a render of ``samples`` samples: the
    indices below the next power of two, bit-reversed in 32 bits (at most 2^INDEX_BITS)."""
    count = max(0, int(samples) - 1).bit_length()
    if count > INDEX_BITS:
        raise ValueError(f"{samples} samples: the Sobol sampler takes at most 2^{INDEX_BITS}")
    return ((1 << count) - 1) << (BITS - count)
