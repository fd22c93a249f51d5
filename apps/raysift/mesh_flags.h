#pragma once
// `raysift mesh`'s flags and what they map to: the options struct, the flag registration (CLI11 validators,
// defaults from the mesh/ and volume/ option structs), the pipeline options they give, and the re-runnable
// command line of verbose mode.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "apps/raysift/command.h"
#include "apps/raysift/volume_input.h"
#include "isosurface/pipeline.h"

namespace raysift::app {

struct MeshCliOptions {
  VolumeFlags input;        ///< VOLUME, --grid, --tf, --tf-normalized
  std::string out;
  std::vector<double> iso;  ///< empty = the TF chooses
  int max_surfaces = volume::IsoValueOptions{}.max_surfaces;
  mesh::SmoothingOptions smoothing;  ///< --smooth, --lambda, --mu; before and after decimation alike
  bool cotangent = false;
  double decimate = mesh::DecimationOptions{}.ratio;
  long long faces = 0;
  double max_error = 0;
  bool flip = false;
  bool unguarded = false;
};

void add_mesh_options(CLI::App& sub, MeshCliOptions& o);

/// The pipeline options of the flags (iso-values are added by the caller, once checked against the data).
/// \throw UsageError for --mu not below -lambda, the one cross-flag rule CLI11's validators cannot state.
isosurface::PipelineOptions mesh_pipeline_options(const MeshCliOptions& o);

/// The effective options as a re-runnable command line (verbose mode).
std::string mesh_echo_command(const MeshCliOptions& o, const std::vector<double>& iso_values,
                              const CommonOptions& common);

}  // namespace raysift::app
