// raysift.Volume, raysift.TransferFunction and raysift.Camera (docs/python.md). Arrays are [z, y, x], x fastest,
// the raw importer's byte order.
#include <cmath>
#include <sstream>

#include "apps/raysift/stats_json.h"
#include "core/camera.h"
#include "core/parallel.h"
#include "core/errors.h"
#include "python/py_bindings.h"
#include "python/py_common.h"
#include "volume/histogram.h"
#include "volume/raycaster.h"
#include "volume/transfer_function.h"
#include "volume/vdb_io.h"

namespace raysift::py {
namespace {

using volume::Volume;

const char* const kVolumeShape = "a 3-D [z, y, x] array of float32, float64, uint8 or uint16";

template <typename T>
Volume volume_from(const pyb::array& any, const volume::DenseSpec& spec) {
  // One copy for a non-contiguous array; a C-ordered one is read in place.
  const auto a = pyb::array_t<T, pyb::array::c_style>::ensure(any);
  const T* data = a.data();
  const std::size_t nx = std::size_t(spec.dims.x), nxy = nx * std::size_t(spec.dims.y);
  const std::size_t count = nxy * std::size_t(spec.dims.z);
  return run_released([&](const std::atomic<bool>&) {
    if constexpr (std::is_floating_point_v<T>) {
      // The raw importer's stage check: a NaN/Inf voxel would poison every ray through it.
      for (std::size_t i = 0; i < count; ++i)
        if (!std::isfinite(float(data[i]))) {
          std::ostringstream s;
          s << "from_numpy: voxel [z=" << i / nxy << ", y=" << (i / nx) % std::size_t(spec.dims.y) << ", x=" << i % nx
            << "] is NaN/Inf (or out of float range); fix the data before import";
          throw InvalidInput(s.str());
        }
    }
    return Volume::from_function(spec, [&](int i, int j, int k) {
      return float(data[std::size_t(i) + nx * std::size_t(j) + nxy * std::size_t(k)]);
    });
  });
}

Vec3d voxel_size_of(const pyb::object& v) {
  if (pyb::isinstance<pyb::float_>(v) || pyb::isinstance<pyb::int_>(v)) {
    const double s = v.cast<double>();
    return {s, s, s};
  }
  const auto t = triple(v, "voxel_size");
  return {t[0], t[1], t[2]};
}

Volume from_numpy(const pyb::array& array, const pyb::object& voxel_size, const pyb::object& origin,
                  double background, double tolerance) {
  if (array.ndim() != 3)
    throw pyb::type_error(std::string("from_numpy expects ") + kVolumeShape + ", got " +
                          std::to_string(array.ndim()) + " dimensions");
  volume::DenseSpec spec;
  spec.dims = {int(array.shape(2)), int(array.shape(1)), int(array.shape(0))};
  spec.voxel_size = voxel_size_of(voxel_size);
  const auto o = triple(origin, "origin");
  spec.origin_ws = {o[0], o[1], o[2]};
  spec.background = float(background);
  spec.tolerance = float(tolerance);
  if (!(tolerance >= 0)) throw InvalidInput("from_numpy: tolerance must be >= 0, got " + std::to_string(tolerance));
  const auto kind = array.dtype();
  if (kind.is(pyb::dtype::of<float>())) return volume_from<float>(array, spec);
  if (kind.is(pyb::dtype::of<double>())) return volume_from<double>(array, spec);
  if (kind.is(pyb::dtype::of<std::uint8_t>())) return volume_from<std::uint8_t>(array, spec);
  if (kind.is(pyb::dtype::of<std::uint16_t>())) return volume_from<std::uint16_t>(array, spec);
  throw pyb::type_error(std::string("from_numpy expects ") + kVolumeShape + ", got dtype " +
                        pyb::str(pyb::handle(kind)).cast<std::string>());
}

/// Dense float32 [z, y, x] over the active voxels' index bbox (inactive voxels read as the background).
pyb::array_t<float> to_numpy(const Volume& v) {
  const volume::GridInfo info = v.info();
  if (info.active_voxels == 0) return pyb::array_t<float>(std::vector<pyb::ssize_t>{0, 0, 0});
  const Vec3i lo = info.index_min, n = info.index_max - info.index_min + Vec3i{1, 1, 1};
  auto values = std::make_unique<std::vector<float>>(std::size_t(n.x) * std::size_t(n.y) * std::size_t(n.z));
  float* out = values->data();
  run_released([&](const std::atomic<bool>&) {
    parallel_for_each(n.z, [&](int k) {  // each z-slice writes its own part of the array
      std::size_t i = std::size_t(k) * std::size_t(n.x) * std::size_t(n.y);
      for (int j = 0; j < n.y; ++j)
        for (int x = 0; x < n.x; ++x) out[i++] = v.value_at({lo.x + x, lo.y + j, lo.z + k});
    });
  });
  const float* data = values->data();
  return owning_array(std::move(values), data, {n.z, n.y, n.x});
}

pyb::dict histogram(const Volume& v, int bins) {
  if (bins < 1) throw InvalidInput("histogram: bins must be >= 1, got " + std::to_string(bins));
  volume::Histogram h = run_released([&](const std::atomic<bool>&) { return volume::compute_histogram(v, bins); });
  pyb::dict d;
  d["grid"] = v.name();
  d["min"] = h.min;
  d["max"] = h.max;
  const pyb::ssize_t size = pyb::ssize_t(h.counts.size());
  d["counts"] = vector_array(std::move(h.counts), {size});
  return d;
}

void bind_volume(pyb::module_& m) {
  pyb::class_<Volume>(m, "Volume", "A sparse OpenVDB float grid (index [z, y, x] in NumPy, x fastest).")
      .def_static(
          "load",
          [](const std::string& path, const std::optional<std::string>& grid) {
            return run_released([&](const std::atomic<bool>&) { return volume::load_vdb(path, grid.value_or("")); });
          },
          pyb::arg("path"), pyb::arg("grid") = pyb::none())
      .def_static("from_numpy", &from_numpy, pyb::arg("array"), pyb::arg("voxel_size") = 1.0,
                  pyb::arg("origin") = pyb::make_tuple(0, 0, 0), pyb::arg("background") = 0.0,
                  pyb::arg("tolerance") = 0.0)
      .def("save",
           [](const Volume& v, const std::string& path) {
             run_released([&](const std::atomic<bool>&) { volume::save_vdb(path, v); });
           },
           pyb::arg("path"))
      .def("info", [](const Volume& v) { return to_python(app::grid_info_json(v.info())); })
      .def("histogram", &histogram, pyb::arg("bins") = 256)
      .def("to_numpy", &to_numpy)
      .def_property_readonly("name", &Volume::name)
      .def_property_readonly("active_voxels", &Volume::active_voxel_count)
      .def("__repr__", [](const Volume& v) {
        return "<raysift.Volume '" + v.name() + "' " + std::to_string(v.active_voxel_count()) + " active voxels>";
      });
}

std::vector<volume::TfPoint> tf_points(const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& x,
                                       const pyb::array_t<float, pyb::array::c_style | pyb::array::forcecast>& rgb,
                                       const pyb::array_t<float, pyb::array::c_style | pyb::array::forcecast>& a) {
  const pyb::ssize_t n = x.ndim() == 1 ? x.shape(0) : -1;
  if (n < 0 || rgb.ndim() != 2 || rgb.shape(0) != n || rgb.shape(1) != 3 || a.ndim() != 1 || a.shape(0) != n)
    throw pyb::type_error("from_points expects values (N,), rgb (N, 3) and opacity (N,)");
  std::vector<volume::TfPoint> points(static_cast<std::size_t>(n));
  for (pyb::ssize_t i = 0; i < n; ++i)
    points[std::size_t(i)] = {x.at(i), rgb.at(i, 0), rgb.at(i, 1), rgb.at(i, 2), a.at(i)};
  return points;
}

pyb::array_t<float> tf_sample(const volume::TransferFunction& tf,
                              const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& values) {
  const pyb::ssize_t n = values.size();
  std::vector<float> out(std::size_t(n) * 4);
  const double* v = values.data();
  for (pyb::ssize_t i = 0; i < n; ++i) {
    const Rgba c = tf.evaluate(v[i]);
    std::copy_n(&c.r, 4, &out[std::size_t(i) * 4]);
  }
  return vector_array(std::move(out), {n, 4});
}

void bind_transfer_function(pyb::module_& m) {
  pyb::class_<volume::TransferFunction>(m, "TransferFunction",
                                        "1-D piecewise-linear RGBA transfer function over the scalar value.")
      .def_static("load", [](const std::string& path) { return volume::load_transfer_function(path); },
                  pyb::arg("path"))
      .def_static("from_points",
                  [](const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& values,
                     const pyb::array_t<float, pyb::array::c_style | pyb::array::forcecast>& rgb,
                     const pyb::array_t<float, pyb::array::c_style | pyb::array::forcecast>& opacity) {
                    return volume::TransferFunction(tf_points(values, rgb, opacity));
                  },
                  pyb::arg("values"), pyb::arg("rgb"), pyb::arg("opacity"))
      .def("to_paraview",
           [](const volume::TransferFunction& tf) { return to_python(transfer_function_to_paraview_json(tf)[0]); })
      .def("sample", &tf_sample, pyb::arg("values"))
      .def_property_readonly("points",
                             [](const volume::TransferFunction& tf) {
                               std::vector<double> rows;
                               for (const volume::TfPoint& p : tf.points()) rows.insert(rows.end(), {p.x, p.r, p.g, p.b, p.a});
                               const pyb::ssize_t n = pyb::ssize_t(tf.points().size());
                               return vector_array(std::move(rows), {n, 5});
                             },
                             "(N, 5) float64 control points [value, r, g, b, opacity]")
      .def_property_readonly("domain", [](const volume::TransferFunction& tf) {
        return pyb::make_tuple(tf.domain_min(), tf.domain_max());
      });
}

CameraSpec make_camera(const pyb::object& eye, const pyb::object& target, const pyb::object& up, double fov_y_deg,
                       int width, int height) {
  CameraSpec c;
  const auto e = triple(eye, "eye"), t = triple(target, "target"), u = triple(up, "up");
  c.eye = {e[0], e[1], e[2]};
  c.target = {t[0], t[1], t[2]};
  c.up = {u[0], u[1], u[2]};
  c.fov_y_deg = fov_y_deg;
  c.width = width;
  c.height = height;
  static_cast<void>(Camera{c});  // validates: InvalidInput names the problem
  return c;
}

pyb::tuple vec3_tuple(const Vec3d& v) { return pyb::make_tuple(v.x, v.y, v.z); }

void bind_camera(pyb::module_& m) {
  pyb::class_<CameraSpec>(m, "Camera", "A pinhole camera (the keys of a camera JSON file).")
      .def(pyb::init(&make_camera), pyb::arg("eye"), pyb::arg("target"), pyb::arg("up") = pyb::make_tuple(0, 1, 0),
           pyb::arg("fov_y_deg") = CameraSpec{}.fov_y_deg, pyb::arg("width") = CameraSpec{}.width,
           pyb::arg("height") = CameraSpec{}.height)
      .def_static("load", [](const std::string& path) { return camera_spec_from_json(read_json_file(path), path); },
                  pyb::arg("path"))
      .def_static("fit", &volume::fit_camera, pyb::arg("volume"), pyb::arg("width"), pyb::arg("height"))
      .def("to_dict", [](const CameraSpec& c) { return to_python(camera_spec_to_json(c)); })
      .def_property_readonly("eye", [](const CameraSpec& c) { return vec3_tuple(c.eye); })
      .def_property_readonly("target", [](const CameraSpec& c) { return vec3_tuple(c.target); })
      .def_property_readonly("up", [](const CameraSpec& c) { return vec3_tuple(c.up); })
      .def_readonly("fov_y_deg", &CameraSpec::fov_y_deg)
      .def_readonly("width", &CameraSpec::width)
      .def_readonly("height", &CameraSpec::height)
      .def("__repr__", [](const CameraSpec& c) { return "<raysift.Camera " + camera_spec_to_json(c).dump() + ">"; });
}

}  // namespace

void bind_volumes(pyb::module_& m) {
  bind_volume(m);
  bind_transfer_function(m);
  bind_camera(m);
}

}  // namespace raysift::py
