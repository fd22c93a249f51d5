#pragma once
// Where the benches find the real data that is not bundled in datasets/: $RAYSIFT_SHARED_DATASETS if set, else
// the shared folder beside the repository (../shared/datasets). Benches that use such data skip it when absent.
#include <cstdlib>
#include <string>

namespace raysift::bench {

inline std::string shared_dataset(const std::string& file) {
  const char* dir = std::getenv("RAYSIFT_SHARED_DATASETS");
  return (dir && *dir ? std::string(dir) : std::string(RAYSIFT_SOURCE_DIR) + "/../shared/datasets") + "/" + file;
}

}  // namespace raysift::bench
