#pragma once
/// \file Shared by the libFuzzer targets: a per-process scratch directory for parsers that take a path, and the
/// rule every target enforces: a parser either returns a valid value or throws one of its documented error types
/// (InvalidInput, IoError). Anything else (another exception, a crash, a sanitizer report, a leak) is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

namespace raysift::fuzz {

/// Writes `size` bytes to `name` inside this process's scratch directory and returns the full path.
std::string write_scratch(const std::string& name, const std::uint8_t* data, std::size_t size);
std::string write_scratch(const std::string& name, const std::string& bytes);

/// Runs `parse`; swallows only the documented error types.
template <typename F>
void parse_or_reject(F&& parse);

/// Aborts (a libFuzzer crash with the message) when `ok` is false: a returned value broke its contract.
void require(bool ok, const char* what);

}  // namespace raysift::fuzz

#include "core/errors.h"

template <typename F>
void raysift::fuzz::parse_or_reject(F&& parse) {
  try {
    parse();
  } catch (const raysift::InvalidInput&) {
  } catch (const raysift::IoError&) {
  }
}
