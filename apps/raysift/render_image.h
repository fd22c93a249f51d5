#pragma once
// `raysift render --distribute image` under mpirun (mpi/image_parallel.h): every rank loads the whole volume and
// traces part of the frame; rank 0 writes the image and the stats (with "distribute": "image" and "ranks").
#include "apps/raysift/command.h"
#include "apps/raysift/render_flags.h"

namespace raysift::app {

/// Collective: every rank calls it with the same flags. \throw as build_inputs, or InvalidInput for --progressive.
void render_image_parallel(const RenderCliOptions& o, const CommonOptions& common);

}  // namespace raysift::app
