#pragma once
/// \file What every binding file shares: JSON <-> Python, capsule-owned NumPy arrays, and running raysift with the
/// GIL released while Ctrl-C stays live (docs/python.md "Conventions").
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // every file: the same std::vector/optional casters everywhere

#include <array>
#include <atomic>
#include <optional>
#include <type_traits>
#include <memory>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/image.h"
#include "core/json_io.h"

namespace raysift::py {

namespace pyb = pybind11;

/// nlohmann JSON -> the dict/list/str/int/float/bool/None json.loads would give.
pyb::object to_python(const Json& json);

/// A NumPy array of `shape` over `data`, owned by the heap object `owner` through a capsule (no copy): the
/// array's .base keeps `owner` alive after every raysift object is gone.
template <typename T, typename Owner>
pyb::array_t<T> owning_array(std::unique_ptr<Owner> owner, const T* data, std::vector<pyb::ssize_t> shape) {
  Owner* raw = owner.release();
  pyb::capsule base(raw, [](void* p) { delete static_cast<Owner*>(p); });
  return pyb::array_t<T>(shape, data, base);
}

/// (H, W, 4) float32 over the image's own buffer (row 0 at the top).
pyb::array_t<float> image_array(ImageRGBA&& image);

/// A vector's buffer moved into an array without a copy.
template <typename T>
pyb::array_t<T> vector_array(std::vector<T>&& values, std::vector<pyb::ssize_t> shape) {
  auto owner = std::make_unique<std::vector<T>>(std::move(values));
  const T* data = owner->data();
  return owning_array(std::move(owner), data, std::move(shape));
}

/// While at least one exists, SIGINT sets `flag()` (the stages poll it and throw Cancelled) and is then passed on to
/// the handler it replaced (Python's: it raises KeyboardInterrupt at the next check; SIG_DFL: the process ends).
/// [choice] Not core/signals' flag: that one never resets (right for a process that exits) and its handler would
/// take SIGINT from Python for good. Not a helper thread polling PyErr_CheckSignals either: handing the result
/// back to a sleeping thread cost 2-3 ms per call on the loaded 2-core machine.
class InterruptScope {
 public:
  InterruptScope();
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;
  static const std::atomic<bool>& flag();
};

/// Runs `work(cancel)` on the calling thread with the GIL released (other Python threads keep running). A Ctrl-C
/// during it stops the work and raises KeyboardInterrupt (through Python's own handler) when it returns; C++
/// exceptions of the work propagate to the translators.
template <typename Work>
auto run_released(Work&& work) {
  using Result = decltype(work(InterruptScope::flag()));
  std::optional<InterruptScope> scope(std::in_place);
  auto finish = [&scope] {
    scope.reset();
    if (PyErr_CheckSignals() != 0) throw pyb::error_already_set();  // KeyboardInterrupt, or the user's handler
  };
  try {
    if constexpr (std::is_void_v<Result>) {
      {
        pyb::gil_scoped_release release;
        work(InterruptScope::flag());
      }
      finish();
    } else {
      std::optional<Result> result;
      {
        pyb::gil_scoped_release release;
        result.emplace(work(InterruptScope::flag()));
      }
      finish();
      return std::move(*result);
    }
  } catch (const Cancelled&) {
    finish();
    throw;
  }
}

/// (3,) floats from a sequence. \throw TypeError naming `what`.
std::array<double, 3> triple(const pyb::handle& value, const char* what);

}  // namespace raysift::py
