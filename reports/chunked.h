// Sums over every vertex of a frame that vectorise and keep their bits, for the per-frame
// metrics and checks (reports/metrics.cpp, reports/verdict.cpp), which `compare` runs
// per model and frame and which cost about as much as a fast model's step.
#pragma once

#include <algorithm>
#include <cstddef>

// Their hot loops are built twice, for x86-64-v4 (AVX-512) and the baseline, and chosen
// at load time; the IEEE operations give the same bits in either (no FMA contraction,
// -ffp-contract=off).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define METRIC_CLONES __attribute__((target_clones("arch=x86-64-v4", "default")))
#else
#define METRIC_CLONES
#endif
// Their helpers are inlined into each build (a call would run the baseline build).
#define METRIC_INLINE [[gnu::always_inline]] inline

namespace hairbench::metrics {

// A sum's terms are computed kChunk at a time into a buffer, by a loop that vectorises,
// and added in order after it: the same additions in the same order as in one loop, so
// the same bits, without each term's arithmetic waiting on the running sum.
inline constexpr std::size_t kChunk = 256;

template <class Term, class Add>
METRIC_INLINE void chunked(std::size_t begin, std::size_t end, Term term, Add add) {
  decltype(term(begin)) buf[kChunk];
  for (std::size_t c = begin; c < end; c += kChunk) {
    const std::size_t m = std::min(kChunk, end - c);
    for (std::size_t k = 0; k < m; ++k) buf[k] = term(c + k);
    for (std::size_t k = 0; k < m; ++k) add(buf[k]);
  }
}

}  // namespace hairbench::metrics
