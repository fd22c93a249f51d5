#pragma once
/// \file The Volume type: a sparse OpenVDB FloatGrid owned by volume/, with its index->world transform.
/// Other modules see only this class; OpenVDB types stay inside volume/ (volume/detail/vdb_grid.h).
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/vec.h"

namespace raysift::volume {

/// Summary of one grid, as printed by `raysift info`. World-space bbox of the active voxels
/// (voxel centres), or all zeros for an empty grid.
struct GridInfo {
  std::string name;
  std::string type;          ///< OpenVDB value type name ("float", "vec3s", ...)
  std::string grid_class;    ///< "fog volume", "level set", "unknown"
  std::uint64_t active_voxels = 0;
  Vec3i index_min, index_max;  ///< inclusive active-voxel bbox, index space
  Vec3d bbox_min, bbox_max;    ///< world space
  Vec3d voxel_size;
  double value_min = 0, value_max = 0;  ///< over active voxels
  double background = 0;
};

/// Dense description used by generators and importers: values at integer index (i,j,k),
/// 0 <= i < dims.x etc., x fastest.
struct DenseSpec {
  Vec3i dims;
  Vec3d voxel_size{1, 1, 1};
  Vec3d origin_ws{0, 0, 0};    ///< world position of voxel (0,0,0)
  /// If set, axes_ws[a] is the world step of index axis a (rotation, shear and flips allowed; voxel_size is
  /// then ignored): world = origin_ws + i*axes_ws[0] + j*axes_ws[1] + k*axes_ws[2]. The axes must be
  /// linearly independent.
  std::optional<std::array<Vec3d, 3>> axes_ws = std::nullopt;
  float background = 0.0f;
  float tolerance = 0.0f;      ///< |v - background| <= tolerance stays inactive
};

/// Upper bound on the memory of a grid with `active_voxels` active voxels in 8^3 leaves: 4 bytes per value
/// plus the leaf masks and headers (about 4.3 bytes per voxel), rounded up to 4.5. Saturates at UINT64_MAX.
std::uint64_t grid_bytes_upper_bound(std::uint64_t active_voxels);
/// grid_bytes_upper_bound of a grid with every voxel of `dims` active (0 if a dim is not positive).
std::uint64_t dense_grid_bytes_upper_bound(const Vec3i& dims);

class Volume {
 public:
  struct Impl;  ///< defined in volume/detail/vdb_grid.h (OpenVDB types)

  Volume();
  explicit Volume(std::shared_ptr<Impl> impl);

  /// Builds a sparse grid from a dense value function, in parallel. Voxels equal to the background
  /// within the tolerance stay inactive. \throw InvalidInput for non-positive dims or voxel size, or
  /// axes_ws that are not finite and linearly independent.
  static Volume from_function(const DenseSpec& spec, const std::function<float(int i, int j, int k)>& value,
                              const std::string& name = "density");

  std::string name() const;
  bool is_empty() const;           ///< no active voxels
  std::uint64_t active_voxel_count() const;
  Vec3d voxel_size() const;
  float background() const;
  GridInfo info() const;

  /// Value at an index-space position (trilinear), for tests and tools; not for hot loops.
  float sample_index(const Vec3d& p_is) const;
  float value_at(const Vec3i& ijk) const;
  Vec3d index_to_world(const Vec3d& p_is) const;
  Vec3d world_to_index(const Vec3d& p_ws) const;

  const Impl& impl() const { return *impl_; }

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace raysift::volume
