#include "nrr/views.h"

#include <cmath>
#include <sstream>

#include "core/errors.h"
#include "core/json_io.h"

namespace raysift::nrr {
namespace {

/// Van der Corput radical inverse in base 2: the second Hammersley coordinate.
double radical_inverse_2(std::uint32_t k) {
  k = (k << 16) | (k >> 16);
  k = ((k & 0x00ff00ffu) << 8) | ((k & 0xff00ff00u) >> 8);
  k = ((k & 0x0f0f0f0fu) << 4) | ((k & 0xf0f0f0f0u) >> 4);
  k = ((k & 0x33333333u) << 2) | ((k & 0xccccccccu) >> 2);
  k = ((k & 0x55555555u) << 1) | ((k & 0xaaaaaaaau) >> 1);
  return double(k) * (1.0 / 4294967296.0);
}

std::vector<CameraSpec> cameras_from_json(const Json& list, const std::string& where) {
  if (!list.is_array()) throw InvalidInput(where + ": expected a list of camera objects");
  std::vector<CameraSpec> out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string entry = where + "[" + std::to_string(i) + "]";
    out.push_back(camera_spec_from_json(list[i], entry));
    try {
      Camera{out.back()};
    } catch (const InvalidInput& e) {
      throw InvalidInput(entry + ": " + e.what());
    }
  }
  return out;
}

CameraSpec weighted(Span<const CameraSpec> views, const double* w) {
  CameraSpec c = views[0];
  c.eye = {};
  c.target = {};
  c.fov_y_deg = 0.0;
  for (std::size_t k = 0; k < views.size(); ++k) {
    c.eye += views[k].eye * w[k];
    c.target += views[k].target * w[k];
    c.fov_y_deg += views[k].fov_y_deg * w[k];
  }
  return c;
}

}  // namespace

ViewRegion parse_view_region(const std::string& name) {
  if (name == "segment") return ViewRegion::Segment;
  if (name == "triangle") return ViewRegion::Triangle;
  if (name == "rectangle") return ViewRegion::Rectangle;
  throw InvalidInput("view region must be one of: segment, triangle, rectangle; got '" + name + "'");
}

int corner_count(ViewRegion region) {
  switch (region) {
    case ViewRegion::Segment: return 2;
    case ViewRegion::Triangle: return 3;
    case ViewRegion::Rectangle: return 4;
  }
  return 0;
}

ViewSet read_views_file(const std::string& path) {
  const Json j = read_json_file(path);
  ViewSet set;
  if (j.is_array()) {
    set.views = cameras_from_json(j, path);
  } else if (j.is_object() && j.contains("views")) {
    set.views = cameras_from_json(j["views"], path + ": views");
    if (j.contains("intermediate_views"))
      set.intermediate = cameras_from_json(j["intermediate_views"], path + ": intermediate_views");
  } else {
    throw InvalidInput(file_message(path, "expected a list of cameras or an object with a \"views\" list"));
  }
  if (set.views.empty()) throw InvalidInput(file_message(path, "the view list is empty; give at least one camera"));
  return set;
}

void write_views_file(const std::string& path, const ViewSet& views) {
  Json j = Json::object();
  j["views"] = Json::array();
  for (const CameraSpec& c : views.views) j["views"].push_back(camera_spec_to_json(c));
  if (!views.intermediate.empty()) {
    j["intermediate_views"] = Json::array();
    for (const CameraSpec& c : views.intermediate) j["intermediate_views"].push_back(camera_spec_to_json(c));
  }
  write_json_file(path, j);
}

std::vector<CameraSpec> region_views(ViewRegion region, Span<const Vec3d> eyes, const CameraSpec& common) {
  if (int(eyes.size()) != corner_count(region))
    throw InvalidInput("a " + std::string(region == ViewRegion::Segment    ? "segment"
                                          : region == ViewRegion::Triangle ? "triangle"
                                                                           : "rectangle") +
                       " view region needs " + std::to_string(corner_count(region)) + " eyes, got " +
                       std::to_string(eyes.size()));
  std::vector<CameraSpec> views;
  for (const Vec3d& eye : eyes) {
    CameraSpec c = common;
    c.eye = eye;
    Camera{c};  // validates (eye == target, up parallel to the view direction, ...)
    views.push_back(c);
  }
  return views;
}

std::vector<CameraSpec> intermediate_views(Span<const CameraSpec> views, int count) {
  if (views.empty() || views.size() > 4)
    throw InvalidInput("intermediate views need 1 to 4 reference views (a point, segment, triangle or "
                       "quadrilateral of eyes), got " + std::to_string(views.size()));
  if (count < 1) throw InvalidInput("the number of intermediate views must be >= 1, got " + std::to_string(count));
  if (views.size() == 1) return {views[0]};
  std::vector<CameraSpec> out;
  out.reserve(std::size_t(count));
  for (int k = 0; k < count; ++k) {
    const double a = (k + 0.5) / count, b = radical_inverse_2(std::uint32_t(k));
    double w[4] = {0, 0, 0, 0};
    if (views.size() == 2) {
      w[0] = 1.0 - a;
      w[1] = a;
    } else if (views.size() == 3) {
      // Area-preserving map of the unit square onto the triangle (uniform density).
      const double s = std::sqrt(a);
      w[0] = 1.0 - s;
      w[1] = s * (1.0 - b);
      w[2] = s * b;
    } else {
      w[0] = (1 - a) * (1 - b);
      w[1] = a * (1 - b);
      w[2] = a * b;
      w[3] = (1 - a) * b;
    }
    out.push_back(weighted(views, w));
  }
  return out;
}

}  // namespace raysift::nrr
