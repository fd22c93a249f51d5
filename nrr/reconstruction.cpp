#include "nrr/reconstruction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "core/errors.h"

namespace raysift::nrr {

namespace {
constexpr std::uint32_t kNoVertex = std::numeric_limits<std::uint32_t>::max();
// Relative: |cos| between a corner ray and the tangent plane below which the plane intersection is
// numerically meaningless (grazing); the corner then falls back to the sample's distance.
constexpr double kGrazingCos = 1e-3;

void validate(const DepthImage& image, const char* what) {
  const std::size_t n = std::size_t(image.camera.width) * std::size_t(image.camera.height);
  Camera(image.camera);  // throws InvalidInput for a bad camera
  if (image.depth.size() != n || image.normal_ws.size() != n || image.triangle_id.size() != n)
    throw InvalidInput(std::string(what) + ": expected " + std::to_string(n) + " depths and normals for a " +
                       std::to_string(image.camera.width) + "x" + std::to_string(image.camera.height) +
                       " camera, got " + std::to_string(image.depth.size()) + " and " +
                       std::to_string(image.normal_ws.size()));
  for (std::size_t i = 0; i < n; ++i) {
    if (!image.has_sample(i)) continue;
    const float z = image.depth[i];
    if (!std::isfinite(z) || z <= 0.0f)
      throw InvalidInput(std::string(what) + ": depth at pixel " + std::to_string(i) + " is " + std::to_string(z) +
                         ", expected a finite depth > 0");
    if (!is_finite(image.normal_ws[i]))
      throw InvalidInput(std::string(what) + ": normal at pixel " + std::to_string(i) + " is not finite");
  }
}

void validate(const ReconstructionOptions& o) {
  if (!(o.discontinuity_rel > 0.0) || !(o.corner_clamp_rel > 0.0) || !(o.normal_cos_min >= -1.0 && o.normal_cos_min <= 1.0) ||
      !(o.corner_clamp_footprints >= 0.0 && std::isfinite(o.corner_clamp_footprints)))
    throw InvalidInput("reconstruction options: discontinuity_rel and corner_clamp_rel must be > 0, "
                       "corner_clamp_footprints finite and >= 0, normal_cos_min in [-1, 1]");
}

// A sample in world space with its normal turned toward the camera.
struct Sample {
  Vec3d p;
  Vec3d n;
  double z = 0;  ///< view depth
};

// Reads the samples of one image; has() is false where the pixel has none.
class SampleReader {
 public:
  explicit SampleReader(const DepthImage& image) : image_(image), camera_(image.camera) {}
  const Camera& camera() const { return camera_; }
  bool has(int x, int y) const { return image_.has_sample(index(x, y)); }
  /// The sample of pixel (x, y); `dir_unit_depth` is the direction of the ray it was taken along.
  Sample at(int x, int y, const Vec3d& dir_unit_depth) const {
    const std::size_t i = index(x, y);
    Sample s;
    s.z = image_.depth[i];
    s.p = camera_.eye() + dir_unit_depth * s.z;
    s.n = normalize(Vec3d(image_.normal_ws[i]));
    if (dot(s.n, dir_unit_depth) > 0.0) s.n = -s.n;
    return s;
  }

