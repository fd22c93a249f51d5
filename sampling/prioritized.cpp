#include "sampling/prioritized.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <tuple>

#include "core/errors.h"
#include "core/parallel.h"
#include "sampling/reconstruction.h"

namespace raysift::sampling {
namespace {

// Per row: object and level-0 object pixels, and the first non-finite value (x, or -1). One parallel pass
// for the check and the counts, which every frame needs.
struct RowScan {
  std::size_t object = 0, level0 = 0;
  int bad_x = -1;
};

// \throw InvalidInput naming the first (row-major) NaN/Inf pixel. \return the counts for `spacing`.
ObjectCounts scan_importance(const ImageF& importance, int spacing) {
  if (importance.width < 1 || importance.height < 1) throw InvalidInput("importance buffer is empty (0x0)");
  std::vector<RowScan> rows(std::size_t(importance.height));
  const int lattice = spacing - 1;  // validate(): a power of two
  parallel_rows(importance.height, [&](int y) {
    const float* row = &importance.pixels[std::size_t(y) * std::size_t(importance.width)];
    RowScan& r = rows[std::size_t(y)];
    for (int x = 0; x < importance.width; ++x) {
      if (!std::isfinite(row[x]) && r.bad_x < 0) r.bad_x = x;
      r.object += row[x] >= 0 ? 1 : 0;
    }
    if ((y & lattice) == 0)
      for (int x = 0; x < importance.width; x += spacing) r.level0 += row[x] >= 0 ? 1 : 0;
  });
  ObjectCounts c;
  for (std::size_t y = 0; y < rows.size(); ++y) {
    if (rows[y].bad_x >= 0)
      throw InvalidInput("importance buffer has a NaN/Inf value at pixel (" + std::to_string(rows[y].bad_x) + "," +
                         std::to_string(y) + ")");
    c.object += rows[y].object;
    c.level0 += rows[y].level0;
  }
  return c;
}

void mark(Span<const std::uint32_t> pixels, ImageMask& mask) {
  for (std::uint32_t p : pixels) mask.pixels[p] = 1;
}

// The selected pixels in 32x32-tile order: neighbouring rays share volume blocks and cache lines, which
// the priority order (scattered by design) does not. Used whenever the whole set is traced anyway.
std::vector<std::uint32_t> in_tile_order(const ImageMask& selected) {
  constexpr int kTile = 32;
  std::vector<std::uint32_t> out;
  for (int ty = 0; ty < selected.height; ty += kTile)
    for (int tx = 0; tx < selected.width; tx += kTile)
      for (int y = ty; y < std::min(ty + kTile, selected.height); ++y)
        for (int x = tx; x < std::min(tx + kTile, selected.width); ++x)
          if (selected(x, y)) out.push_back(std::uint32_t(y) * std::uint32_t(selected.width) + std::uint32_t(x));
  return out;
}

// Traces every selected pixel in tile order into `frame` (image, traced mask, ray count). The time since
// `stage` was reset is the priority stage; `stage` then times the trace.
void trace_selection(const ImageMask& selected, const TraceBatch& trace, SampledFrame& frame, Timer& stage) {
  const std::vector<std::uint32_t> rays = in_tile_order(selected);
  frame.priorities_ms = stage.elapsed_ms();
  stage.reset();
  trace_all(rays, trace, frame.image);
  frame.trace_ms = stage.elapsed_ms();
  mark(rays, frame.traced);
  frame.rays_traced = rays.size();
}

std::size_t ray_target(const SamplingOptions& options, std::size_t object, std::size_t level0) {
  const auto wanted = std::size_t(std::llround(options.ray_fraction * double(object)));
  return std::min(object, std::max(level0, wanted));
}


double reconstruct_reserve(const SamplingOptions& options, int w, int h, std::size_t object_pixels) {
  return options.reconstruct_reserve_ms >= 0 ? options.reconstruct_reserve_ms
                                             : estimate_reconstruct_ms(w, h, options.base_spacing, options.interpolation,
                                                                                object_pixels);
}

// Budget mode with the a priori bucketed queue (RP paper section 5).
void trace_budgeted_queue(const ImageF& importance, const FractalPattern& pattern, const SamplingOptions& options,
                          const TraceBatch& trace, const ElapsedMs& now, double elapsed_before_ms,
                          SampledFrame& frame, Timer& stage) {
  const RayQueue queue = make_bucketed_queue(importance, pattern, options.mapping, options.buckets, options.seed);
  frame.priorities_ms = stage.elapsed_ms();
  const double reserve = reconstruct_reserve(options, importance.width, importance.height, queue.object_pixels);
  stage.reset();
  const Span<const std::uint32_t> all(queue.pixels.data(), queue.pixels.size());
  trace_all(Span<const std::uint32_t>(all.data(), queue.level0_count), trace, frame.image);
  const double deadline = options.budget_ms - elapsed_before_ms - reserve;
  frame.budget_too_small = now() > deadline;
  const std::size_t more = trace_until(
      Span<const std::uint32_t>(all.data() + queue.level0_count, all.size() - queue.level0_count), trace,
      frame.image, now, deadline);
  frame.rays_traced = queue.level0_count + more;
  frame.trace_ms = stage.elapsed_ms();
  mark(Span<const std::uint32_t>(queue.pixels.data(), frame.rays_traced), frame.traced);
}

// Fraction or budget mode with a posteriori refinement; the priorities are computed inside the trace rounds
// and counted as trace time.
void trace_refined_frame(const ImageF& importance, const FractalPattern& pattern, const SamplingOptions& options,
                         const TraceBatch& trace, std::size_t target, const ElapsedMs& now,
                         double elapsed_before_ms, SampledFrame& frame, Timer& stage, ImageMask& known) {
  RefinementStop stop;
  stop.rays = target;
  if (options.budget_ms > 0) {
    stop.deadline_ms = options.budget_ms - elapsed_before_ms - reconstruct_reserve(options, importance.width,
                                                                                  importance.height, frame.full_rays);
    stop.now = &now;
  }
  frame.priorities_ms = stage.elapsed_ms();
  stage.reset();
  const RefinementResult r =
      trace_refined(importance, pattern, options.refinement, stop, options.seed, trace, frame.image, frame.traced,
                    &known);
  frame.trace_ms = stage.elapsed_ms();
  frame.rays_traced = r.rays;
  frame.budget_too_small = r.level0_overran;
}

}  // namespace

SamplingMode parse_sampling_mode(const std::string& name) {
  if (name == "full") return SamplingMode::Full;
  if (name == "prioritized") return SamplingMode::Prioritized;
  if (name == "subsample") return SamplingMode::Subsample;
  throw InvalidInput("the sampling mode must be one of: full, prioritized, subsample; got '" + name + "'");
}

const char* sampling_mode_name(SamplingMode mode) {
  switch (mode) {
    case SamplingMode::Full: return "full";
    case SamplingMode::Prioritized: return "prioritized";
    case SamplingMode::Subsample: return "subsample";
  }
  return "?";
}

void validate(const SamplingOptions& o) {
  if (!(o.ray_fraction > 0.0 && o.ray_fraction <= 1.0))
    throw InvalidInput("the ray fraction must be in (0, 1], got " + std::to_string(o.ray_fraction));
  if (!std::isfinite(o.budget_ms) || o.budget_ms < 0)
    throw InvalidInput("the frame budget must be >= 0 ms (0 = no budget), got " + std::to_string(o.budget_ms));
  if (o.base_spacing < 1 || o.base_spacing > 128 || (o.base_spacing & (o.base_spacing - 1)) != 0)
    throw InvalidInput("fractal base spacing must be a power of two in 1..128, got " + std::to_string(o.base_spacing));
  if (o.buckets < 1 || o.buckets > 65536)
    throw InvalidInput("priority bucket count must be in 1..65536, got " + std::to_string(o.buckets));
  for (float a : o.mapping.alpha)
    if (!std::isfinite(a)) throw InvalidInput("the priority mapping's alpha coefficients must be finite");
}

ImageF control_importance(const ImageF& importance) {
  ImageF out = importance;
  for (float& v : out.pixels) v = v < 0 ? v : 0.0f;
  return out;
}

double estimate_reconstruct_ms(int width, int height, int base_spacing, Interpolation interpolation,
                               std::size_t object_pixels) {
  // Measured once per (crop, spacing, rule) and process: the estimate must not cost a reconstruction per frame.
  // Two per-pixel costs: an object pixel with only level 0 traced around it (the worst case), and a known pixel
  // (background: only scanned). Each is the fastest of 3 runs: the first run pays for page faults on the fresh
  // crop, which later frames do not (their buffers are reused), and a reserve sized by it wasted a third of a 15 ms
  // budget.
  struct PixelCosts {
    double object_ms, known_ms;
  };
  static std::mutex mutex;
  static std::map<std::tuple<int, int, Interpolation>, PixelCosts> costs;  // key (crop side, spacing, rule)
  const int side = std::min(256, std::max(16, std::min(width, height)));
  std::lock_guard<std::mutex> lock(mutex);
  auto it = costs.find({side, base_spacing, interpolation});
  if (it == costs.end()) {
    const FractalPattern pattern = make_fractal_pattern(side, side, base_spacing);
    auto ms_per_pixel = [&](const ImageMask& known) {
      double best_ms = 1e300;
      for (int run = 0; run < 3; ++run) {
        ImageRGBA image(side, side);
        const Timer timer;
        reconstruct_fractal(image, known, pattern, interpolation);
        best_ms = std::min(best_ms, timer.elapsed_ms());
      }
      return best_ms / double(side * side);
    };
    ImageMask level0(side, side, 0);
    for (std::size_t i = 0; i < level0.size(); ++i) level0.pixels[i] = pattern.level.pixels[i] == 0 ? 1 : 0;
    const PixelCosts measured{ms_per_pixel(level0), ms_per_pixel(ImageMask(side, side, 1))};
    it = costs.emplace(std::make_tuple(side, base_spacing, interpolation), measured).first;
  }
  const double pixels = double(width) * double(height), object = std::min(pixels, double(object_pixels));
  return it->second.object_ms * object + it->second.known_ms * (pixels - object);
}

SampledFrame render_sampled(const ImageF& importance, const TraceBatch& trace, const SamplingOptions& options,
                            double elapsed_before_ms) {
  const Timer clock;
  validate(options);
  const ObjectCounts counts = scan_importance(importance, options.base_spacing);
  const ElapsedMs now = options.clock_ms ? options.clock_ms : ElapsedMs([&clock] { return clock.elapsed_ms(); });
  const int w = importance.width, h = importance.height;
  SampledFrame frame;
  frame.image = ImageRGBA(w, h);
  frame.traced = ImageMask(w, h, 0);

  Timer stage;
  frame.full_rays = counts.object;
  frame.level0_rays = counts.level0;
  const std::size_t target = ray_target(options, counts.object, counts.level0);

  if (options.mode == SamplingMode::Full) {
    ImageMask object(w, h, 0);
    for (std::size_t i = 0; i < importance.size(); ++i) object.pixels[i] = importance.pixels[i] >= 0 ? 1 : 0;
    trace_selection(object, trace, frame, stage);
    return frame;
  }

  if (options.mode == SamplingMode::Subsample) {
    const SampleGrid grid = subsample_grid_for(importance, target, nullptr);
    ImageMask on_grid(w, h, 0);
    for (int y : grid.ys)
      for (int x : grid.xs) on_grid(x, y) = importance(x, y) >= 0 ? 1 : 0;
    trace_selection(on_grid, trace, frame, stage);
    frame.trace_end_ms = clock.elapsed_ms();
    stage.reset();
    if (frame.rays_traced < counts.object) reconstruct_bilinear(frame.image, grid, background_known(importance));
    frame.reconstruct_ms = stage.elapsed_ms();
    return frame;
  }

  const FractalPattern pattern = make_fractal_pattern(w, h, options.base_spacing);
  ImageMask known;  // background and traced pixels: the refinement gives it, the other paths build it after tracing
  if (options.refinement.enabled && !std::isfinite(options.threshold)) {
    trace_refined_frame(importance, pattern, options, trace, target, now, elapsed_before_ms, frame, stage, known);
  } else if (options.budget_ms > 0) {
    trace_budgeted_queue(importance, pattern, options, trace, now, elapsed_before_ms, frame, stage);
  } else {
    const RayQueue queue =
        select_top_rays(importance, pattern, options.mapping, target, options.seed, options.threshold);
    ImageMask selected(w, h, 0);
    mark(queue.pixels, selected);
    trace_selection(selected, trace, frame, stage);
  }

  frame.trace_end_ms = clock.elapsed_ms();
  stage.reset();
  if (frame.rays_traced < counts.object) {
    if (known.pixels.empty()) known = background_known(importance, &frame.traced);
    reconstruct_fractal(frame.image, known, pattern, options.interpolation);
  }
  frame.reconstruct_ms = stage.elapsed_ms();
  return frame;
}

void BudgetReserve::update(double tail_ms, double frame_ms, double budget_ms) {
  if (!(std::isfinite(tail_ms) && std::isfinite(frame_ms) && budget_ms > 0)) return;
  tail_ms_ = tail_ms_ < 0 ? tail_ms : 0.5 * (tail_ms_ + tail_ms);
  margin_.update(frame_ms, budget_ms);
}

ProgressiveSampler::ProgressiveSampler(const ImageF& importance, const SamplingOptions& options) : options_(options) {
  validate(options);
  scan_importance(importance, options.base_spacing);
  if (options.mode != SamplingMode::Prioritized)
    throw InvalidInput("progressive frames need the prioritized mode, got " + std::string(sampling_mode_name(options.mode)));
  const Timer timer;
  pattern_ = make_fractal_pattern(importance.width, importance.height, options.base_spacing);
  queue_ = make_bucketed_queue(importance, pattern_, options.mapping, options.buckets, options.seed);
  samples_ = ImageRGBA(importance.width, importance.height);
  known_ = background_known(importance);
  priorities_ms_ = timer.elapsed_ms();
}

SampledFrame ProgressiveSampler::next_frame(const TraceBatch& trace) {
  const Timer clock;
  const ElapsedMs now = options_.clock_ms ? options_.clock_ms : ElapsedMs([&clock] { return clock.elapsed_ms(); });
  SampledFrame frame;
  frame.full_rays = queue_.object_pixels;
  frame.level0_rays = queue_.level0_count;
  frame.priorities_ms = priorities_ms_;  // the queue is built once; later frames reuse it
  priorities_ms_ = 0;
  const Span<const std::uint32_t> all(queue_.pixels.data(), queue_.pixels.size());
  const std::size_t begin = next_;

  Timer stage;
  if (next_ == 0) {
    trace_all(Span<const std::uint32_t>(all.data(), queue_.level0_count), trace, samples_);
    next_ = queue_.level0_count;
  }
  if (options_.budget_ms > 0) {
    // The previous frame's reconstruction time (with 25% margin) is the best estimate for this one.
    const double reserve = options_.reconstruct_reserve_ms >= 0 ? options_.reconstruct_reserve_ms
                           : last_reconstruct_ms_ >= 0
                               ? 1.25 * last_reconstruct_ms_
                               : estimate_reconstruct_ms(samples_.width, samples_.height, options_.base_spacing,
                                                         options_.interpolation, queue_.object_pixels);
    const double deadline = options_.budget_ms - reserve;
    frame.budget_too_small = begin == 0 && now() > deadline;
    next_ += trace_until(Span<const std::uint32_t>(all.data() + next_, all.size() - next_), trace, samples_, now,
                         deadline);
  } else {
    const auto step = std::size_t(std::llround(options_.ray_fraction * double(queue_.object_pixels)));
    const std::size_t end = std::min(all.size(), std::max(next_, begin + std::max<std::size_t>(step, 1)));
    trace_all(Span<const std::uint32_t>(all.data() + next_, end - next_), trace, samples_);
    next_ = end;
  }
  frame.trace_ms = stage.elapsed_ms();
  mark(Span<const std::uint32_t>(all.data() + begin, next_ - begin), known_);

  frame.traced = ImageMask(samples_.width, samples_.height, 0);
  mark(Span<const std::uint32_t>(all.data(), next_), frame.traced);
  frame.rays_traced = next_;
  stage.reset();
  frame.image = samples_;
  if (!converged()) reconstruct_fractal(frame.image, known_, pattern_, options_.interpolation);
  frame.reconstruct_ms = stage.elapsed_ms();
  last_reconstruct_ms_ = frame.reconstruct_ms;
  return frame;
}

}  // namespace raysift::sampling
