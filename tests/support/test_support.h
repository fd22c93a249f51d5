#pragma once
/// \file Helpers shared by the test executables.
#include <string>

namespace raysift::test {

/// A fresh, empty temporary directory for one test (removed by the OS; tests may leave files).
std::string make_temp_dir(const std::string& tag);

}  // namespace raysift::test
