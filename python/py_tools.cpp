// raysift.compare, mesh and lines: `raysift compare` on arrays, `raysift mesh` and `raysift lines` returning arrays.
#include <optional>
#include <sstream>

#include "apps/raysift/stats_json.h"
#include "core/errors.h"
#include "core/image.h"
#include "features/lines_pipeline.h"
#include "isosurface/pipeline.h"
#include "python/py_bindings.h"
#include "python/py_common.h"
#include "sampling/metrics.h"

namespace raysift::py {
namespace {

using FloatArray = pyb::array_t<float, pyb::array::c_style | pyb::array::forcecast>;

/// An (H, W, 4) RGBA array as an image (one copy: the metrics read raysift images).
ImageRGBA image_of(const FloatArray& a, const char* what) {
  if (a.ndim() != 3 || a.shape(2) != 4)
    throw pyb::type_error(std::string(what) + " must be an (H, W, 4) RGBA array, got " + std::to_string(a.ndim()) +
                          " dimensions" + (a.ndim() == 3 ? " with " + std::to_string(a.shape(2)) + " channels" : ""));
  ImageRGBA image(int(a.shape(1)), int(a.shape(0)));
  std::copy_n(a.data(), a.size(), &image.pixels.data()->r);
  return image;
}

/// `raysift compare A B [--mask M] --ppd P --stats` (the same keys cmd_compare.cpp writes inline).
pyb::object compare(const FloatArray& reference, const FloatArray& test, const std::optional<FloatArray>& mask,
                    double ppd) {
  const ImageRGBA ref = image_of(reference, "reference"), tst = image_of(test, "test");
  std::optional<sampling::ImageMask> object;
  if (mask) {
    if (mask->ndim() != 2 || mask->shape(0) != reference.shape(0) || mask->shape(1) != reference.shape(1))
      throw pyb::type_error("mask must be an (H, W) array of the reference's size (> 0.5 = object)");
    object = sampling::ImageMask(ref.width, ref.height, 0);
    for (std::size_t i = 0; i < object->size(); ++i) object->pixels[i] = mask->data()[i] > 0.5f ? 1 : 0;
  }
  sampling::CompareOptions options;
  options.flip_ppd = ppd;
  const sampling::Comparison result = run_released([&](const std::atomic<bool>&) {
    return sampling::compare_images(ref, tst, object ? &*object : nullptr, options);
  });
  Json stats;
  sampling::add_metrics_json(stats, result.frame, "");
  sampling::add_metrics_json(stats, result.object, "_object");
  stats["object_pixels"] = result.object.pixels;
  stats["flip_ppd"] = ppd;
  return to_python(stats);
}

Json mesh_stats(const isosurface::IsosurfaceSet& set) {
  Json iso = Json::array(), surfaces = Json::array();
  for (const isosurface::Surface& s : set.surfaces) {
    iso.push_back(s.iso.value);
    surfaces.push_back(app::surface_json(s.mesh));
  }
  return {{"iso_values", iso}, {"surfaces", surfaces}, {"stages", app::stages_json(set.stages)}};
}

/// `raysift mesh VOLUME --tf TF [--iso V,...] --smooth S --decimate R`: (vertices, faces, stats).
pyb::tuple extract_mesh(const volume::Volume& v, const volume::TransferFunction& tf,
                        const std::optional<std::vector<double>>& iso, int smooth, double decimate) {
  if (smooth < 0) throw InvalidInput("smooth must be >= 0, got " + std::to_string(smooth));
  if (!(decimate > 0 && decimate <= 1)) throw InvalidInput("decimate must be in (0, 1], got " + std::to_string(decimate));
  isosurface::PipelineOptions options;
  options.prep.smooth_before.iterations = options.prep.smooth_after.iterations = smooth;
  options.prep.decimation.ratio = decimate;
  if (iso) {  // the CLI's --iso rule: within the data range, background included
    const volume::GridInfo info = v.info();
    const double lo = std::min(info.value_min, info.background), hi = std::max(info.value_max, info.background);
    for (const double value : *iso)
      if (!(value >= lo && value <= hi)) {
        std::ostringstream s;
        s << "iso must be within the data range [" << lo << ", " << hi << "] of grid '" << info.name
          << "' (background included), got " << value;
        throw InvalidInput(s.str());
      }
    options.iso_values = *iso;
  }
  TriMesh merged;
  Json stats;
  run_released([&](const std::atomic<bool>& cancel) {
    options.cancel = &cancel;
    const isosurface::IsosurfaceSet set = isosurface::build_isosurfaces(v, iso ? nullptr : &tf, options);
    merged = isosurface::merge_surfaces(set);
    if (merged.empty()) throw InvalidInput("no iso-surface found at the chosen iso-values");
    stats = mesh_stats(set);
  });
  const pyb::ssize_t n = pyb::ssize_t(merged.positions.size()), m = pyb::ssize_t(merged.triangles.size());
  auto mesh = std::make_unique<TriMesh>(std::move(merged));
  const float* xyz = &mesh->positions.data()->x;
  const auto* faces = reinterpret_cast<const std::int32_t*>(mesh->triangles.data());  // indices < 2^31 (int32 faces)
  pyb::array_t<float> vertices = owning_array(std::make_unique<std::vector<Vec3f>>(std::move(mesh->positions)), xyz, {n, 3});
  pyb::array_t<std::int32_t> triangles = owning_array(std::move(mesh), faces, {m, 3});
  return pyb::make_tuple(vertices, triangles, to_python(stats));
}

/// (N, 3) float32 vertices and (M, 3) int32 faces as a mesh, each index checked.
TriMesh mesh_of(const FloatArray& vertices,
                const pyb::array_t<std::int32_t, pyb::array::c_style | pyb::array::forcecast>& faces) {
  if (vertices.ndim() != 2 || vertices.shape(1) != 3 || faces.ndim() != 2 || faces.shape(1) != 3)
    throw pyb::type_error("lines expects vertices (N, 3) float32 and faces (M, 3) int32");
  TriMesh m;
  m.positions.resize(std::size_t(vertices.shape(0)));
  std::copy_n(vertices.data(), vertices.size(), &m.positions.data()->x);
  m.triangles.resize(std::size_t(faces.shape(0)));
  for (std::size_t i = 0; i < std::size_t(faces.size()); ++i) {
    const std::int32_t v = faces.data()[i];
    if (v < 0 || std::size_t(v) >= m.positions.size())
      throw InvalidInput("lines: face " + std::to_string(i / 3) + " names vertex " + std::to_string(v) + " of " +
                         std::to_string(m.positions.size()));
    m.triangles[i / 3][i % 3] = std::uint32_t(v);
  }
  return m;
}

/// `raysift lines --stats` (a duplicate of cmd_lines.cpp's private stats_json; "mesh" names no file here).
Json lines_stats(const TriMesh& mesh, const CameraSpec& spec, const features::LinesPipelineOptions& options,
                 const features::LinesPipelineResult& r) {
  Json segments = Json::object();
  for (int c = 0; c < features::kLineClassCount; ++c)
    if (options.classes.has(features::LineClass(c)))
      segments[features::line_class_name(features::LineClass(c))] = r.visible.count(features::LineClass(c));
  const mesh::MeshCurvature& k = r.curvature;
  return {{"command", "lines"},
          {"mesh", "<array>"},
          {"camera", camera_spec_to_json(spec)},
          {"segments", segments},
          {"segments_extracted", r.extracted.segments.size()},
          {"feature_size", k.feature_size},
          {"mesh_report",
           {{"triangles", mesh.triangle_count()},
            {"degenerate_faces", k.degenerate_faces},
            {"boundary_vertices", k.boundary_vertices},
            {"nonmanifold_vertices", k.nonmanifold_vertices},
            {"unreferenced_vertices", k.unreferenced_vertices}}},
          {"importance_size", {r.importance->values.width, r.importance->values.height}},
          {"times_ms",
           {{"read", 0.0},
            {"curvature", r.times_ms.curvature},
            {"lines", r.times_ms.lines},
            {"visibility", r.times_ms.visibility},
            {"raster", r.times_ms.raster}}}};
}

/// Visible segments per enabled class as (K, 2, 2) image-space endpoints [segment, end, (x, y)].
pyb::dict segment_arrays(const features::FeatureLines& visible, const Camera& camera,
                         const features::LineClassSet& classes) {
  pyb::dict out;
  for (int c = 0; c < features::kLineClassCount; ++c) {
    if (!classes.has(features::LineClass(c))) continue;
    std::vector<float> xy;
    for (const features::LineSegment& s : visible.segments) {
      if (s.line_class != features::LineClass(c)) continue;
      for (const Vec3f& p : {s.p0_ws, s.p1_ws}) {
        // Visible pieces lie in front of the eye; NaN marks the impossible case rather than dropping an end.
        const auto q = camera.project(Vec3d{p.x, p.y, p.z});
        xy.push_back(q ? float(q->x_ss) : NAN);
        xy.push_back(q ? float(q->y_ss) : NAN);
      }
    }
    const pyb::ssize_t k = pyb::ssize_t(xy.size() / 4);
    out[features::line_class_name(features::LineClass(c))] = vector_array(std::move(xy), {k, 2, 2});
  }
  return out;
}

/// `raysift lines MESH --camera C --features F --importance I`: (segments, importance, stats).
pyb::tuple lines(const FloatArray& vertices,
                 const pyb::array_t<std::int32_t, pyb::array::c_style | pyb::array::forcecast>& faces,
                 const CameraSpec& spec, const std::string& classes, int threads) {
  const TriMesh m = mesh_of(vertices, faces);
  features::LinesPipelineOptions options;
  options.classes = features::parse_line_classes(classes);
  options.threaded = threads != 1;
  options.with_importance = true;
  const Camera camera(spec);
  features::LinesPipelineResult r =
      run_released([&](const std::atomic<bool>&) { return features::run_lines_pipeline(m, camera, options); });
  const Json stats = lines_stats(m, spec, options, r);
  ImageF& importance = r.importance->values;
  const pyb::ssize_t h = importance.height, w = importance.width;
  auto owner = std::make_unique<ImageF>(std::move(importance));
  const float* data = owner->pixels.data();
  return pyb::make_tuple(segment_arrays(r.visible, camera, options.classes), owning_array(std::move(owner), data, {h, w}),
                         to_python(stats));
}

pyb::array_t<float> read_image(const std::string& path) {
  return image_array(run_released([&](const std::atomic<bool>&) { return read_image_rgba(path); }));
}

}  // namespace

void bind_tools(pyb::module_& m) {
  m.def("lines", &lines, pyb::arg("vertices"), pyb::arg("faces"), pyb::arg("camera"), pyb::kw_only(),
        pyb::arg("features") = "all", pyb::arg("threads") = 0,
        "`raysift lines`: (segments {class: (K, 2, 2) float32 pixel endpoints}, importance (H', W') float32, stats).");
  m.def("read_image", &read_image, pyb::arg("path"),
        "An image file as (H, W, 4) float32 RGBA, read as `raysift compare` reads it.");
  m.def("write_image",
        [](const std::string& path, const FloatArray& image) {
          const ImageRGBA copy = image_of(image, "image");
          run_released([&](const std::atomic<bool>&) { write_image(path, copy); });
        },
        pyb::arg("path"), pyb::arg("image"), "Writes (H, W, 4) RGBA as `raysift render -o` does (EXR float, PNG 8-bit).");
  m.def("compare", &compare, pyb::arg("reference"), pyb::arg("test"), pyb::arg("mask") = pyb::none(),
        pyb::kw_only(), pyb::arg("ppd") = sampling::default_flip_ppd(),
        "`raysift compare` on (H, W, 4) arrays: PSNR, SSIM, MAE and FLIP over the frame and the object pixels.");
  m.def("mesh", &extract_mesh, pyb::arg("volume"), pyb::arg("tf"), pyb::arg("iso") = pyb::none(),
        pyb::arg("smooth") = mesh::SmoothingOptions{}.iterations, pyb::arg("decimate") = mesh::DecimationOptions{}.ratio,
        "`raysift mesh`: (vertices (N, 3) float32, faces (M, 3) int32, stats).");
}

}  // namespace raysift::py
