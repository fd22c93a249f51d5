#include "tests/support/test_support.h"

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>

namespace raysift::test {

std::string make_temp_dir(const std::string& tag) {
  static std::atomic<int> counter{0};
  const auto dir = std::filesystem::temp_directory_path() /
                   ("raysift_test_" + tag + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

CliRun run_cli(const std::string& exe, const std::string& dir, const std::string& args, const std::string& tag) {
  const std::string out = "stdout" + tag + ".txt", err = "stderr" + tag + ".txt";
  const std::string cmd = "cd '" + dir + "' && '" + exe + "' " + args + " >" + out + " 2>" + err + " </dev/null";
  const int status = std::system(cmd.c_str());
  CliRun r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_text(dir + "/" + out);
  r.err = read_text(dir + "/" + err);
  return r;
}

std::vector<CliRun> run_cli_all(const std::string& exe, const std::string& dir, const std::vector<std::string>& args) {
  std::vector<std::future<CliRun>> jobs;
  for (std::size_t i = 0; i < args.size(); ++i)
    jobs.push_back(std::async(std::launch::async, [&, i] { return run_cli(exe, dir, args[i], std::to_string(i)); }));
  std::vector<CliRun> runs;
  for (auto& job : jobs) runs.push_back(job.get());
  return runs;
}

}  // namespace raysift::test
