#include "core/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace raysift {

ProgressBar::ProgressBar(std::string label, bool enabled, double delay_ms)
    : label_(std::move(label)), enabled_(enabled && isatty(fileno(stdout)) == 1), delay_ms_(delay_ms) {}

ProgressBar::~ProgressBar() {
  if (drawn_) {
    std::fputc('\n', stdout);
    std::fflush(stdout);
  }
}

void ProgressBar::update(double fraction) {
  if (!enabled_ || timer_.elapsed_ms() < delay_ms_) return;
  std::unique_lock<std::mutex> lock(draw_mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  const int percent = int(std::clamp(fraction, 0.0, 1.0) * 100.0);
  if (percent == last_percent_) return;
  last_percent_ = percent;
  constexpr int kWidth = 40;
  const int filled = percent * kWidth / 100;
  std::fprintf(stdout, "\r%s [%s%s] %3d%%", label_.c_str(), std::string(std::size_t(filled), '#').c_str(),
               std::string(std::size_t(kWidth - filled), ' ').c_str(), percent);
  std::fflush(stdout);
  drawn_ = true;
}

}  // namespace raysift
