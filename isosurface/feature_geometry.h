#pragma once
/// \file View-independent feature geometry of a volume under a transfer function: the iso-surfaces merged
/// into one mesh, prepared (Taubin, simplification, Taubin; RP paper §7.1-7.2), with its curvature. Key
/// decision: the importance buffer the lines feed is a few hundred pixels across, so the geometry is built
/// only as fine as that buffer resolves: marching cubes runs on a coarser level of the grid whose cells
/// project to about one importance pixel, and simplification stops at a fraction of a pixel of error.
/// Built once per (volume, TF, options) and reused for every view; optionally cached (feature_cache.h).
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "isosurface/feature_cache.h"
#include "isosurface/pipeline.h"
#include "mesh/curvature.h"
#include "core/tri_mesh.h"
#include "volume/transfer_function.h"
#include "volume/volume.h"

namespace raysift::isosurface {

struct FeatureGeometry {
  TriMesh mesh;
  mesh::MeshCurvature curvature;
  std::vector<double> iso_values;  ///< the surfaces in `mesh`
  std::vector<double> hidden_iso_values;  ///< chosen, but hidden by the TF from every probe direction: not built
  int coarsening = 1;              ///< grid level used: cells of this many voxels per axis
  bool from_cache = false;
  double build_ms = 0;             ///< wall time of the whole set-up (cache look-up included)
  /// Where the set-up went (ms; zero on a cache hit): coarse level, visibility probe, pipeline stages
  /// (summed over surfaces), curvature.
  double level_ms = 0, probe_ms = 0, curvature_ms = 0;
  StageTimes stages;
};

/// The view the geometry is made for: the frame camera and the importance buffer's size relative to it.
struct FeatureView {
  CameraSpec camera;
  double importance_scale = 0.5;  ///< importance buffer side / frame side, in (0, 1]
};

struct FeatureGeometryOptions {
  std::vector<double> iso_values;  ///< empty = chosen from the histogram and the TF
  int max_surfaces = 3;            ///< cap for the automatic choice (volume/iso_values.h)
  int smooth_iterations = 10;      ///< Taubin iterations before and after simplification (0 = off)
  double decimate_ratio = 0.1;     ///< target faces / input faces, in (0,1] (1 = off)
  /// Grid level: 0 = chosen from `view` (1 without a view); else 1, 2, 4 or 8 voxels per cell.
  int coarsening = 0;
  double cell_px = 4.0;            ///< automatic level: the coarsest whose cells project to <= this many importance px
                                   ///< (4 and max_error_px 2: docs/isosurface.md, "The defaults")
  /// > 0 and a view: simplification also stops once its error would exceed this many importance pixels.
  double max_error_px = 2.0;
  /// Drop iso-surfaces that the TF hides from every direction (volume/iso_visibility.h), e.g. inside opaque
  /// material; if the probe finds none visible, all are kept.
  bool drop_hidden = true;
  std::optional<FeatureView> view;
  const std::atomic<bool>* cancel = nullptr;  ///< see PipelineOptions::cancel
  std::function<void(double)> progress;       ///< see PipelineOptions::progress
};

/// Size of one importance-buffer pixel in world units at the point of the volume's bounding box nearest to
/// the eye (the finest the view resolves anywhere in the volume).
double importance_pixel_size(const volume::Volume& volume, const FeatureView& view);
double importance_pixel_size(const volume::GridInfo& info, const FeatureView& view);  ///< from the grid's info

/// The coarsening the options choose for `volume` (1, 2, 4 or 8): monotone, a larger view never gets a
/// coarser level. The coarse grid keeps at least 32 cells along its longest active extent.
int choose_coarsening(const volume::Volume& volume, const FeatureGeometryOptions& options);
int choose_coarsening(const volume::GridInfo& info, const FeatureGeometryOptions& options);  ///< from the grid's info

/// The view-dependent choices of a build: the level and the simplification bound (world units). They depend on
/// the whole grid's GridInfo alone, so every rank of a split grid makes the same ones.
struct FeatureLevel {
  int coarsening = 1;
  double max_error = 0;
};
FeatureLevel choose_feature_level(const volume::GridInfo& info, const FeatureGeometryOptions& options);

/// \brief Builds (or finds in `cache`, when given) the feature geometry.
/// \throw InvalidInput if the TF is transparent everywhere (no iso-value), or no surface can be extracted;
///        Cancelled when the cancel flag is set.
FeatureGeometry build_feature_geometry(const volume::Volume& volume, const volume::TransferFunction& tf,
                                       const FeatureGeometryOptions& options = {}, FeatureCache* cache = nullptr);

/// \brief The rest of a build on marching-cubes surfaces extracted elsewhere (the bricks of --distribute data,
/// mpi/distributed_features.h): preparation, merging and curvature. raw[i] is the surface of iso_values[i] on the
/// level `level` chose. The same steps as build_feature_geometry(), so the same surfaces give the same geometry.
/// \throw InvalidInput as build_feature_geometry() when no surface remains.
FeatureGeometry finish_feature_geometry(std::vector<TriMesh> raw, const std::vector<double>& iso_values,
                                        const FeatureGeometryOptions& options, const FeatureLevel& level);

/// \brief Feature geometry from a prepared mesh file (e.g. the output of `raysift mesh`) instead of the
/// volume's iso-surfaces. With `volume`, the mesh's bounding box must lie within the volume's world bounding
/// box grown by one voxel (iso-surfaces of that volume always do).
/// \throw IoError / InvalidInput naming the file (and both boxes when they do not match).
FeatureGeometry load_feature_geometry(const std::string& mesh_path, const volume::Volume* volume = nullptr);

}  // namespace raysift::isosurface
