// Mesh input through mesh_io; built once per format (RAYSIFT_FUZZ_MESH_EXT = ".ply", ".obj" or ".off"). A mesh that
// loads must pass the same validation every mesh stage applies at its entry.
#include "mesh/mesh_io.h"
#include "tests/fuzz/fuzz_support.h"

using namespace raysift;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::write_scratch(std::string("in") + RAYSIFT_FUZZ_MESH_EXT, data, size);
  TriMesh mesh;
  bool loaded = false;
  fuzz::parse_or_reject([&] {
    mesh = mesh::read_mesh(path);
    loaded = true;
  });
  if (!loaded) return 0;
  fuzz::require(mesh.triangle_count() > 0, "a loaded mesh has a triangle");
  try {
    mesh::validate_mesh(mesh, path);
  } catch (const InvalidInput&) {
    fuzz::require(false, "a loaded mesh passes validate_mesh");
  }
  return 0;
}
