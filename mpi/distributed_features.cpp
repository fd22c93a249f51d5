#include "mpi/distributed_features.h"

#include <cmath>
#include <stdexcept>

#include "core/errors.h"
#include "core/timer.h"
#include "isosurface/brick_pieces.h"
#include "mpi/session.h"
#include "volume/histogram.h"
#include "volume/iso_values.h"
#include "volume/resample.h"

namespace raysift::mpi {

namespace {

/// This rank's half-open ownership box on a level of `factor` voxels per cell. The planes are leaf boundaries
/// (multiples of 8) and factor <= 8 divides them, so every coarse point averages voxels of one brick only.
volume::IndexRegion owned_region(const Brick& brick, int factor) {
  return {brick.own_lo / double(factor), brick.own_hi / double(factor)};
}

/// The iso-values: given, or chosen on the whole grid's histogram (the sum of the owned voxels' histograms over
/// the agreed finite range), as one process chooses them.
std::vector<double> agreed_iso_values(const volume::Volume& brick, const volume::IndexRegion& owned,
                                      const volume::TransferFunction& tf,
                                      const isosurface::FeatureGeometryOptions& options) {
  if (!options.iso_values.empty()) return options.iso_values;
  volume::IsoValueOptions iso_options;
  iso_options.max_surfaces = options.max_surfaces;
  volume::ValueRange range = volume::finite_value_range(brick, owned);
  range.min = min_all(range.min);
  range.max = max_all(range.max);
  volume::Histogram histogram = volume::compute_histogram(brick, iso_options.bins, range, owned);
  histogram.counts.push_back(histogram.non_finite);
  sum_all(histogram.counts);
  histogram.non_finite = histogram.counts.back();
  histogram.counts.pop_back();
  std::vector<double> values;
  all_or_none([&] {  // every rank holds the same histogram, so every rank agrees (or fails alike)
    for (const volume::IsoValue& v : volume::select_iso_values(histogram, tf, iso_options)) values.push_back(v.value);
  });
  return values;
}

/// On rank 0: every rank's piece of each surface, assembled (one gather). Elsewhere: empty.
std::vector<TriMesh> gathered_surfaces(const std::vector<isosurface::MeshPiece>& pieces, RankStats& stats) {
  const std::vector<std::uint8_t> bytes = isosurface::to_bytes(pieces);
  const std::vector<std::vector<std::uint8_t>> all = gather(bytes);
  if (!is_root()) {
    stats.bytes_sent += bytes.size();
    return {};
  }
  std::vector<std::vector<isosurface::MeshPiece>> by_surface(pieces.size());
  for (std::size_t r = 0; r < all.size(); ++r) {
    std::vector<isosurface::MeshPiece> received = isosurface::from_bytes(all[r]);
    if (received.size() != pieces.size()) throw std::logic_error("mesh pieces: ranks disagree on the surface count");
    for (std::size_t i = 0; i < received.size(); ++i) by_surface[i].push_back(std::move(received[i]));
    if (r != 0) stats.bytes_received += all[r].size();
  }
  std::vector<TriMesh> surfaces;
  for (const std::vector<isosurface::MeshPiece>& surface : by_surface) surfaces.push_back(isosurface::assemble_pieces(surface));
  return surfaces;
}

}  // namespace

std::optional<isosurface::FeatureGeometry> build_distributed_feature_geometry(
    const DataParallelPlan& plan, const volume::Volume& brick, const volume::GridInfo& whole,
    const volume::TransferFunction& tf, const isosurface::FeatureGeometryOptions& options, RankStats& stats) {
  const Timer timer;
  const Brick& mine = plan.split.bricks[std::size_t(rank())];
  const isosurface::FeatureLevel level = isosurface::choose_feature_level(whole, options);
  const std::vector<double> iso_values = agreed_iso_values(brick, {mine.own_lo, mine.own_hi}, tf, options);
  Timer stage;
  volume::Volume coarse;
  std::vector<isosurface::MeshPiece> pieces;
  double level_ms = 0, marching_cubes_ms = 0;
  all_or_none([&] {
    coarse = brick.is_empty() ? brick : volume::downsample(brick, level.coarsening);
    level_ms = stage.elapsed_ms();
    stage.reset();
    volume::MarchingCubesOptions mc;
    mc.cancel = options.cancel;
    pieces = isosurface::extract_owned_pieces(coarse, iso_values, owned_region(mine, level.coarsening), mc);
    marching_cubes_ms = stage.elapsed_ms();
  });
  coarse = volume::Volume{};  // the level is not needed once the pieces exist
  const Timer composite;
  std::vector<TriMesh> surfaces = gathered_surfaces(pieces, stats);
  stats.composite_ms += composite.elapsed_ms();
  std::optional<isosurface::FeatureGeometry> geometry;
  all_or_none([&] {
    if (!is_root()) return;
    geometry = isosurface::finish_feature_geometry(std::move(surfaces), iso_values, options, level);
    geometry->level_ms = level_ms;
    geometry->stages.marching_cubes.ms = marching_cubes_ms;
    geometry->build_ms = timer.elapsed_ms();
  });
  return geometry;
}

}  // namespace raysift::mpi
