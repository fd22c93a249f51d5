// Marching-cubes speed: ours (volume/marching_cubes.h) vs OpenVDB tools::volumeToMesh (adaptivity 0) vs VTK
// vtkFlyingEdges3D, same grid and iso-value, in one run, with the same thread count for all three. Plain main
// printing a table; ratios > 1 mean ours is slower. Each time is the fastest of N runs (the least disturbed
// on a shared machine); ours is timed N times before and N times after the references.
//
// Usage: marching_cubes_bench [--runs N] [--threads N] [--ours-only] [FILE.vdb:ISO[,ISO...] ...]
//   Without volume arguments: the bundled engine CT and MRI (datasets/), a 256^3 synthetic fog of Gaussian blobs,
//   and two volumes that are not bundled (bench/bench_data.h: $RAYSIFT_SHARED_DATASETS or ../shared/datasets
//   beside the repository): the OpenVDB smoke sample and the hydrogen orbital, when present.
//   --ours-only skips OpenVDB and VTK (for profiling).
//
// VTK sees the volume exactly as ours does: the active bounding box, inactive voxels at the background value,
// written densely with a one-voxel background border, so both close the surface where it leaves the data
// (ours always does). FlyingEdges3D is timed on the padded and on the unpadded box; the ratio uses the faster
// of the two (the conservative choice) and the triangle difference uses the padded one (the same surface).
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "bench/bench_data.h"
#include "core/heap_policy.h"
#include "core/timer.h"
#include "volume/detail/vdb_grid.h"
#include "volume/generate.h"
#include "volume/import.h"
#include "volume/marching_cubes.h"
#include "volume/vdb_io.h"

