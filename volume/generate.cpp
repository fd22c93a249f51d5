#include "volume/generate.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "core/errors.h"
#include "core/hash.h"

namespace raysift::volume {

namespace {

void require(bool ok, const std::string& option, const std::string& range, double got) {
  if (ok) return;
  std::ostringstream s;
  s << "make-volume: " << option << " must be " << range << ", got " << got;
  throw InvalidInput(s.str());
}

void validate_grid(const GridSpec& g) {
  require(g.dims.x > 0 && g.dims.y > 0 && g.dims.z > 0, "dims", "positive on every axis",
          std::min({g.dims.x, g.dims.y, g.dims.z}));
  require(g.voxel_size > 0 && std::isfinite(g.voxel_size), "voxel size", "> 0 and finite", g.voxel_size);
  if (g.center_is) require(is_finite(*g.center_is), "centre", "finite", g.center_is->x + g.center_is->y + g.center_is->z);
}

void validate_density(float d) { require(d > 0 && std::isfinite(d), "density", "> 0 and finite", d); }

Vec3d center_of(const GridSpec& g) {
  return g.center_is ? *g.center_is : Vec3d(g.dims.x - 1, g.dims.y - 1, g.dims.z - 1) * 0.5;
}

DenseSpec dense_spec(const GridSpec& g, float tolerance = 0.0f) {
  DenseSpec spec;
  spec.dims = g.dims;
  spec.voxel_size = {g.voxel_size, g.voxel_size, g.voxel_size};
  spec.tolerance = tolerance;
  return spec;
}

/// The 1-voxel boundary ramp: 1 at signed distance <= -1/2 (inside), 0 at >= +1/2, 1/2 on the surface.
inline double ramp(double signed_distance) { return std::clamp(0.5 - signed_distance, 0.0, 1.0); }

inline double distance(int i, int j, int k, const Vec3d& c) {
  return length(Vec3d(i - c.x, j - c.y, k - c.z));
}

/// Uniform in [0, 1) from (index, seed).
double hash_uniform(std::uint64_t index, std::uint64_t seed) {
  return unit_double(mix64(mix64(index) ^ seed));
}

}  // namespace

Volume make_ball(const BallOptions& o) {
  validate_grid(o.grid);
  validate_density(o.density);
  require(o.radius_voxels > 0 && std::isfinite(o.radius_voxels), "radius", "> 0", o.radius_voxels);
  const Vec3d c = center_of(o.grid);
  const double r = o.radius_voxels, d = o.density;
  return Volume::from_function(dense_spec(o.grid),
                               [&](int i, int j, int k) { return float(d * ramp(distance(i, j, k, c) - r)); },
                               o.grid.name);
}

Volume make_shells(const ShellsOptions& o) {
  validate_grid(o.grid);
  validate_density(o.density);
  require(o.count >= 1, "shell count", ">= 1", o.count);
  require(o.outer_radius_voxels > 0 && std::isfinite(o.outer_radius_voxels), "outer radius", "> 0",
          o.outer_radius_voxels);
  const double spacing = o.outer_radius_voxels / o.count;
  // Each ramp is 1 voxel wide: thickness > 1 keeps a shell's two ramps apart, and a gap of > 1 voxel
  // between shells keeps neighbouring shells apart, so every iso-d/2 sphere sits at its analytic radius.
  require(o.thickness_voxels > 1 && o.thickness_voxels < spacing - 1, "shell thickness",
          "in (1, outer_radius/count - 1) = (1, " + std::to_string(spacing - 1) + ")", o.thickness_voxels);
  const Vec3d c = center_of(o.grid);
  const double d = o.density, t = o.thickness_voxels;
  return Volume::from_function(
      dense_spec(o.grid),
      [&](int i, int j, int k) {
        const double dist = distance(i, j, k, c);
        // Only the shell whose outer radius is nearest above dist can cover this voxel.
        const int shell = std::clamp(int(std::floor((o.outer_radius_voxels + 0.5 - dist) / spacing)), 0, o.count - 1);
        const double outer = o.outer_radius_voxels - shell * spacing;
        const double inner = outer - t;
        return float(d * std::min(ramp(dist - outer), ramp(inner - dist)));
      },
      o.grid.name);
}

Volume make_blobs(const BlobsOptions& o) {
  validate_grid(o.grid);
  validate_density(o.density);
  require(o.count >= 1, "blob count", ">= 1", o.count);
  require(o.sigma_voxels > 0 && std::isfinite(o.sigma_voxels), "blob sigma", "> 0", o.sigma_voxels);
  require(o.cutoff >= 0 && o.cutoff < 1, "blob cutoff", "in [0, 1)", o.cutoff);
  std::vector<Vec3d> centers(std::size_t(o.count));
  for (int b = 0; b < o.count; ++b)
    for (int axis = 0; axis < 3; ++axis) {
      // Keep centres 3 sigma from the faces where the box allows it, else spread over the whole axis.
      const double hi = o.grid.dims[axis] - 1.0;
      const double margin = std::min(3.0 * o.sigma_voxels, 0.5 * hi);
      centers[std::size_t(b)][axis] =
          margin + hash_uniform(std::uint64_t(b) * 3 + std::uint64_t(axis), o.seed) * (hi - 2 * margin);
    }
  const double d = o.density, inv_two_sigma2 = 1.0 / (2.0 * o.sigma_voxels * o.sigma_voxels);
  return Volume::from_function(
      dense_spec(o.grid, o.cutoff * o.density),
      [&](int i, int j, int k) {
        double sum = 0;
        for (const Vec3d& c : centers) {
          const Vec3d v(i - c.x, j - c.y, k - c.z);
          sum += std::exp(-dot(v, v) * inv_two_sigma2);
        }
        return float(d * sum);
      },
      o.grid.name);
}

Volume make_torus(const TorusOptions& o) {
  validate_grid(o.grid);
  validate_density(o.density);
  require(o.minor_radius_voxels > 0 && std::isfinite(o.minor_radius_voxels), "torus minor radius", "> 0",
          o.minor_radius_voxels);
  require(o.major_radius_voxels > o.minor_radius_voxels && std::isfinite(o.major_radius_voxels),
          "torus major radius", "> minor radius (" + std::to_string(o.minor_radius_voxels) + ")",
          o.major_radius_voxels);
  const Vec3d c = center_of(o.grid);
  const double big_r = o.major_radius_voxels, small_r = o.minor_radius_voxels, d = o.density;
  return Volume::from_function(
      dense_spec(o.grid),
      [&](int i, int j, int k) {
        const double radial = std::hypot(i - c.x, j - c.y) - big_r;  // distance from the ring, in its plane
        return float(d * ramp(std::hypot(radial, k - c.z) - small_r));
      },
      o.grid.name);
}

Volume make_empty(const GridSpec& grid) {
  validate_grid(grid);
  return Volume::from_function(dense_spec(grid), [](int, int, int) { return 0.0f; }, grid.name);
}

Volume make_single_voxel(const SingleVoxelOptions& o) {
  validate_grid(o.grid);
  validate_density(o.density);
  const Vec3d c = center_of(o.grid);
  const Vec3i at = o.ijk ? *o.ijk
                         : Vec3i(int(std::floor(c.x + 0.5)), int(std::floor(c.y + 0.5)), int(std::floor(c.z + 0.5)));
  for (int axis = 0; axis < 3; ++axis)
    require(at[axis] >= 0 && at[axis] < o.grid.dims[axis], std::string("voxel index ") + "xyz"[axis],
            "in [0, " + std::to_string(o.grid.dims[axis]) + ")", at[axis]);
  const float d = o.density;
  return Volume::from_function(
      dense_spec(o.grid), [&](int i, int j, int k) { return Vec3i(i, j, k) == at ? d : 0.0f; }, o.grid.name);
}

}  // namespace raysift::volume
