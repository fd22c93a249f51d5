#pragma once
/// \file Analytic test volumes (ball, nested shells, Gaussian blobs, torus, empty, single voxel) as sparse
/// `Volume`s, for tests, benchmarks and `raysift make-volume`.
///
/// One iso convention everywhere ("fog style"): a solid of density d has value d inside, 0 outside, and
/// a 1-voxel linear ramp across its boundary, centred on the analytic surface. So the iso-value d/2 lies
/// exactly on the analytic surface (sphere radius r, torus tube radius r, ...) and marching cubes or a
/// ray caster see a smooth surface instead of voxel stairs. Voxels with value 0 (the background) stay
/// inactive. All lengths are in voxels (index space); world = index * voxel_size, voxel (0,0,0) at the
/// world origin.
#include <cstdint>
#include <optional>
#include <string>

#include "core/vec.h"
#include "volume/volume.h"

namespace raysift::volume {

/// Grid shared by every generator.
struct GridSpec {
  Vec3i dims{64, 64, 64};            ///< voxels along x, y, z; each > 0
  double voxel_size = 1.0;           ///< world units per voxel (uniform), > 0
  std::optional<Vec3d> center_is;    ///< shape centre in index space; default the volume centre (dims-1)/2
  std::string name = "density";      ///< grid name
};

/// Homogeneous ball: value d for distance <= r - 1/2, 0 beyond r + 1/2, linear in between (d/2 at r).
struct BallOptions {
  GridSpec grid;
  double radius_voxels = 24.0;  ///< > 0
  float density = 1.0f;         ///< > 0, finite
};

/// `count` concentric spherical shells of equal density d. Shell i (0 = outermost) has outer radius
/// R_i = outer_radius * (count - i) / count and inner radius R_i - thickness, each boundary with the
/// 1-voxel ramp, so iso d/2 gives 2 * count spheres at exactly those radii.
struct ShellsOptions {
  GridSpec grid;
  int count = 3;                    ///< >= 1
  double outer_radius_voxels = 28.0;  ///< > 0
  double thickness_voxels = 3.0;    ///< > 1 (the ramps need room) and < outer_radius / count (shells stay apart)
  float density = 1.0f;
};

/// Sum of `count` isotropic Gaussians d * exp(-|x - c|^2 / (2 sigma^2)). Centres are uniform in the box
/// shrunk by 3 sigma (by hash(blob index, seed), independent of threads). Values below cutoff * d stay
/// inactive. An isolated blob crosses d/2 at distance sigma * sqrt(2 ln 2) = 1.1774 sigma from its centre.
/// `center_is` is ignored.
struct BlobsOptions {
  GridSpec grid;
  int count = 8;                 ///< >= 1
  double sigma_voxels = 4.0;     ///< > 0
  float density = 1.0f;          ///< peak of one blob
  std::uint64_t seed = 1;
  float cutoff = 1e-3f;          ///< relative to density, in [0, 1)
};

/// Torus around the z axis through the centre: ring radius R (major), tube radius r (minor). Fog style like
/// the ball: value d within r - 1/2 of the ring circle, 0 beyond r + 1/2, iso d/2 exactly at tube radius r.
/// (Not a signed-distance level set, so one iso convention works for every generated volume.)
struct TorusOptions {
  GridSpec grid;
  double major_radius_voxels = 20.0;  ///< > minor radius
  double minor_radius_voxels = 6.0;   ///< > 0
  float density = 1.0f;
};

/// One active voxel of value d, at `ijk` or (default) the voxel nearest the centre.
struct SingleVoxelOptions {
  GridSpec grid;
  std::optional<Vec3i> ijk;  ///< must lie inside the dims
  float density = 1.0f;
};

/// \throw InvalidInput for any out-of-range option (message names the option, its range and the value).
Volume make_ball(const BallOptions& options = {});
/// \throw InvalidInput as make_ball.
Volume make_shells(const ShellsOptions& options = {});
/// \throw InvalidInput as make_ball.
Volume make_blobs(const BlobsOptions& options = {});
/// \throw InvalidInput as make_ball.
Volume make_torus(const TorusOptions& options = {});
/// A volume with the given grid and no active voxels. \throw InvalidInput for bad dims or voxel size.
Volume make_empty(const GridSpec& grid = {});
/// \throw InvalidInput as make_ball, or when `ijk` lies outside the dims.
Volume make_single_voxel(const SingleVoxelOptions& options = {});

}  // namespace raysift::volume
