#pragma once
/// \file Pinhole camera. World space is right-handed; pixel (0,0) is the top-left pixel and pixel
/// centres sit at +0.5. right = normalize(forward × up), image up = right × forward, so a scene looks
/// as it would in ParaView.
#include <optional>

#include "core/vec.h"

namespace raysift {

/// Plain camera description, as stored in JSON (keys eye, target, up, fov_y_deg, width, height).
struct CameraSpec {
  Vec3d eye{0, 0, 5};
  Vec3d target{0, 0, 0};
  Vec3d up{0, 1, 0};
  double fov_y_deg = 45.0;  ///< vertical field of view, degrees, in (0, 180)
  int width = 512;          ///< pixels, 1..kMaxImageSide
  int height = 512;         ///< pixels, 1..kMaxImageSide
};

inline constexpr int kMaxImageSide = 16384;

/// A world-space ray; `direction` has unit length.
struct Ray {
  Vec3d origin;
  Vec3d direction;
};

/// Where a world point lands in the image.
struct PixelProjection {
  double x_ss = 0;   ///< continuous pixel coordinate (pixel centres at +0.5)
  double y_ss = 0;
  double depth = 0;  ///< view depth: distance along the forward axis, > 0 in front of the eye
};

/// A validated camera with its orthonormal basis precomputed.
class Camera {
 public:
  /// \throw InvalidInput for non-finite values, eye == target, up (nearly) parallel to the view
  ///        direction, fov outside (0,180) degrees, or an image side outside 1..kMaxImageSide.
  explicit Camera(const CameraSpec& spec);

  const CameraSpec& spec() const { return spec_; }
  int width() const { return spec_.width; }
  int height() const { return spec_.height; }
  const Vec3d& eye() const { return spec_.eye; }
  const Vec3d& forward() const { return forward_; }
  const Vec3d& right() const { return right_; }
  const Vec3d& image_up() const { return up_; }

  /// Ray through the continuous pixel position (x_ss, y_ss); the centre of pixel (i,j) is (i+0.5, j+0.5).
  Ray ray(double x_ss, double y_ss) const;
  /// Unnormalised direction through (x_ss, y_ss) whose forward component is exactly 1, so that
  /// t along it equals view depth.
  Vec3d direction_unit_depth(double x_ss, double y_ss) const;
  /// Projection of a world point; empty when the point is not strictly in front of the eye.
  std::optional<PixelProjection> project(const Vec3d& p_ws) const;

 private:
  CameraSpec spec_;
  Vec3d forward_, right_, up_;
  double tan_half_y_ = 0, tan_half_x_ = 0;
};

}  // namespace raysift
