// Area-light JSON (a scene's "light" entry, or --light FILE) and the samples drawn from it.
#include <cmath>

#include "core/json_io.h"
#include "nrr/area_light.h"
#include "tests/fuzz/fuzz_support.h"

using namespace raysift;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::write_scratch("light.json", data, size);
  fuzz::parse_or_reject([&] {
    const nrr::AreaLight light = nrr::area_light_from_json(read_json_file(path), path);
    for (const Vec3d& s : nrr::light_samples(light, 3))
      fuzz::require(std::isfinite(s.x) && std::isfinite(s.y) && std::isfinite(s.z), "light sample finite");
    const Vec3d n = light.normal();
    fuzz::require(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z), "light normal finite");
    nrr::rescale_light(light, 2.0);
  });
  return 0;
}
