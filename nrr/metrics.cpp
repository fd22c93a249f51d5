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
detail::ImageRule reference_rule(SamplingMode mode, Span<const Camera> cameras, Span<const detail::PixelLookup> lookups,
                                 std::size_t i) {
  detail::ImageRule rule;
  rule.mode = mode;
  if (mode == SamplingMode::Peel) {
    rule.layer = int(i);
  } else {
    rule.previous_cameras = Span<const Camera>(cameras.data(), i);
    rule.previous_lookups = Span<const detail::PixelLookup>(lookups.data(), i);
  }
  return rule;
}

void validate_inputs(SamplingMode mode, Span<const CameraSpec> views, Span<const DepthImage> reference,
                     Span<const DepthImage> conventional, Span<const CameraSpec> intermediate) {
  if (views.empty()) throw InvalidInput("metrics need at least one view");
  if (conventional.size() != views.size())
    throw InvalidInput("metrics need one conventional image per view: " + std::to_string(views.size()) + " views, " +
                       std::to_string(conventional.size()) + " conventional images");
  if (reference.empty() || (mode != SamplingMode::Peel && reference.size() != views.size()))
    throw InvalidInput("metrics: " + std::to_string(reference.size()) + " reference images for " +
                       std::to_string(views.size()) + " views");
  if (intermediate.empty()) throw InvalidInput("metrics need at least one intermediate view");
}

/// The inputs every metric reads, with the cameras and projectors of the reference and conventional images.
struct MetricsContext {
  const SampledScene& scene;
  SamplingMode mode;
  Span<const DepthImage> reference, conventional;
  bool threaded, by_pixel;
  Redundancy redundancy;
  std::vector<Camera> ref_cameras, conv_cameras;
  /// Pixel redundancy against the reference and conventional images (also nrr-pixel's sampling rule):
  /// the projector of pixel_captured with the blocked triangle lookup, so the same answers, faster.
  std::vector<detail::PixelLookup> ref_lookups, conv_lookups;

  MetricsContext(const SampledScene& s, SamplingMode m, Span<const DepthImage> ref, Span<const DepthImage> conv,
                 const MetricsOptions& options)
      : scene(s), mode(m), reference(ref), conventional(conv), threaded(options.threaded),
        by_pixel(options.redundancy == Redundancy::Pixel), redundancy(options.redundancy) {
    for (const DepthImage& im : reference) ref_cameras.emplace_back(im.camera);
    for (const DepthImage& im : conventional) conv_cameras.emplace_back(im.camera);
    for (const DepthImage& im : reference) ref_lookups.emplace_back(im);
    for (const DepthImage& im : conventional) conv_lookups.emplace_back(im);
  }

  /// Whether `image` (taken by `camera`) captured the surface point x of triangle id, by the redundancy rule.
  bool captured(const Camera& camera, const detail::PixelLookup& lookup, const Vec3f& x, mesh::TriangleId id) const {
    return by_pixel ? lookup.holds(x, id)
                    : detail::visibility_redundant(scene, camera, redundancy, x, id);
  }
};

/// Metrics (1) and (2) of reference image i: its redundant samples, and its disoccluded ones (marked in `cls`).
void classify_image(const MetricsContext& c, std::size_t i, ImageMetrics& image_metrics,
                    std::vector<SampleClass>& cls) {
  const DepthImage& im = c.reference[i];
  cls.assign(im.pixel_count(), SampleClass::Empty);
  for (std::size_t p = 0; p < im.pixel_count(); ++p)
    if (im.has_sample(p)) cls[p] = SampleClass::Ordinary;
  image_metrics.samples = im.sample_count();
  image_metrics.redundant = count_if_index(im.pixel_count(), c.threaded, [&](std::size_t p) {
    if (!im.has_sample(p)) return false;
    for (std::size_t j = 0; j < i; ++j)
      if (c.captured(c.ref_cameras[j], c.ref_lookups[j], im.position_ws(p), im.triangle_id[p]))
        return true;
    return false;
  });
  if (c.mode == SamplingMode::Conventional) return;  // (2) is 0 for conventional images by definition
  // For NRR the conventional image of the same view; for peeling, any conventional image (§6.1.2).
  const std::size_t first = c.mode == SamplingMode::Peel ? 0 : i;
  const std::size_t last = c.mode == SamplingMode::Peel ? c.conventional.size() : i + 1;
  image_metrics.disoccluded = count_if_index(im.pixel_count(), c.threaded, [&](std::size_t p) {
    if (!im.has_sample(p)) return false;
    for (std::size_t j = first; j < last; ++j) {
      // Same view, pixel redundancy: the sample reprojects onto its own pixel, so compare there
      // directly (also right for hits at t = 0, which cannot be projected).
      const bool is_same_view = c.by_pixel && j == i && c.mode != SamplingMode::Peel;
      if (is_same_view ? c.conventional[j].triangle_id[p] == im.triangle_id[p]
                       : c.captured(c.conv_cameras[j], c.conv_lookups[j], im.position_ws(p),
                                    im.triangle_id[p]))
        return false;
    }
    cls[p] = SampleClass::Disoccluded;
    return true;
  });
}

