#include "mpi/distributed_sweep.h"

#include <cstdint>
#include <cstring>

#include "core/errors.h"
#include "mpi/session.h"

namespace raysift::mpi {
namespace {

// One rank's texts as (u64 length, bytes) records; the receiver knows the unit of each from dealt_units.
std::vector<std::uint8_t> pack(const std::vector<std::string>& texts) {
  std::vector<std::uint8_t> out;
  for (const std::string& t : texts) {
    const std::uint64_t n = t.size();
    const auto* len = reinterpret_cast<const std::uint8_t*>(&n);
    out.insert(out.end(), len, len + sizeof n);
    out.insert(out.end(), t.begin(), t.end());
  }
  return out;
}

std::vector<std::string> unpack(const std::vector<std::uint8_t>& bytes, std::size_t count) {
  std::vector<std::string> out;
  std::size_t at = 0;
  for (std::size_t i = 0; i < count; ++i) {
    std::uint64_t n = 0;
    RAYSIFT_CHECK(at + sizeof n <= bytes.size());
    std::memcpy(&n, bytes.data() + at, sizeof n);
    at += sizeof n;
    RAYSIFT_CHECK(at + n <= bytes.size());
    out.emplace_back(reinterpret_cast<const char*>(bytes.data() + at), std::size_t(n));
    at += n;
  }
  RAYSIFT_CHECK(at == bytes.size());
  return out;
}

}  // namespace

std::vector<std::size_t> dealt_units(std::size_t units, int rank, int size) {
  RAYSIFT_CHECK(size >= 1 && rank >= 0 && rank < size);
  std::vector<std::size_t> out;
  for (std::size_t u = std::size_t(rank); u < units; u += std::size_t(size)) out.push_back(u);
  return out;
}

std::vector<std::string> deal_and_gather(std::size_t units, const UnitRunner& run) {
  const std::vector<std::size_t> mine = dealt_units(units, rank(), size());
  std::vector<std::string> texts;
  all_or_none([&] {
    texts = run(mine);
    if (texts.size() != mine.size())
      throw InvalidInput("a rank's sweep units returned " + std::to_string(texts.size()) + " texts for " +
                         std::to_string(mine.size()) + " units");
  });
  const std::vector<std::vector<std::uint8_t>> all = gather(pack(texts));
  if (!is_root()) return {};
  std::vector<std::string> out(units);
  for (int r = 0; r < size(); ++r) {
    const std::vector<std::size_t> theirs = dealt_units(units, r, size());
    std::vector<std::string> got = unpack(all[std::size_t(r)], theirs.size());
    for (std::size_t i = 0; i < theirs.size(); ++i) out[theirs[i]] = std::move(got[i]);
  }
  return out;
}

}  // namespace raysift::mpi
