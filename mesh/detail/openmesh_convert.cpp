#include "mesh/detail/openmesh_convert.h"

#include "core/errors.h"

namespace raysift::mesh::detail {

OmTriMesh to_openmesh(const TriMesh& mesh, std::size_t* rejected_faces) {
  OmTriMesh om;
  om.reserve(mesh.positions.size(), mesh.triangles.size() * 3 / 2, mesh.triangles.size());
  for (const Vec3f& p : mesh.positions) om.add_vertex(OmTriMesh::Point(p.x, p.y, p.z));
  std::size_t rejected = 0;
  MuteOpenMeshLog mute;
  for (const auto& t : mesh.triangles) {
    const auto f = om.add_face(OmTriMesh::VertexHandle(int(t[0])), OmTriMesh::VertexHandle(int(t[1])),
                               OmTriMesh::VertexHandle(int(t[2])));
    if (!f.is_valid()) ++rejected;
  }
  if (rejected_faces) *rejected_faces = rejected;
  return om;
}

TriMesh from_openmesh(const OmTriMesh& om) {
  TriMesh mesh;
  mesh.positions.reserve(om.n_vertices());
  for (const auto v : om.vertices()) {
    RAYSIFT_CHECK(!om.has_vertex_status() || !om.status(v).deleted());
    const auto& p = om.point(v);
    mesh.positions.push_back({p[0], p[1], p[2]});
  }
  mesh.triangles.reserve(om.n_faces());
  for (const auto f : om.faces()) {
    if (om.has_face_status() && om.status(f).deleted()) continue;
    std::array<std::uint32_t, 3> tri{};
    int k = 0;
    for (const auto v : om.fv_range(f)) tri[k++] = std::uint32_t(v.idx());
    RAYSIFT_CHECK_OP(k, ==, 3);
    mesh.triangles.push_back(tri);
  }
  return mesh;
}

}  // namespace raysift::mesh::detail
