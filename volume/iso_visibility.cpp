#include "volume/iso_visibility.h"

#include <openvdb/tools/Dense.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "core/errors.h"
#include "core/parallel.h"
#include "volume/detail/vdb_grid.h"

namespace raysift::volume {

namespace {

/// The active bounding box (plus one background voxel on each side) as a dense x-fastest array.
struct DenseBlock {
  Vec3i origin, dims;
  std::vector<float> values;
  float at(int x, int y, int z) const { return values[(std::size_t(z) * dims.y + y) * dims.x + x]; }
  /// Trilinear at a position relative to origin, clamped to the block.
  float sample(double x, double y, double z) const {
    x = std::clamp(x, 0.0, dims.x - 1.001);
    y = std::clamp(y, 0.0, dims.y - 1.001);
    z = std::clamp(z, 0.0, dims.z - 1.001);
    const int i = int(x), j = int(y), k = int(z);
    const float fx = float(x - i), fy = float(y - j), fz = float(z - k);
    auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
    const float c00 = lerp(at(i, j, k), at(i + 1, j, k), fx), c10 = lerp(at(i, j + 1, k), at(i + 1, j + 1, k), fx);
    const float c01 = lerp(at(i, j, k + 1), at(i + 1, j, k + 1), fx),
                c11 = lerp(at(i, j + 1, k + 1), at(i + 1, j + 1, k + 1), fx);
    return lerp(lerp(c00, c10, fy), lerp(c01, c11, fy), fz);
  }
};

DenseBlock densify(const openvdb::FloatGrid& grid) {
  openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  box.expand(1);
  DenseBlock block;
  block.origin = {box.min().x(), box.min().y(), box.min().z()};
  block.dims = {box.dim().x(), box.dim().y(), box.dim().z()};
  block.values.resize(std::size_t(block.dims.x) * block.dims.y * block.dims.z);
  openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, block.values.data());
  openvdb::tools::copyToDense(grid, dense);  // inactive voxels read as the background
  return block;
}

std::vector<Vec3d> cube_directions() {
  std::vector<Vec3d> dirs;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x || y || z) dirs.push_back(normalize(Vec3d(x, y, z)));
  return dirs;
}

/// Transmittance of one march step as a table over the TF domain (values outside clamp to the end points).
struct StepTransmittance {
  double lo = 0, scale = 0;
  std::vector<float> factor;
  StepTransmittance(const TransferFunction& tf, double exponent, int size = 4096) : factor(std::size_t(size)) {
    lo = tf.domain_min();
    const double span = tf.domain_max() - lo;
    scale = span > 0 ? (size - 1) / span : 0.0;
    for (int i = 0; i < size; ++i)
      factor[std::size_t(i)] = float(std::pow(1.0 - double(tf.opacity(lo + i / std::max(scale, 1e-300))), exponent));
  }
  float at(float f) const {
    if (!(f == f)) return 1.0f;  // NaN is transparent, as in the TF
    const double i = std::clamp((f - lo) * scale, 0.0, double(factor.size() - 1));
    return factor[std::size_t(i + 0.5)];
  }
};

void validate(const IsoVisibilityOptions& o) {
  if (o.rays_per_side < 2) throw InvalidInput("iso visibility: rays_per_side must be >= 2");
  if (!(o.step_voxels > 0 && o.step_voxels <= 4)) throw InvalidInput("iso visibility: step must be in (0, 4]");
  if (!(o.voxel_length > 0) || !std::isfinite(o.voxel_length)) throw InvalidInput("iso visibility: voxel_length must be > 0");
  if (!(o.min_transmittance > 0 && o.min_transmittance < 1))
    throw InvalidInput("iso visibility: min_transmittance must be in (0, 1)");
}

/// Marches one ray through the block, front to back, marking the iso-values whose first crossing it sees.
void march(const DenseBlock& b, const StepTransmittance& step, Span<const double> isos, const IsoVisibilityOptions& o,
           const Vec3d& start, const Vec3d& dir, double length, std::vector<char>& crossed, std::vector<char>& seen) {
  std::fill(crossed.begin(), crossed.end(), char(0));
  double transmittance = 1.0;
  for (double t = 0; t <= length && transmittance > o.min_transmittance; t += o.step_voxels) {
    const Vec3d p = start + dir * t;
    const float f = b.sample(p.x, p.y, p.z);
    for (std::size_t k = 0; k < isos.size(); ++k)
      if (!crossed[k] && f >= isos[k]) {
        crossed[k] = 1;
        seen[k] = 1;  // reached with transmittance above the threshold
      }
    transmittance *= step.at(f);
  }
}

}  // namespace

std::vector<bool> visible_iso_surfaces(const Volume& volume, const TransferFunction& tf, Span<const double> iso_values,
                                       const IsoVisibilityOptions& options) {
  validate(options);
  std::vector<bool> visible(iso_values.size(), true);
  if (volume.is_empty() || iso_values.empty()) return visible;
  const DenseBlock block = densify(*volume.impl().grid);
  const StepTransmittance step(tf, options.step_voxels * options.voxel_length);
  const Vec3d size(block.dims.x - 1, block.dims.y - 1, block.dims.z - 1), centre = size * 0.5;
  const double radius = 0.5 * length(size);
  const std::vector<Vec3d> dirs = cube_directions();
  const int n = options.rays_per_side;
  // One flag vector per direction; OR-ing them afterwards keeps the result independent of scheduling.
  std::vector<std::vector<char>> seen(dirs.size(), std::vector<char>(iso_values.size(), 0));
  auto one_direction = [&](std::size_t d) {
    const Vec3d dir = dirs[d];
    const Vec3d u = normalize(std::abs(dir.x) < 0.9 ? cross(dir, Vec3d(1, 0, 0)) : cross(dir, Vec3d(0, 1, 0)));
    const Vec3d v = cross(dir, u);
    std::vector<char> crossed(iso_values.size());  // per-ray scratch, allocated once per direction
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double s = radius * (2.0 * (i + 0.5) / n - 1.0), r = radius * (2.0 * (j + 0.5) / n - 1.0);
        const Vec3d start = centre + u * s + v * r - dir * radius;
        march(block, step, iso_values, options, start, dir, 2 * radius, crossed, seen[d]);
      }
  };
  parallel_for_each(dirs.size(), one_direction, options.threaded);
  const double background = volume.background();
  for (std::size_t k = 0; k < iso_values.size(); ++k) {
    bool any = iso_values[k] <= background;
    for (const auto& s : seen) any = any || s[k];
    visible[k] = any;
  }
  return visible;
}

}  // namespace raysift::volume
