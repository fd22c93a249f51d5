#pragma once
// Scenes the NRR benches share beyond nrr/scenes.h's grass and urban: a procedural "Lucy-like" statue (held
// out: nothing in the library was written against it) and the real dragon tower mesh from the shared
// datasets, each with three views on a triangle of eyes in front of and above it. Header-only because every
// bench is one translation unit (bench/CMakeLists.txt).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/bench_data.h"
#include "core/camera.h"
#include "core/tri_mesh.h"
#include "mesh/mesh_io.h"
#include "volume/marching_cubes.h"
#include "volume/volume.h"

namespace raysift::bench {

struct NamedScene {
  std::string name;
  TriMesh mesh;
  std::vector<CameraSpec> views;  ///< three reference views; width/height set by the caller
};

/// Three eyes on a triangle in front of (+z) and above the mesh, looking at its centre, fov 40 degrees.
inline std::vector<CameraSpec> views_around(const TriMesh& m) {
  Bbox3d box;
  for (const Vec3f& p : m.positions) box.expand(Vec3d(p));
  const Vec3d c = box.center();
  const double d = box.diagonal();
  std::vector<CameraSpec> views;
  for (const Vec3d& offset : {Vec3d{-0.35, 0.3, 1.0}, Vec3d{0.35, 0.3, 1.0}, Vec3d{0.0, 0.6, 0.9}}) {
    CameraSpec v;
    v.eye = c + offset * (1.3 * d);
    v.target = c;
    v.up = {0, 1, 0};
    v.fov_y_deg = 40.0;
    views.push_back(v);
  }
  return views;
}

namespace detail {

inline double capsule_sdf(const Vec3d& p, const Vec3d& a, const Vec3d& b, double r) {
  const Vec3d pa = p - a, ba = b - a;
  const double h = std::clamp(dot(pa, ba) / dot(ba, ba), 0.0, 1.0);
  return length(pa - ba * h) - r;
}

/// Ellipsoid distance bound (exact for spheres; fine for an iso-surface, which only needs the zero set).
inline double ellipsoid_sdf(const Vec3d& p, const Vec3d& c, const Vec3d& r) {
  const Vec3d q{(p.x - c.x) / r.x, (p.y - c.y) / r.y, (p.z - c.z) / r.z};
  return (length(q) - 1.0) * std::min({r.x, r.y, r.z});
}

/// Polynomial smooth minimum with blend radius k, so limbs merge without creases.
inline double smooth_min(double a, double b, double k) {
  const double h = std::clamp(0.5 + 0.5 * (b - a) / k, 0.0, 1.0);
  return b + (a - b) * h - k * h * (1.0 - h);
}

/// Signed distance (world units, statue 1 tall, y up, facing +z) of a robed, winged figure on a pedestal
/// raising one arm, the silhouette of the Stanford Lucy; robe folds and feather ridges are small sine
/// displacements so the surface has detail at every scale down to the voxel.
inline double lucy_sdf(const Vec3d& p) {
  double d = ellipsoid_sdf(p, {0, 0.04, 0}, {0.2, 0.04, 0.16});                               // pedestal
  d = smooth_min(d, capsule_sdf(p, {0, 0.08, 0}, {0, 0.55, 0.01}, 0.085 + 0.05 * (0.55 - p.y)), 0.04);  // robe
  d = smooth_min(d, ellipsoid_sdf(p, {0, 0.62, 0.01}, {0.085, 0.11, 0.06}), 0.04);            // torso
  d = smooth_min(d, ellipsoid_sdf(p, {0, 0.79, 0.02}, {0.045, 0.058, 0.05}), 0.02);           // head
  d = smooth_min(d, capsule_sdf(p, {0.07, 0.68, 0.01}, {0.13, 0.86, 0.06}, 0.022), 0.02);     // raised arm
  d = smooth_min(d, capsule_sdf(p, {0.13, 0.86, 0.06}, {0.12, 0.99, 0.08}, 0.016), 0.01);     // torch
  d = smooth_min(d, capsule_sdf(p, {-0.07, 0.68, 0.01}, {-0.11, 0.52, 0.09}, 0.02), 0.02);    // lowered arm
  for (double side : {-1.0, 1.0}) {  // wings: thin slabs spreading back and up from the shoulders
    const Vec3d w{side * 0.19, 0.7, -0.12};
    d = smooth_min(d, ellipsoid_sdf(p, w, {0.17, 0.24, 0.022}) + 0.004 * std::sin(90.0 * p.y), 0.03);
  }
  const double folds = 0.005 * std::sin(70.0 * std::atan2(p.x, p.z + 1e-9) + 9.0 * p.y) * (p.y < 0.56 ? 1.0 : 0.3);
  return d + folds + 0.0015 * std::sin(210.0 * p.x) * std::sin(190.0 * p.y) * std::sin(230.0 * p.z);
}

}  // namespace detail

/// The Lucy-like statue, marching cubes of lucy_sdf on a grid of `voxel` world units (statue height 1).
/// The default makes triangles about 2 pixels across in a 512^2 view from views_around(); halving the
/// voxel quarters their area.
inline TriMesh make_lucy_like(double voxel = 0.0058) {
  const Vec3d lo{-0.42, -0.02, -0.22}, hi{0.42, 1.04, 0.2};
  volume::DenseSpec spec;
  spec.dims = {int((hi.x - lo.x) / voxel) + 1, int((hi.y - lo.y) / voxel) + 1, int((hi.z - lo.z) / voxel) + 1};
  spec.voxel_size = {voxel, voxel, voxel};
  spec.origin_ws = lo;
  // Fog style (volume/generate.h): 1 inside, 0 outside, a one-voxel ramp across the surface; iso 0.5.
  const volume::Volume vol = volume::Volume::from_function(spec, [&](int i, int j, int k) {
    const double sdf = detail::lucy_sdf(lo + Vec3d{double(i), double(j), double(k)} * voxel) / voxel;
    return float(std::clamp(0.5 - sdf, 0.0, 1.0));
  });
  return volume::extract_isosurface(vol, 0.5);
}

/// The dragon tower of the shared datasets (97K triangles), or an empty scene when it is absent.
inline NamedScene dragon_tower_scene() {
  const std::string path = shared_dataset("dragon_tower_with_window_holes_49291v_97374tri.obj");
  if (!std::filesystem::exists(path)) return {"dragon_tower", {}, {}};
  TriMesh m = mesh::read_mesh(path);
  std::vector<CameraSpec> views = views_around(m);
  return {"dragon_tower", std::move(m), std::move(views)};
}

inline NamedScene lucy_like_scene() {
  TriMesh m = make_lucy_like();
  std::vector<CameraSpec> views = views_around(m);
  return {"lucy_like", std::move(m), std::move(views)};
}

}  // namespace raysift::bench
