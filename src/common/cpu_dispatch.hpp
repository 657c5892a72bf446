#pragma once
// ALOFT_CPU_DISPATCH marks the step's hot loops (the factorization sweep, the substitution, the drift,
// the kicks) to be compiled twice, for AVX2 and for the x86-64 baseline; the dynamic loader picks the
// clone the processor runs (GCC's target_clones, a glibc ifunc), once, at start-up. The release build
// targets the baseline (no -march), so without this the loops on 3x3 blocks use SSE2 only.
//
// The clones compute the same numbers bit for bit: AVX2 is only wider registers and three-operand
// instructions; fused multiply-add is a separate extension (FMA) that the clone does not enable, and
// -ffp-contract=off forbids contracting anyway. GCC does not reorder floating-point sums to vectorize
// them without -ffast-math. So trajectories do not depend on which clone runs (docs/performance.md,
// "2026-11-25, evening: AVX2 clones of the hot loops", gives the checksums of both).
//
// Off (an empty macro) with clang (the fuzzing build), off x86-64, and with -DALOFT_CPU_DISPATCH=OFF.
#if defined(ALOFT_CPU_DISPATCH_ENABLED) && defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define ALOFT_CPU_DISPATCH __attribute__((target_clones("avx2", "default")))
#else
#define ALOFT_CPU_DISPATCH
#endif
