#pragma once
/// \file Subcommand registry. Each cmd_*.cpp registers itself with a static RegisterCommand, so adding
/// a subcommand touches no shared file. A command's `setup` adds its options to the CLI11 subcommand
/// and returns the function that runs it (after parsing succeeded).
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "core/json_io.h"

namespace raysift::app {

/// Flags every subcommand shares (STYLE.md §10).
struct CommonOptions {
  int threads = 0;            ///< 0 = all cores, 1 = serial
  std::uint64_t seed = 1;
  bool verbose = false;
  bool quiet = false;
  std::string stats_path;     ///< --stats FILE: JSON with timings and counts
  std::string scene_path;     ///< --scene FILE
  std::string max_memory;     ///< --max-memory SIZE (guard_flags.h); "" = MemAvailable
  std::string non_finite = "error";  ///< --non-finite error|background|clamp (guard_flags.h)
};

using RunFunction = std::function<void()>;
using SetupFunction = std::function<RunFunction(CLI::App& sub, CommonOptions& common)>;

struct CommandEntry {
  std::string name;
  std::string description;
  SetupFunction setup;
  bool takes_scene = true;
};

std::vector<CommandEntry>& command_registry();

struct RegisterCommand {
  RegisterCommand(std::string name, std::string description, SetupFunction setup, bool takes_scene = true) {
    command_registry().push_back({std::move(name), std::move(description), std::move(setup), takes_scene});
  }
};

/// Writes `stats` to common.stats_path if given (atomically).
void write_stats_if_requested(const CommonOptions& common, const Json& stats);

/// Message for a flag value outside its range: "--flag must be RANGE, got VALUE; see --help" (exit 2).
[[noreturn]] void bad_flag(const std::string& flag, const std::string& range, const std::string& got);

}  // namespace raysift::app
