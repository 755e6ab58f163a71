#include "harness/progress.h"

#include <cstdio>
#include <unistd.h>

namespace hairbench {

Progress::Progress(int total_runs, bool enabled)
    : enabled_(enabled && isatty(STDERR_FILENO) == 1), total_(total_runs), start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() { clear(); }

std::string Progress::clock(double seconds) {
  const long s = seconds < 0 ? 0 : static_cast<long>(seconds + 0.5);
  char buf[32];
  if (s >= 3600) std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  else std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
  return buf;
}

void Progress::begin(int runs, std::string what) {
  batch_ = runs;
  what_ = std::move(what);
  draw(0.0);
}

void Progress::frame(int done, int frames) {
  if (!enabled_) return;
  // A terminal redraw per frame would cost more than a small model's step: redraw at
  // most five times a second.
  const auto now = std::chrono::steady_clock::now();
  if (done < frames && now - last_draw_ < std::chrono::milliseconds(200)) return;
  draw(static_cast<double>(done) / frames);
}

void Progress::end() {
  done_ += batch_;
  batch_ = 0;
  clear();
}

void Progress::draw(double fraction_of_batch) {
  if (!enabled_) return;
  last_draw_ = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(last_draw_ - start_).count();
  // Runs of one batch finish together; count the batch's share by frames stepped.
  const double done = done_ + batch_ * fraction_of_batch;
  std::string left = "?";
  if (done > 0.0) left = std::string("~").append(clock(elapsed * (total_ - done) / done));
  std::fprintf(stderr, "\r\033[Kruns %d/%d done · %s · %3.0f%% · elapsed %s · left %s", done_, total_, what_.c_str(),
               100.0 * fraction_of_batch, clock(elapsed).c_str(), left.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void Progress::clear() {
  if (!enabled_ || !drawn_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  drawn_ = false;
}

}  // namespace hairbench
