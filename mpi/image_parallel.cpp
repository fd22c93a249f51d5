#include "mpi/image_parallel.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <utility>

#include "core/errors.h"
#include "core/parallel.h"
#include "core/timer.h"
#include "mpi/composite.h"
#include "mpi/session.h"
#include "mpi/tile_queue.h"

#if RAYSIFT_HAVE_MPI
#include <mpi.h>
#endif

namespace raysift::mpi {
namespace {

#if RAYSIFT_HAVE_MPI
constexpr int kFloatsPerPixel = 5;  // composited RGBA and depth, as RenderResult holds them

/// Traces one tile exactly as render_full does and writes its pixels, row-major, to `out` (kFloatsPerPixel
/// each). \return the volume samples taken.
std::uint64_t trace_tile(const volume::RayCaster& caster, const TileGrid::Rect& r, float* out) {
  const Vec3f background = caster.options().background;
  std::atomic<std::uint64_t> samples{0};
  const int w = r.x1 - r.x0;
  parallel_rows(r.y1 - r.y0, [&](int dy) {
    std::uint64_t row_samples = 0;
    for (int dx = 0; dx < w; ++dx) {
      const volume::RaySample s = caster.trace(r.x0 + dx, r.y0 + dy);
      const Rgba c = volume::composite_over_background(s.color, background);
      float* p = out + std::size_t(dy * w + dx) * kFloatsPerPixel;
      p[0] = c.r, p[1] = c.g, p[2] = c.b, p[3] = c.a, p[4] = s.depth;
      row_samples += s.samples;
    }
    samples += row_samples;
  });
  return samples;
}

void place_tile(const TileGrid::Rect& r, const float* in, volume::RenderResult& result) {
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x, in += kFloatsPerPixel) {
      result.image(x, y) = {in[0], in[1], in[2], in[3]};
      result.depth(x, y) = in[4];
    }
}

constexpr int kTagRequest = 19001, kTagTile = 19002, kTagTileList = 19003, kTagTileData = 19004;
constexpr int kDepth = 2;  // requests each worker keeps outstanding

void answer(TileQueue& queue, int worker, RankStats& stats) {
  const int tile = queue.next();
  MPI_Send(&tile, 1, MPI_INT, worker, kTagTile, MPI_COMM_WORLD);
  stats.bytes_sent += sizeof tile;
}

/// Rank 0: deals tiles, tracing one itself between rounds of answering the requests that have arrived.
void master(const volume::RayCaster& caster, const TileGrid& grid, volume::RenderResult& result, RankStats& stats,
            std::uint64_t& samples) {
  TileQueue queue(grid.count(), size() - 1, kDepth);
  std::vector<float> buffer(std::size_t(grid.tile * grid.tile) * kFloatsPerPixel);
  while (!queue.finished()) {
    int pending = 0, dummy = 0;
    MPI_Status status;
    // With tiles left, answer what has arrived and trace; without, wait for the workers' last requests.
    if (queue.has_tiles()) MPI_Iprobe(MPI_ANY_SOURCE, kTagRequest, MPI_COMM_WORLD, &pending, &status);
    if (pending || !queue.has_tiles()) {
      MPI_Recv(&dummy, 1, MPI_INT, MPI_ANY_SOURCE, kTagRequest, MPI_COMM_WORLD, &status);
      stats.bytes_received += sizeof dummy;
      answer(queue, status.MPI_SOURCE, stats);
      continue;
    }
    const TileGrid::Rect r = grid.rect(queue.next());
    const Timer timer;
    samples += trace_tile(caster, r, buffer.data());
    stats.render_ms += timer.elapsed_ms();
    place_tile(r, buffer.data(), result);
  }
}

/// Other ranks: trace the tiles the master deals, then send them (tile indices, then their pixels) to rank 0.
void worker(const volume::RayCaster& caster, const TileGrid& grid, RankStats& stats, std::uint64_t& samples) {
  std::vector<int> tiles;
  std::vector<float> pixels;
  const int request = 0;
  for (int d = 0; d < kDepth; ++d) MPI_Send(&request, 1, MPI_INT, 0, kTagRequest, MPI_COMM_WORLD);
  stats.bytes_sent += kDepth * sizeof request;
  for (int outstanding = kDepth; outstanding > 0;) {
    int tile = TileQueue::kNoTile;
    MPI_Recv(&tile, 1, MPI_INT, 0, kTagTile, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    stats.bytes_received += sizeof tile;
    --outstanding;
    if (tile == TileQueue::kNoTile) continue;
    MPI_Send(&request, 1, MPI_INT, 0, kTagRequest, MPI_COMM_WORLD);  // ask for the next before tracing this one
    stats.bytes_sent += sizeof request;
    ++outstanding;
    const TileGrid::Rect r = grid.rect(tile);
    const std::size_t at = pixels.size();
    pixels.resize(at + std::size_t(r.pixels()) * kFloatsPerPixel);
    const Timer timer;
    samples += trace_tile(caster, r, pixels.data() + at);
    stats.render_ms += timer.elapsed_ms();
    tiles.push_back(tile);
  }
  const Timer timer;
  MPI_Send(tiles.data(), int(tiles.size()), MPI_INT, 0, kTagTileList, MPI_COMM_WORLD);
  MPI_Send(pixels.data(), int(pixels.size()), MPI_FLOAT, 0, kTagTileData, MPI_COMM_WORLD);
  stats.bytes_sent += tiles.size() * sizeof(int) + pixels.size() * sizeof(float);
  stats.composite_ms += timer.elapsed_ms();
}

/// Rank 0: receives every worker's tiles and places them.
void assemble(const TileGrid& grid, volume::RenderResult& result, RankStats& stats) {
  for (int source = 1; source < size(); ++source) {
    MPI_Status status;
    MPI_Probe(source, kTagTileList, MPI_COMM_WORLD, &status);
    int count = 0;
    MPI_Get_count(&status, MPI_INT, &count);
    std::vector<int> tiles(static_cast<std::size_t>(count));
    MPI_Recv(tiles.data(), count, MPI_INT, source, kTagTileList, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    std::size_t floats = 0;
    for (int t : tiles) floats += std::size_t(grid.rect(t).pixels()) * kFloatsPerPixel;
    std::vector<float> pixels(floats);
    MPI_Recv(pixels.data(), int(floats), MPI_FLOAT, source, kTagTileData, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    stats.bytes_received += tiles.size() * sizeof(int) + floats * sizeof(float);
    const float* in = pixels.data();
    for (int t : tiles) {
      place_tile(grid.rect(t), in, result);
      in += std::size_t(grid.rect(t).pixels()) * kFloatsPerPixel;
    }
  }
}

std::uint64_t sum_on_root(std::uint64_t value) {
  std::uint64_t total = 0;
  MPI_Reduce(&value, &total, 1, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
  return total;
}
#endif

}  // namespace

volume::RenderResult render_full_image_parallel(const volume::RayCaster& caster, RankStats& stats) {
  if (size() == 1) {
    const Timer timer;
    volume::RenderResult r = volume::render_full(caster);
    stats.render_ms += timer.elapsed_ms();
    return r;
  }
#if RAYSIFT_HAVE_MPI
  const TileGrid grid{caster.width(), caster.height(), 32};
  volume::RenderResult result;
  std::uint64_t samples = 0;
  if (is_root()) {
    result.image = ImageRGBA(grid.width, grid.height);
    result.depth = ImageF(grid.width, grid.height);
    master(caster, grid, result, stats, samples);
    const Timer timer;
    assemble(grid, result, stats);
    stats.composite_ms += timer.elapsed_ms();
  } else {
    worker(caster, grid, stats, samples);
  }
  result.samples = sum_on_root(samples);
  if (is_root()) result.rays_traced = std::uint64_t(grid.width) * std::uint64_t(grid.height);
  return result;
#else
  RAYSIFT_CHECK(false);  // size() > 1 needs MPI
  return {};
#endif
}

namespace {

#if RAYSIFT_HAVE_MPI
/// The lock-step tracer: each rank traces the positions ray_owner gives it and one all-gather gives every rank all
/// of the set (a whole refinement round through trace_set, a budget group through trace_group). Called only from
/// render_sampled in a one-thread arena, so every rank makes the same collectives in the same order and the
/// buffers are reused; the rank's own rays are traced on all its threads. With a `segment_order` (data mode)
/// every rank traces every ray of the set through its brick instead, and each ray is its ranks' segments
/// composited front to back in that order.
class LockstepTracer {
 public:
  LockstepTracer(const volume::RayCaster& caster, RankStats& stats, const std::vector<int>& segment_order)
      : caster_(caster), stats_(stats), order_(segment_order) {}

  void trace_group(Span<const std::uint32_t> pixels, Span<Rgba> out) {
    exchange(pixels, [&](std::size_t k, const Rgba& c) { out[k] = c; });
  }
  void trace_set(Span<const std::uint32_t> pixels, ImageRGBA& image) {
    exchange(pixels, [&](std::size_t k, const Rgba& c) { image.pixels[pixels[k]] = c; });
  }

  /// Budget mode: the queue in chunks of kChunkGroups groups per rank while rank 0's clock (`elapsed_ms`, a
  /// broadcast) is before the deadline: a prefix, two collectives per chunk instead of per group.
  std::size_t trace_prefix(Span<const std::uint32_t> queue, ImageRGBA& image, const std::function<double()>& elapsed_ms,
                           double deadline_ms) {
    const std::size_t chunk = kChunkGroups * sampling::kRayGroup * std::size_t(segments() ? 1 : size());
    std::size_t done = 0;
    while (done < queue.size() && elapsed_ms() < deadline_ms) {
      const std::size_t n = std::min(chunk, queue.size() - done);
      trace_set(Span<const std::uint32_t>(queue.data() + done, n), image);
      done += n;
    }
    return done;
  }

  static constexpr std::size_t kChunkGroups = 8;
  std::uint64_t samples = 0;  ///< volume samples this rank's rays took

 private:
  struct Header {
    std::uint32_t count, first, last;  ///< the set every rank must be tracing
  };

  bool segments() const { return !order_.empty(); }
  /// Rays of a set of `count` that rank `r` traces.
  std::size_t rays_of(int r, std::size_t count) const {
    if (segments()) return count;
    std::size_t k = 0;
    for (std::size_t i = 0; i < count; ++i) k += ray_owner(i, count, size()) == r;
    return k;
  }

  void trace_mine(Span<const std::uint32_t> pixels) {
    const int me = rank(), n = size();
    mine_.clear();
    for (std::size_t k = 0; k < pixels.size(); ++k)
      if (segments() || ray_owner(k, pixels.size(), n) == me) mine_.push_back(pixels[k]);
    rays_.resize(mine_.size());
    const Timer timer;
    std::atomic<std::uint64_t> taken{0};
    all_threads_.execute([&] {
      parallel_chunks(mine_.size(), sampling::kRayGroup, [&](std::size_t, std::size_t begin, std::size_t end) {
        caster_.trace_pixels(Span<const std::uint32_t>(mine_.data() + begin, end - begin),
                             Span<volume::RaySample>(rays_.data() + begin, end - begin));
        std::uint64_t t = 0;
        for (std::size_t i = begin; i < end; ++i) t += rays_[i].samples;
        taken += t;
      });
    });
    samples += taken;
    stats_.render_ms += timer.elapsed_ms();
  }

  template <typename Store>
  void exchange(Span<const std::uint32_t> pixels, const Store& store) {
    const int n = size();
    const Header header{std::uint32_t(pixels.size()), pixels.empty() ? 0u : pixels[0],
                        pixels.empty() ? 0u : pixels[pixels.size() - 1]};
    trace_mine(pixels);
    send_.resize(sizeof header + rays_.size() * sizeof(Rgba));
    std::memcpy(send_.data(), &header, sizeof header);
    for (std::size_t j = 0; j < rays_.size(); ++j)
      std::memcpy(send_.data() + sizeof header + j * sizeof(Rgba), &rays_[j].color, sizeof(Rgba));
    counts_.resize(std::size_t(n));
    for (int r = 0; r < n; ++r) counts_[std::size_t(r)] = int(sizeof header + rays_of(r, pixels.size()) * sizeof(Rgba));
    displs_.assign(std::size_t(n), 0);
    for (int r = 1; r < n; ++r) displs_[std::size_t(r)] = displs_[std::size_t(r - 1)] + counts_[std::size_t(r - 1)];
    recv_.resize(std::size_t(displs_.back() + counts_.back()));
    const Timer timer;
    MPI_Allgatherv(send_.data(), int(send_.size()), MPI_BYTE, recv_.data(), counts_.data(), displs_.data(), MPI_BYTE,
                   MPI_COMM_WORLD);
    stats_.composite_ms += timer.elapsed_ms();
    stats_.bytes_sent += send_.size() * std::size_t(n - 1);
    stats_.bytes_received += recv_.size() - send_.size();
    for (int r = 0; r < n; ++r) {
      Header theirs;
      std::memcpy(&theirs, recv_.data() + displs_[std::size_t(r)], sizeof theirs);
      // A mismatch means the ranks' sampling runs diverged: a bug, never input.
      RAYSIFT_CHECK(theirs.count == header.count && theirs.first == header.first && theirs.last == header.last);
    }
    if (segments()) {
      for (std::size_t k = 0; k < pixels.size(); ++k) store(k, composited(k));
      return;
    }
    cursor_.assign(std::size_t(n), 0);
    for (std::size_t k = 0; k < pixels.size(); ++k) {
      const std::size_t r = std::size_t(ray_owner(k, pixels.size(), n));
      store(k, received(r, cursor_[r]++));
    }
  }

  Rgba received(std::size_t r, std::size_t j) const {
    Rgba c;
    std::memcpy(&c, recv_.data() + displs_[r] + sizeof(Header) + j * sizeof(Rgba), sizeof c);
    return c;
  }

  /// Ray k of the set: every rank's segment of it, front to back ("over" as the full frame's binary swap).
  Rgba composited(std::size_t k) const {
    float ray[4] = {0, 0, 0, 0}, segment[4];
    for (int r : order_) {
      const Rgba c = received(std::size_t(r), k);
      segment[0] = c.r, segment[1] = c.g, segment[2] = c.b, segment[3] = c.a;
      composite_over(ray, segment, 1);
    }
    return {ray[0], ray[1], ray[2], ray[3]};
  }

  const volume::RayCaster& caster_;
  RankStats& stats_;
  const std::vector<int>& order_;  ///< data mode: ranks front to back; empty = image mode
  tbb::task_arena all_threads_;  ///< the rank's own rays use every thread, unlike the lock-step control
  std::vector<std::uint32_t> mine_;
  std::vector<volume::RaySample> rays_;
  std::vector<std::uint8_t> send_, recv_;
  std::vector<int> counts_, displs_;
  std::vector<std::size_t> cursor_;
};

template <typename T>
void broadcast_value(T& value) {
  MPI_Bcast(&value, int(sizeof value), MPI_BYTE, 0, MPI_COMM_WORLD);
}

/// Rank 0's feature geometry and importance, on every rank; `out` gets the geometry summary on rank 0.
ImageF shared_importance(const volume::Volume& volume, const volume::TransferFunction& tf,
                         const volume::RayCaster& caster, const sampling::SampledRenderRequest& request,
                         sampling::SampledRender& out, RankStats& stats) {
  ImageF importance(caster.width(), caster.height());
  all_or_none([&] {
    if (!is_root()) return;
    // The choice render_sampled_volume makes, so both build the same lines.
    const bool wants = request.sampling.mode == sampling::SamplingMode::Prioritized && !request.features.classes.is_empty();
    out.features_skipped = wants && request.feature_mesh.empty() && sampling::transparent_over_data(volume, tf);
    if (!wants || out.features_skipped) {
      importance = sampling::frame_importance(caster, nullptr, request.features);
      return;
    }
    const isosurface::FeatureView view{caster.camera().spec(), request.features.importance.scale};
    const sampling::FeatureGeometry geometry = sampling::feature_geometry_for(
        volume, tf, view, request.geometry, request.feature_mesh, request.feature_cache);
    out.features = sampling::summarize(geometry);
    importance = sampling::frame_importance(caster, &geometry, request.features);
  });
  broadcast_importance(importance, stats);
  return importance;
}

/// The sampling options every rank uses: rank 0's clock, broadcast at every reading (lock step makes the readings
/// collective), and rank 0's reconstruction reserve.
sampling::SamplingOptions lockstep_options(const sampling::SamplingOptions& given, int width, int height,
                                           const Timer& frame) {
  sampling::SamplingOptions o = given;
  const sampling::ElapsedMs local = given.clock_ms ? given.clock_ms : sampling::ElapsedMs([&frame] {
    return frame.elapsed_ms();
  });
  o.clock_ms = [local] {
    double t = is_root() ? local() : 0.0;
    broadcast_value(t);
    return t;
  };
  if (o.budget_ms > 0 && o.reconstruct_reserve_ms < 0) {
    o.reconstruct_reserve_ms = is_root() ? sampling::estimate_reconstruct_ms(width, height, o.base_spacing, o.interpolation)
                                        : 0.0;
    broadcast_value(o.reconstruct_reserve_ms);
  }
  return o;
}
#endif

}  // namespace

sampling::SampledRender render_sampled_image_parallel(const volume::Volume& volume, const volume::TransferFunction& tf,
                                                      const volume::RayCaster& caster,
                                                      const sampling::SampledRenderRequest& request, RankStats& stats) {
  if (request.progressive_frames != 0)
    throw InvalidInput("--distribute image renders single frames; --progressive is not distributed");
  if (size() == 1) {
    const Timer timer;
    sampling::SampledRender r = sampling::render_sampled_volume(volume, tf, caster, request);
    stats.render_ms += timer.elapsed_ms();
    return r;
  }
#if RAYSIFT_HAVE_MPI
  sampling::validate(request.sampling);
  const Timer total;
  sampling::SampledRender lines;
  const ImageF importance = shared_importance(volume, tf, caster, request, lines, stats);
  sampling::SampledRender out =
      render_sampled_lockstep(importance, total, caster, request.sampling, caster.options().background, {}, stats);
  out.features = std::move(lines.features);
  out.features_skipped = lines.features_skipped;
  return out;
#else
  RAYSIFT_CHECK(false);  // size() > 1 needs MPI
  return {};
#endif
}

void broadcast_importance(ImageF& importance, RankStats& stats) {
#if RAYSIFT_HAVE_MPI
  const Timer timer;
  MPI_Bcast(importance.pixels.data(), int(importance.pixels.size()), MPI_FLOAT, 0, MPI_COMM_WORLD);
  stats.composite_ms += timer.elapsed_ms();
  const std::uint64_t bytes = importance.pixels.size() * sizeof(float);
  if (is_root())
    stats.bytes_sent += bytes * std::uint64_t(size() - 1);
  else
    stats.bytes_received += bytes;
#else
  (void)importance, (void)stats;
#endif
}

sampling::SampledRender render_sampled_lockstep(const ImageF& importance, const Timer& total,
                                                const volume::RayCaster& caster,
                                                const sampling::SamplingOptions& sampling, const Vec3f& background,
                                                const std::vector<int>& segment_order, RankStats& stats) {
#if RAYSIFT_HAVE_MPI
  sampling::SampledRender out;
  out.mode = sampling.mode;
  double importance_ms = total.elapsed_ms();
  broadcast_value(importance_ms);
  const Timer frame_clock;
  const sampling::SamplingOptions options = lockstep_options(sampling, caster.width(), caster.height(), frame_clock);
  LockstepTracer tracer(caster, stats, segment_order);
  sampling::SampledFrame frame;
  tbb::task_arena one_thread(1);
  one_thread.execute([&] {
    const sampling::SetTracer set{[&tracer](Span<const std::uint32_t> p, ImageRGBA& image) { tracer.trace_set(p, image); },
                                  [&tracer](Span<const std::uint32_t> p, Span<Rgba> o) { tracer.trace_group(p, o); },
                                  [&tracer](Span<const std::uint32_t> q, ImageRGBA& image,
                                            const std::function<double()>& elapsed_ms, double deadline_ms) {
                                    return tracer.trace_prefix(q, image, elapsed_ms, deadline_ms);
                                  }};
    frame = sampling::render_sampled(importance, set, options, importance_ms);
  });
  out.samples = sum_on_root(tracer.samples);
  if (!is_root()) return out;
  out.image = sampling::composite_frame(std::move(frame.image), background);
  sampling::record_frame(out, frame, importance_ms, total.elapsed_ms(), out.samples);
  return out;
#else
  (void)importance, (void)total, (void)caster, (void)sampling, (void)background, (void)segment_order, (void)stats;
  RAYSIFT_CHECK(false);  // needs MPI
  return {};
#endif
}

}  // namespace raysift::mpi