/// Metric (4): whether the reference images hold the surface point x of triangle id.
bool is_available(const MetricsContext& c, const Vec3f& x, mesh::TriangleId id) {
  // Whether an image holds x is a fact about the image, so it always includes the image's frustum,
  // whichever visibility definition the metrics use. Conventional and frustum-visibility NRR images
  // hold every point visible inside one of their frusta (a point visible in I_j is in I_j or, being
  // redundant, in an earlier image): a cheap occlusion ray settles most samples before the full rule
  // is traced. Alg. 2 NRR images do not: a point seen from V_j outside I_j's frustum is in none.
  const bool holds_all_visible =
      c.mode == SamplingMode::Conventional || c.mode == SamplingMode::NrrVisibilityFrustum;
  if (!c.by_pixel && holds_all_visible) {
    for (const Camera& cam : c.ref_cameras)
      if (detail::visible_in_image(c.scene, cam, x, id)) return true;
    if (c.mode == SamplingMode::Conventional) return false;
  }
  for (std::size_t i = 0; i < c.reference.size(); ++i) {
    if (c.by_pixel) {
      if (c.ref_lookups[i].holds(x, id)) return true;
      continue;
    }
    const Camera& cam = c.ref_cameras[i];
    if (!detail::faces_eye(c.scene, cam.eye(), x, id) || !detail::in_frustum(cam, x)) continue;
    const Vec3f eye(cam.eye());
    const mesh::RayF ray{eye, x - eye};
    mesh::Hit hit;
    detail::trace(c.scene, reference_rule(c.mode, Span<const Camera>(c.ref_cameras),
                                          Span<const detail::PixelLookup>(c.ref_lookups), i),
                  Span<const mesh::RayF>(&ray, 1), Span<mesh::Hit>(&hit, 1), false);
    if (hit.triangle_id == id) return true;
  }
  return false;
}

/// Metrics (3) and (4) over the intermediate views: the availability percentages into `m`, and the
/// disoccluded samples some frame captures marked useful.
void evaluate_intermediate_views(const MetricsContext& c, Span<const CameraSpec> intermediate, SamplingMetrics& m) {
  std::vector<std::pair<std::size_t, std::size_t>> disoccluded;  // (image, pixel) not yet found useful
  for (std::size_t i = 0; i < c.reference.size(); ++i)
    for (std::size_t p = 0; p < m.sample_classes[i].size(); ++p)
      if (m.sample_classes[i][p] == SampleClass::Disoccluded) disoccluded.emplace_back(i, p);
  double pct_sum = 0.0;
  for (const CameraSpec& spec : intermediate) {
    SamplingOptions conv;
    conv.mode = SamplingMode::Conventional;
    conv.threaded = c.threaded;
    const DepthImage frame = std::move(render_depth_images(c.scene, Span<const CameraSpec>(&spec, 1), conv)[0]);
    const Camera frame_camera(frame.camera);
    const detail::PixelLookup frame_lookup(frame);
    const std::size_t samples = frame.sample_count();
    if (samples > 0) {
      const std::size_t available = count_if_index(frame.pixel_count(), c.threaded, [&](std::size_t p) {
        return frame.has_sample(p) && is_available(c, frame.position_ws(p), frame.triangle_id[p]);
      });
      const double pct = 100.0 * double(available) / double(samples);
      pct_sum += pct;
      m.available_min_pct = m.frames_with_samples == 0 ? pct : std::min(m.available_min_pct, pct);
      ++m.frames_with_samples;
    }
    // (3): a disoccluded sample is useful once it is redundant with (captured by) some frame.
    count_if_index(disoccluded.size(), c.threaded, [&](std::size_t k) {
      const auto [i, p] = disoccluded[k];
      if (m.sample_classes[i][p] == SampleClass::Useful) return false;
      if (!c.captured(frame_camera, frame_lookup, c.reference[i].position_ws(p), c.reference[i].triangle_id[p]))
        return false;
      m.sample_classes[i][p] = SampleClass::Useful;
      return true;
    });
  }
  if (m.frames_with_samples > 0) m.available_avg_pct = pct_sum / double(m.frames_with_samples);
}

}  // namespace

SamplingMetrics compute_sampling_metrics(const SampledScene& scene, SamplingMode mode, Span<const CameraSpec> views,
                                         Span<const DepthImage> reference, Span<const DepthImage> conventional,
                                         Span<const CameraSpec> intermediate, const MetricsOptions& options) {
  validate_inputs(mode, views, reference, conventional, intermediate);
  const MetricsContext context(scene, mode, reference, conventional, options);
  SamplingMetrics m;
  m.images.resize(reference.size());
  m.sample_classes.resize(reference.size());
  for (std::size_t i = 0; i < reference.size(); ++i) classify_image(context, i, m.images[i], m.sample_classes[i]);
  evaluate_intermediate_views(context, intermediate, m);
  for (std::size_t i = 0; i < reference.size(); ++i)
    m.images[i].useful = std::size_t(
        std::count(m.sample_classes[i].begin(), m.sample_classes[i].end(), SampleClass::Useful));
  return m;
}

ImageRGBA sample_class_image(const DepthImage& image, const std::vector<SampleClass>& classes) {
  RAYSIFT_CHECK_OP(classes.size(), ==, image.pixel_count());
  RAYSIFT_CHECK_OP(image.normal_ws.size(), ==, image.pixel_count());
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