 private:
  std::size_t index(int x, int y) const { return std::size_t(y) * std::size_t(image_.camera.width) + std::size_t(x); }
  const DepthImage& image_;
  Camera camera_;
};

// View depth at which the ray eye + t * dir (dir with unit forward component) meets s's tangent plane;
// at grazing incidence or behind the eye, the depth of the point at s's distance along the ray.
double plane_depth(const Sample& s, const Vec3d& eye, const Vec3d& dir) {
  const double denom = dot(s.n, dir);
  const double dir_len = length(dir);
  if (std::abs(denom) >= kGrazingCos * dir_len) {
    const double t = dot(s.n, s.p - eye) / denom;
    if (t > 0.0) return t;
  }
  return length(s.p - eye) / dir_len;
}

// True if `other` (at view depth z_other along dir) lies on s's surface: within the relative depth
// threshold of s's tangent plane and with a similar normal.
bool is_continuous(const Sample& s, const Sample& other, const Vec3d& eye, const Vec3d& dir,
                   const ReconstructionOptions& o) {
  const double t_plane = plane_depth(s, eye, dir);
  return std::abs(other.z - t_plane) < o.discontinuity_rel * t_plane && dot(s.n, other.n) > o.normal_cos_min;
}
}  // namespace

CameraSpec corner_camera(const CameraSpec& camera) {
  CameraSpec h = camera;
  h.width = camera.width + 1;
  h.height = camera.height + 1;
  const double tan_half = std::tan(camera.fov_y_deg * M_PI / 360.0) * double(camera.height + 1) / camera.height;
  h.fov_y_deg = std::atan(tan_half) * 360.0 / M_PI;
  return h;
}

Reconstruction reconstruct_conventional(const DepthImage& image, const ReconstructionOptions& options) {
  validate(image, "conventional reconstruction");
  validate(options);
  const SampleReader reader(image);
  const Camera& cam = reader.camera();
  const int w = image.camera.width, h = image.camera.height;
  Reconstruction out;
  out.stats.samples = image.sample_count();
  std::vector<std::uint32_t> vertex(std::size_t(w) * std::size_t(h), kNoVertex);
  auto vertex_of = [&](int x, int y, const Sample& s) {
    std::uint32_t& v = vertex[std::size_t(y) * std::size_t(w) + std::size_t(x)];
    if (v == kNoVertex) {
      v = std::uint32_t(out.mesh.positions.size());
      out.mesh.positions.push_back(Vec3f(s.p));
    }
    return v;
  };
  const Vec3d eye = cam.eye();
  for (int y = 0; y + 1 < h; ++y) {
    for (int x = 0; x + 1 < w; ++x) {
      // Block corners a (x,y), b (x+1,y), c (x+1,y+1), d (x,y+1); triangles abc and acd.
      const int px[4] = {x, x + 1, x + 1, x}, py[4] = {y, y, y + 1, y + 1};
      bool has[4];
      Sample s[4];
      Vec3d dir[4];
      for (int k = 0; k < 4; ++k) {
        has[k] = reader.has(px[k], py[k]);
        dir[k] = cam.direction_unit_depth(px[k] + 0.5, py[k] + 0.5);
        if (has[k]) s[k] = reader.at(px[k], py[k], dir[k]);
      }
      auto linked = [&](int i, int j) {
        return is_continuous(s[i], s[j], eye, dir[j], options) || is_continuous(s[j], s[i], eye, dir[i], options);
      };
      for (const auto& t : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
        if (!has[t[0]] || !has[t[1]] || !has[t[2]]) continue;
        if (!linked(t[0], t[1]) || !linked(t[1], t[2]) || !linked(t[2], t[0])) continue;
        out.mesh.triangles.push_back({vertex_of(px[t[0]], py[t[0]], s[t[0]]), vertex_of(px[t[1]], py[t[1]], s[t[1]]),
                                      vertex_of(px[t[2]], py[t[2]], s[t[2]])});
      }
    }
  }
  out.stats.triangles = out.mesh.triangles.size();
  return out;
}

Reconstruction reconstruct_hybrid(const DepthImage& image, const DepthImage& corners,
                                  const ReconstructionOptions& options) {
  validate(image, "hybrid reconstruction (image)");
  validate(corners, "hybrid reconstruction (corner image H)");
  validate(options);
  const CameraSpec expected = corner_camera(image.camera);
  if (corners.camera.width != expected.width || corners.camera.height != expected.height ||
      corners.camera.eye != expected.eye || corners.camera.target != expected.target ||
      std::abs(corners.camera.fov_y_deg - expected.fov_y_deg) > 1e-9 * expected.fov_y_deg)
    throw InvalidInput("hybrid reconstruction: the corner image H must use corner_camera(image camera), i.e. " +
                       std::to_string(expected.width) + "x" + std::to_string(expected.height) +
                       " pixels centred on the image's pixel corners");
  const SampleReader reader(image), corner_reader(corners);
  const Camera& cam = reader.camera();
  const Vec3d eye = cam.eye();
  const int w = image.camera.width, h = image.camera.height;
  Reconstruction out;
  out.stats.samples = image.sample_count();
  std::vector<std::uint32_t> corner_vertex(std::size_t(w + 1) * std::size_t(h + 1), kNoVertex);
  // Half-width of the depth interval of an estimated corner, per unit of the sample's depth.
  const double pixel_side = 2.0 * std::tan(image.camera.fov_y_deg * M_PI / 360.0) / double(h);
  const double clamp_rel = options.corner_clamp_footprints > 0.0
                               ? std::min(options.corner_clamp_rel, options.corner_clamp_footprints * pixel_side)
                               : options.corner_clamp_rel;

  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!reader.has(x, y)) continue;
      const Sample s = reader.at(x, y, cam.direction_unit_depth(x + 0.5, y + 0.5));
      // Corners c0 (x,y), c1 (x+1,y), c2 (x+1,y+1), c3 (x,y+1) in the image's pixel coordinates; H's
      // pixel (i, j) has its centre exactly there.
      const int cx[4] = {x, x + 1, x + 1, x}, cy[4] = {y, y, y + 1, y + 1};
      std::uint32_t v[4];
      int estimated = 0;
      for (int k = 0; k < 4; ++k) {
        const Vec3d dir = cam.direction_unit_depth(cx[k], cy[k]);
        if (corner_reader.has(cx[k], cy[k])) {
          const Sample c = corner_reader.at(cx[k], cy[k], dir);
          if (is_continuous(s, c, eye, dir, options)) {
            std::uint32_t& shared = corner_vertex[std::size_t(cy[k]) * std::size_t(w + 1) + std::size_t(cx[k])];
            if (shared == kNoVertex) {
              shared = std::uint32_t(out.mesh.positions.size());
              out.mesh.positions.push_back(Vec3f(c.p));
              ++out.stats.shared_corners;
            }
            v[k] = shared;
            continue;
          }
        }
        // Missing or discontinuous corner: the corner ray meets the tangent plane, clamped in depth.
        const double t = std::clamp(plane_depth(s, eye, dir), s.z * (1.0 - clamp_rel), s.z * (1.0 + clamp_rel));
        v[k] = std::uint32_t(out.mesh.positions.size());
        out.mesh.positions.push_back(Vec3f(eye + dir * t));
        ++out.stats.estimated_corners;
        ++estimated;
      }
      if (estimated == 4) ++out.stats.isolated_samples;
      out.mesh.triangles.push_back({v[0], v[1], v[2]});
      out.mesh.triangles.push_back({v[2], v[3], v[0]});
    }
  }
  out.stats.triangles = out.mesh.triangles.size();
  return out;
}

}  // namespace raysift::nrr
