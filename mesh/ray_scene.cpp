#include "mesh/ray_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <sstream>
#include <string>

#include "core/errors.h"

namespace raysift::mesh {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

const char* error_name(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE: return "RTC_ERROR_NONE";
    case RTC_ERROR_UNKNOWN: return "RTC_ERROR_UNKNOWN";
    case RTC_ERROR_INVALID_ARGUMENT: return "RTC_ERROR_INVALID_ARGUMENT";
    case RTC_ERROR_INVALID_OPERATION: return "RTC_ERROR_INVALID_OPERATION";
    case RTC_ERROR_OUT_OF_MEMORY: return "RTC_ERROR_OUT_OF_MEMORY";
    case RTC_ERROR_UNSUPPORTED_CPU: return "RTC_ERROR_UNSUPPORTED_CPU";
    case RTC_ERROR_CANCELLED: return "RTC_ERROR_CANCELLED";
  }
  return "RTC_ERROR_(unknown code)";
}

/// The device error callback records the first error here; construction checks it after each commit.
struct ErrorLog {
  std::mutex mutex;
  RTCError code = RTC_ERROR_NONE;
  std::string message;
};

void record_error(void* user, RTCError code, const char* str) {
  auto* log = static_cast<ErrorLog*>(user);
  std::lock_guard<std::mutex> lock(log->mutex);
  if (log->code != RTC_ERROR_NONE) return;
  log->code = code;
  log->message = str ? str : "";
}

/// Per-query data reaches the context filter through the context pointer, which Embree passes
/// through unchanged; `rtc` must therefore be the first member.
struct FilterContext {
  RTCIntersectContext rtc;
  const QueryOptions* options = nullptr;
};
static_assert(std::is_standard_layout_v<FilterContext>, "FilterContext must start with RTCIntersectContext");

void context_filter(const RTCFilterFunctionNArguments* args) {
  const auto* ctx = reinterpret_cast<const FilterContext*>(args->context);
  const QueryOptions& options = *ctx->options;
  const unsigned n = args->N;
  for (unsigned i = 0; i < n; ++i) {
    if (args->valid[i] == 0) continue;
    HitCandidate c;
    c.direction = {RTCRayN_dir_x(args->ray, n, i), RTCRayN_dir_y(args->ray, n, i), RTCRayN_dir_z(args->ray, n, i)};
    c.geometric_normal = {RTCHitN_Ng_x(args->hit, n, i), RTCHitN_Ng_y(args->hit, n, i),
                          RTCHitN_Ng_z(args->hit, n, i)};
    if (options.cull_back_faces && !c.is_front_facing()) {
      args->valid[i] = 0;
      continue;
    }
    if (!options.filter) continue;  // culling only: the common, hot case ends here
    c.ray_index = RTCRayN_id(args->ray, n, i);
    c.origin = {RTCRayN_org_x(args->ray, n, i), RTCRayN_org_y(args->ray, n, i), RTCRayN_org_z(args->ray, n, i)};
    c.t = RTCRayN_tfar(args->ray, n, i);
    c.triangle_id = make_triangle_id(RTCHitN_geomID(args->hit, n, i), RTCHitN_primID(args->hit, n, i));
    c.u = RTCHitN_u(args->hit, n, i);
    c.v = RTCHitN_v(args->hit, n, i);
    if (!(*options.filter)(c)) args->valid[i] = 0;
  }
}

void init_context(FilterContext& ctx, const QueryOptions& options) {
  rtcInitIntersectContext(&ctx.rtc);
  ctx.options = &options;
  if (options.is_coherent) ctx.rtc.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  // Without culling or a filter no callback is installed, so plain queries cost what bare Embree costs.
  if (options.cull_back_faces || options.filter) ctx.rtc.filter = context_filter;
}

/// Closest-hit queries whose culling/filter only decides can run in two passes: a plain traversal
/// without callbacks (bare Embree speed), then, for rays whose nearest hit the options reject, a
/// traversal with the callbacks. Both together return the nearest accepted hit, as one filtered
/// traversal would.
bool is_two_pass(const QueryOptions& options) {
  return options.filter ? options.is_filter_pure : options.cull_back_faces;
}

/// Whether `options` accept a hit found by the plain pass.
bool accepts(const QueryOptions& options, HitCandidate& c) {
  if (options.cull_back_faces && !c.is_front_facing()) return false;
  return !options.filter || (*options.filter)(c);
}

