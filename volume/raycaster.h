#pragma once
/// \file Emission-absorption volume ray caster over a sparse Volume, callable ray by ray.
///
/// API (the contract the prioritized renderer in sampling/ builds on):
///   RayCaster caster(volume, tf, camera_spec, options);   // validates, builds LUT + skip blocks
///   RaySample s = caster.trace(x, y);                      // one pixel centre; thread-safe, no allocation
///   caster.trace_pixels(indices, out);                     // pixel index = y * width + x, any order/subset
///   caster.pixel_is_background(x, y);                      // ray misses every TF-visible block
///   Image<uint8_t> bg = caster.background_mask();          // the same test for every pixel, fast
///   Rgba final = composite_over_background(s.color, caster.options().background);
///   RenderResult r = render_full(caster);                  // all pixels, TBB tiles, deterministic
/// A RaySample is premultiplied and NOT yet composited over the background; every render mode must
/// use composite_over_background() so that they agree bit for bit.
///
/// Optics (ALGORITHMS.md §8): front-to-back compositing of samples at t_k = t_entry + (k + ξ)·Δt
/// along the index-space ray, trilinear reconstruction, TF opacity defined per voxel length and
/// corrected to α_s = 1 − (1 − α)^s for a step of s voxels. Empty-space skipping works on 8³ blocks
/// (the OpenVDB leaf size) whose sample value range maps to exactly zero opacity; it skips whole steps, so the
/// sample lattice and hence the image are identical with and without it.
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>

#include "core/camera.h"
#include "core/image.h"
#include "core/span.h"
#include "volume/transfer_function.h"
#include "volume/volume.h"

namespace raysift::volume {

enum class Shading { None, Phong };

/// Blinn-Phong parameters (ALGORITHMS.md §8 defaults). Lighting is two-sided (|n·l|).
struct PhongParams {
  float ambient = 0.2f, diffuse = 0.7f, specular = 0.3f, shininess = 20.0f;
  bool headlight = true;              ///< light from the eye; otherwise `light_dir_ws`
  Vec3d light_dir_ws{0, 0, -1};       ///< direction the light travels (world), used when !headlight
  /// Gradient magnitude (value units per voxel) below which only the ambient+emission term is used:
  /// flat regions have noisy gradient directions.
  double min_gradient = 1e-3;
};

/// Sort-last rendering (mpi/data_parallel.h): a rank that holds one brick of the volume renders only the ray
/// segment inside it. Samples stay on the whole volume's lattice t_k = t_entry + (k + ξ)·Δt, with t_entry
/// taken from `lattice_min/max` (the whole grid's active voxel bbox, inclusive) instead of this rank's grid,
/// and a sample is kept iff its index-space position p satisfies lo <= p < hi on every axis. Bricks that
/// tile space with shared planes thus own every sample position exactly once.
struct SegmentClip {
  bool enabled = false;
  Vec3d lo{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
           -std::numeric_limits<double>::infinity()};
  Vec3d hi{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
           std::numeric_limits<double>::infinity()};
  Vec3i lattice_min, lattice_max;
};

struct RenderOptions {
  double step_voxels = 0.5;           ///< sample distance in voxels (index-space length), in (0, 64]
  Shading shading = Shading::None;
  PhongParams phong;
  Vec3f background{0, 0, 0};          ///< linear RGB composited behind the volume
  double early_termination = 0.99;    ///< stop when accumulated opacity >= this; 1 disables; in (0, 1]
  bool skip_empty_space = true;       ///< false = brute force (same image, more samples)
  bool jitter = false;                ///< random start offset ξ per pixel instead of 0.5
  std::uint64_t seed = 1;             ///< jitter seed: ξ = hash(pixel, seed)
  int lut_size = 4096;                ///< transfer-function table entries, >= 2
  SegmentClip clip;                   ///< disabled: the whole ray
};

/// One traced ray.
struct RaySample {
  Rgba color;                          ///< premultiplied RGBA, before compositing over the background
  float depth = std::numeric_limits<float>::infinity();  ///< world distance from the eye where the
                                       ///< accumulated opacity first reached 0.5; +inf if never
  std::uint32_t samples = 0;           ///< volume samples taken (TF lookups)
};

/// The one compositing rule every render mode uses: linear RGB = C + (1 − A)·background, alpha = A.
inline Rgba composite_over_background(const Rgba& premultiplied, const Vec3f& background) {
  const float t = 1.0f - premultiplied.a;
  return {premultiplied.r + t * background.x, premultiplied.g + t * background.y,
          premultiplied.b + t * background.z, premultiplied.a};
}

/// TF- and camera-independent acceleration data of a volume: 9³ bricks (each 8³ leaf block plus a
/// one-voxel apron) and per-block value ranges. Defined in volume/detail/brick_cache.h.
struct VolumeBricks;

/// Builds the bricks once so that several RayCasters (new TF, new camera) can share them.
/// Memory: 2.9 KB per 8³ block whose trilinear support is not constant.
std::shared_ptr<const VolumeBricks> build_volume_bricks(const Volume& volume);
/// For a clipped caster (a brick of a larger grid): the block table the whole grid has over the cells the clip
/// owns (and one more on each side, for gradients), so that its blocks, value ranges and hence its visibility
/// and background test are the whole grid's there. \pre `volume` holds the whole grid's voxels of those blocks
/// and their apron (mpi's bricks: 2 ghost layers, planes on 8³ block boundaries).
std::shared_ptr<const VolumeBricks> build_volume_bricks(const Volume& volume, const SegmentClip& clip);

/// \warning Thread-safe for concurrent trace calls (no per-thread state: samples read the immutable
/// bricks). Not copyable. Construction costs one pass over the tree's leaves unless bricks are passed in.
class RayCaster {
 public:
  /// \throw InvalidInput for a step outside (0, 64], early termination outside (0, 1], lut_size < 2,
  ///        a non-finite background, a grid transform that is not linear, or an invalid camera
  ///        (see Camera).
  RayCaster(const Volume& volume, const TransferFunction& tf, const CameraSpec& camera,
            const RenderOptions& options = {});
  /// Same, reusing bricks from build_volume_bricks(volume) (recomputes only the TF-dependent
  /// visibility of each block). \pre `bricks` was built from `volume`.
  RayCaster(const Volume& volume, std::shared_ptr<const VolumeBricks> bricks, const TransferFunction& tf,
            const CameraSpec& camera, const RenderOptions& options = {});
  ~RayCaster();
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  const Camera& camera() const;
  const RenderOptions& options() const;
  int width() const;
  int height() const;

