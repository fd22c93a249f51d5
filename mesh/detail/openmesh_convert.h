#pragma once
/// \file mesh/-internal: the OpenMesh mesh types used inside mesh/ and conversions to and from the
/// plain TriMesh. Heavy header: include only from mesh/*.cpp.
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include "core/tri_mesh.h"

namespace raysift::mesh::detail {

/// Float positions like TriMesh, so conversions are exact; the quadric module accumulates in double.
struct OmTraits : OpenMesh::DefaultTraits {
  VertexAttributes(OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::PrevHalfedge);
  FaceAttributes(OpenMesh::Attributes::Status | OpenMesh::Attributes::Normal);
};
using OmTriMesh = OpenMesh::TriMesh_ArrayKernelT<OmTraits>;
using OmPolyMesh = OpenMesh::PolyMesh_ArrayKernelT<>;

/// OpenMesh reports refused faces and parse problems on its own streams; library code must not print
/// (STYLE.md §5), so they are muted in this scope and outcomes are reported through exceptions instead.
/// Not thread-safe (OpenMesh's streams are global).
class MuteOpenMeshLog {
 public:
  MuteOpenMeshLog() {
    omerr().disable();
    omlog().disable();
    omout().disable();
  }
  ~MuteOpenMeshLog() {
    omerr().enable();
    omlog().enable();
    omout().enable();
  }
  MuteOpenMeshLog(const MuteOpenMeshLog&) = delete;
  MuteOpenMeshLog& operator=(const MuteOpenMeshLog&) = delete;
};

/// Every TriMesh vertex becomes an OpenMesh vertex with the same index. OpenMesh refuses faces that
/// would make an edge or vertex non-manifold; those are skipped and counted in `rejected_faces`.
OmTriMesh to_openmesh(const TriMesh& mesh, std::size_t* rejected_faces = nullptr);

/// Copies the non-deleted vertices and faces (call garbage_collection() first for compact indices).
TriMesh from_openmesh(const OmTriMesh& mesh);

}  // namespace raysift::mesh::detail
