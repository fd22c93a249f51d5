#pragma once
/// \file Error types shared by every module. Library code throws these; only apps print and exit.
#include <sstream>
#include <stdexcept>
#include <string>

namespace raysift {

/// Bad user input (a file's content, a parameter value). The message names the file and the problem.
struct InvalidInput : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

/// A command-line usage error (bad flag value or combination); apps exit with code 2.
struct UsageError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

/// Reading or writing a file failed (missing, unreadable, truncated, wrong format).
struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A numerical stage failed (no convergence, NaN after a solve).
struct SolverError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A stage would need more memory than the limit allows (core/memory_limit.h); checked before allocating.
struct ResourceError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The caller asked a long stage to stop (its cancel flag was set); nothing was produced.
struct Cancelled : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// "path: message", the form every file-related error takes.
inline std::string file_message(const std::string& path, const std::string& message) {
  return path + ": " + message;
}

namespace detail {
[[noreturn]] void check_failed(const char* expr, const char* file, int line, const std::string& values);
template <typename A, typename B>
std::string format_operands(const A& a, const B& b) {
  std::ostringstream s;
  s << " (" << a << " vs " << b << ")";
  return s.str();
}
}  // namespace detail
}  // namespace raysift

/// Internal invariant, always checked (cheap): a failure is a bug, not bad input.
#define RAYSIFT_CHECK(cond) \
  do { if (!(cond)) ::raysift::detail::check_failed(#cond, __FILE__, __LINE__, {}); } while (0)
#define RAYSIFT_CHECK_OP(a, op, b)                                                        \
  do {                                                                                    \
    if (!((a)op(b)))                                                                      \
      ::raysift::detail::check_failed(#a " " #op " " #b, __FILE__, __LINE__,              \
                                      ::raysift::detail::format_operands((a), (b)));      \
  } while (0)
#ifndef NDEBUG
#define RAYSIFT_DCHECK(cond) RAYSIFT_CHECK(cond)
#else
#define RAYSIFT_DCHECK(cond) do { (void)sizeof(cond); } while (0)
#endif
