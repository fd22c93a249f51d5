#pragma once
/// \file What `raysift serve --stats FILE` writes when it stops: frames served, frame times per mode, clients.
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "core/json_io.h"

namespace raysift::server {

/// Thread-safe counters every session reports to.
class ServeStats {
 public:
  void client_connected();
  void client_disconnected();
  /// One frame sent: its render time (ms) and what it took end to end (render + encode + send).
  void frame_sent(const std::string& mode, double render_ms, double total_ms);
  /// {"frames_served", "clients": {"total", "max_concurrent"}, "frame_ms": {mode: {"frames", "p50", "p95",
  ///  "total_p50", "total_p95"}}}; percentiles by the nearest-rank rule.
  Json to_json() const;

 private:
  mutable std::mutex mutex_;
  std::uint64_t frames_ = 0;
  int clients_total_ = 0, clients_now_ = 0, clients_max_ = 0;
  std::map<std::string, std::vector<double>> render_ms_, total_ms_;
};

}  // namespace raysift::server