bool is_valid_ray(const RayF& r) {
  // x - x is 0 for finite x and NaN for NaN/Inf: one test per vector instead of three isfinite calls.
  const float o = (r.origin.x - r.origin.x) + (r.origin.y - r.origin.y) + (r.origin.z - r.origin.z);
  const float d = (r.direction.x - r.direction.x) + (r.direction.y - r.direction.y) + (r.direction.z - r.direction.z);
  return o == 0.0f && d == 0.0f && r.t_near >= 0.0f && r.t_near <= r.t_far && r.t_near < kInfinity &&
         (r.direction.x != 0.0f || r.direction.y != 0.0f || r.direction.z != 0.0f);
}

Hit hit_from(float t, unsigned geom_id, unsigned prim_id, float ng_x, float ng_y, float ng_z, float u, float v) {
  Hit h;
  if (geom_id == RTC_INVALID_GEOMETRY_ID) return h;
  h.t = t;
  h.triangle_id = make_triangle_id(geom_id, prim_id);
  h.normal_ws = normalize(Vec3f{ng_x, ng_y, ng_z});
  h.u = u;
  h.v = v;
  return h;
}

constexpr std::size_t kPacket = 16;

}  // namespace

struct RayScene::Impl {
  ErrorLog errors;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  Bbox3d bounds;
  std::size_t triangle_count = 0;
  std::size_t degenerate_count = 0;

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }

  void throw_if_error(const char* stage) {
    RTCError code = device ? rtcGetDeviceError(device) : RTC_ERROR_UNKNOWN;
    std::lock_guard<std::mutex> lock(errors.mutex);
    if (errors.code != RTC_ERROR_NONE) code = errors.code;
    if (code == RTC_ERROR_NONE) return;
    throw SolverError(std::string("embree: ") + stage + " failed with " + error_name(code) +
                      (errors.message.empty() ? "" : ": " + errors.message));
  }
};

namespace {

void validate_mesh(const TriMesh& mesh, std::size_t mesh_index) {
  for (std::size_t v = 0; v < mesh.positions.size(); ++v)
    if (!is_finite(mesh.positions[v])) {
      std::ostringstream s;
      s << "ray scene: mesh " << mesh_index << " vertex " << v << " is not finite " << mesh.positions[v]
        << "; repair or re-export the mesh";
      throw InvalidInput(s.str());
    }
  if (mesh.triangles.size() > std::size_t(std::numeric_limits<std::uint32_t>::max()))
    throw InvalidInput("ray scene: mesh " + std::to_string(mesh_index) + " has more than 2^32-1 triangles");
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (std::uint32_t idx : mesh.triangles[t])
      if (idx >= mesh.positions.size()) {
        std::ostringstream s;
        s << "ray scene: mesh " << mesh_index << " triangle " << t << " references vertex " << idx << " but the mesh has "
          << mesh.positions.size() << " vertices";
        throw InvalidInput(s.str());
      }
}

}  // namespace

RayScene::RayScene(const TriMesh& mesh) : RayScene(Span<const TriMesh* const>(std::vector<const TriMesh*>{&mesh})) {}

