#pragma once
/// \file CLI11 validators the subcommands share, so every range and choice is checked by CLI11 while
/// parsing (exit 2 naming the flag) and shown in --help next to the flag's default.
#include <CLI/CLI.hpp>
#include <map>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "core/camera.h"

namespace raysift::app {

/// An image side in pixels: 1..kMaxImageSide.
inline CLI::Range image_side() { return CLI::Range(1, kMaxImageSide); }

/// Whether an interval end belongs to it.
enum class End { Closed, Open };

/// A finite number in [lo, hi] (either end open on request); NaN never passes, and hi = INFINITY means
/// unbounded. Applied to each entry of a list option.
CLI::Validator number_in(double lo, double hi, End lo_end = End::Closed, End hi_end = End::Closed);

/// A path ending in one of `extensions` (e.g. {".exr", ".png"}).
CLI::Validator has_extension(const std::vector<std::string>& extensions);

/// "x,y,z" as three finite numbers (spaces allowed around them); nullopt for anything else.
std::optional<Vec3d> parse_vec3(const std::string& text);

/// An entry "x,y,z" of three finite numbers, for lists of points split at another delimiter (e.g. ';').
CLI::Validator vec3_text();

/// Adds `flag` choosing one of `names` into the enum `value`: an unknown name exits 2 listing the names, and
/// --help shows the names and the name of `value`'s initial value as the default.
template <typename E>
CLI::Option* add_choice(CLI::App& app, const std::string& flag, E& value, const std::map<std::string, E>& names,
                        const std::string& help) {
  std::string listed, current;
  for (const auto& [name, v] : names) {
    listed += (listed.empty() ? "" : "|") + name;
    if (v == value) current = name;
  }
  CLI::Validator to_value(
      [names, listed](std::string& text) -> std::string {
        const auto it = names.find(text);
        if (it == names.end()) return "must be one of " + listed + ", got '" + text + "'";
        text = std::to_string(static_cast<std::underlying_type_t<E>>(it->second));
        return "";
      },
      listed, "choice");
  return app.add_option(flag, value, help)->transform(to_value)->default_str(current);
}

}  // namespace raysift::app
