#pragma once
/// \file A terminal progress bar for long operations. It draws only when stdout is a terminal and the
/// operation has run longer than a delay (1 s by default), so pipes, logs and tests stay clean.
#include <atomic>
#include <mutex>
#include <string>

#include "core/timer.h"

namespace raysift {

/// \warning update() is thread-safe (workers may call it per chunk); drawing never blocks a worker:
/// a call that finds another thread drawing returns at once.
class ProgressBar {
 public:
  /// \param label   text before the bar
  /// \param enabled false = never draw (e.g. --quiet)
  /// \param delay_ms draw only once this much time has passed
  explicit ProgressBar(std::string label, bool enabled = true, double delay_ms = 1000.0);
  /// Ends the line if anything was drawn.
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  /// \param fraction finished part in [0,1] (clamped)
  void update(double fraction);

 private:
  std::string label_;
  bool enabled_;
  double delay_ms_;
  Timer timer_;
  std::mutex draw_mutex_;
  int last_percent_ = -1;
  std::atomic<bool> drawn_{false};
};

}  // namespace raysift
