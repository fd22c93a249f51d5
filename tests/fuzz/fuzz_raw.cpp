// Raw import: the first 4 bytes choose the layout (dims 1..16 each, scalar type, endianness, gzip or not, a
// tolerance), the rest is the file. Small dims keep each run fast; the size check is what is under test.
#include <cmath>

#include "tests/fuzz/fuzz_support.h"
#include "volume/import.h"

using namespace raysift;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 4) return 0;
  volume::RawLayout layout;
  layout.dims = Vec3i{data[0] % 16 + 1, data[1] % 16 + 1, data[2] % 16 + 1};
  layout.type = volume::ScalarType(data[3] % 8);
  layout.endian = data[3] & 8 ? volume::Endian::Big : volume::Endian::Little;
  volume::ImportOptions options;
  options.tolerance = data[3] & 32 ? 0.5f : 0.0f;
  const std::string path = fuzz::write_scratch(data[3] & 16 ? "in.raw.gz" : "in.raw", data + 4, size - 4);
  fuzz::parse_or_reject([&] {
    const volume::GridInfo info = volume::import_raw(path, layout, options).info();
    fuzz::require(std::isfinite(info.value_min) && std::isfinite(info.value_max), "imported values finite");
    fuzz::require(info.active_voxels <= std::uint64_t(layout.dims.x) * layout.dims.y * layout.dims.z,
                  "no more active voxels than the dims hold");
  });
  return 0;
}