namespace {

using namespace raysift;

struct Case {
  std::string label;
  volume::Volume volume;
  std::vector<double> isos;
};

struct VtkResult {
  double ms = -1, interior_ms = -1;
  long triangles = 0, interior_triangles = 0;
};

/// Fastest of `runs` wall times: on a shared machine the least disturbed run (the same statistic for all three).
double min_ms(int runs, const std::function<void()>& fn) {
  double best = 1e300;
  for (int r = 0; r < runs; ++r) {
    Timer t;
    fn();
    best = std::min(best, t.elapsed_ms());
  }
  return best;
}

/// The active bounding box grown by one voxel, dense, x fastest; inactive voxels at the background. Written as
/// u8 when every value is an integer in [0, 255] (the CT and MRI), else as f32. Returns the type name.
std::string write_dense(const volume::Volume& vol, const std::string& path, Vec3i& dims) {
  const openvdb::FloatGrid& grid = *vol.impl().grid;
  openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  box.expand(1);
  dims = {box.dim().x(), box.dim().y(), box.dim().z()};
  std::vector<float> dense(std::size_t(dims.x) * dims.y * dims.z);
  auto acc = grid.getConstAccessor();
  bool is_u8 = true;
  std::size_t n = 0;
  for (int z = box.min().z(); z <= box.max().z(); ++z)
    for (int y = box.min().y(); y <= box.max().y(); ++y)
      for (int x = box.min().x(); x <= box.max().x(); ++x) {
        float v;
        if (!acc.probeValue(openvdb::Coord(x, y, z), v)) v = grid.background();
        dense[n++] = v;
        is_u8 = is_u8 && v >= 0 && v <= 255 && v == std::floor(v);
      }
  std::ofstream out(path, std::ios::binary);
  if (is_u8) {
    const std::vector<unsigned char> bytes(dense.begin(), dense.end());
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  } else {
    out.write(reinterpret_cast<const char*>(dense.data()), std::streamsize(dense.size() * sizeof(float)));
  }
  return is_u8 ? "u8" : "f32";
}

VtkResult vtk_flying_edges(const std::string& raw, const Vec3i& dims, const std::string& type, double iso, int runs,
                           int threads) {
  char iso_text[64];
  std::snprintf(iso_text, sizeof iso_text, "%.17g", iso);
  const std::string cmd = "/usr/bin/python3 " RAYSIFT_SOURCE_DIR "/bench/vtk_reference.py flying-edges " + raw + " " +
                          std::to_string(dims.x) + " " + std::to_string(dims.y) + " " + std::to_string(dims.z) + " " +
                          type + " " + iso_text + " " + std::to_string(runs) + " 1 " + std::to_string(threads) +
                          " 2>/dev/null";
  VtkResult r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  if (std::fscanf(pipe, "ms=%lf triangles=%ld interior_ms=%lf interior_triangles=%ld", &r.ms, &r.triangles,
                  &r.interior_ms, &r.interior_triangles) != 4)
    r = VtkResult{};
  pclose(pipe);
  return r;
}

void bench_case(const Case& c, double iso, int runs, int threads, bool ours_only) {
  std::size_t ours_tris = 0;
  auto ours = [&] { ours_tris = volume::extract_isosurface(c.volume, iso).triangle_count(); };
  if (ours_only) {
    std::printf("%-26s iso %-7g | ours %7.1f ms %8zu tri\n", c.label.c_str(), iso, min_ms(runs, ours), ours_tris);
    return;
  }
  // Ours is timed before and after the references, so a change of machine load during the case hits all three.
  double ours_ms = min_ms(runs, ours);
  std::size_t vdb_tris = 0;
  const openvdb::FloatGrid& grid = *c.volume.impl().grid;
  const double vdb_ms = min_ms(runs, [&] {
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> tris;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(grid, points, tris, quads, iso, 0.0);
    vdb_tris = tris.size() + 2 * quads.size();
  });
  const std::string raw = (std::filesystem::temp_directory_path() / "raysift_mc_bench_dense.raw").string();
  Vec3i dims;
  const std::string type = write_dense(c.volume, raw, dims);
  const VtkResult vtk = vtk_flying_edges(raw, dims, type, iso, runs, threads);
  std::filesystem::remove(raw);
  ours_ms = std::min(ours_ms, min_ms(runs, ours));
  std::printf("%-26s iso %-7g | ours %7.1f ms %8zu tri | OpenVDB %7.1f ms %8zu tri, ours/OpenVDB %5.2f", c.label.c_str(),
              iso, ours_ms, ours_tris, vdb_ms, vdb_tris, ours_ms / vdb_ms);
  if (vtk.ms < 0) {
    std::printf(" | VTK unavailable (/usr/bin/python3 with python3-vtk9)\n");
    return;
  }
  const double best = std::min(vtk.ms, vtk.interior_ms);
  std::printf(" | VTK FE3D %7.1f ms (unpadded %7.1f) %8ld tri (unpadded %8ld), tri diff %+6.2f%% | ours/VTK %5.2f\n",
              vtk.ms, vtk.interior_ms, vtk.triangles, vtk.interior_triangles,
              100.0 * (double(ours_tris) - double(vtk.triangles)) / double(std::max(1L, vtk.triangles)),
              ours_ms / best);
}

/// Loads `path` if it exists; a missing file is reported and skipped (the shared folder is optional).
void add_vdb(std::vector<Case>& cases, const std::string& label, const std::string& path, std::vector<double> isos) {
  if (!std::filesystem::exists(path)) {
    std::printf("%s not found at %s; skipped\n", label.c_str(), path.c_str());
    return;
  }
  cases.push_back({label, volume::load_vdb(path), std::move(isos)});
}

std::vector<Case> default_cases() {
  const std::string data = raysift::bench::bundled_datasets_dir(), shared = raysift::bench::shared_datasets_dir();
  std::vector<Case> cases;
  add_vdb(cases, "engine CT 256x256x128", data + "engine_ct.vdb", {80.0, 150.0});
  add_vdb(cases, "MRI head 128x128x84", data + "mri_head.vdb", {40.0, 90.0});
  volume::BlobsOptions blobs;
  blobs.grid.dims = {256, 256, 256};
  blobs.count = 24;
  blobs.sigma_voxels = 14.0;
  cases.push_back({"synthetic fog 256^3 (blobs)", volume::make_blobs(blobs), {0.2, 0.5}});
  add_vdb(cases, "smoke VDB (not bundled)", shared + "openvdb_sample_smoke1_density_fog_111x222x112.vdb", {0.1, 0.5});
  const std::string hydrogen = shared + "hydrogen_atom_3d_orbital_64x64x64_f32le.raw.gz";
  if (std::filesystem::exists(hydrogen)) {
    volume::RawLayout layout;
    layout.dims = {64, 64, 64};
    layout.type = volume::ScalarType::F32;
    cases.push_back({"hydrogen 64^3 (not bundled)", volume::import_raw(hydrogen, layout), {0.01, 0.1}});
  } else {
    std::printf("hydrogen orbital not found at %s; skipped\n", hydrogen.c_str());
  }
  return cases;
}

/// "FILE.vdb:ISO[,ISO...]" -> a case labelled with the file name.
Case parse_case(const std::string& arg) {
  const std::size_t colon = arg.rfind(':');
  if (colon == std::string::npos) throw std::invalid_argument("expected FILE.vdb:ISO[,ISO...], got '" + arg + "'");
  Case c{std::filesystem::path(arg.substr(0, colon)).filename().string(), volume::load_vdb(arg.substr(0, colon)), {}};
  for (std::size_t start = colon + 1; start <= arg.size();) {
    const std::size_t end = std::min(arg.find(',', start), arg.size());
    c.isos.push_back(std::stod(arg.substr(start, end - start)));
    start = end + 1;
  }
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  raysift::keep_freed_buffers_for_reuse();  // as the raysift program (core/heap_policy.h)
  int runs = 7, threads = 2;
  bool ours_only = false;
  std::vector<Case> cases;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--runs" && i + 1 < argc) {
        runs = std::max(1, std::atoi(argv[++i]));
      } else if (a == "--threads" && i + 1 < argc) {
        threads = std::max(1, std::atoi(argv[++i]));
      } else if (a == "--ours-only") {
        ours_only = true;
      } else {
        cases.push_back(parse_case(a));
      }
    }
    if (cases.empty()) cases = default_cases();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "marching_cubes_bench: %s\n", e.what());
    return 1;
  }
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  std::printf("fastest of %d runs (ours: of 2 x %d, before and after the references), %d threads for ours, OpenVDB (TBB) and VTK (vtkSMPTools)\n", runs, runs, threads);
  for (const Case& c : cases)
    for (const double iso : c.isos) bench_case(c, iso, runs, threads, ours_only);
  return 0;
}
