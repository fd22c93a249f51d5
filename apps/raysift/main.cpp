// raysift: one program, many subcommands (see README "CLI reference").
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <csignal>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <utility>

#include "apps/raysift/command.h"
#include "core/errors.h"
#include "core/heap_policy.h"
#include "core/signals.h"
#include "mpi/session.h"

namespace raysift::app {

std::vector<CommandEntry>& command_registry() {
  static std::vector<CommandEntry> registry;
  return registry;
}

void write_stats_if_requested(const CommonOptions& common, const Json& stats) {
  // Rank 0 alone writes (under mpirun every rank runs the command; mpi/session.h).
  if (!common.stats_path.empty() && mpi::is_root()) write_json_file(common.stats_path, stats);
}

void bad_flag(const std::string& flag, const std::string& range, const std::string& got) {
  throw UsageError(flag + " must be " + range + ", got " + got + "; see --help");
}

namespace {

/// Levenshtein distance: the number of single-character edits from a to b.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t substitute = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
      diagonal = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitute});
    }
  }
  return row[b.size()];
}

/// "unknown command 'rendr'; did you mean 'render'?" when `word` names no command (CLI11 alone would list
/// the unexpected arguments instead); "" when it is one.
std::string unknown_command_message(const std::string& word, const std::vector<std::string>& names) {
  if (std::find(names.begin(), names.end(), word) != names.end()) return "";
  std::string nearest = names.front();
  for (const std::string& n : names)
    if (edit_distance(word, n) < edit_distance(word, nearest)) nearest = n;
  return "unknown command '" + word + "'; did you mean '" + nearest + "'? ('raysift help' lists the commands)";
}

/// One line per command: its name and the first line of its description.
std::string command_list(const CLI::App& cli) {
  std::ostringstream s;
  s << cli.get_description() << "\n\nUsage: raysift COMMAND [OPTIONS] [ARGS]\n\nCommands:\n";
  for (const CLI::App* sub : cli.get_subcommands({}))
    s << "  " << std::left << std::setw(12) << sub->get_name() << " " << sub->get_description() << "\n";
  s << "\n'raysift COMMAND --help' prints a command's options with their defaults, and examples.\n";
  return s.str();
}

}  // namespace

}  // namespace raysift::app

int main(int argc, char** argv) {
  using namespace raysift;
  using namespace raysift::app;
  keep_freed_buffers_for_reuse();  // frame-sized buffers reused, not faulted in again every frame
  const mpi::Session mpi_session(&argc, &argv);  // under mpirun: every rank runs the same command
  CLI::App cli{"raysift: prioritized volume ray casting and non-redundant scene discretization", "raysift"};
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
  CLI::App* help = cli.add_subcommand("help", "list the commands, or print one command's help");
  std::string help_topic;
  help->add_option("COMMAND", help_topic, "the command whose --help to print");

  std::vector<std::string> names;
  for (const CLI::App* sub : cli.get_subcommands({})) names.push_back(sub->get_name());
  if (argc >= 2 && argv[1][0] != '-') {
    if (const std::string unknown = unknown_command_message(argv[1], names); !unknown.empty()) {
      std::cerr << "raysift: error: " << unknown << "\n";
      return 2;
    }
  }
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
  if (help->parsed() && !help_topic.empty()) {
    if (const std::string unknown = unknown_command_message(help_topic, names); !unknown.empty()) {
      std::cerr << "raysift: error: " << unknown << "\n";
      return 2;
    }
    std::cout << cli.get_subcommand(help_topic)->help();
    return 0;
  }
  if (help->parsed() || !run) {
    (help->parsed() ? std::cout : std::cerr) << command_list(cli);
    return help->parsed() ? 0 : 2;
  }
  try {
    const int threads = common.threads > 0 ? common.threads : tbb::this_task_arena::max_concurrency();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    install_cancel_handlers();
    mpi::all_or_none(run);  // with several ranks a failure anywhere fails every rank alike (mpi/session.h)
    return 0;
  } catch (const std::exception& e) {
    if (cancel_signal() == 0) {
      const auto* agreed = dynamic_cast<const mpi::RankFailure*>(&e);
      if (mpi::is_root()) std::cerr << "raysift: error: " << e.what() << "\n";  // one message, from rank 0
      return agreed ? agreed->exit_code : dynamic_cast<const UsageError*>(&e) ? 2 : 1;
    }
  }
  // Whatever a signal interrupted failed as a consequence; the staged outputs are gone by now.
  if (mpi::is_root()) std::cerr << "raysift: interrupted by " << (cancel_signal() == SIGTERM ? "SIGTERM" : "SIGINT")
            << "; no output written\n";
  return 128 + cancel_signal();
}
