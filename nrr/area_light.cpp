#include "nrr/area_light.h"

#include <cmath>

#include "core/errors.h"

namespace raysift::nrr {

namespace {
// Relative: |cos| of the edge angle above which the light is not a rectangle.
constexpr double kEdgePerpendicularCos = 1e-3;
constexpr int kMaxSamplesPerSide = 256;
}  // namespace

Vec3d AreaLight::normal() const { return normalize(cross(edge_u, edge_v)); }

Vec3d AreaLight::corner(int i) const {
  RAYSIFT_CHECK(i >= 0 && i < 4);
  const double su = (i == 1 || i == 2) ? 0.5 : -0.5;
  const double sv = (i >= 2) ? 0.5 : -0.5;
  return center + edge_u * su + edge_v * sv;
}

double AreaLight::diagonal() const { return length(edge_u + edge_v); }

bool AreaLight::is_point() const { return length(edge_u) == 0.0 && length(edge_v) == 0.0; }

bool AreaLight::emits_toward(const Vec3d& p_ws) const {
  return is_point() || dot(p_ws - center, normal()) > 0.0;
}

AreaLight area_light_from_json(const Json& j, const std::string& where) {
  if (!j.is_object()) throw InvalidInput(where + ": expected a light object {center, edge_u, edge_v}, got " + j.dump());
  for (const char* key : {"center", "edge_u", "edge_v"})
    if (!j.contains(key)) throw InvalidInput(where + ": missing key \"" + key + "\" (expected center, edge_u, edge_v)");
  AreaLight light{vec3_from_json(j["center"], where + ".center"), vec3_from_json(j["edge_u"], where + ".edge_u"),
                  vec3_from_json(j["edge_v"], where + ".edge_v")};
  const double lu = length(light.edge_u), lv = length(light.edge_v);
  if ((lu == 0.0) != (lv == 0.0))
    throw InvalidInput(where + ": one edge is zero and the other is not (a line light); give two edges or none");
  if (lu > 0.0 && std::abs(dot(light.edge_u, light.edge_v)) > kEdgePerpendicularCos * lu * lv)
    throw InvalidInput(where + ": edge_u and edge_v must be perpendicular (a rectangle)");
  return light;
}

Json area_light_to_json(const AreaLight& light) {
  return Json{{"center", vec3_to_json(light.center)},
              {"edge_u", vec3_to_json(light.edge_u)},
              {"edge_v", vec3_to_json(light.edge_v)}};
}

AreaLight rescale_light(const AreaLight& light, double diagonal) {
  if (!std::isfinite(diagonal) || diagonal < 0.0)
    throw InvalidInput("light size: expected a finite size >= 0, got " + std::to_string(diagonal));
  if (light.is_point()) throw InvalidInput("light size: cannot rescale a point light (both edges are zero)");
  const double scale = diagonal / light.diagonal();
  return AreaLight{light.center, light.edge_u * scale, light.edge_v * scale};
}

std::vector<Vec3d> light_samples(const AreaLight& light, int n) {
  if (n < 1 || n > kMaxSamplesPerSide)
    throw InvalidInput("light samples: expected 1.." + std::to_string(kMaxSamplesPerSide) + " per side, got " +
                       std::to_string(n));
  std::vector<Vec3d> samples;
  samples.reserve(std::size_t(n) * std::size_t(n));
  const Vec3d origin = light.corner(0);
  for (int k = 0; k < n; ++k)
    for (int m = 0; m < n; ++m)
      samples.push_back(origin + light.edge_u * ((m + 0.5) / n) + light.edge_v * ((k + 0.5) / n));
  return samples;
}

AreaLight light_above_box(const Bbox3d& box, const Vec3d& up, double diagonal_rel, double height_rel) {
  RAYSIFT_CHECK(!box.is_empty());
  const Vec3d u = any_perpendicular(up);
  const Vec3d v = cross(u, up);  // u x (u x up) = -up: the light emits down
  const double side = diagonal_rel * box.diagonal() / std::sqrt(2.0);
  // Distance from the centre to the top face along up (up need not be an axis).
  const Vec3d half = box.extent() * 0.5;
  const double top = half.x * std::abs(up.x) + half.y * std::abs(up.y) + half.z * std::abs(up.z);
  return AreaLight{box.center() + up * (top + height_rel * box.diagonal()), u * side, v * side};
}

Vec3d any_perpendicular(const Vec3d& v) {
  const Vec3d axis = std::abs(v.x) < 0.6 ? Vec3d{1, 0, 0} : (std::abs(v.y) < 0.6 ? Vec3d{0, 1, 0} : Vec3d{0, 0, 1});
  return normalize(cross(v, axis));
}

}  // namespace raysift::nrr
