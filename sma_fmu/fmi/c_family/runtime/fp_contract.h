/* No fused multiply-add: every runtime file includes this first.
 *
 * The C family must equal the Python runtime to the last bit (CPython never fuses a*b + c).
 * GCC contracts a*b + c into one FMA by default wherever the target has it (aarch64 always,
 * x86-64 with -march=x86-64-v3 or native), and a tool that compiles sources/ chooses its own
 * flags (fmpy's CMake passes no -ffp-contract=off). So the sources say it themselves. */
#ifndef SMA_FP_CONTRACT_H
#define SMA_FP_CONTRACT_H

#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC optimize ("fp-contract=off")
#elif defined(_MSC_VER)
#pragma fp_contract (off)
#endif

#endif
