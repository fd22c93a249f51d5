#include "core/memory_limit.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/errors.h"

namespace raysift {

constexpr std::uint64_t kUnlimited = std::numeric_limits<std::uint64_t>::max();

std::uint64_t available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key, unit;
  std::uint64_t kib = 0;
  while (in >> key >> kib) {
    std::getline(in, unit);
    if (key == "MemAvailable:") return kib * 1024;
  }
  return kUnlimited;
}

std::uint64_t parse_byte_size(const std::string& text) {
  const auto bad = [&] {
    return InvalidInput("'" + text + "' is not a memory size; expected e.g. 8G, 512M or a byte count > 0");
  };
  std::size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    throw bad();
  }
  std::string suffix = text.substr(used);
  for (const char* tail : {"iB", "B"})
    if (suffix.size() >= std::string(tail).size() && suffix.compare(suffix.size() - std::string(tail).size(),
                                                                     std::string::npos, tail) == 0) {
      suffix.resize(suffix.size() - std::string(tail).size());
      break;
    }
  const std::string units = "KMGT";
  double scale = 1;
  if (suffix.size() == 1 && units.find(char(std::toupper(suffix[0]))) != std::string::npos)
    scale = std::pow(1024.0, double(units.find(char(std::toupper(suffix[0]))) + 1));
  else if (!suffix.empty())
    throw bad();
  const double bytes = value * scale;
  // 2^64 itself is not representable; anything at or above it is out of range.
  if (!(bytes >= 1) || !(bytes < 18446744073709551616.0)) throw bad();
  return std::uint64_t(bytes);
}

std::string format_bytes(std::uint64_t bytes) {
  if (bytes == kUnlimited) return "more than 2^64 bytes";
  const char* units[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double value = double(bytes) / 1024.0;
  int unit = 0;
  while (value >= 1024.0 && unit < 5) value /= 1024.0, ++unit;
  char buf[80];
  std::snprintf(buf, sizeof buf, "%.2f %s (%llu bytes)", value, units[unit], static_cast<unsigned long long>(bytes));
  return buf;
}

std::uint64_t saturating_product(std::uint64_t a, std::uint64_t b) {
  if (a != 0 && b > kUnlimited / a) return kUnlimited;
  return a * b;
}

void require_memory(std::uint64_t needed_bytes, const MemoryLimit& limit, SizeSource source, const std::string& what,
                    const std::string& hint) {
  const std::uint64_t allowed = limit.bytes != 0 ? limit.bytes : available_memory_bytes();
  if (needed_bytes <= allowed) return;
  std::string message = what + " needs " + format_bytes(needed_bytes) + ", more than the " + format_bytes(allowed) +
                        (limit.from_flag ? " that --max-memory allows" : " of memory available (MemAvailable; raise "
                                                                         "or lower the limit with --max-memory)");
  if (!hint.empty()) message += "; " + hint;
  if (source == SizeSource::Flag) throw UsageError(message + "; see --help");
  throw ResourceError(message);
}

}  // namespace raysift
