// Han & Harada 2012 methods 1-3 (han_m1, han_m2, han_m3) as one fused pass per block of
// strands over the structure-of-arrays kernel kernels/han2012/fused/han_soa.*: the same algorithm,
// parameters and results as models/han2012/reference/ (registered as han_m*_ref), laid out so that
// vector lanes process 16 strands at once and a block stays in L1 through a frame.
#pragma once

#include "core/hair_model.h"
#include "core/sleep.h"
#include "kernels/han2012/fused/han_soa.h"
#include "models/block_threads.h"
#include "models/han2012/reference/han_reference.h"

#include <array>
#include <cstdint>
#include <memory>
#include <new>
#include <vector>

namespace hairbench::han_fused {

// Cache-line aligned storage, so every block (a multiple of 64 bytes) starts on a line.
template <class T>
struct LineAllocator {
  using value_type = T;
  LineAllocator() = default;
  template <class U>
  LineAllocator(const LineAllocator<U>&) {}
  T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{64})); }
  void deallocate(T* p, std::size_t) { ::operator delete(p, std::align_val_t{64}); }
  bool operator==(const LineAllocator&) const { return true; }
};
using FloatBuffer = std::vector<float, LineAllocator<float>>;

class HanFusedModel final : public HairModel {
 public:
  HanFusedModel(han::Method method, const ModelContext& ctx);
  void reset(const Groom& rest, const ParamSet& params) override;
  // Positions and the blocks' previous positions at the given ones; method 2's frames stay
  // at rest, as the reference's do.
  bool start_from(std::span<const Vec4f> positions) override;
  void step(const FrameInput& in, StageTimes& out_times) override;
  std::span<const Vec4f> positions() const override { return pos_; }
  std::size_t state_bytes() const override;
  // The kernel variant to run (default: the best for this CPU); for the tests that
  // compare ISA variants.
  void use_kernel(kernels::han_soa::FrameFn kernel) { kernel_ = kernel; }

 private:
  struct BlockInfo {
    std::size_t offset;  // into data_
    std::size_t row_kinds;  // into row_kinds_
    std::size_t rounding_first;  // into rounding_rows_, rounding_count of them (method 2)
    int rounding_count;
    int n, method;
    std::uint16_t region;
    std::array<std::uint32_t, kernels::han_soa::kLanes> out_offset;
    std::array<std::uint32_t, kernels::han_soa::kLanes> in_offset;  // Block::in_offset
    std::array<std::uint32_t, kernels::han_soa::kLanes> strand;  // groom index, or kNoStrand
  };
  // One kernel call: up to kMaxBlocks consecutive blocks of one region and vertex count.
  struct Job {
    std::size_t first;
    int count;
    bool sampled;  // times its stages (see step())
  };
  using ThreadState = BlockThread;
  void run_thread(int t);
  void feed_job(const Job& job, kernels::soa::LineFeed& feed) const;
  void observe_sleep(int t, float dt);

  han::Method method_;
  ModelContext ctx_;
  kernels::han_soa::FrameFn kernel_ = nullptr;
  std::vector<BlockInfo> blocks_;
  std::vector<Job> jobs_;
  std::vector<kernels::han_soa::BlockParams> region_;
  FloatBuffer data_;
  FloatBuffer scratch_;  // per thread, scratch_stride_ floats each
  std::size_t scratch_stride_ = 0;
  std::vector<ThreadState> threads_;
  std::vector<kernels::han_soa::RowKind> row_kinds_;
  std::vector<kernels::han_soa::RoundingRow> rounding_rows_;
  std::vector<Vec4f> pos_;
  int substeps_ = 1;
  bool any_global_ = false, any_local_ = false, any_length_ = false;

  // Sleeping strands (core/sleep.h): a block whose strands all sleep is not
  // run; a block with some asleep runs whole and its sleepers' lanes and positions are
  // put back from copies (backup_ and pos_backup_, per thread), so they stay
  // bit-exactly as they were.
  StrandSleep sleep_;
  bool calm_ = false;
  FloatBuffer backup_;
  std::size_t backup_stride_ = 0;
  std::vector<Vec4f> pos_backup_;
  std::size_t pos_backup_stride_ = 0;
  std::vector<Vec4f> prev_tmp_;  // per thread, max strand length: observe()'s prev

  // Per-step input, filled before the parallel pass (capacity reserved in reset()).
  std::vector<kernels::han_soa::Substep> substep_;
  std::vector<float> spheres_;
  kernels::han_soa::Frame frame_{};
};

std::unique_ptr<HairModel> make(han::Method method, const ModelContext& ctx);

}  // namespace hairbench::han_fused
