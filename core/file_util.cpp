#include "core/file_util.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "core/output_set.h"
#include "core/signals.h"

namespace fs = std::filesystem;

namespace raysift {

std::string file_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

void require_readable_file(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw IoError(file_message(path, "no such file"));
  if (fs::is_directory(path, ec)) throw IoError(file_message(path, "is a directory, expected a file"));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(file_message(path, "cannot be opened for reading (check permissions)"));
}

std::string read_file_bytes(const std::string& path) {
  require_readable_file(path);
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw IoError(file_message(path, "read error"));
  return s.str();
}

void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write) {
  const std::string tmp = temporary_sibling(path);
  std::error_code ec;
  try {
    write(tmp);
    throw_if_cancelled();  // a command stopped by a signal moves nothing into place
    fs::rename(tmp, path, ec);
    if (ec) throw IoError(file_message(path, "cannot move finished output into place: " + ec.message()));
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

void write_text_file(const std::string& path, const std::string& text) {
  write_atomically(path, [&](const std::string& tmp) {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw IoError(file_message(path, "cannot open for writing"));
    const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    if (std::fclose(f) != 0 || !ok) throw IoError(file_message(path, "write failed"));
  });
}

}  // namespace raysift
