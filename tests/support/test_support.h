#pragma once
/// \file Helpers shared by the test executables.
#include <string>
#include <vector>

namespace raysift::test {

/// A fresh, empty temporary directory for one test (removed by the OS; tests may leave files).
std::string make_temp_dir(const std::string& tag);

/// Whole file as a string ("" if it cannot be read).
std::string read_text(const std::string& path);

/// Exit code and captured output of one command-line run.
struct CliRun {
  int code = -1;  ///< exit code, -1 if the process did not exit normally
  std::string out, err;
};

/// Runs `exe args` through the shell inside `dir`; stdout and stderr go to stdout<tag>.txt and stderr<tag>.txt
/// there (use distinct tags for runs in parallel in the same dir) and are returned.
CliRun run_cli(const std::string& exe, const std::string& dir, const std::string& args, const std::string& tag = "");

/// Runs independent invocations concurrently (process start-up, hundreds of shared libraries, dominates a CLI
/// test); run i uses tag std::to_string(i). Results are in the order of `args`.
std::vector<CliRun> run_cli_all(const std::string& exe, const std::string& dir, const std::vector<std::string>& args);

}  // namespace raysift::test
