// A fixed pool of worker threads for data-parallel loops over strands.
//
// Work is split into `threads()` contiguous blocks, one per thread, so every strand is
// always processed by exactly one thread with the same code path: results are
// bit-identical for any thread count (no reductions across threads happen here).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace hairbench {

class ThreadPool {
 public:
  // threads <= 0 means std::thread::hardware_concurrency().
  explicit ThreadPool(int threads = 0);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls body(begin, end) over a static partition of [0, n); returns when all are done.
  // The calling thread takes the first block.
  void parallel_for(std::size_t n, const std::function<void(std::size_t, std::size_t)>& body);

 private:
  void worker_loop(int index);

  std::vector<std::thread> workers_;
  // A loop is published by bumping generation_ and finished when pending_ reaches 0. Both
  // sides spin on these for a short while before they sleep on the condition variables
  // (see kSpin in parallel.cpp).
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  const std::function<void(std::size_t, std::size_t)>* body_ = nullptr;
  std::size_t n_ = 0;
  std::atomic<std::size_t> generation_{0};
  std::atomic<int> pending_{0};
  bool stop_ = false;
};

}  // namespace hairbench
