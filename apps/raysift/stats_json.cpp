#include "apps/raysift/stats_json.h"

#include "mesh/mesh_analysis.h"

namespace raysift::app {

namespace {
Json vec3i_to_json(const Vec3i& v) { return Json::array({v.x, v.y, v.z}); }
Json stage_json(const mesh::StageReport& s) { return {{"ms", s.ms}, {"triangles", s.triangles}}; }
}  // namespace

Json grid_info_json(const volume::GridInfo& g) {
  return {{"name", g.name},
          {"type", g.type},
          {"class", g.grid_class},
          {"active_voxels", g.active_voxels},
          {"index_min", vec3i_to_json(g.index_min)},
          {"index_max", vec3i_to_json(g.index_max)},
          {"bbox_min", vec3_to_json(g.bbox_min)},
          {"bbox_max", vec3_to_json(g.bbox_max)},
          {"voxel_size", vec3_to_json(g.voxel_size)},
          {"value_min", g.value_min},
          {"value_max", g.value_max},
          {"background", g.background}};
}

Json surface_json(const TriMesh& m) {
  if (m.empty()) return {{"triangles", 0}, {"vertices", 0}, {"watertight", false}, {"euler_characteristic", 0}, {"area", 0.0}};
  const mesh::MeshAnalysis a = mesh::analyze_mesh(m);
  Json s = {{"triangles", a.faces},
            {"vertices", a.vertices},
            {"watertight", a.is_watertight()},
            {"euler_characteristic", a.euler_characteristic},
            {"area", a.area}};
  if (a.is_watertight()) s["enclosed_volume"] = a.signed_volume;
  return s;
}

Json stages_json(const isosurface::StageTimes& t) {
  return {{"marching_cubes", stage_json(t.marching_cubes)},
          {"smooth_before", stage_json(t.smooth_before)},
          {"decimate", stage_json(t.decimate)},
          {"smooth_after", stage_json(t.smooth_after)}};
}

}  // namespace raysift::app
