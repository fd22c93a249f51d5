#pragma once
/// \file Scene JSON: {"volume", "grid", "transfer_function", "camera", "light"}. The last three may each
/// be a path (relative to the scene file) or an inline object. Every subcommand takes `--scene`;
/// command-line flags override its fields.
#include <optional>
#include <string>

#include "core/camera.h"
#include "core/json_io.h"

namespace raysift {

struct Scene {
  std::string source;             ///< the scene file ("" when built from flags only)
  std::string volume;             ///< volume path, resolved relative to the scene file
  std::string grid;               ///< grid name ("" = first float grid)
  Json transfer_function;         ///< null when absent; parsed by volume/transfer_function
  std::string transfer_function_source;  ///< file the TF came from, for messages
  std::optional<CameraSpec> camera;
  std::string mesh;               ///< triangle mesh path (mesh-based commands), resolved like volume
  Json light;                     ///< null when absent; parsed by nrr/ (area light)
  std::string light_source;
};

/// \throw IoError / InvalidInput naming the scene file (or the referenced file) and the key.
Scene load_scene(const std::string& path);

}  // namespace raysift
