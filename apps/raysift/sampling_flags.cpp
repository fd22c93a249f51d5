#include "apps/raysift/sampling_flags.h"

#include <sstream>

#include "sampling/ray_order.h"

namespace raysift::app {

std::string alpha_flag_help() {
  std::ostringstream s;
  s << "a priori priority mapping a00,a10,a01,a11,a20,a02 (used with --no-refine, threshold and progressive "
       "frames; default ";
  const auto& a = sampling::PriorityMapping{}.alpha;
  for (std::size_t i = 0; i < a.size(); ++i) s << (i ? "," : "") << a[i];
  s << ")";
  return s.str();
}

}  // namespace raysift::app
