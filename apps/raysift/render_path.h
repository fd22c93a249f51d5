#pragma once
// `raysift render --camera-path`: a sequence rendered through sampling::run_path_request, its frames written
// one by one as they finish, then the manifest that marks the sequence complete, and the path stats.
#include "apps/raysift/command.h"
#include "apps/raysift/render_flags.h"

namespace raysift::app {

/// \throw as sampling::run_path_request, or IoError for a frame or manifest that cannot be written.
void render_path(const PathCliOptions& p, const RenderCliOptions& o, const RenderInputs& in, const CommonOptions& common);

}  // namespace raysift::app
