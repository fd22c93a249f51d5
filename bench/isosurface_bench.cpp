// The iso-surface pipeline in one run (issue 12): the whole `raysift mesh` pipeline (iso choice, marching cubes,
// Taubin, simplification, Taubin) vs VTK's equivalent (FlyingEdges3D + WindowedSinc + QuadricDecimation +
// WindowedSinc, bench/vtk_pipeline.py) on the same grid and iso-values, and the view-driven feature set-up of a
// prioritized render vs the full render's frame (trace + compositing) of the same 960x600 view.
// Usage: isosurface_bench [RUNS] [EXTRA.vdb TF.json ...]   (default 1 run; extra volumes use a fitted camera)
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "core/heap_policy.h"
#include "core/json_io.h"
#include "core/scene.h"
#include "core/timer.h"
#include "features/importance.h"
#include "isosurface/feature_geometry.h"
#include "isosurface/pipeline.h"
#include "volume/generate.h"
#include "volume/raycaster.h"
#include "volume/vdb_io.h"

namespace {

using namespace raysift;

struct Case {
  std::string name;
  volume::Volume volume;
  std::shared_ptr<volume::TransferFunction> tf;
  CameraSpec camera;
};

double median_ms(int runs, const std::function<void()>& fn) {
  std::vector<double> ms;
  for (int r = 0; r < runs; ++r) {
    const Timer t;
    fn();
    ms.push_back(t.elapsed_ms());
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

/// The active bounding box (plus one voxel) as little-endian f32, x fastest, for VTK's image reader.
Vec3i write_raw(const volume::Volume& v, const std::string& path) {
  const volume::GridInfo info = v.info();
  const Vec3i lo{info.index_min.x - 1, info.index_min.y - 1, info.index_min.z - 1};
  const Vec3i dims{info.index_max.x - lo.x + 2, info.index_max.y - lo.y + 2, info.index_max.z - lo.z + 2};
  std::vector<float> data(std::size_t(dims.x) * dims.y * dims.z);
  std::size_t i = 0;
  for (int z = 0; z < dims.z; ++z)
    for (int y = 0; y < dims.y; ++y)
      for (int x = 0; x < dims.x; ++x) data[i++] = v.value_at({lo.x + x, lo.y + y, lo.z + z});
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size() * 4));
  return dims;
}

std::pair<double, long> vtk_pipeline(const volume::Volume& v, const std::vector<double>& isos, int runs) {
  const std::string raw = (std::filesystem::temp_directory_path() / "raysift_isosurface_bench.raw").string();
  const Vec3i d = write_raw(v, raw);
  std::string list;
  for (const double iso : isos) list += (list.empty() ? "" : ",") + std::to_string(iso);
  const mesh::MeshPrepOptions prep;
  const std::string cmd = "/usr/bin/python3 " RAYSIFT_SOURCE_DIR "/bench/vtk_pipeline.py " + raw + " " +
                          std::to_string(d.x) + " " + std::to_string(d.y) + " " + std::to_string(d.z) + " " + list +
                          " " + std::to_string(prep.smooth_before.iterations) + " " +
                          std::to_string(prep.decimation.ratio) + " " + std::to_string(runs) + " 2>/dev/null";
  FILE* pipe = popen(cmd.c_str(), "r");
  double ms = -1;
  long triangles = 0;
  if (!pipe || std::fscanf(pipe, "ms=%lf triangles=%ld", &ms, &triangles) != 2) ms = -1;
  if (pipe) pclose(pipe);
  std::filesystem::remove(raw);
  return {ms, triangles};
}

void run_case(const Case& c, int runs) {
  std::printf("\n%s: %llu active voxels\n", c.name.c_str(), (unsigned long long)c.volume.active_voxel_count());
  isosurface::IsosurfaceSet set;
  const double ours_ms = median_ms(runs, [&] { set = isosurface::build_isosurfaces(c.volume, c.tf.get()); });
  std::vector<double> isos;
  for (const auto& s : set.surfaces) isos.push_back(s.iso.value);
  const auto [vtk_ms, vtk_tris] = vtk_pipeline(c.volume, isos, runs);
  const std::size_t tris = isosurface::merge_surfaces(set).triangle_count();
  const isosurface::StageTimes& t = set.stages;
  std::printf("  mesh pipeline: ours %.0f ms (mc %.0f, smooth %.0f, simplify %.0f, smooth %.0f; summed per surface) "
              "%zu tris | VTK %.0f ms %ld tris | ratio %.2f\n",
              ours_ms, t.marching_cubes.ms, t.smooth_before.ms, t.decimate.ms, t.smooth_after.ms, tris, vtk_ms,
              vtk_tris, vtk_ms > 0 ? ours_ms / vtk_ms : -1.0);

  const volume::RayCaster caster(c.volume, *c.tf, c.camera);
  const double frame_ms = median_ms(std::max(runs, 3), [&] { volume::render_full(caster); });
  isosurface::FeatureGeometryOptions o;
  o.view = isosurface::FeatureView{c.camera, features::ImportanceOptions{}.scale};
  isosurface::FeatureGeometry g;
  const double setup_ms = median_ms(runs, [&] { g = isosurface::build_feature_geometry(c.volume, *c.tf, o); });
  std::printf("  feature set-up %.0f ms (level %d, %zu tris, %zu hidden iso) | full frame %dx%d %.0f ms | ratio %.2f\n",
              setup_ms, g.coarsening, g.mesh.triangle_count(), g.hidden_iso_values.size(), c.camera.width,
              c.camera.height, frame_ms, setup_ms / frame_ms);
}

Case bundled(const std::string& name, const std::string& stem) {
  const std::string dir = std::string(RAYSIFT_SOURCE_DIR) + "/datasets/";
  Case c{name, volume::load_vdb(dir + stem + ".vdb"),
         std::make_shared<volume::TransferFunction>(volume::load_transfer_function(dir + stem + "_tf.json")), {}};
  c.camera = camera_spec_from_json(read_json_file(dir + stem + "_camera.json"), stem);
  c.camera.width = 960;
  c.camera.height = 600;
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  raysift::keep_freed_buffers_for_reuse();  // as the raysift program (core/heap_policy.h)
  const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 1;
  std::printf("isosurface_bench: %d run(s), median wall times; ratios < 1 mean raysift is faster\n", runs);
  std::vector<Case> cases = {bundled("engine CT", "engine_ct"), bundled("MRI head", "mri_head")};
  volume::BlobsOptions blobs;
  blobs.grid.dims = {256, 256, 256};
  blobs.count = 12;
  blobs.sigma_voxels = 14;
  Case fog{"256^3 blobs (synthetic fog)", volume::make_blobs(blobs),
           std::make_shared<volume::TransferFunction>(std::vector<volume::TfPoint>{
               {0.0, 0, 0, 0, 0}, {0.3, 0.8, 0.5, 0.3, 0.0}, {0.5, 0.9, 0.7, 0.4, 0.6}, {1.0, 1, 1, 1, 0.9}}),
           {}};
  fog.camera = volume::fit_camera(fog.volume, 960, 600);
  cases.push_back(fog);
  for (int i = 2; i + 1 < argc; i += 2) {
    Case extra{argv[i], volume::load_vdb(argv[i]),
               std::make_shared<volume::TransferFunction>(volume::load_transfer_function(argv[i + 1])), {}};
    extra.camera = volume::fit_camera(extra.volume, 960, 600);
    cases.push_back(extra);
  }
  for (const Case& c : cases) run_case(c, runs);
  return 0;
}
