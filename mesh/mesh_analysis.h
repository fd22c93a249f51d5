#pragma once
/// \file Topology and geometry checks of a TriMesh: closedness, manifoldness, orientation consistency,
/// Euler characteristic, area, enclosed volume and connected components. Used by tests, by the `mesh`
/// command's stats and by later stages that must reject broken meshes. Works on any index soup
/// (non-manifold, degenerate, open); nothing here modifies the mesh.
#include <cstdint>
#include <vector>

#include "core/vec.h"
#include "core/tri_mesh.h"

namespace raysift::mesh {

/// Counts and measures of one mesh. An "edge" is an unordered vertex pair used by at least one
/// triangle side; triangles with a repeated index contribute no edges and count as degenerate.
struct MeshAnalysis {
  std::size_t vertices = 0;              ///< all vertices, including isolated ones
  std::size_t isolated_vertices = 0;     ///< used by no triangle
  std::size_t edges = 0;
  std::size_t faces = 0;
  std::size_t boundary_edges = 0;        ///< in exactly one triangle
  std::size_t non_manifold_edges = 0;    ///< in three or more triangles
  /// Incident triangles form more than one fan (two cones touching at a tip), or the vertex lies on a
  /// non-manifold edge.
  std::size_t non_manifold_vertices = 0;
  std::size_t inconsistent_edges = 0;    ///< two-triangle edges whose triangles traverse it in the same direction
  std::size_t degenerate_faces = 0;      ///< repeated index or exactly zero area
  std::size_t components = 0;            ///< connected components (triangles linked through shared vertices)
  /// V − E + F with V = vertices used by a triangle: 2 per sphere-like closed component, 0 for a torus.
  std::int64_t euler_characteristic = 0;
  double area = 0;                       ///< world units², summed in double
  /// (1/6) Σ p0·(p1×p2): the enclosed volume (world units³) if the mesh is watertight, positive when the
  /// triangles are counter-clockwise seen from outside. Meaningless for open meshes.
  double signed_volume = 0;
  Bbox3d bbox;                           ///< of the vertices used by triangles

  /// Every edge in exactly two triangles, every vertex a single fan: a closed 2-manifold.
  bool is_closed_manifold() const {
    return faces > 0 && boundary_edges == 0 && non_manifold_edges == 0 && non_manifold_vertices == 0;
  }
  /// Closed 2-manifold with consistent orientation, so the enclosed volume is well defined.
  bool is_watertight() const { return is_closed_manifold() && inconsistent_edges == 0; }
};

/// Analyses `mesh`. O(V + F) time and memory. \pre every index < vertex_count() (validate_mesh()).
MeshAnalysis analyze_mesh(const TriMesh& mesh);

/// Role of a vertex in the mesh's connectivity (degenerate triangles with a repeated index are ignored).
enum class VertexKind : std::uint8_t {
  Isolated,     ///< in no triangle
  Interior,     ///< one closed fan of triangles, every incident edge in exactly two
  Boundary,     ///< one fan, on at least one edge used by a single triangle
  NonManifold,  ///< several fans, or on an edge used by three or more triangles
};
/// One kind per vertex; smoothing keeps boundary and non-manifold vertices fixed. O(V + F).
/// \pre every index < vertex_count().
std::vector<VertexKind> classify_vertices(const TriMesh& mesh);

/// Connected components of the triangles (linked through shared vertices), numbered 0..count-1 in order of
/// their first triangle, so the labelling is deterministic.
struct ComponentLabels {
  std::vector<std::uint32_t> face_component;  ///< one label per triangle
  std::size_t count = 0;
};
/// \pre every index < vertex_count().
ComponentLabels label_components(const TriMesh& mesh);

/// The triangles with label `component`, with their used vertices renumbered compactly in first-use order.
/// \pre component < labels.count.
TriMesh extract_component(const TriMesh& mesh, const ComponentLabels& labels, std::size_t component);

}  // namespace raysift::mesh
