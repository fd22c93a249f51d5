// raysift._raysift: the extension behind `import raysift` (docs/python.md).
#include <csignal>
#include <mutex>

#include "core/errors.h"
#include "core/heap_policy.h"
#include "python/py_bindings.h"
#include "python/py_common.h"

namespace raysift::py {

pyb::object to_python(const Json& j) {
  switch (j.type()) {
    case Json::value_t::object: {
      pyb::dict d;
      for (const auto& [key, value] : j.items()) d[pyb::str(key)] = to_python(value);
      return std::move(d);
    }
    case Json::value_t::array: {
      pyb::list l;
      for (const Json& value : j) l.append(to_python(value));
      return std::move(l);
    }
    case Json::value_t::string: return pyb::str(j.get<std::string>());
    case Json::value_t::boolean: return pyb::bool_(j.get<bool>());
    case Json::value_t::number_integer: return pyb::int_(j.get<std::int64_t>());
    case Json::value_t::number_unsigned: return pyb::int_(j.get<std::uint64_t>());
    case Json::value_t::number_float: return pyb::float_(j.get<double>());
    default: return pyb::none();
  }
}

pyb::array_t<float> image_array(ImageRGBA&& image) {
  auto owner = std::make_unique<ImageRGBA>(std::move(image));
  const float* data = &owner->pixels.data()->r;
  const pyb::ssize_t h = owner->height, w = owner->width;
  return owning_array(std::move(owner), data, {h, w, 4});
}

std::array<double, 3> triple(const pyb::handle& value, const char* what) {
  try {
    const auto v = value.cast<std::vector<double>>();
    if (v.size() == 3) return {v[0], v[1], v[2]};
  } catch (const pyb::cast_error&) {
  }
  throw pyb::type_error(std::string(what) + " must be a sequence of 3 numbers, got " +
                        pyb::repr(value).cast<std::string>());
}

namespace {

std::mutex g_scope_mutex;
int g_scopes = 0;                    ///< InterruptScopes alive
struct sigaction g_replaced {};      ///< the SIGINT action the first scope replaced; read-only while installed
std::atomic<bool> g_interrupted{false};

extern "C" void on_interrupt(int signo, siginfo_t* info, void* context) {
  if (!(g_replaced.sa_flags & SA_SIGINFO) && g_replaced.sa_handler == SIG_IGN) return;
  g_interrupted.store(true);
  if (g_replaced.sa_flags & SA_SIGINFO) {
    g_replaced.sa_sigaction(signo, info, context);
  } else if (g_replaced.sa_handler == SIG_DFL) {
    sigaction(signo, &g_replaced, nullptr);  // the process was meant to end on Ctrl-C: let it
    raise(signo);
  } else {
    g_replaced.sa_handler(signo);
  }
}

}  // namespace

InterruptScope::InterruptScope() {
  const std::lock_guard<std::mutex> lock(g_scope_mutex);
  if (g_scopes++ > 0) return;
  g_interrupted.store(false);
  struct sigaction action {};
  action.sa_sigaction = on_interrupt;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_SIGINFO | SA_ONSTACK;  // Python's own flags: no SA_RESTART, its I/O retries EINTR itself
  sigaction(SIGINT, &action, &g_replaced);
}

InterruptScope::~InterruptScope() {
  const std::lock_guard<std::mutex> lock(g_scope_mutex);
  if (--g_scopes == 0) sigaction(SIGINT, &g_replaced, nullptr);
}

const std::atomic<bool>& InterruptScope::flag() { return g_interrupted; }

namespace {

void register_exceptions(pyb::module_& m) {
  static pyb::exception<InvalidInput> invalid(m, "InvalidInput", PyExc_ValueError);
  static pyb::exception<IoError> io(m, "IOError", PyExc_OSError);
  pyb::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InvalidInput& e) {
      PyErr_SetString(invalid.ptr(), e.what());
    } catch (const UsageError& e) {  // a bad keyword value, as the CLI's bad flag value
      PyErr_SetString(invalid.ptr(), e.what());
    } catch (const IoError& e) {
      PyErr_SetString(io.ptr(), e.what());
    } catch (const ResourceError& e) {
      PyErr_SetString(PyExc_MemoryError, e.what());
    } catch (const Cancelled& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    }
  });
}

}  // namespace
}  // namespace raysift::py

PYBIND11_MODULE(_raysift, m) {
  m.doc() = "raysift: prioritized volume ray casting; NumPy arrays in and out, indexed [z, y, x] / [row, column]";
  m.attr("__version__") = RAYSIFT_VERSION;
  raysift::keep_freed_buffers_for_reuse();  // as the raysift program: frame buffers reused across calls
  raysift::py::register_exceptions(m);
  raysift::py::bind_volumes(m);
  raysift::py::bind_render(m);
  raysift::py::bind_tools(m);
  raysift::py::bind_sweep(m);
}
