#pragma once
/// \file Safe file output: write to a temporary name beside the target, then rename, so a failure
/// never leaves a partial output file.
#include <functional>
#include <string>

namespace raysift {

/// Calls `write(tmp_path)` where tmp_path keeps the target's extension (format detection), then
/// renames it to `path`. On any exception the temporary file is removed and the exception rethrown.
/// For several files that must appear together use OutputSet (core/output_set.h).
/// \throw Cancelled if a SIGINT/SIGTERM arrived before the rename (core/signals.h); IoError if `path` is a directory, its parent folder does not exist, or the rename fails.
void write_atomically(const std::string& path, const std::function<void(const std::string& tmp_path)>& write);

/// Writes `text` to `path` atomically (write_atomically). \throw IoError naming the file, or as write_atomically.
void write_text_file(const std::string& path, const std::string& text);

/// \throw IoError naming the file if it is missing, a directory or unreadable.
void require_readable_file(const std::string& path);

/// Lower-case extension including the dot (".png"), or "" if none.
std::string file_extension(const std::string& path);

/// Reads a whole file into memory. \throw IoError naming the file.
std::string read_file_bytes(const std::string& path);

}  // namespace raysift
