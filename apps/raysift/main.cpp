// raysift: one program, many subcommands (see README "CLI reference").
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <csignal>
#include <iostream>
#include <utility>

#include "apps/raysift/command.h"
#include "core/errors.h"
#include "core/signals.h"

namespace raysift::app {

std::vector<CommandEntry>& command_registry() {
  static std::vector<CommandEntry> registry;
  return registry;
}

void write_stats_if_requested(const CommonOptions& common, const Json& stats) {
  if (!common.stats_path.empty()) write_json_file(common.stats_path, stats);
}

void bad_flag(const std::string& flag, const std::string& range, const std::string& got) {
  throw UsageError(flag + " must be " + range + ", got " + got + "; see --help");
}

}  // namespace raysift::app

int main(int argc, char** argv) {
  using namespace raysift;
  using namespace raysift::app;
  CLI::App cli{"raysift: prioritized volume ray casting and non-redundant scene discretization"};
  cli.set_version_flag("--version", std::string("raysift ") + RAYSIFT_VERSION);
  cli.require_subcommand(0, 1);
  CommonOptions common;
  std::vector<std::pair<CLI::App*, RunFunction>> runners;

  auto& registry = command_registry();
  std::sort(registry.begin(), registry.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  for (const CommandEntry& entry : registry) {
    CLI::App* sub = cli.add_subcommand(entry.name, entry.description);
    sub->add_option("--threads", common.threads, "worker threads (0 = all cores, 1 = serial)")
        ->check(CLI::NonNegativeNumber)->capture_default_str();
    sub->add_option("--seed", common.seed, "random seed")->capture_default_str();
    sub->add_flag("-v,--verbose", common.verbose, "print per-stage timings");
    sub->add_flag("--quiet", common.quiet, "print nothing but errors");
    sub->add_option("--stats", common.stats_path, "write timings and counts as JSON to FILE");
    if (entry.takes_scene) sub->add_option("--scene", common.scene_path, "scene JSON (flags override its fields)");
    runners.emplace_back(sub, entry.setup(*sub, common));
  }
  CLI::App* help = cli.add_subcommand("help", "list the subcommands");

  try {
    cli.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return cli.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return cli.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return cli.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "raysift: error: " << e.what() << "; see --help\n";
    return 2;
  }
  RunFunction run;
  for (auto& [sub, runner] : runners)
    if (sub->parsed()) run = runner;
  if (help->parsed() || !run) {
    std::cout << cli.help();
    return help->parsed() ? 0 : 2;
  }
  try {
    const int threads = common.threads > 0 ? common.threads : tbb::this_task_arena::max_concurrency();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    install_cancel_handlers();
    run();
    return 0;
  } catch (const std::exception& e) {
    if (cancel_signal() == 0) {
      std::cerr << "raysift: error: " << e.what() << "\n";
      return dynamic_cast<const UsageError*>(&e) ? 2 : 1;
    }
  }
  // Whatever a signal interrupted failed as a consequence; the staged outputs are gone by now.
  std::cerr << "raysift: interrupted by " << (cancel_signal() == SIGTERM ? "SIGTERM" : "SIGINT")
            << "; no output written\n";
  return 128 + cancel_signal();
}
