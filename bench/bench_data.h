#pragma once
// Where the benches find their data, relative to the repository: the bundled datasets/ folder, and the real data
// that is not bundled: $RAYSIFT_SHARED_DATASETS if set, else the shared folder beside the repository
// (../shared/datasets). Benches that use such data skip it when absent, or take paths as arguments.
#include <cstdlib>
#include <string>

namespace raysift::bench {

/// The bundled datasets/ folder, with a trailing slash.
inline std::string bundled_datasets_dir() { return std::string(RAYSIFT_SOURCE_DIR) + "/datasets/"; }
inline std::string bundled_dataset(const std::string& file) { return bundled_datasets_dir() + file; }

/// The shared (not bundled) datasets folder, with a trailing slash.
inline std::string shared_datasets_dir() {
  const char* dir = std::getenv("RAYSIFT_SHARED_DATASETS");
  return (dir && *dir ? std::string(dir) : std::string(RAYSIFT_SOURCE_DIR) + "/../shared/datasets") + "/";
}
inline std::string shared_dataset(const std::string& file) { return shared_datasets_dir() + file; }

}  // namespace raysift::bench
