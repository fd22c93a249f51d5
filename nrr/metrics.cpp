#include "nrr/metrics.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <functional>

#include "core/errors.h"
#include "nrr/detail/tracer.h"

namespace raysift::nrr {
namespace {

/// Number of i in [0, n) with pred(i). Integer sums, so 1 and N threads agree exactly.
std::size_t count_if_index(std::size_t n, bool threaded, const std::function<bool(std::size_t)>& pred) {
  if (!threaded) {
    std::size_t count = 0;
    for (std::size_t i = 0; i < n; ++i) count += pred(i) ? 1 : 0;
    return count;
  }
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 1024), std::size_t(0),
      [&](const tbb::blocked_range<std::size_t>& r, std::size_t count) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) count += pred(i) ? 1 : 0;
        return count;
      },
      std::plus<std::size_t>());
}

/// The rule that produced reference image i (for visibility availability in metric 4).
detail::ImageRule reference_rule(SamplingMode mode, Span<const DepthImage> reference, Span<const Camera> cameras,
                                 std::size_t i) {
  detail::ImageRule rule;
  rule.mode = mode;
  if (mode == SamplingMode::Peel) {
    rule.layer = int(i);
  } else {
    rule.previous = Span<const DepthImage>(reference.data(), i);
    rule.previous_cameras = Span<const Camera>(cameras.data(), i);
  }
  return rule;
}

}  // namespace

Redundancy parse_redundancy(const std::string& name) {
  if (name == "pixel") return Redundancy::Pixel;
  if (name == "visibility") return Redundancy::Visibility;
  throw InvalidInput("redundancy must be one of: pixel, visibility; got '" + name + "'");
}

std::string to_string(Redundancy redundancy) { return redundancy == Redundancy::Pixel ? "pixel" : "visibility"; }

