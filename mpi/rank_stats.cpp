#include "mpi/rank_stats.h"

#include "mpi/session.h"

namespace raysift::mpi {

Json gather_rank_stats(const RankStats& mine, const std::string& distribute) {
  const Json row = {{"rank", rank()},
                    {"active_voxels_loaded", mine.active_voxels_loaded},
                    {"bytes_read", mine.bytes_read},
                    {"render_ms", mine.render_ms},
                    {"composite_ms", mine.composite_ms},
                    {"wait_ms", mine.wait_ms},
                    {"bytes_sent", mine.bytes_sent},
                    {"bytes_received", mine.bytes_received}};
  Json rows = gather_json(row);
  if (!is_root()) return Json::object();
  Json total = {{"active_voxels_loaded", 0}, {"bytes_read", 0},     {"render_ms", 0.0},
                {"composite_ms", 0.0},       {"wait_ms", 0.0},      {"bytes_sent", 0},
                {"bytes_received", 0}};
  for (const Json& r : rows)
    for (auto& [key, sum] : total.items())
      sum = sum.is_number_float() ? Json(sum.get<double>() + r[key].get<double>())
                                  : Json(sum.get<std::uint64_t>() + r[key].get<std::uint64_t>());
  return {{"distribute", distribute}, {"ranks", std::move(rows)}, {"ranks_total", std::move(total)}};
}

}  // namespace raysift::mpi
