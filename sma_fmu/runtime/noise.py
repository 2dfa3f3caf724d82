"""A portable noise source: SplitMix64 words and an approximately normal number from them.

The sensor noise of a run must be the same in every path (library, fmpy master, C FMUs,
C master, batch engine), so it is a pure function of (seed, sample index), computed with
integer operations and one exact division, which Python, C (``uint64_t``) and numpy
(``uint64``) all carry out bit for bit. No ``random``, no ``numpy.random``, no libm
function (``log``, ``cos``: their last bit differs between libraries and CPUs).

- **Words**: SplitMix64 (Steele, Lea, Flood 2014), as in Java's ``SplittableRandom`` and
  Vigna's reference ``splitmix64.c``: the i-th output (i = 1, 2, ...) from ``seed`` is
  ``mix(seed + i * GAMMA mod 2^64)``. Counter-based: any sample is computed without the
  ones before it (a saved state is just the index).
- **Normal number** (:func:`standard_normal`): the sum of twelve uniform numbers minus six
  (Irwin-Hall, n = 12). Sample k takes the words 3k + 1, 3k + 2, 3k + 3, cut into twelve
  16-bit lanes b_i; u_i = (b_i + 1/2) / 2^16 lies in (0, 1), and

      z = sum(u_i) - 6 = (sum(b_i) - 393210) / 65536        (exact in double arithmetic)

  Mean 0, variance 12 (2^32 - 1) / (12 2^32) = 1 - 2^-32, excess kurtosis -1/10 (a normal's
  is 0), |z| <= 6 - 6/65536, steps of 1/65536. **choice**: for sensor noise a bounded,
  slightly light-tailed normal is as good as an exact one, and it needs no transcendental
  function, so it is portable.
"""
__all__ = ["GAMMA", "MASK", "LANE_OFFSET", "mix", "word", "standard_normal"]

MASK = (1 << 64) - 1
GAMMA = 0x9E3779B97F4A7C15          # SplitMix64's increment: 2^64 / golden ratio, odd
_MIX1, _MIX2 = 0xBF58476D1CE4E5B9, 0x94D049BB133111EB
_PAIRS = 0x0000FFFF0000FFFF         # lanes 0 and 2 of a word (and, shifted, 1 and 3)
LANE_OFFSET = 12 * 32768 - 6        # 393210: sum(b_i) - LANE_OFFSET = 65536 (sum(u_i) - 6)


def mix(state):
    """SplitMix64's output function of a 64-bit ``state`` (an int; taken mod 2^64)."""
    z = state & MASK
    z = ((z ^ (z >> 30)) * _MIX1) & MASK
    z = ((z ^ (z >> 27)) * _MIX2) & MASK
    return z ^ (z >> 31)


def word(seed, index):
    """The ``index``-th SplitMix64 output (``index`` >= 1) of the generator seeded with ``seed``."""
    return mix(seed + index * GAMMA)


def standard_normal(seed, sample, _m=MASK, _a=_MIX1, _b=_MIX2, _p=_PAIRS, _g=GAMMA,
                    _g2=2 * GAMMA, _g3=3 * GAMMA):
    """z [1] of sample ``sample`` (>= 0) of the stream ``seed`` (see the module docstring).

    The three words written out (a loop costs a third more: this runs once per step).
    """
    state = seed + sample * _g3
    z = (state + _g) & _m
    z = ((z ^ (z >> 30)) * _a) & _m
    z = ((z ^ (z >> 27)) * _b) & _m
    z ^= z >> 31
    lanes = (z & _p) + ((z >> 16) & _p)          # lanes 0+1 in the low half, 2+3 in the high
    z = (state + _g2) & _m
    z = ((z ^ (z >> 30)) * _a) & _m
    z = ((z ^ (z >> 27)) * _b) & _m
    z ^= z >> 31
    lanes += (z & _p) + ((z >> 16) & _p)
    z = (state + _g3) & _m
    z = ((z ^ (z >> 30)) * _a) & _m
    z = ((z ^ (z >> 27)) * _b) & _m
    z ^= z >> 31
    lanes += (z & _p) + ((z >> 16) & _p)         # each half < 6 x 65535: no carry between them
    return ((lanes & 0xFFFFFFFF) + (lanes >> 32) - LANE_OFFSET) / 65536.0
