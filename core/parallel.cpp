#include "core/parallel.h"

#include <chrono>

namespace hairbench {

namespace {
// Block i of `parts` over [0, n).
std::pair<std::size_t, std::size_t> block(std::size_t n, int parts, int i) {
  const std::size_t p = static_cast<std::size_t>(parts);
  const std::size_t k = static_cast<std::size_t>(i);
  return {n * k / p, n * (k + 1) / p};
}

// How long a worker waits for the next loop, and the caller for the workers, spinning
// before it sleeps on a condition variable. A sleeping thread is woken through the
// kernel, which takes tens of microseconds on small virtual machines, and plante_wisp
// runs one or two loops per 1 ms integration step: a wake-up per loop would be a visible
// share of its step. The other models run a loop per frame or stage; a spin that ends
// unanswered costs them this much of the worker's time.
constexpr auto kSpin = std::chrono::microseconds(100);

// Spins until done() or kSpin has passed; whether done() held. Each turn yields the
// core: where more threads run than there are cores (tests in parallel), a thread that
// spins without yielding holds a core the others need.
template <class F>
bool spin_until(F&& done) {
  const auto until = std::chrono::steady_clock::now() + kSpin;
  while (!done()) {
    if (std::chrono::steady_clock::now() >= until) return done();
    std::this_thread::yield();
  }
  return true;
}
}  // namespace

ThreadPool::ThreadPool(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this, i] { worker_loop(i); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (auto& w : workers_) w.join();
}

void ThreadPool::parallel_for(std::size_t n,
                              const std::function<void(std::size_t, std::size_t)>& body) {
  if (n == 0) return;
  if (workers_.empty() || n == 1) {
    body(0, n);
    return;
  }
  {
    // Under the mutex, so that a worker about to sleep sees the new generation or is
    // woken after it.
    std::lock_guard lock(mutex_);
    body_ = &body;
    n_ = n;
    pending_.store(static_cast<int>(workers_.size()), std::memory_order_relaxed);
    generation_.fetch_add(1, std::memory_order_release);
  }
  wake_.notify_all();
  const auto [b, e] = block(n, threads(), 0);
  if (b < e) body(b, e);
  auto finished = [this] { return pending_.load(std::memory_order_acquire) == 0; };
  if (!spin_until(finished)) {
    std::unique_lock lock(mutex_);
    done_.wait(lock, finished);
  }
  std::lock_guard lock(mutex_);
  body_ = nullptr;
}

void ThreadPool::worker_loop(int index) {
  std::size_t seen = 0;
  for (;;) {
    const std::function<void(std::size_t, std::size_t)>* body;
    std::size_t n;
    {
      auto published = [&] { return generation_.load(std::memory_order_acquire) != seen; };
      spin_until(published);
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || published(); });
      if (stop_) return;
      seen = generation_.load(std::memory_order_relaxed);
      body = body_;
      n = n_;
    }
    const auto [b, e] = block(n, threads(), index);
    if (b < e) (*body)(b, e);
    if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
      // The caller may be asleep: notify under the mutex so the wake-up is not lost
      // between its check and its wait.
      std::lock_guard lock(mutex_);
      done_.notify_one();
    }
  }
}

}  // namespace hairbench
