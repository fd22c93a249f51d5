// Memory limits: size parsing, overflow-safe products and the two error types of require_memory.
#include "core/memory_limit.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <limits>

#include "core/errors.h"

namespace raysift {
namespace {

TEST(MemoryLimit, ParsesSizesWithBinaryUnits) {
  EXPECT_EQ(parse_byte_size("4096"), 4096u);
  EXPECT_EQ(parse_byte_size("512M"), 512ull << 20);
  EXPECT_EQ(parse_byte_size("8G"), 8ull << 30);
  EXPECT_EQ(parse_byte_size("8GiB"), 8ull << 30);
  EXPECT_EQ(parse_byte_size("1.5k"), 1536u);
  EXPECT_EQ(parse_byte_size("2T"), 2ull << 40);
  for (const char* bad : {"", "G", "0", "-1G", "12Q", "1e30", "nan", "8 G"})
    EXPECT_THROW(parse_byte_size(bad), InvalidInput) << bad;
}

TEST(MemoryLimit, ProductSaturatesInsteadOfWrapping) {
  const std::uint64_t max = std::numeric_limits<std::uint64_t>::max();
  EXPECT_EQ(saturating_product(40000, 40000), 1600000000u);
  EXPECT_EQ(saturating_product(std::uint64_t(1) << 40, std::uint64_t(1) << 30), max);
  EXPECT_EQ(saturating_product(0, max), 0u);
}

TEST(MemoryLimit, RequireMemoryNamesBytesAndBlamesTheSource) {
  const MemoryLimit limit{1000, true};
  EXPECT_NO_THROW(require_memory(1000, limit, SizeSource::Flag, "x"));
  try {
    require_memory(2048, limit, SizeSource::Flag, "a 32x16 render");
    ADD_FAILURE() << "no throw";
  } catch (const UsageError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("a 32x16 render needs 2.00 KiB (2048 bytes)"), std::string::npos) << m;
    EXPECT_NE(m.find("--max-memory"), std::string::npos) << m;
  }
  EXPECT_THROW(require_memory(2048, limit, SizeSource::Input, "mesh"), ResourceError);
}

TEST(MemoryLimit, AvailableMemoryIsMemAvailable) {
  // Independent reading of the same kernel field; the two reads may differ by what other processes did
  // in between, so only the order of magnitude (and being below MemTotal) is compared.
  std::ifstream in("/proc/meminfo");
  std::string key, unit;
  std::uint64_t kib = 0, total = 0;
  while (in >> key >> kib >> unit)
    if (key == "MemTotal:") total = kib * 1024;
  const std::uint64_t available = available_memory_bytes();
  ASSERT_GT(total, 0u);
  EXPECT_GT(available, 0u);
  EXPECT_LE(available, total);
}

}  // namespace
}  // namespace raysift
