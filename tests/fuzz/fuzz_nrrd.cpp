// NRRD: an input with the line "#--data--" is split there into a detached header (in.nhdr) and its data file
// (data.raw, which the corpus headers name); any other input is an attached-data .nrrd.
#include <cmath>

#include "tests/fuzz/fuzz_support.h"
#include "volume/import.h"

using namespace raysift;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const std::string marker = "\n#--data--\n";
  const std::size_t split = bytes.find(marker);
  std::string path;
  if (split == std::string::npos) {
    path = fuzz::write_scratch("in.nrrd", bytes);
  } else {
    path = fuzz::write_scratch("in.nhdr", bytes.substr(0, split + 1));
    fuzz::write_scratch("data.raw", bytes.substr(split + marker.size()));
  }
  fuzz::parse_or_reject([&] {
    const volume::GridInfo info = volume::import_nrrd(path).info();
    fuzz::require(std::isfinite(info.value_min) && std::isfinite(info.value_max), "imported values finite");
    fuzz::require(info.voxel_size.x > 0 && info.voxel_size.y > 0 && info.voxel_size.z > 0, "positive voxel size");
  });
  return 0;
}