RayScene::RayScene(Span<const TriMesh* const> meshes) : impl_(std::make_unique<Impl>()) {
  Impl& im = *impl_;
  bool has_triangles = false;
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    RAYSIFT_CHECK(meshes[k] != nullptr);
    validate_mesh(*meshes[k], k);
    has_triangles = has_triangles || !meshes[k]->empty();
  }
  if (!has_triangles) throw InvalidInput("ray scene: the mesh has no triangles; nothing can be ray traced");

  im.device = rtcNewDevice(nullptr);
  if (!im.device) throw SolverError(std::string("embree: rtcNewDevice failed with ") + error_name(rtcGetDeviceError(nullptr)));
  rtcSetDeviceErrorFunction(im.device, record_error, &im.errors);
  im.scene = rtcNewScene(im.device);
  // ROBUST keeps shared edges watertight; CONTEXT_FILTER_FUNCTION enables the per-query filter.
  rtcSetSceneFlags(im.scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
  im.throw_if_error("scene creation");

  for (std::size_t k = 0; k < meshes.size(); ++k) {
    const TriMesh& m = *meshes[k];
    RTCGeometry geom = rtcNewGeometry(im.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Copy (rather than share) the vertices: Embree's buffers carry the padding its SIMD loads need
    // and the scene then outlives the caller's mesh.
    auto* verts = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                              3 * sizeof(float), std::max<std::size_t>(1, m.vertex_count())));
    auto* tris = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                     3 * sizeof(std::uint32_t), m.triangle_count()));
    if (!verts || (!tris && m.triangle_count() > 0)) {
      rtcReleaseGeometry(geom);
      im.throw_if_error("buffer allocation");
      throw SolverError("embree: buffer allocation failed");
    }
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
      verts[3 * v + 0] = m.positions[v].x;
      verts[3 * v + 1] = m.positions[v].y;
      verts[3 * v + 2] = m.positions[v].z;
    }
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const auto& tri = m.triangles[t];
      std::copy(tri.begin(), tri.end(), tris + 3 * t);
      const Vec3d p0(m.positions[tri[0]]), p1(m.positions[tri[1]]), p2(m.positions[tri[2]]);
      if (length(cross(p1 - p0, p2 - p0)) == 0.0) ++im.degenerate_count;
      im.bounds.expand(p0);
      im.bounds.expand(p1);
      im.bounds.expand(p2);
    }
    im.triangle_count += m.triangle_count();
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(im.scene, geom, unsigned(k));
    rtcReleaseGeometry(geom);
    im.throw_if_error("geometry commit");
  }
  rtcCommitScene(im.scene);
  im.throw_if_error("scene commit");
}

RayScene::~RayScene() = default;
RayScene::RayScene(RayScene&&) noexcept = default;
RayScene& RayScene::operator=(RayScene&&) noexcept = default;

const Bbox3d& RayScene::bounds() const { return impl_->bounds; }
std::size_t RayScene::triangle_count() const { return impl_->triangle_count; }
std::size_t RayScene::degenerate_triangle_count() const { return impl_->degenerate_count; }

Hit RayScene::intersect(const RayF& ray, const QueryOptions& options) const {
  if (!is_valid_ray(ray)) return {};
  const bool two_pass = is_two_pass(options);
  const QueryOptions plain{false, nullptr, false, options.is_coherent};
  FilterContext ctx;
  init_context(ctx, two_pass ? plain : options);
  RTCRayHit rh;
  const auto reset = [&] {
    rh.ray.org_x = ray.origin.x;
    rh.ray.org_y = ray.origin.y;
    rh.ray.org_z = ray.origin.z;
    rh.ray.dir_x = ray.direction.x;
    rh.ray.dir_y = ray.direction.y;
    rh.ray.dir_z = ray.direction.z;
    rh.ray.tnear = ray.t_near;
    rh.ray.tfar = ray.t_far;
    rh.ray.time = 0.0f;
    rh.ray.mask = ~0u;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  };
  reset();
  rtcIntersect1(impl_->scene, &ctx.rtc, &rh);
  if (two_pass && rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
    HitCandidate c;
    c.origin = ray.origin;
    c.direction = ray.direction;
    c.t = rh.ray.tfar;
    c.triangle_id = make_triangle_id(rh.hit.geomID, rh.hit.primID);
    c.geometric_normal = {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
    c.u = rh.hit.u;
    c.v = rh.hit.v;
    if (!accepts(options, c)) {
      reset();
      init_context(ctx, options);
      rtcIntersect1(impl_->scene, &ctx.rtc, &rh);
    }
  }
  return hit_from(rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z, rh.hit.u, rh.hit.v);
}

namespace {

/// Fills lanes [0, count) of a 16-wide packet from rays[base..]; invalid rays become inactive lanes.
template <typename Ray16>
void fill_packet(Ray16& r, int* valid, Span<const RayF> rays, std::size_t base, std::size_t count) {
  for (std::size_t i = 0; i < kPacket; ++i) {
    const bool active = i < count && is_valid_ray(rays[base + i]);
    valid[i] = active ? -1 : 0;
    const RayF& src = active ? rays[base + i] : rays[base];
    r.org_x[i] = src.origin.x;
    r.org_y[i] = src.origin.y;
    r.org_z[i] = src.origin.z;
    r.dir_x[i] = active ? src.direction.x : 1.0f;
    r.dir_y[i] = active ? src.direction.y : 0.0f;
    r.dir_z[i] = active ? src.direction.z : 0.0f;
    r.tnear[i] = active ? src.t_near : 0.0f;
    r.tfar[i] = active ? src.t_far : 0.0f;
    r.time[i] = 0.0f;
    r.mask[i] = ~0u;
    r.id[i] = unsigned(base + i);
    r.flags[i] = 0;
  }
}

}  // namespace

void RayScene::intersect(Span<const RayF> rays, Span<Hit> hits, const QueryOptions& options) const {
  RAYSIFT_CHECK_OP(hits.size(), ==, rays.size());
  RAYSIFT_CHECK(rays.size() < std::size_t(std::numeric_limits<std::uint32_t>::max()));
  const bool two_pass = is_two_pass(options);
  const QueryOptions plain{false, nullptr, false, options.is_coherent};
  FilterContext ctx, full_ctx;
  init_context(ctx, two_pass ? plain : options);
  init_context(full_ctx, options);
  alignas(64) RTCRayHit16 rh;
  alignas(64) int valid[kPacket];
  alignas(64) int again[kPacket];
  for (std::size_t base = 0; base < rays.size(); base += kPacket) {
    const std::size_t count = std::min(kPacket, rays.size() - base);
    fill_packet(rh.ray, valid, rays, base, count);
    for (std::size_t i = 0; i < kPacket; ++i) {
      rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, impl_->scene, &ctx.rtc, &rh);
    if (two_pass) {
      bool has_rejected = false;
      for (std::size_t i = 0; i < kPacket; ++i) {
        again[i] = 0;
        if (!valid[i] || rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) continue;
        HitCandidate c;
        c.ray_index = base + i;
        c.origin = rays[base + i].origin;
        c.direction = rays[base + i].direction;
        c.t = rh.ray.tfar[i];
        c.triangle_id = make_triangle_id(rh.hit.geomID[i], rh.hit.primID[i]);
        c.geometric_normal = {rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i]};
        c.u = rh.hit.u[i];
        c.v = rh.hit.v[i];
        if (accepts(options, c)) continue;
        again[i] = -1;
        has_rejected = true;
        rh.ray.tfar[i] = rays[base + i].t_far;
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      }
      if (has_rejected) rtcIntersect16(again, impl_->scene, &full_ctx.rtc, &rh);
    }
    for (std::size_t i = 0; i < count; ++i)
      hits[base + i] = valid[i] ? hit_from(rh.ray.tfar[i], rh.hit.geomID[i], rh.hit.primID[i], rh.hit.Ng_x[i],
                                           rh.hit.Ng_y[i], rh.hit.Ng_z[i], rh.hit.u[i], rh.hit.v[i])
                                : Hit{};
  }
}

