// The memory floor of a step: the time to stream a model's per-frame state
// once, read and write, on all threads of the pool. A model's step time over this is its
// roofline_ratio (report timing.roofline_ratio, hairbench_bench's BM_step counter).
#pragma once

#include <cstddef>

namespace hairbench {

class ThreadPool;

// Seconds to read, scale and write back `bytes` of floats with every thread of `pool`,
// the best pass of at least 20 and 10 ms after two warm-up passes; measured once per
// size and thread count in a process and cached.
double stream_seconds(std::size_t bytes, ThreadPool& pool);

}  // namespace hairbench
