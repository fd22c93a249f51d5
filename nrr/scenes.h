#pragma once
/// \file Procedural test scenes for multi-view sampling (Xie, Wang & Popescu 2016): the four-block
/// configuration of their Fig. 3 extruded to 3D, and a grass field and an urban block field resembling
/// their test scenes. Random choices come from hash(element index, seed), so a scene depends only on
/// its parameters.
#include <cstdint>
#include <string>

#include "core/tri_mesh.h"
#include "nrr/views.h"

namespace raysift::nrr {

enum class SceneKind { Blocks4, Grass, Urban };

/// "blocks4", "grass", "urban". \throw InvalidInput otherwise.
SceneKind parse_scene_kind(const std::string& name);

struct SceneOptions {
  std::uint64_t seed = 1;
  /// Target triangle count; 0 = default_triangles(kind). Ignored by blocks4 (fixed).
  std::size_t triangles = 0;
};

/// The triangle count of a grass or urban scene when none is asked for (grass 56000, urban 50000; blocks4 44,
/// fixed): one number for make_scene and the help texts.
std::size_t default_triangles(SceneKind kind);

struct GeneratedScene {
  TriMesh mesh;  ///< world units, y up
  ViewSet views;       ///< suggested reference views (blocks4 also has its intermediate view)
};

/// blocks4: blocks A, B, D and a wedge-shaped C (36 + 8 triangles), eyes V0 = (-4,0,10), V1 = (4,0,10)
/// looking at the origin; C is hidden from V0 (by D), from V1 (by B, whose part in front of C V0 sees)
/// and doubly from the midpoint (by A, then B), but visible from the intermediate eye (-2,0,10).
/// grass: a 10 x 10 ground square and thin two-sided blades of 10 triangles each.
/// urban: a ground square and a grid of box buildings of 10 triangles each (no floors).
/// grass and urban come with three views on a triangle of eyes above the scene.
/// \throw InvalidInput if `triangles` is nonzero but below 100 for grass or urban.
GeneratedScene make_scene(SceneKind kind, const SceneOptions& options = {});

}  // namespace raysift::nrr
