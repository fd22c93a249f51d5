#include "core/output_set.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>

#include "core/errors.h"
#include "core/signals.h"

namespace fs = std::filesystem;

namespace raysift {

std::string temporary_sibling(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const fs::path target(path);
  std::error_code ec;
  if (target.filename().empty() || fs::is_directory(target, ec))
    throw IoError(file_message(path, "is a directory, expected an output file name"));
  const fs::path parent = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(parent, ec))
    throw IoError(file_message(path, "output folder '" + parent.string() + "' does not exist"));
  return (parent / ("." + target.stem().string() + ".tmp" + std::to_string(::getpid()) + "_" +
                    std::to_string(counter++) + target.extension().string()))
      .string();
}

OutputSet::~OutputSet() {
  if (committed_) return;
  std::error_code ec;
  for (const Entry& e : entries_) fs::remove(e.temp, ec);
  // Innermost first; only folders left empty (a folder that now holds someone else's file stays).
  for (auto dir = created_dirs_.rbegin(); dir != created_dirs_.rend(); ++dir) fs::remove(*dir, ec);
}

std::string OutputSet::stage(const std::string& path) {
  const fs::path target = fs::absolute(path).lexically_normal();
  for (const Entry& e : entries_)
    if (fs::absolute(e.target).lexically_normal() == target)
      throw IoError(file_message(path, "is the target of two outputs of the same command"));
  entries_.push_back({path, temporary_sibling(path)});
  return entries_.back().temp;
}

void OutputSet::make_directories(const std::string& dir) {
  std::vector<std::string> missing;
  std::error_code ec;
  for (fs::path p = fs::absolute(dir).lexically_normal(); !p.empty() && !fs::exists(p, ec); p = p.parent_path())
    missing.push_back(p.string());
  fs::create_directories(dir, ec);
  if (ec) throw IoError(file_message(dir, "cannot create the output folder: " + ec.message()));
  created_dirs_.insert(created_dirs_.end(), missing.rbegin(), missing.rend());
}

void OutputSet::commit() {
  throw_if_cancelled();
  std::error_code ec;
  for (const Entry& e : entries_)
    if (!fs::is_regular_file(e.temp, ec))
      throw IoError(file_message(e.target, "was staged but never written (internal error)"));
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    fs::rename(entries_[i].temp, entries_[i].target, ec);
    if (ec) {
      std::string done;
      for (std::size_t j = 0; j < i; ++j) done += " " + entries_[j].target;
      entries_.erase(entries_.begin(), entries_.begin() + std::ptrdiff_t(i));  // the destructor removes the rest
      throw IoError(file_message(entries_.front().target, "cannot move the finished output into place (" +
                                                               ec.message() + ")" +
                                                               (done.empty() ? "" : "; already written:" + done)));
    }
  }
  committed_ = true;
}

}  // namespace raysift
