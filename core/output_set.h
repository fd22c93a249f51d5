#pragma once
/// \file All-or-nothing output of a command that writes several files. Each file is first written to a hidden
/// temporary sibling (same folder, same extension, so format detection and the final rename stay on one file
/// system); commit() renames them all into place. Until then no target is touched, and a failure or a signal
/// (the exception unwinding through the destructor) removes every temporary file and every folder the set
/// created. The renames themselves are not one atomic step: a rename that fails at commit (rare: all checks
/// are done when a file is staged) leaves the earlier ones in place and says which.
#include <string>
#include <vector>

namespace raysift {

/// \warning Not thread-safe; one set per command.
class OutputSet {
 public:
  OutputSet() = default;
  /// Removes whatever was staged and not committed.
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  /// Reserves `path` and returns the temporary name to write it to (any writer, e.g. write_image).
  /// \throw IoError if `path` is a directory, its folder does not exist, or it was staged already.
  std::string stage(const std::string& path);

  /// create_directories(dir), remembering what it created so that a failed command removes it again.
  void make_directories(const std::string& dir);

  /// Moves every staged file into place, in staging order.
  /// \throw Cancelled if a SIGINT/SIGTERM arrived (nothing is moved); IoError if a staged file is missing
  ///        (its writer did not write it) or a rename fails.
  void commit();

 private:
  struct Entry {
    std::string target, temp;
  };
  std::vector<Entry> entries_;
  std::vector<std::string> created_dirs_;  ///< outermost first
  bool committed_ = false;
};

/// The hidden temporary sibling of `path` (".stem.tmp<pid>_<n>.ext"), unique within the process.
/// \throw IoError if `path` is a directory or its folder does not exist.
std::string temporary_sibling(const std::string& path);

}  // namespace raysift
