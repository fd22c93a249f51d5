#include "mesh/mesh_io.h"

#include <OpenMesh/Core/IO/MeshIO.hh>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "core/errors.h"
#include "core/file_util.h"
#include "mesh/detail/openmesh_convert.h"

namespace raysift::mesh {

namespace {

void require_mesh_extension(const std::string& path) {
  const std::string ext = file_extension(path);
  if (ext != ".ply" && ext != ".obj" && ext != ".off")
    throw IoError(file_message(path, "unsupported mesh format '" + ext + "'; expected .ply, .obj or .off"));
}

bool is_ply_type(const std::string& t) {
  static const char* types[] = {"char",  "uchar",  "short", "ushort", "int",   "uint",    "float",   "double",
                                "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
  return std::any_of(std::begin(types), std::end(types), [&](const char* k) { return t == k; });
}

/// One PLY header line is well formed: OpenMesh 9's header parser reads past malformed ones (a crash, or a loop).
bool is_ply_header_line(const std::string& line) {
  std::istringstream in(line);
  std::string word, a, b, c, rest;
  if (!(in >> word)) return false;
  if (word == "comment" || word == "obj_info") return true;
  if (word == "format") return (in >> a >> b) && !(in >> rest) && b == "1.0" &&  // PLY has one version
                               (a == "ascii" || a == "binary_little_endian" || a == "binary_big_endian");
  if (word == "element") {
    long long count = -1;
    return (in >> a >> count) && count >= 0 && !(in >> rest);
  }
  if (word != "property" || !(in >> a >> b)) return false;
  if (a != "list") return is_ply_type(a) && !(in >> rest);
  return is_ply_type(b) && (in >> c) && is_ply_type(c) && (in >> rest) && !(in >> word);
}

/// An ASCII PLY face whose list count is negative or exceeds the numbers on its line makes OpenMesh allocate
/// gigabytes (found by tests/fuzz). `before_faces` = the lines of the elements that precede "face".
void reject_bad_ascii_face_counts(std::istream& in, int number, long long before_faces, long long faces,
                                  const std::string& path) {
  std::string line;
  for (long long skipped = 0; skipped < before_faces && std::getline(in, line); ++skipped) ++number;
  for (long long face = 0; face < faces && std::getline(in, line); ++face) {
    ++number;
    std::istringstream tokens(line);
    long long count = 0;
    if (!(tokens >> count)) continue;
    long long rest = 0;
    for (std::string t; tokens >> t;) ++rest;
    if (count < 0 || count > rest)
      throw IoError(path + ":" + std::to_string(number) + ": face list count " + std::to_string(count) +
                    " does not match the " + std::to_string(rest) + " indices on its line");
  }
}

/// Input that Debian's OpenMesh 9 does not survive, rejected before it gets there (found by tests/fuzz): a PLY
/// header without `end_header` loops its reader forever and a malformed header line crashes it; an OBJ face
/// corner without a vertex index ("f /1/1 ...") trips an assert that aborts the process.
void reject_openmesh_traps(const std::string& path, const std::string& ext) {
  if (ext != ".ply" && ext != ".obj") return;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  bool seen_element = false, ascii = false, seen_face = false;
  long long before_faces = 0, faces = 0;
  std::set<std::string> element_names;
  for (int number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string where = path + ":" + std::to_string(number) + ": ";
    if (ext == ".ply") {
      if (line == "end_header") {
        if (ascii && seen_face) reject_bad_ascii_face_counts(in, number, before_faces, faces, path);
        return;
      }
      const bool is_property = line.rfind("property", 0) == 0;  // a property before any element segfaults OpenMesh
      if (number == 1 ? line != "ply" : !is_ply_header_line(line) || (is_property && !seen_element))
        throw IoError(where + "malformed PLY header line '" + line.substr(0, 60) + "'");
      seen_element = seen_element || line.rfind("element", 0) == 0;
      ascii = ascii || line.rfind("format ascii", 0) == 0;
      std::istringstream words(line);
      std::string keyword, name;
      long long count = 0;
      if (words >> keyword >> name >> count && keyword == "element" && !element_names.insert(name).second)
        throw IoError(where + "PLY element '" + name + "' declared twice");  // OpenMesh's header scan loops on it
      if (!seen_face && keyword == "element") {
        if (name == "face") {
          seen_face = true;
          faces = count;
        } else {
          before_faces += std::max(0LL, count);
        }
      }
      continue;
    }
    std::istringstream tokens(line);
    std::string word;
    if (!(tokens >> word) || word != "f") continue;
    for (std::string corner; tokens >> corner;) {
      const std::size_t digit = corner[0] == '-' ? 1 : 0;
      if (digit >= corner.size() || !std::isdigit(static_cast<unsigned char>(corner[digit])))
        throw IoError(where + "face corner '" + corner + "' has no vertex index; expected v, v/vt, v//vn or v/vt/vn");
    }
  }
  if (ext == ".ply") throw IoError(file_message(path, "malformed PLY: the header has no 'end_header' line"));
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
  reject_openmesh_traps(path, file_extension(path));
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
    if (corners.size() > 3 && !options.triangulate_polygons)
      throw InvalidInput(file_message(path, "face " + std::to_string(f.idx()) + " has " +
                                                std::to_string(corners.size()) +
                                                " corners; expected triangles (enable polygon triangulation)"));
    for (std::size_t i = 1; i + 1 < corners.size(); ++i) mesh.triangles.push_back({corners[0], corners[i], corners[i + 1]});
  }
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
