// Progress of a long compare or sweep on a terminal: runs done / total, the current run,
// elapsed time and an estimate of the time left. Silent when stderr is not a terminal
// (CI logs, pipes), so that output stays the per-run result lines only.
#pragma once

#include <chrono>
#include <string>

namespace hairbench {

class Progress {
 public:
  // `enabled` false (or stderr not a terminal) makes every call a no-op.
  Progress(int total_runs, bool enabled);
  ~Progress();
  // A batch of `runs` runs stepping in lockstep starts; `what` names it.
  void begin(int runs, std::string what);
  // Frame `done` of `frames` of the current batch has been stepped.
  void frame(int done, int frames);
  // The current batch is done; clears the line so that result lines print cleanly.
  void end();

  // "1:05" / "1:02:03"
  static std::string clock(double seconds);

 private:
  void draw(double fraction_of_batch);
  void clear();
  bool enabled_;
  int total_, done_ = 0, batch_ = 0;
  std::string what_;
  std::chrono::steady_clock::time_point start_, last_draw_;
  bool drawn_ = false;
};

}  // namespace hairbench
