// FAHR_VECTOR_CLONES before a function with a hot loop compiles it twice,
// for AVX2 and for the baseline x86-64 the build targets, and picks one when
// the program loads (GCC's target_clones, an ifunc): a Haswell or later
// processor runs four doubles a vector instruction instead of two, an older
// one still runs. Only "avx2", not FMA: a fused multiply-add rounds once
// where a multiply and an add round twice, so with FMA the two clones would
// give different bits and a lockstep run would hash differently on machines
// of either kind. Without FMA, and without reassociation (no -ffast-math),
// vectorising changes how many elements an instruction takes, never the
// operations on each: both clones give the same bits, which the pinned
// lockstep hashes (tests/determinism, stack_sim_pinned_hashes) check on
// whichever clone the test machine runs. Lives in fahr::geometry because
// every physics library links it.
#pragma once

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define FAHR_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define FAHR_VECTOR_CLONES
#endif
