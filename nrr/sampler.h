#pragma once
/// \file Multi-view depth images of a triangle scene: conventional images, non-redundant rendering
/// (Xie, Wang & Popescu 2016, Alg. 1 with pixel redundancy, Alg. 3, or visibility redundancy, Alg. 2)
/// and depth peeling. Key decision: every mode is ray casting with Embree where a redundant or
/// back-facing candidate is rejected inside traversal and the ray continues, so each pixel costs one
/// traversal (ALGORITHMS.md §10). Visibility redundancy and peeling collect candidates during that
/// traversal and test them afterwards, because no ray query may start inside a filter.
#include <array>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/span.h"
#include "mesh/ray_scene.h"
#include "core/tri_mesh.h"
#include "nrr/depth_image.h"

namespace raysift::nrr {

/// The redundancy definitions of Xie, Wang & Popescu 2016, by name. A sample x of triangle t is
/// redundant with an earlier image I_j when:
/// - Pixel (Alg. 3): x reprojects into I_j onto a pixel holding t;
/// - Visibility (Alg. 2): the first surface hit from V_j toward x is x, nothing else (hits are
///   front faces only, as every image culls back faces, so x's face must look at V_j);
/// - VisibilityFrustum: Visibility and x lies inside I_j's frustum ([choice] ALGORITHMS.md §10).
enum class Redundancy { Pixel, Visibility, VisibilityFrustum };

/// "pixel", "visibility", "visibility-frustum". \throw InvalidInput otherwise.
Redundancy parse_redundancy(const std::string& name);
std::string to_string(Redundancy redundancy);

/// NrrVisibility is Alg. 2 exactly; NrrVisibilityFrustum adds the frustum test (see Redundancy).
enum class SamplingMode { Conventional, NrrPixel, NrrVisibility, NrrVisibilityFrustum, Peel };

/// "conventional", "nrr-pixel", "nrr-visibility", "nrr-visibility-frustum", "peel".
/// \throw InvalidInput for anything else.
SamplingMode parse_sampling_mode(const std::string& name);
std::string to_string(SamplingMode mode);
/// The NRR mode that renders with `redundancy`.
SamplingMode nrr_mode(Redundancy redundancy);
/// The redundancy an NRR mode renders with. \pre mode is one of the Nrr* modes.
Redundancy redundancy_of(SamplingMode mode);

/// A mesh prepared for sampling: its Embree scene, triangle normals and per-corner shading normals
/// (area-weighted over the faces around the vertex within a 45 degree crease angle).
/// @warning Immutable after construction; all queries are thread-safe.
class SampledScene {
 public:
  /// \throw InvalidInput for an empty mesh, a NaN/Inf vertex or an out-of-range index.
  explicit SampledScene(const TriMesh& mesh);

  const mesh::RayScene& rays() const { return rays_; }
  /// Unit normal of the CCW front face (zero for a degenerate triangle).
  const Vec3d& face_normal(mesh::TriangleId id) const { return face_normals_[mesh::triangle_id_index(id)]; }
  /// Corner normals interpolated at barycentrics (u, v); `face_normal` (the unit normal of triangle
  /// `id`, e.g. mesh::Hit::normal_ws) for flat triangles or where the interpolation faces away.
  Vec3f shading_normal(mesh::TriangleId id, float u, float v, const Vec3f& face_normal) const;
  /// shading_normal at the sample point x on triangle `id` hit by a ray from `origin` (barycentrics
  /// recomputed from x; the face normal as Embree reports it for that ray).
  Vec3f shading_normal_at(mesh::TriangleId id, const Vec3f& x, const Vec3f& origin) const;
  /// Scene bounding-box diagonal, world units.
  double diagonal() const { return rays_.bounds().diagonal(); }
  /// Mean triangle edge length, world units (for the triangle-size / pixel-size ratio in reports).
  double mean_edge_length() const { return mean_edge_; }
  /// The three corners of triangle `id`, CCW seen from its front.
  std::array<Vec3d, 3> corners(mesh::TriangleId id) const {
    const auto& t = mesh_.triangles[mesh::triangle_id_index(id)];
    return {Vec3d(mesh_.positions[t[0]]), Vec3d(mesh_.positions[t[1]]), Vec3d(mesh_.positions[t[2]])};
  }

 private:
  mesh::RayScene rays_;
  TriMesh mesh_;  ///< for the barycentrics of derived shading normals
  std::vector<Vec3d> face_normals_;
  std::vector<std::array<Vec3f, 3>> corner_normals_;  ///< per triangle, normals at its corners
  std::vector<std::uint8_t> is_flat_;                 ///< per triangle: corner normals == face normal
  double mean_edge_ = 0.0;
};

enum class NormalKind { Face, Shading };

/// Fills image.normal_ws (the lean record derives normals on demand): per sample the unit normal of
/// its triangle's front face, or the interpolated shading normal; zero where empty.
void fill_normals(const SampledScene& scene, DepthImage& image, NormalKind kind);

struct SamplingOptions {
  SamplingMode mode = SamplingMode::NrrPixel;
  int peel_layers = 0;  ///< peel only: number of layers, 0 = as many as views
  bool threaded = true; ///< false renders serially (same result; for bisecting bugs)
};

/// Renders one depth image per view (per layer for peel, all from peel_camera(views)). All modes
/// cull back faces. Image 0 of the NRR modes equals the conventional image 0 bit for bit.
/// Coincident eyes are allowed: with pixel redundancy NRR image 1 from the eye of image 0 is the
/// second depth-peeling layer.
/// \throw InvalidInput if `views` is empty, a camera is invalid, or peel_layers < 0.
std::vector<DepthImage> render_depth_images(const SampledScene& scene, Span<const CameraSpec> views,
                                            const SamplingOptions& options = {});

/// Depth peeling's view: eye and target at the centroids of the views' eyes and targets; up, field
/// of view and size of views[0]. \throw InvalidInput if `views` is empty.
CameraSpec peel_camera(Span<const CameraSpec> views);

}  // namespace raysift::nrr
