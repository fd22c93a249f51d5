#pragma once
/// \file The page `raysift serve` answers HTTP with: every file under web/, compiled into the binary at build time
/// (server/embed_web.cmake), and the one rule that maps a request target to one of them.
#include <string>
#include <string_view>
#include <vector>

namespace raysift::server {

struct EmbeddedFile {
  std::string_view path;  ///< relative to web/, '/'-separated, e.g. "index.html"
  std::string_view data;  ///< the file's bytes
};

/// All embedded files, sorted by path.
const std::vector<EmbeddedFile>& embedded_files();

/// The file a GET of `target` (the request-target: path, optional "?query") serves: "/" is index.html; the
/// path is percent-decoded once, and a path with an empty, "." or ".." segment, a backslash or a NUL byte, a
/// bad %-escape, or no exact match among the embedded files gives null (404).
const EmbeddedFile* find_embedded_file(std::string_view target);

/// The Content-Type for a file name by its extension (application/octet-stream when unknown).
std::string content_type(std::string_view path);

namespace detail {
const std::vector<EmbeddedFile>& generated_files();  ///< the build-time table (embed_web.cmake)
}  // namespace detail

}  // namespace raysift::server
