#include "nrr/scenes.h"

#include <cmath>

#include "core/errors.h"
#include "core/hash.h"

namespace raysift::nrr {
namespace {

/// Uniform in [0,1) from hash(element index, seed, stream): independent of generation order.
double uniform(std::uint64_t index, std::uint64_t seed, std::uint64_t stream) {
  return unit_double(mix64(mix64(mix64(seed) ^ index) + stream));
}

std::uint32_t add_vertex(TriMesh& m, const Vec3d& p) {
  m.positions.push_back(Vec3f(p));
  return std::uint32_t(m.positions.size() - 1);
}

/// Quad a b c d, counter-clockwise seen from its front, as two triangles.
void add_quad(TriMesh& m, std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
  m.triangles.push_back({a, b, c});
  m.triangles.push_back({a, c, d});
}

/// Axis-aligned box with outward faces; the floor (y = lo.y) is left out when `has_floor` is false.
void add_box(TriMesh& m, const Vec3d& lo, const Vec3d& hi, bool has_floor = true) {
  std::uint32_t v[8];
  for (int i = 0; i < 8; ++i) v[i] = add_vertex(m, {i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
  add_quad(m, v[0], v[2], v[3], v[1]);  // -z
  add_quad(m, v[4], v[5], v[7], v[6]);  // +z
  if (has_floor) add_quad(m, v[0], v[1], v[5], v[4]);  // -y
  add_quad(m, v[2], v[6], v[7], v[3]);  // +y
  add_quad(m, v[0], v[4], v[6], v[2]);  // -x
  add_quad(m, v[1], v[3], v[7], v[5]);  // +x
}

void add_ground(TriMesh& m, double half) {
  const std::uint32_t a = add_vertex(m, {-half, 0, half}), b = add_vertex(m, {half, 0, half}),
                      c = add_vertex(m, {half, 0, -half}), d = add_vertex(m, {-half, 0, -half});
  add_quad(m, a, b, c, d);
}

CameraSpec view(const Vec3d& eye, const Vec3d& target, double fov_y_deg) {
  CameraSpec c;
  c.eye = eye;
  c.target = target;
  c.up = {0, 1, 0};
  c.fov_y_deg = fov_y_deg;
  return c;
}

GeneratedScene make_blocks4() {
  GeneratedScene s;
  TriMesh& m = s.mesh;
  const double h = 1.5;  // blocks span y in [-h, h]; the eyes at y = 0 see no top or bottom face
  add_box(m, {-0.2, -h, 5.5}, {0.2, h, 6.0});   // A: hides C from the midpoint of the eyes
  add_box(m, {-0.3, -h, 2.8}, {1.8, h, 3.0});   // B: hides C from V1 and, behind A, from the midpoint
  add_box(m, {-2.8, -h, 5.5}, {-2.1, h, 6.0});  // D: hides C from V0
  // C: a wedge whose front faces +z and whose slanted sides face away from the intermediate eye, so
  // everything that eye sees of C is its front face.
  const std::uint32_t flb = add_vertex(m, {-0.3, -h, 0}), frb = add_vertex(m, {0.3, -h, 0}),
                      ab = add_vertex(m, {0, -h, -1}), flt = add_vertex(m, {-0.3, h, 0}),
                      frt = add_vertex(m, {0.3, h, 0}), at = add_vertex(m, {0, h, -1});
  add_quad(m, flb, frb, frt, flt);
  add_quad(m, frb, ab, at, frt);
  add_quad(m, ab, flb, flt, at);
  m.triangles.push_back({flt, frt, at});
  m.triangles.push_back({flb, ab, frb});
  const double fov = 75.0;  // wide enough that each eye sees every block face it faces
  s.views.views = {view({-4, 0, 10}, {0, 0, 0}, fov), view({4, 0, 10}, {0, 0, 0}, fov)};
  s.views.intermediate = {view({-2, 0, 10}, {0, 0, 0}, fov)};
  return s;
}

constexpr int kTrianglesPerBlade = 10;
constexpr double kFieldHalf = 5.0;  ///< grass and urban stand on the ground |x|, |z| <= 5 at y = 0

/// A scene holding only the ground of grass and urban (two triangles).
GeneratedScene field_scene() {
  GeneratedScene s;
  add_ground(s.mesh, kFieldHalf);
  return s;
}

/// How many items of `per_item` triangles fill a `triangles` budget beside the ground's two.
std::size_t items_beside_ground(std::size_t triangles, int per_item) { return (triangles - 2) / std::size_t(per_item); }
constexpr double kBladeThickness = 1e-3;  ///< world units; blades are 0.04-0.08 wide
constexpr int kTrianglesPerBuilding = 10;

GeneratedScene make_grass(std::uint64_t seed, std::size_t triangles) {
  GeneratedScene s = field_scene();
  TriMesh& m = s.mesh;
  const double half = kFieldHalf;
  const std::size_t blades = items_beside_ground(triangles, kTrianglesPerBlade);
  for (std::size_t b = 0; b < blades; ++b) {
    const Vec3d base{(2 * uniform(b, seed, 0) - 1) * (half - 0.5), 0.0, (2 * uniform(b, seed, 1) - 1) * (half - 0.5)};
    const double angle = 2 * M_PI * uniform(b, seed, 2);
    const double height = 0.5 + 0.6 * uniform(b, seed, 3);
    const double width = 0.04 + 0.04 * uniform(b, seed, 4);
    const double bend = (uniform(b, seed, 5) - 0.5) * 0.6 * height;
    const Vec3d side{std::cos(angle), 0, std::sin(angle)};
    const Vec3d normal{-side.z, 0, side.x};  // side x up: the front normal of the blade
    std::uint32_t front[7];
    for (int level = 0; level < 3; ++level) {
      const double f = level / 3.0;
      const Vec3d centre = base + Vec3d{0, height * f, 0} + normal * (bend * f * f);
      const double hw = 0.5 * width * (1.0 - 0.7 * f);
      front[2 * level] = add_vertex(m, centre - side * hw);
      front[2 * level + 1] = add_vertex(m, centre + side * hw);
    }
    front[6] = add_vertex(m, base + Vec3d{0, height, 0} + normal * bend);
    const std::size_t first = m.triangles.size();
    add_quad(m, front[0], front[1], front[3], front[2]);
    add_quad(m, front[2], front[3], front[5], front[4]);
    m.triangles.push_back({front[4], front[5], front[6]});
    // Blades are thin sheets seen from both sides under back-face culling: the back is a second copy
    // with its own vertices and reversed winding, kBladeThickness behind the front, so that from
    // either side the nearest hit is a front face (a closed thin slab but for its rim).
    std::uint32_t back[7];
    for (int k = 0; k < 7; ++k) back[k] = add_vertex(m, Vec3d(m.positions[front[k]]) - normal * kBladeThickness);
    for (std::size_t t = first; t < first + 5; ++t) {
      const auto tri = m.triangles[t];
      const auto remap = [&](std::uint32_t v) { return back[v - front[0]]; };
      m.triangles.push_back({remap(tri[0]), remap(tri[2]), remap(tri[1])});
    }
  }
  s.views.views = {view({-2.5, 2.5, 7}, {0, 0.3, 0}, 45), view({2.5, 2.5, 7}, {0, 0.3, 0}, 45),
                   view({0, 4.5, 6}, {0, 0.3, 0}, 45)};
  return s;
}

GeneratedScene make_urban(std::uint64_t seed, std::size_t triangles) {
  GeneratedScene s = field_scene();
  TriMesh& m = s.mesh;
  const double half = kFieldHalf;
  const std::size_t buildings = items_beside_ground(triangles, kTrianglesPerBuilding);
  const auto grid = std::size_t(std::ceil(std::sqrt(double(buildings))));
  const double cell = 2 * half / double(grid);
  for (std::size_t b = 0; b < buildings; ++b) {
    const double fx = 0.45 + 0.4 * uniform(b, seed, 0), fz = 0.45 + 0.4 * uniform(b, seed, 1);
    const double x0 = -half + cell * (double(b % grid) + (1 - fx) * uniform(b, seed, 2));
    const double z0 = -half + cell * (double(b / grid) + (1 - fz) * uniform(b, seed, 3));
    const double u = uniform(b, seed, 4);
    const double height = 0.1 + 1.2 * u * u;  // mostly low blocks, a few towers
    add_box(m, {x0, 0, z0}, {x0 + fx * cell, height, z0 + fz * cell}, false);
  }
  s.views.views = {view({-2.5, 4, 7}, {0, 0, 0}, 45), view({2.5, 4, 7}, {0, 0, 0}, 45),
                   view({0, 6, 6}, {0, 0, 0}, 45)};
  return s;
}

}  // namespace

SceneKind parse_scene_kind(const std::string& name) {
  if (name == "blocks4") return SceneKind::Blocks4;
  if (name == "grass") return SceneKind::Grass;
  if (name == "urban") return SceneKind::Urban;
  throw InvalidInput("scene must be one of: blocks4, grass, urban; got '" + name + "'");
}

std::size_t default_triangles(SceneKind kind) {
  switch (kind) {
    case SceneKind::Blocks4: return 44;
    case SceneKind::Grass: return 56000;
    case SceneKind::Urban: return 50000;
  }
  return 0;
}

GeneratedScene make_scene(SceneKind kind, const SceneOptions& options) {
  if (kind == SceneKind::Blocks4) return make_blocks4();
  if (options.triangles != 0 && options.triangles < 100)
    throw InvalidInput("a grass or urban scene needs at least 100 triangles, got " + std::to_string(options.triangles));
  const std::size_t triangles = options.triangles ? options.triangles : default_triangles(kind);
  if (kind == SceneKind::Grass) return make_grass(options.seed, triangles);
  return make_urban(options.seed, triangles);
}

}  // namespace raysift::nrr
