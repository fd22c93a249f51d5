#include "tests/fuzz/fuzz_support.h"

#include <stdlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

namespace raysift::fuzz {
namespace {
// One directory per process (libFuzzer -jobs/-fork run several), removed when the process exits normally.
struct ScratchDir {
  std::filesystem::path path;
  ScratchDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "raysift_fuzz_XXXXXX").string();
    if (!mkdtemp(pattern.data())) std::abort();
    path = pattern;
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};
}  // namespace

std::string write_scratch(const std::string& name, const std::uint8_t* data, std::size_t size) {
  static ScratchDir dir;
  const std::string path = (dir.path / name).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  if (!out) std::abort();
  return path;
}

std::string write_scratch(const std::string& name, const std::string& bytes) {
  return write_scratch(name, reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
}

void require(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "fuzz contract violated: %s\n", what);
  std::abort();
}

}  // namespace raysift::fuzz
