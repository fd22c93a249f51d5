#pragma once
/// \file The two safety flags shared by the commands that read volumes or allocate large buffers:
/// --non-finite (volume/vdb_io.h NonFinite) and --max-memory (core/memory_limit.h). Values live in CommonOptions.
#include <CLI/CLI.hpp>

#include "apps/raysift/command.h"
#include "core/memory_limit.h"
#include "volume/vdb_io.h"

namespace raysift::app {

/// Adds --non-finite error|background|clamp to a command that reads a .vdb.
void add_non_finite_flag(CLI::App& sub, CommonOptions& common);

/// Adds --max-memory SIZE to a command that checks its buffers before allocating.
void add_max_memory_flag(CLI::App& sub, CommonOptions& common);

/// The parsed --non-finite value. \throw UsageError (exit 2) for an unknown name.
volume::NonFinite non_finite_policy(const CommonOptions& common);

/// The parsed --max-memory value (bytes 0 = MemAvailable). \throw UsageError (exit 2) for a malformed size.
MemoryLimit memory_limit(const CommonOptions& common);

}  // namespace raysift::app