bool RayScene::occluded(const RayF& ray, const QueryOptions& options) const {
  if (!is_valid_ray(ray)) return false;
  FilterContext ctx;
  init_context(ctx, options);
  RTCRay r;
  r.org_x = ray.origin.x;
  r.org_y = ray.origin.y;
  r.org_z = ray.origin.z;
  r.dir_x = ray.direction.x;
  r.dir_y = ray.direction.y;
  r.dir_z = ray.direction.z;
  r.tnear = ray.t_near;
  r.tfar = ray.t_far;
  r.time = 0.0f;
  r.mask = ~0u;
  r.id = 0;
  r.flags = 0;
  rtcOccluded1(impl_->scene, &ctx.rtc, &r);
  // Embree marks an occluded ray by setting tfar to -inf.
  return r.tfar == -std::numeric_limits<float>::infinity();
}

void RayScene::occluded(Span<const RayF> rays, Span<std::uint8_t> is_occluded, const QueryOptions& options) const {
  RAYSIFT_CHECK_OP(is_occluded.size(), ==, rays.size());
  RAYSIFT_CHECK(rays.size() < std::size_t(std::numeric_limits<std::uint32_t>::max()));
  FilterContext ctx;
  init_context(ctx, options);
  alignas(64) RTCRay16 r;
  alignas(64) int valid[kPacket];
  for (std::size_t base = 0; base < rays.size(); base += kPacket) {
    const std::size_t count = std::min(kPacket, rays.size() - base);
    fill_packet(r, valid, rays, base, count);
    rtcOccluded16(valid, impl_->scene, &ctx.rtc, &r);
    for (std::size_t i = 0; i < count; ++i)
      is_occluded[base + i] = valid[i] && r.tfar[i] == -std::numeric_limits<float>::infinity() ? 1 : 0;
  }
}

}  // namespace raysift::mesh
