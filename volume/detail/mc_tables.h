#pragma once
/// \file volume/-internal: the 256-case marching-cubes table, generated (not pasted) from one face rule so
/// that it is consistent by construction. Cube numbering: corner n sits at offset (n&1, (n>>1)&1, (n>>2)&1);
/// edge e runs along axis e/4 from corner kEdgeStart[e] to kEdgeStart[e] + (1 << axis). Bit n of a case
/// index is set when corner n is inside (value >= iso).
///
/// Face rule: on each cube face, every maximal run of inside corners (cyclically) is cut off by one
/// segment, so two diagonal inside corners of an ambiguous face are never joined. The rule depends only on
/// the face's four corners, hence the two cells sharing a face always cut it the same way: the surface is
/// crack-free and closed (no complement symmetry is used). Segments chain into loops, one per surface
/// patch, which are triangulated without any edge across a cube face (such an edge could be created by both
/// cells sharing the face). Triangles are counter-clockwise seen from the outside (f < iso) side.
#include <array>
#include <cstdint>

namespace raysift::volume::detail {

inline constexpr int kMcMaxTriangles = 5;  ///< the most any case needs (the generator checks it)

inline constexpr std::array<std::uint8_t, 12> kEdgeStart = {0, 2, 4, 6, 0, 1, 4, 5, 0, 1, 2, 3};
inline constexpr int edge_axis(int edge) { return edge / 4; }

struct McCase {
  std::uint8_t triangle_count = 0;
  std::uint16_t cut_edges = 0;  ///< bit e set when cube edge e is cut
  std::array<std::uint8_t, 3 * kMcMaxTriangles> edges{};  ///< cube edge per triangle corner
};

/// The table, built once on first use (thread-safe static initialisation).
const std::array<McCase, 256>& marching_cubes_cases();

}  // namespace raysift::volume::detail