  /// Traces the ray through the centre of pixel (x, y). \pre 0 <= x < width, 0 <= y < height.
  RaySample trace(int x, int y) const;
  /// out[i] = trace(pixel_indices[i] % width, pixel_indices[i] / width). \pre same sizes, valid indices.
  void trace_pixels(Span<const std::uint32_t> pixel_indices, Span<RaySample> out) const;
  /// True iff the pixel's ray misses every TF-visible 8³ block, each block taken as a closed index-space
  /// box clipped to the volume's domain and grown by 1e-6 voxels (covering the rounding of the sample
  /// positions). Then trace() returns transparent black (with zero samples when skipping is on).
  /// The exact reference of background_mask(): up to one ray-box test per visible block on the
  /// volume's outer surface, so use the mask for whole frames.
  bool pixel_is_background(int x, int y) const;
  /// pixel_is_background() for every pixel (1 = background), equal to it pixel for pixel, from the screen
  /// footprints of the visible blocks' outer faces: a pixel whose centre lies clearly inside a footprint
  /// hits; only centres within 0.01 px of a footprint edge get the exact ray-box test. An eye inside a
  /// visible block sees no background; an eye within one block of one falls back to the per-pixel test.
  /// Identical for any thread count.
  Image<std::uint8_t> background_mask(bool threaded = true) const;

  /// Number of 8³ blocks with a non-zero opacity somewhere in their value range (diagnostics).
  std::uint64_t visible_block_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct RenderResult {
  ImageRGBA image;        ///< linear RGB composited over the background, alpha = accumulated opacity
  ImageF depth;           ///< RaySample::depth per pixel (+inf where opacity never reached 0.5)
  std::uint64_t rays_traced = 0;
  std::uint64_t samples = 0;
};

/// Default view of a volume: core/camera_fit.h's fit_camera_to_box of the active voxels' world box (an empty
/// volume gets the view of a unit box at the origin).
/// \throw InvalidInput for an image side outside 1..kMaxImageSide.
CameraSpec fit_camera(const Volume& volume, int width, int height);

/// Called with the finished fraction in [0,1], from worker threads (must be thread-safe).
using ProgressCallback = std::function<void(double fraction)>;

/// Bytes render_full() allocates for a width×height frame (colour and depth per pixel). The caster's own tables
/// grow with the volume, not the image, and are not counted.
std::uint64_t render_full_bytes(int width, int height);

/// Traces every pixel in 32×32 tiles with TBB; the image is identical for any thread count.
/// `threaded = false` runs serially (for debugging).
RenderResult render_full(const RayCaster& caster, const ProgressCallback& progress = {}, bool threaded = true);

}  // namespace raysift::volume
