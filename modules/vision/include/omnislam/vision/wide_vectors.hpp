#pragma once

/// @file
/// OMNISLAM_WIDE_VECTORS marks a hot, vectorised loop to be compiled twice: for the x86-64
/// baseline every build targets (SSE2) and for AVX2 (twice the lanes, and gathers). The CPU
/// picks one when the program loads (GCC's target_clones, an ifunc resolved once by glibc),
/// so one binary runs on every robot and uses the wider vectors where they exist.
///
/// Only for code whose result must not depend on the CPU: AVX2 here comes without FMA
/// (no contraction of a * b + c) and the compiler does not reorder floating-point sums, so
/// each lane computes what the SSE2 version computes, bit for bit (checked on the bench's
/// scans). Elsewhere (another compiler or architecture; ThreadSanitizer, whose runtime is
/// not up yet when the loader resolves an ifunc) it expands to nothing.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__gnu_linux__) && \
    !defined(__SANITIZE_THREAD__) && !defined(OMNISLAM_NO_WIDE_VECTORS)
#define OMNISLAM_WIDE_VECTORS __attribute__((target_clones("avx2", "default")))
#else
#define OMNISLAM_WIDE_VECTORS
#endif
