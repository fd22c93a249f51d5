#pragma once
// Flag texts shared by the commands that render sampled frames (render, sweep).
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace raysift::app {

/// Adds --alpha (six comma-separated finite numbers a00,a10,a01,a11,a20,a02) into `alpha`; its help shows the
/// default taken from sampling::PriorityMapping{} (never a hand-copied string).
void add_alpha_option(CLI::App& app, std::vector<float>& alpha, const std::string& help_prefix = "");

/// Splits a --features list into the line-class list and the image-space feature: removes the entry
/// "saliency" (setting `has_saliency`) and returns the rest, "none" when nothing is left.
std::string split_saliency_feature(const std::string& list, bool& has_saliency);

}  // namespace raysift::app
