// Camera JSON as a scene's "camera" entry is read: the object, then the validated Camera and its rays.
#include <cmath>

#include "core/camera.h"
#include "core/json_io.h"
#include "tests/fuzz/fuzz_support.h"

using namespace raysift;

namespace {
bool finite(const Vec3d& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void check(const Camera& cam) {
  for (double fx : {0.0, 0.5, 1.0})
    for (double fy : {0.0, 0.5, 1.0}) {
      const Ray r = cam.ray(fx * cam.width(), fy * cam.height());
      fuzz::require(finite(r.origin) && finite(r.direction), "camera ray finite");
      fuzz::require(std::abs(length(r.direction) - 1) < 1e-9, "camera ray direction has unit length");
    }
  // The target, not eye + a unit step: at |eye| ~ 1e23 a unit step rounds away, while the target stays ahead.
  const auto p = cam.project(cam.spec().target);
  fuzz::require(p && std::isfinite(p->x_ss) && std::isfinite(p->y_ss), "the target projects");
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::write_scratch("camera.json", data, size);
  fuzz::parse_or_reject([&] { check(Camera(camera_spec_from_json(read_json_file(path), path))); });
  return 0;
}
