#pragma once
/// \file What every binding file shares: JSON <-> Python, capsule-owned NumPy arrays, and running raysift with the
/// GIL released while Ctrl-C stays live (docs/python.md "Behaviour").
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // every file: the same std::vector/optional casters everywhere

#include <array>
#include <atomic>
#include <chrono>
#include <future>
#include <memory>
#include <string>
#include <vector>

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

/// A 1-D vector's buffer moved into an array without a copy.
template <typename T>
pyb::array_t<T> vector_array(std::vector<T>&& values, std::vector<pyb::ssize_t> shape) {
  auto owner = std::make_unique<std::vector<T>>(std::move(values));
  const T* data = owner->data();
  return owning_array(std::move(owner), data, std::move(shape));
}

/// Python threads keep running while `work(cancel)` computes on a helper thread; the calling thread wakes every
/// 50 ms to let Python see signals. On Ctrl-C it sets `cancel` (the stages poll it and throw Cancelled), waits for
/// the work to unwind and raises KeyboardInterrupt; C++ exceptions of the work propagate to the translators.
template <typename Work>
auto run_released(Work&& work) -> decltype(work(std::declval<const std::atomic<bool>&>())) {
  std::atomic<bool> cancel{false};
  PyObject *type = nullptr, *value = nullptr, *trace = nullptr;
  auto done = std::async(std::launch::async, [&] { return work(cancel); });
  {
    pyb::gil_scoped_release release;
    while (done.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
      pyb::gil_scoped_acquire gil;
      if (!type && PyErr_CheckSignals() != 0) {
        PyErr_Fetch(&type, &value, &trace);
        cancel = true;
      }
    }
  }
  if (type) {
    PyErr_Restore(type, value, trace);
    throw pyb::error_already_set();
  }
  return done.get();
}

/// (3,) floats from a sequence. \throw TypeError naming `what`.
std::array<double, 3> triple(const pyb::handle& value, const char* what);

}  // namespace raysift::py
