/* SplitMix64 and the Irwin-Hall normal; runtime/noise.py (see noise.h). */
#include "fp_contract.h"
#include "noise.h"

#define PAIRS 0x0000FFFF0000FFFFULL    /* lanes 0 and 2 of a word (and, shifted, 1 and 3) */
#define LANE_OFFSET 393210.0           /* 12 * 32768 - 6 */

uint64_t splitmix64_mix(uint64_t state)
{
    uint64_t z = state;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

uint64_t splitmix64_word(uint64_t seed, uint64_t index)
{
    return splitmix64_mix(seed + index * SPLITMIX64_GAMMA);
}

double standard_normal(uint64_t seed, uint64_t sample)
{
    uint64_t state = seed + sample * (3u * SPLITMIX64_GAMMA), lanes = 0, z;
    int word;
    for (word = 1; word <= 3; word++) {
        z = splitmix64_mix(state + (uint64_t)word * SPLITMIX64_GAMMA);
        lanes += (z & PAIRS) + ((z >> 16) & PAIRS);   /* each half < 6 x 65535: no carry */
    }
    return ((double)((lanes & 0xFFFFFFFFULL) + (lanes >> 32)) - LANE_OFFSET) / 65536.0;
}
