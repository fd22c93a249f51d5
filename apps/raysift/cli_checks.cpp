#include "apps/raysift/cli_checks.h"

#include <cmath>
#include <sstream>

#include "core/file_util.h"

namespace raysift::app {

CLI::Validator number_in(double lo, double hi, End lo_end, End hi_end) {
  std::ostringstream range;
  if (std::isinf(lo) && std::isinf(hi)) {
    range << "(-inf, inf)";  // any finite number
  } else {
    range << (lo_end == End::Open ? "(" : "[") << lo << ", " << hi << (hi_end == End::Open || std::isinf(hi) ? ")" : "]");
  }
  return CLI::Validator(
      [lo, hi, lo_end, hi_end, text = range.str()](std::string& value) -> std::string {
        double v = 0;
        const bool parsed = CLI::detail::lexical_cast(value, v);
        const bool above = lo_end == End::Open ? v > lo : v >= lo;
        const bool below = hi_end == End::Open ? v < hi : v <= hi;
        if (parsed && std::isfinite(v) && above && below) return "";
        return "must be a number in " + text + ", got '" + value + "'";
      },
      "in " + range.str(), "number_in");
}

CLI::Validator has_extension(const std::vector<std::string>& extensions) {
  std::string names;
  for (const std::string& e : extensions) names += (names.empty() ? "" : "|") + e;
  return CLI::Validator(
      [extensions, names](std::string& path) -> std::string {
        for (const std::string& e : extensions)
          if (file_extension(path) == e) return "";
        return "must be a " + names + " path, got " + path;
      },
      "PATH(" + names + ")", "extension");
}

std::optional<Vec3d> parse_vec3(const std::string& text) {
  std::istringstream in(text);
  Vec3d v;
  char c1 = 0, c2 = 0;
  if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() || !is_finite(v))
    return std::nullopt;
  return v;
}

CLI::Validator vec3_text() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        return parse_vec3(text) ? "" : "must be three finite numbers x,y,z, got '" + text + "'";
      },
      "X,Y,Z", "vec3");
}

}  // namespace raysift::app
