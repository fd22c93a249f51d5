#include "apps/raysift/sampling_flags.h"

#include <cmath>
#include <sstream>

#include "apps/raysift/cli_checks.h"
#include "sampling/ray_order.h"
#include "sampling/volume_sampling.h"

namespace raysift::app {

namespace {

std::string alpha_flag_help() {
  std::ostringstream s;
  s << "a priori priority mapping a00,a10,a01,a11,a20,a02 (used with --no-refine, threshold and progressive "
       "frames; default ";
  const auto& a = sampling::PriorityMapping{}.alpha;
  for (std::size_t i = 0; i < a.size(); ++i) s << (i ? "," : "") << a[i];
  s << ")";
  return s.str();
}

}  // namespace

void add_alpha_option(CLI::App& app, std::vector<float>& alpha, const std::string& help_prefix) {
  app.add_option("--alpha", alpha, help_prefix + alpha_flag_help())
      ->delimiter(',')
      ->expected(6)
      ->check(number_in(-INFINITY, INFINITY));
}

std::string split_saliency_feature(const std::string& list, bool& has_saliency) {
  has_saliency = false;
  std::string rest;
  for (const std::string& item : sampling::feature_list_entries(list)) {
    if (item == "saliency") {
      has_saliency = true;
    } else if (item != "none") {
      rest += (rest.empty() ? "" : ",") + item;
    }
  }
  return rest.empty() ? "none" : rest;
}

}  // namespace raysift::app
