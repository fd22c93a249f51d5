#include "server/serve_stats.h"

#include <algorithm>
#include <cmath>

namespace raysift::server {
namespace {

double nearest_rank(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto rank = std::size_t(std::ceil(p * double(v.size())));
  return v[std::max<std::size_t>(rank, 1) - 1];
}

}  // namespace

void ServeStats::client_connected() {
  const std::lock_guard<std::mutex> lock(mutex_);
  ++clients_total_;
  clients_max_ = std::max(clients_max_, ++clients_now_);
}

void ServeStats::client_disconnected() {
  const std::lock_guard<std::mutex> lock(mutex_);
  --clients_now_;
}

void ServeStats::frame_sent(const std::string& mode, double render_ms, double total_ms) {
  const std::lock_guard<std::mutex> lock(mutex_);
  ++frames_;
  render_ms_[mode].push_back(render_ms);
  total_ms_[mode].push_back(total_ms);
}

Json ServeStats::to_json() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  Json modes = Json::object();
  for (const auto& [mode, ms] : render_ms_) {
    const std::vector<double>& total = total_ms_.at(mode);
    modes[mode] = {{"frames", ms.size()},
                   {"p50", nearest_rank(ms, 0.5)},
                   {"p95", nearest_rank(ms, 0.95)},
                   {"total_p50", nearest_rank(total, 0.5)},
                   {"total_p95", nearest_rank(total, 0.95)}};
  }
  return {{"frames_served", frames_},
          {"clients", {{"total", clients_total_}, {"max_concurrent", clients_max_}}},
          {"frame_ms", modes}};
}

}  // namespace raysift::server
