#pragma once
/// \file A rectangular area light sampled at N x N cell centres (NRR §6.2; ALGORITHMS.md §9).
/// Key decision: the light is one-sided. It emits into the half-space on the side of edge_u x edge_v,
/// so a point behind (or on) the light plane receives nothing from any sample. A light whose edges
/// are both zero is a point light and emits in every direction.
#include <string>
#include <vector>

#include "core/json_io.h"
#include "core/vec.h"

namespace raysift::nrr {

/// World-space rectangle: centre plus full edge vectors (the corners are centre +- edge_u/2 +- edge_v/2).
struct AreaLight {
  Vec3d center;
  Vec3d edge_u;
  Vec3d edge_v;

  /// Unit normal edge_u x edge_v (the emitting side), or the zero vector for a point light.
  Vec3d normal() const;
  /// Corner i in {0,1,2,3}: c - u/2 - v/2, c + u/2 - v/2, c + u/2 + v/2, c - u/2 + v/2.
  Vec3d corner(int i) const;
  /// |edge_u + edge_v|, world units (0 for a point light).
  double diagonal() const;
  bool is_point() const;
  /// True if the light emits toward p (always true for a point light).
  bool emits_toward(const Vec3d& p_ws) const;
};

/// Parses {"center": [x,y,z], "edge_u": [x,y,z], "edge_v": [x,y,z]}.
/// \throw InvalidInput naming `where` for a missing key, non-finite values, edges that are not
///        perpendicular (|cos| > 1e-3), or exactly one zero edge (a line light).
AreaLight area_light_from_json(const Json& j, const std::string& where);
Json area_light_to_json(const AreaLight& light);

/// The same light with its edges scaled so that its diagonal equals `diagonal` (world units).
/// \throw InvalidInput if diagonal < 0 or is not finite, or if the light is a point (no direction to scale).
AreaLight rescale_light(const AreaLight& light, double diagonal);

/// The n x n cell-centre samples c - u/2 - v/2 + ((m+0.5)/n) u + ((k+0.5)/n) v, index m + n*k.
/// n = 1 gives the centre. \throw InvalidInput if n < 1 or n > 256.
std::vector<Vec3d> light_samples(const AreaLight& light, int n);

/// A square light of diagonal `diagonal_rel` x the box diagonal, centred over the box along `up` at
/// `height_rel` box diagonals above the box's top, emitting toward -up (the benchmark and test setup;
/// the NRR experiments use diagonal_rel = 1). \pre box not empty, up unit length.
AreaLight light_above_box(const Bbox3d& box, const Vec3d& up, double diagonal_rel, double height_rel = 0.5);

/// A unit vector perpendicular to v (zero for v = 0); used to complete view frames.
Vec3d any_perpendicular(const Vec3d& v);

}  // namespace raysift::nrr
