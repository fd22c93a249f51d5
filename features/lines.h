#pragma once
/// \file DeCarlo-style line features of a triangle mesh for one eye position (DeCarlo et al. 2003,
/// DeCarlo, Finkelstein & Rusinkiewicz 2004, DeCarlo & Rusinkiewicz 2007, Ohtake et al. 2004), following
/// the rtsc viewer's formulas (see docs/feature_lines.md and ALGORITHMS.md §5). Key decision: every line is
/// a set of independent 3D segments, at most three per face and class, so extraction is one parallel
/// pass over faces; exterior silhouettes are classified later, by features/visibility.h, because "borders the
/// background" is an image-space property.
#include <cstdint>
#include <string>
#include <vector>

#include "core/vec.h"
#include "mesh/curvature.h"
#include "core/tri_mesh.h"

namespace raysift::features {

/// Line classes. Exterior silhouettes are the subset of contours that border the background.
enum class LineClass : std::uint8_t { Contour, Silhouette, SuggestiveContour, SuggestiveHighlight, Ridge, Valley };
inline constexpr int kLineClassCount = 6;

/// Name used by the CLI (`--features`) and stats: contours, silhouettes, suggestive, highlights, ridges, valleys.
const char* line_class_name(LineClass line_class);

/// A set of line classes (bit i = LineClass i).
struct LineClassSet {
  std::uint8_t bits = 0;
  bool has(LineClass c) const { return (bits >> int(c)) & 1u; }
  void add(LineClass c) { bits = std::uint8_t(bits | (1u << int(c))); }
  bool is_empty() const { return bits == 0; }
  static LineClassSet all() { return {std::uint8_t((1u << kLineClassCount) - 1u)}; }
};

/// Parses a comma-separated list of class names ("contours,ridges"); "all" selects every class.
/// \throw InvalidInput naming the unknown entry and listing the valid names.
LineClassSet parse_line_classes(const std::string& comma_list);

/// One straight piece of a feature line, world space.
struct LineSegment {
  Vec3f p0_ws, p1_ws;
  /// rtsc fade factor in [0,1] at each end (how far the line's test value exceeds its threshold);
  /// used only for drawing the picture, never for the importance buffer.
  float strength0 = 1.0f, strength1 = 1.0f;
  LineClass line_class = LineClass::Contour;
  std::uint32_t face = 0;  ///< triangle the segment was extracted from
};

struct FeatureLines {
  std::vector<LineSegment> segments;  ///< deterministic order: by face, then by class
  std::size_t count(LineClass c) const;
};

/// Thresholds are rtsc's dimensionless defaults; they are scaled by the mesh's feature size `fs`
/// (MeshCurvature::feature_size): suggestive / highlight thresholds by 1/fs², ridge/valley by 1/fs.
struct LineOptions {
  /// Classes to extract. Silhouettes need contours: extract_lines emits LineClass::Contour segments when
  /// either is enabled; visibility decides which are silhouettes. Disabled classes are not computed.
  LineClassSet classes = LineClassSet::all();
  double suggestive_threshold = 0.01;  ///< rtsc sug_thresh: keep where D_w κ_r · tanθ > value / fs²
  double highlight_threshold = 0.02;   ///< rtsc sh_thresh: keep where −D_w κ_r · tanθ > value / fs²
  double ridge_threshold = 0.1;        ///< rtsc rv_thresh: keep where |κ1| > value / fs
  bool test_contours = true;           ///< rtsc test_c: keep contour parts with κ_r > 0 only
  bool cull_back_faces = true;         ///< skip faces with n·v <= 0 at all three vertices
  bool threaded = true;
};

/// Extracts the enabled line classes seen from `eye_ws` (perspective view vectors, per vertex).
/// Faces touching a vertex that MeshCurvature marks invalid (non-manifold, unreferenced) and degenerate
/// faces are skipped. The result is identical for any thread count.
/// \pre `curvature` was computed from `mesh` (same vertex count).
/// \throw InvalidInput if the eye is not finite, a threshold is negative or not finite, or the curvature
///        does not match the mesh.
FeatureLines extract_lines(const TriMesh& mesh, const mesh::MeshCurvature& curvature, const Vec3d& eye_ws,
                           const LineOptions& options = {});

}  // namespace raysift::features
