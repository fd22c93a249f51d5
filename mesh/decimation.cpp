#include "mesh/decimation.h"

#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModHausdorffT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include <cmath>

#include "core/errors.h"
#include "mesh/detail/openmesh_convert.h"
#include "mesh/mesh_io.h"

namespace raysift::mesh {

namespace {

std::size_t target_face_count(const TriMesh& mesh, const DecimationOptions& o) {
  if (!(o.ratio > 0 && o.ratio <= 1)) throw InvalidInput("decimation: ratio must be in (0, 1], got " + std::to_string(o.ratio));
  if (o.target_faces > mesh.triangle_count())
    throw InvalidInput("decimation: target of " + std::to_string(o.target_faces) + " faces exceeds the input's " +
                       std::to_string(mesh.triangle_count()));
  if (!(o.max_error >= 0) || !std::isfinite(o.max_error))
    throw InvalidInput("decimation: max_error must be a finite distance >= 0, got " + std::to_string(o.max_error));
  if (!(o.max_normal_deviation_deg > 0 && o.max_normal_deviation_deg <= 180))
    throw InvalidInput("decimation: max_normal_deviation_deg must be in (0, 180], got " +
                       std::to_string(o.max_normal_deviation_deg));
  if (o.target_faces > 0) return o.target_faces;
  return std::size_t(std::llround(o.ratio * double(mesh.triangle_count())));
}

}  // namespace

DecimationResult decimate(const TriMesh& mesh, const DecimationOptions& options) {
  validate_mesh(mesh, "decimation");
  const std::size_t target = target_face_count(mesh, options);
  DecimationResult result;
  if (target >= mesh.triangle_count()) {
    result.mesh = mesh;
    result.reached_target = true;
    return result;
  }
  std::size_t rejected = 0;
  detail::OmTriMesh om = detail::to_openmesh(mesh, &rejected);
  if (rejected > 0)
    throw InvalidInput("decimation: " + std::to_string(rejected) +
                       " triangles make the mesh non-manifold (or repeat a vertex); OpenMesh's decimater needs a "
                       "manifold mesh. Hint: check it with mesh_analysis first");
  om.update_face_normals();

  using Decimater = OpenMesh::Decimater::DecimaterT<detail::OmTriMesh>;
  Decimater decimater(om);
  OpenMesh::Decimater::ModQuadricT<detail::OmTriMesh>::Handle quadric;
  OpenMesh::Decimater::ModNormalFlippingT<detail::OmTriMesh>::Handle flipping;
  OpenMesh::Decimater::ModHausdorffT<detail::OmTriMesh>::Handle hausdorff;
  decimater.add(quadric);
  // The priority module must stay non-binary: unset_max_err() (no cost cap) keeps it so. A cost cap would
  // be in area x distance² units; the distance bound is enforced exactly by ModHausdorff instead.
  decimater.module(quadric).unset_max_err();
  decimater.add(flipping);
  decimater.module(flipping).set_max_normal_deviation(options.max_normal_deviation_deg);
  if (options.max_error > 0) {
    decimater.add(hausdorff);
    decimater.module(hausdorff).set_tolerance(float(options.max_error));
  }
  RAYSIFT_CHECK(decimater.initialize());
  result.collapses = decimater.decimate_to_faces(0, target);
  om.garbage_collection();
  result.mesh = detail::from_openmesh(om);
  // A collapse removes two faces on a closed mesh (one at a boundary), so the count lands on target or
  // one below.
  result.reached_target = result.mesh.triangle_count() <= target + 1;
  return result;
}

}  // namespace raysift::mesh
