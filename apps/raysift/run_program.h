#pragma once
// Runs a helper program (e.g. a plotting script) with an argument vector: no shell, so paths need no quoting.
#include <string>
#include <vector>

namespace raysift::app {

/// Runs argv[0] with argv, waits, and returns its exit code (127 if it could not be started).
int run_program(const std::vector<std::string>& argv);

}  // namespace raysift::app
