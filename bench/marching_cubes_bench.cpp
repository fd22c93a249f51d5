// Marching-cubes speed: ours (volume/marching_cubes.h) vs OpenVDB tools::volumeToMesh (adaptivity 0) vs VTK
// vtkFlyingEdges3D, same grid and iso-value, in one run. Plain main printing a table; ratios > 1 mean ours
// is slower. Usage: marching_cubes_bench [RUNS]   (default 7; median wall time per extractor)
#include <openvdb/tools/VolumeToMesh.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "core/timer.h"
#include "volume/detail/vdb_grid.h"
#include "volume/generate.h"
#include "volume/import.h"
#include "volume/marching_cubes.h"

namespace {

using namespace raysift;

double median_ms(int runs, const std::function<void()>& fn) {
  std::vector<double> ms;
  for (int r = 0; r < runs; ++r) {
    Timer t;
    fn();
    ms.push_back(t.elapsed_ms());
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

/// Runs bench/vtk_reference.py; returns {ms, triangles} or {-1, 0} if VTK is unavailable.
std::pair<double, long> vtk_flying_edges(const std::string& raw, const Vec3i& dims, const std::string& type,
                                         double iso, int runs) {
  const std::string cmd = "/usr/bin/python3 " RAYSIFT_SOURCE_DIR "/bench/vtk_reference.py flying-edges " + raw + " " +
                          std::to_string(dims.x) + " " + std::to_string(dims.y) + " " + std::to_string(dims.z) + " " +
                          type + " " + std::to_string(iso) + " " + std::to_string(runs) + " 2>/dev/null";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return {-1, 0};
  double ms = -1;
  long triangles = 0;
  if (std::fscanf(pipe, "ms=%lf triangles=%ld", &ms, &triangles) != 2) ms = -1;
  pclose(pipe);
  return {ms, triangles};
}

void bench(const std::string& label, const volume::Volume& vol, double iso, const std::string& raw,
           const std::string& raw_type, const Vec3i& dims, int runs) {
  std::size_t ours_tris = 0;
  const double ours_ms = median_ms(runs, [&] { ours_tris = volume::extract_isosurface(vol, iso).triangle_count(); });
  std::size_t vdb_tris = 0;
  const openvdb::FloatGrid& grid = *vol.impl().grid;
  const double vdb_ms = median_ms(runs, [&] {
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> tris;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(grid, points, tris, quads, iso, 0.0);
    vdb_tris = tris.size() + 2 * quads.size();
  });
  const auto [vtk_ms, vtk_tris] = vtk_flying_edges(raw, dims, raw_type, iso, runs);
  std::printf("%-28s iso %-6g | ours %8.1f ms %8zu tri | OpenVDB %8.1f ms %8zu tri | ratio ours/OpenVDB %5.2f", label.c_str(),
              iso, ours_ms, ours_tris, vdb_ms, vdb_tris, ours_ms / vdb_ms);
  if (vtk_ms > 0)
    std::printf(" | VTK FlyingEdges3D %8.1f ms %8ld tri | ratio ours/VTK %5.2f\n", vtk_ms, vtk_tris, ours_ms / vtk_ms);
  else
    std::printf(" | VTK unavailable (/usr/bin/python3 with python3-vtk9)\n");
}

}  // namespace

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 7;
  const std::string engine_raw = "/work/shared/datasets/engine_ct_256x256x128_u8.raw.gz";
  std::printf("median of %d runs, default thread count\n", runs);
  if (std::filesystem::exists(engine_raw)) {
    volume::RawLayout layout;
    layout.dims = {256, 256, 128};
    const volume::Volume engine = volume::import_raw(engine_raw, layout);
    for (const double iso : {80.0, 150.0}) bench("engine CT 256x256x128 u8", engine, iso, engine_raw, "u8", layout.dims, runs);
  } else {
    std::printf("engine CT not found at %s; skipped\n", engine_raw.c_str());
  }

  // 256^3 analytic volume: 24 Gaussian blobs; the dense float copy feeds VTK.
  volume::BlobsOptions blobs;
  blobs.grid.dims = {256, 256, 256};
  blobs.count = 24;
  blobs.sigma_voxels = 14.0;
  const volume::Volume analytic = volume::make_blobs(blobs);
  const std::string raw = (std::filesystem::temp_directory_path() / "raysift_mc_bench_blobs_256.raw").string();
  {
    std::vector<float> dense(std::size_t(256) * 256 * 256);
    auto acc = analytic.impl().grid->getConstAccessor();
    for (int k = 0; k < 256; ++k)
      for (int j = 0; j < 256; ++j)
        for (int i = 0; i < 256; ++i) dense[(std::size_t(k) * 256 + j) * 256 + i] = acc.getValue(openvdb::Coord(i, j, k));
    std::ofstream(raw, std::ios::binary).write(reinterpret_cast<const char*>(dense.data()), dense.size() * sizeof(float));
  }
  bench("analytic blobs 256^3 f32", analytic, 0.5, raw, "f32", blobs.grid.dims, runs);
  std::filesystem::remove(raw);
  return 0;
}
