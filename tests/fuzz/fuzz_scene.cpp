// Scene JSON: the file itself, then each part the commands go on to parse (TF, camera, light), as the apps do.
#include "core/camera.h"
#include "core/scene.h"
#include "nrr/area_light.h"
#include "tests/fuzz/fuzz_support.h"
#include "volume/transfer_function.h"

using namespace raysift;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::write_scratch("scene.json", data, size);
  fuzz::parse_or_reject([&] {
    const Scene scene = load_scene(path);
    if (!scene.transfer_function.is_null())
      fuzz::parse_or_reject([&] {
        volume::transfer_function_from_json(scene.transfer_function, scene.transfer_function_source);
      });
    if (scene.camera) fuzz::parse_or_reject([&] { Camera cam(*scene.camera); });
    if (!scene.light.is_null())
      fuzz::parse_or_reject([&] { nrr::area_light_from_json(scene.light, scene.light_source); });
  });
  return 0;
}
