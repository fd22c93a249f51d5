#include "mesh/mesh_io.h"

#include <OpenMesh/Core/IO/MeshIO.hh>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "core/file_util.h"
#include "mesh/detail/openmesh_convert.h"
#include "mesh/detail/off_reader.h"
#include "mesh/detail/ply_reader.h"
#include "mesh/detail/polygon_fan.h"

namespace raysift::mesh {

namespace {

void require_mesh_extension(const std::string& path) {
  const std::string ext = file_extension(path);
  if (ext != ".ply" && ext != ".obj" && ext != ".off")
    throw IoError(file_message(path, "unsupported mesh format '" + ext + "'; expected .ply, .obj or .off"));
}

/// An OBJ face corner without a vertex index ("f /1/1 ...") trips an assert in Debian's OpenMesh 9 that aborts the
/// process (found by tests/fuzz); it is rejected before OpenMesh sees it.
void reject_obj_corner_without_index(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    std::istringstream tokens(line);
    std::string word;
    if (!(tokens >> word) || word != "f") continue;
    for (std::string corner; tokens >> corner;) {
      const std::size_t digit = corner[0] == '-' ? 1 : 0;
      if (digit >= corner.size() || !std::isdigit(static_cast<unsigned char>(corner[digit])))
        throw IoError(path + ":" + std::to_string(number) + ": face corner '" + corner +
                      "' has no vertex index; expected v, v/vt, v//vn or v/vt/vn");
    }
  }
}

/// OBJ through OpenMesh; a polygon is fanned (or refused) here.
TriMesh read_obj(const std::string& path, const MeshReadOptions& options) {
  reject_obj_corner_without_index(path);
  detail::OmPolyMesh poly;
  {
    detail::MuteOpenMeshLog mute;
    if (!OpenMesh::IO::read_mesh(poly, path))
      throw IoError(file_message(path, "could not parse the mesh (malformed or truncated file)"));
  }
  TriMesh mesh;
  mesh.positions.reserve(poly.n_vertices());
  for (const auto v : poly.vertices()) {
    const auto& p = poly.point(v);
    mesh.positions.push_back({p[0], p[1], p[2]});
  }
  mesh.triangles.reserve(poly.n_faces());
  std::vector<std::uint32_t> corners;
  for (const auto f : poly.faces()) {
    corners.clear();
    for (const auto v : poly.fv_range(f)) corners.push_back(std::uint32_t(v.idx()));
    detail::append_polygon(corners, options.triangulate_polygons, path, f.idx(), mesh);
  }
  return mesh;
}

}  // namespace

void validate_mesh(const TriMesh& mesh, const std::string& what) {
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    if (!is_finite(mesh.positions[i]))
      throw InvalidInput(what + ": vertex " + std::to_string(i) + " has a non-finite coordinate; positions must be finite");
  const std::size_t n = mesh.positions.size();
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    for (const std::uint32_t v : mesh.triangles[f])
      if (v >= n)
        throw InvalidInput(what + ": triangle " + std::to_string(f) + " uses vertex " + std::to_string(v) +
                           " but the mesh has only " + std::to_string(n) + " vertices");
}

TriMesh read_mesh(const std::string& path, const MeshReadOptions& options) {
  require_readable_file(path);
  require_mesh_extension(path);
  const std::string ext = file_extension(path);
  const TriMesh mesh = ext == ".ply"   ? detail::read_ply(path, options.triangulate_polygons)
                       : ext == ".off" ? detail::read_off(path, options.triangulate_polygons)
                                       : read_obj(path, options);
  if (mesh.triangles.empty())
    throw InvalidInput(file_message(path, "the mesh has no faces (" + std::to_string(mesh.positions.size()) +
                                              " vertices); expected a triangle mesh"));
  validate_mesh(mesh, path);
  return mesh;
}

void write_mesh(const std::string& path, const TriMesh& mesh, const MeshWriteOptions& options) {
  require_mesh_extension(path);
  validate_mesh(mesh, path);
  // OpenMesh's halfedge kernel cannot hold a face that would make an edge or vertex non-manifold;
  // such a face gets its own copies of its three vertices (OpenMesh's importer does the same).
  detail::MuteOpenMeshLog mute;  // add_face reports refused (non-manifold) faces on omerr; they are handled below
  detail::OmPolyMesh om;
  om.reserve(mesh.positions.size(), mesh.triangles.size() * 3 / 2, mesh.triangles.size());
  for (const Vec3f& p : mesh.positions) om.add_vertex({p.x, p.y, p.z});
  for (const auto& t : mesh.triangles) {
    std::array<detail::OmPolyMesh::VertexHandle, 3> vh;
    for (int k = 0; k < 3; ++k) vh[k] = detail::OmPolyMesh::VertexHandle(int(t[k]));
    if (!om.add_face(vh.data(), 3).is_valid()) {
      for (int k = 0; k < 3; ++k) vh[k] = om.add_vertex({mesh.positions[t[k]].x, mesh.positions[t[k]].y, mesh.positions[t[k]].z});
      om.add_face(vh.data(), 3);
    }
  }
  OpenMesh::IO::Options opt;
  if (options.binary && file_extension(path) == ".ply") opt += OpenMesh::IO::Options::Binary;
  write_atomically(path, [&](const std::string& tmp) {
    if (!OpenMesh::IO::write_mesh(om, tmp, opt, 9)) throw IoError(file_message(path, "writing the mesh failed"));
  });
}

}  // namespace raysift::mesh
