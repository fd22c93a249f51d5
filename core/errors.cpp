#include "core/errors.h"

namespace raysift::detail {
void check_failed(const char* expr, const char* file, int line, const std::string& values) {
  std::ostringstream s;
  s << "internal check failed: " << expr << values << " at " << file << ":" << line
    << " (this is a raysift bug; please report it)";
  throw std::logic_error(s.str());
}
}  // namespace raysift::detail
