/* A portable noise source: SplitMix64 words and an approximately normal number from them;
 * runtime/noise.py (the same integers, the same one exact division: the same bits).
 *
 * splitmix64_word(seed, i) = mix(seed + i GAMMA mod 2^64), i >= 1: SplitMix64's i-th output.
 * standard_normal(seed, k): the words 3k + 1 ... 3k + 3 cut into twelve 16-bit lanes b_i,
 * z = (sum b_i - 393210) / 65536 (Irwin-Hall, n = 12: mean 0, variance 1 - 2^-32). */
#ifndef SMA_NOISE_H
#define SMA_NOISE_H

#include <stdint.h>

#define SPLITMIX64_GAMMA 0x9E3779B97F4A7C15ULL

/* SplitMix64's output function of a 64-bit state. */
uint64_t splitmix64_mix(uint64_t state);

/* The index-th output (index >= 1) of the generator seeded with `seed`. */
uint64_t splitmix64_word(uint64_t seed, uint64_t index);

/* z [1] of sample `sample` of the stream `seed`. */
double standard_normal(uint64_t seed, uint64_t sample);

#endif
