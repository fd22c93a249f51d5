#pragma once
// `raysift lines`' flags and what they map to: the options struct, the flag registration (CLI11 validators,
// defaults from features::LinesPipelineOptions), the pipeline options they give, and the mesh, camera and
// volume box taken from MESH_OR_SCENE, --scene and --camera.
#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "apps/raysift/command.h"
#include "core/camera.h"
#include "features/lines_pipeline.h"

namespace raysift::app {

struct LinesCliOptions {
  std::string input;  ///< mesh (.ply/.obj/.off) or scene (.json)
  std::string camera_path;
  std::string features = "all";
  std::string out, svg, importance;
  int width = 0, height = 0;            ///< 0 = from the camera (default camera: CameraSpec's default size)
  std::vector<std::string> priorities;  ///< "class=value" overrides
  features::LinesPipelineOptions lib;
};

void add_lines_options(CLI::App& sub, LinesCliOptions& o);

/// o.lib with the parsed --features and --priority, the thread switch and whether the importance is wanted.
features::LinesPipelineOptions lines_pipeline_options(const LinesCliOptions& o, const CommonOptions& common);

/// The mesh path, the camera and the volume box from MESH_OR_SCENE, --scene and --camera.
struct LinesInputs {
  std::string mesh_path;
  std::optional<CameraSpec> camera;
  std::optional<Bbox3d> volume_box;  ///< the scene volume's voxels, importance non-background like the mesh
};

/// \throw UsageError without a mesh; IoError/InvalidInput naming the scene or camera file at fault.
LinesInputs resolve_lines_inputs(const LinesCliOptions& o, const CommonOptions& common);

}  // namespace raysift::app
