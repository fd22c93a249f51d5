#pragma once
// Flag texts shared by the commands that render sampled frames (render, sweep).
#include <string>

namespace raysift::app {

/// The --alpha help text with the default taken from sampling::PriorityMapping{} (never a hand-copied string).
std::string alpha_flag_help();

}  // namespace raysift::app