SamplingMetrics compute_sampling_metrics(const SampledScene& scene, SamplingMode mode, Span<const CameraSpec> views,
                                         Span<const DepthImage> reference, Span<const DepthImage> conventional,
                                         Span<const CameraSpec> intermediate, const MetricsOptions& options) {
  if (views.empty()) throw InvalidInput("metrics need at least one view");
  if (conventional.size() != views.size())
    throw InvalidInput("metrics need one conventional image per view: " + std::to_string(views.size()) + " views, " +
                       std::to_string(conventional.size()) + " conventional images");
  if (reference.empty() || (mode != SamplingMode::Peel && reference.size() != views.size()))
    throw InvalidInput("metrics: " + std::to_string(reference.size()) + " reference images for " +
                       std::to_string(views.size()) + " views");
  if (intermediate.empty()) throw InvalidInput("metrics need at least one intermediate view");
  const bool threaded = options.threaded;
  const bool by_pixel = options.redundancy == Redundancy::Pixel;

  std::vector<Camera> ref_cameras, conv_cameras;
  for (const DepthImage& im : reference) ref_cameras.emplace_back(im.camera);
  for (const DepthImage& im : conventional) conv_cameras.emplace_back(im.camera);
  const std::vector<detail::PixelProjector> ref_projectors(ref_cameras.begin(), ref_cameras.end());
  const std::vector<detail::PixelProjector> conv_projectors(conv_cameras.begin(), conv_cameras.end());
  const auto captured = [&](const DepthImage& image, const Camera& camera, const detail::PixelProjector& projector,
                            const Vec3f& x, mesh::TriangleId id) {
    return by_pixel ? detail::pixel_captured(image, projector, x, id) : detail::visible_from(scene, camera, x, id);
  };

  SamplingMetrics m;
  const std::size_t n = reference.size();
  m.images.resize(n);
  m.sample_classes.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const DepthImage& im = reference[i];
    std::vector<SampleClass>& cls = m.sample_classes[i];
    cls.assign(im.pixel_count(), SampleClass::Empty);
    for (std::size_t p = 0; p < im.pixel_count(); ++p)
      if (im.has_sample(p)) cls[p] = SampleClass::Ordinary;
    m.images[i].samples = im.sample_count();
    m.images[i].redundant = count_if_index(im.pixel_count(), threaded, [&](std::size_t p) {
      if (!im.has_sample(p)) return false;
      for (std::size_t j = 0; j < i; ++j)
        if (captured(reference[j], ref_cameras[j], ref_projectors[j], im.position_ws[p], im.triangle_id[p]))
          return true;
      return false;
    });
    if (mode == SamplingMode::Conventional) continue;  // (2) is 0 for conventional images by definition
    // For NRR the conventional image of the same view; for peeling, any conventional image (§6.1.2).
    const std::size_t first = mode == SamplingMode::Peel ? 0 : i;
    const std::size_t last = mode == SamplingMode::Peel ? conventional.size() : i + 1;
    m.images[i].disoccluded = count_if_index(im.pixel_count(), threaded, [&](std::size_t p) {
      if (!im.has_sample(p)) return false;
      for (std::size_t j = first; j < last; ++j) {
        // Same view, pixel redundancy: the sample reprojects onto its own pixel, so compare there
        // directly (also right for hits at t = 0, which cannot be projected).
        const bool is_same_view = by_pixel && j == i && mode != SamplingMode::Peel;
        if (is_same_view ? conventional[j].triangle_id[p] == im.triangle_id[p]
                         : captured(conventional[j], conv_cameras[j], conv_projectors[j], im.position_ws[p],
                                    im.triangle_id[p]))
          return false;
      }
      cls[p] = SampleClass::Disoccluded;
      return true;
    });
  }

  std::vector<std::pair<std::size_t, std::size_t>> disoccluded;  // (image, pixel) not yet found useful
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t p = 0; p < m.sample_classes[i].size(); ++p)
      if (m.sample_classes[i][p] == SampleClass::Disoccluded) disoccluded.emplace_back(i, p);

  // Conventional and visibility-NRR images hold every point visible from one of their eyes (a point
  // visible from V_j is in I_j or, being redundant, in an earlier image): a cheap occlusion ray settles
  // most samples before the full rule is traced. For conventional images the rule adds nothing more.
  const bool holds_all_visible = mode == SamplingMode::Conventional || mode == SamplingMode::NrrVisibility;
  const auto is_available = [&](const Vec3f& x, mesh::TriangleId id) {
    if (!by_pixel && holds_all_visible) {
      for (const Camera& cam : ref_cameras)
        if (detail::visible_from(scene, cam, x, id)) return true;
      if (mode == SamplingMode::Conventional) return false;
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (by_pixel) {
        if (detail::pixel_captured(reference[i], ref_projectors[i], x, id)) return true;
        continue;
      }
      const Camera& cam = ref_cameras[i];
      if (!detail::may_be_visible_from(scene, cam, x, id)) continue;
      const Vec3f eye(cam.eye());
      const mesh::RayF ray{eye, x - eye};
      mesh::Hit hit;
      detail::trace(scene, reference_rule(mode, reference, Span<const Camera>(ref_cameras), i),
                    Span<const mesh::RayF>(&ray, 1), Span<mesh::Hit>(&hit, 1), false);
      if (hit.triangle_id == id) return true;
    }
    return false;
  };

  double pct_sum = 0.0;
  for (const CameraSpec& spec : intermediate) {
    SamplingOptions conv;
    conv.mode = SamplingMode::Conventional;
    conv.threaded = threaded;
    const DepthImage frame = std::move(render_depth_images(scene, Span<const CameraSpec>(&spec, 1), conv)[0]);
    const Camera frame_camera(frame.camera);
    const detail::PixelProjector frame_projector(frame_camera);
    const std::size_t samples = frame.sample_count();
    if (samples > 0) {
      const std::size_t available = count_if_index(frame.pixel_count(), threaded, [&](std::size_t p) {
        return frame.has_sample(p) && is_available(frame.position_ws[p], frame.triangle_id[p]);
      });
      const double pct = 100.0 * double(available) / double(samples);
      pct_sum += pct;
      m.available_min_pct = m.frames_with_samples == 0 ? pct : std::min(m.available_min_pct, pct);
      ++m.frames_with_samples;
    }
    // (3): a disoccluded sample is useful once it is redundant with (captured by) some frame.
    count_if_index(disoccluded.size(), threaded, [&](std::size_t k) {
      const auto [i, p] = disoccluded[k];
      if (m.sample_classes[i][p] == SampleClass::Useful) return false;
      if (!captured(frame, frame_camera, frame_projector, reference[i].position_ws[p], reference[i].triangle_id[p]))
        return false;
      m.sample_classes[i][p] = SampleClass::Useful;
      return true;
    });
  }
  if (m.frames_with_samples > 0) m.available_avg_pct = pct_sum / double(m.frames_with_samples);
  for (std::size_t i = 0; i < n; ++i)
    m.images[i].useful = std::size_t(
        std::count(m.sample_classes[i].begin(), m.sample_classes[i].end(), SampleClass::Useful));
  return m;
}

ImageRGBA sample_class_image(const DepthImage& image, const std::vector<SampleClass>& classes) {
  RAYSIFT_CHECK_OP(classes.size(), ==, image.pixel_count());
  ImageRGBA out(image.width, image.height, Rgba{0, 0, 0, 1});
  const Vec3d view = normalize(image.camera.target - image.camera.eye);
  for (std::size_t p = 0; p < classes.size(); ++p) {
    switch (classes[p]) {
      case SampleClass::Empty: break;
      case SampleClass::Ordinary: {
        // Grey shaded by facing, so the geometry stays readable beside the coloured samples.
        const float g = 0.15f + 0.55f * float(std::abs(dot(Vec3d(image.normal_ws[p]), view)));
        out.pixels[p] = {g, g, g, 1};
        break;
      }
      case SampleClass::Disoccluded: out.pixels[p] = {0.1f, 0.8f, 0.1f, 1}; break;
      case SampleClass::Useful: out.pixels[p] = {0.95f, 0.85f, 0.1f, 1}; break;
    }
  }
  return out;
}

}  // namespace raysift::nrr
