// Mesh preparation on marching-cubes output (bundled engine CT iso 80 and 150, bundled MRI iso 60, 256^3
// Gaussian blobs iso 0.5), in one run: our Taubin smoothing vs OpenMesh JacobiLaplaceSmootherT and VTK
// vtkWindowedSincPolyDataFilter (vertex-iterations per second), and our quadric-collapse decimation vs VTK
// vtkQuadricDecimation to 10% of the faces: time, ratio, and the one-sided Hausdorff distances of both results
// measured by the same C++ code (VTK's result is read back from a PLY the python script writes).
// Usage: mesh_prep_bench [ITERATIONS] (default 20 smoothing iterations)
#include <OpenMesh/Tools/Smoother/JacobiLaplaceSmootherT.hh>
#include <meshoptimizer.h>

#include <algorithm>
#include <cfloat>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/bench_data.h"
#include "core/heap_policy.h"
#include "core/timer.h"
#include "mesh/decimation.h"
#include "mesh/detail/openmesh_convert.h"
#include "mesh/mesh_analysis.h"
#include "mesh/mesh_io.h"
#include "mesh/primitives.h"
#include "mesh/smoothing.h"
#include "volume/generate.h"
#include "volume/vdb_io.h"
#include "volume/marching_cubes.h"

namespace {

using namespace raysift;

/// Runs one mode of bench/vtk_reference.py and returns {ms, triangles}; ms < 0 if VTK is unavailable.
std::pair<double, long> vtk(const std::string& mode, const std::string& ply, long arg, int runs = 1,
                            const std::string& out = "") {
  const std::string cmd = "/usr/bin/python3 " RAYSIFT_SOURCE_DIR "/bench/vtk_reference.py " + mode + " " + ply + " " +
                          std::to_string(arg) + " " + std::to_string(runs) + " " + out + " 2>/dev/null";
  FILE* pipe = popen(cmd.c_str(), "r");
  double ms = -1;
  long triangles = 0;
  if (!pipe || std::fscanf(pipe, "ms=%lf triangles=%ld", &ms, &triangles) != 2) ms = -1;
  if (pipe) pclose(pipe);
  return {ms, triangles};
}

/// Points on a simplified surface: its vertices plus each triangle's centroid and edge midpoints (vertices
/// alone would say nothing about the triangles between).
std::vector<Vec3f> surface_samples(const TriMesh& m) {
  std::vector<Vec3f> out = m.positions;
  for (const auto& t : m.triangles) {
    const Vec3f a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
    out.push_back((a + b + c) * (1.0f / 3));
    out.push_back((a + b) * 0.5f);
    out.push_back((b + c) * 0.5f);
    out.push_back((c + a) * 0.5f);
  }
  return out;
}

struct Quality {
  double to_original = 0;  ///< simplified surface samples -> original surface (the issue's direction)
  double from_original = 0;  ///< original vertices -> simplified surface (decimate()'s max_error direction)
  bool watertight = false;
  long euler = 0;
};

Quality quality(const TriMesh& original, const TriMesh& simplified) {
  const mesh::MeshAnalysis a = mesh::analyze_mesh(simplified);
  return {mesh::max_distance_to_surface(surface_samples(simplified), original),
          mesh::max_distance_to_surface(original.positions, simplified), a.is_watertight(), long(a.euler_characteristic)};
}

void bench_decimation(const TriMesh& m, const std::string& ply) {
  mesh::DecimationOptions dec;
  dec.ratio = 0.1;
  mesh::DecimationResult ours;
  std::vector<double> times;
  for (int run = 0; run < 3; ++run) {  // median of 3, like the VTK script
    Timer t;
    ours = mesh::decimate(m, dec);
    times.push_back(t.elapsed_ms());
  }
  std::sort(times.begin(), times.end());
  const double dec_ms = times[1];
  const std::size_t faces = ours.mesh.triangle_count();
  const mesh::MeshAnalysis in = mesh::analyze_mesh(m);
  const Quality q = quality(m, ours.mesh);
  std::printf("  input: watertight %d, euler %ld, %zu components\n", int(in.is_watertight()),
              long(in.euler_characteristic), in.components);
  std::printf("  decimation (ours = quadric collapse) to %zu faces %9.1f ms  %6.2f M input triangles/s\n", faces,
              dec_ms, double(m.triangle_count()) / dec_ms * 1e-3);
  std::printf("    %zu collapses, %zu locked vertices, topology kept (watertight and euler as input) %d\n",
              ours.collapses, ours.locked_vertices,
              int(q.watertight == in.is_watertight() && q.euler == long(in.euler_characteristic)));
  std::printf("    Hausdorff simplified->original %.4f, original->simplified %.4f, watertight %d, euler %ld\n",
              q.to_original, q.from_original, int(q.watertight), q.euler);
  const std::string vtk_ply = ply + ".vtk.ply";
  const auto [vtk_ms, vtk_tris] = vtk("quadric-decimation", ply, long(dec.ratio * double(m.triangle_count()) + 0.5),
                                      3, vtk_ply);
  if (vtk_ms < 0) return;
  const Quality v = quality(m, mesh::read_mesh(vtk_ply));
  std::printf("  VTK QuadricDecimation to %ld faces           %9.1f ms  ratio ours/VTK time %.2f (target <= 0.5)\n",
              vtk_tris, vtk_ms, dec_ms / vtk_ms);
  std::printf("    Hausdorff simplified->original %.4f, original->simplified %.4f, watertight %d, euler %ld\n",
              v.to_original, v.from_original, int(v.watertight), v.euler);
  std::printf("    ratio ours/VTK Hausdorff simplified->original %.2f (target <= 1.1), original->simplified %.2f\n",
              q.to_original / v.to_original, q.from_original / v.from_original);
  std::filesystem::remove(vtk_ply);
}

void bench_mesh(const std::string& label, const TriMesh& m, int iterations) {
  const double v = double(m.vertex_count());
  std::printf("\n%s: %zu vertices, %zu triangles, %d iterations\n", label.c_str(), m.vertex_count(), m.triangle_count(),
              iterations);
  const std::string ply = (std::filesystem::temp_directory_path() / "raysift_mesh_prep_bench.ply").string();
  mesh::write_mesh(ply, m);

  mesh::SmoothingOptions taubin;
  taubin.iterations = iterations;
  Timer t;
  mesh::taubin_smooth(m, taubin);
  const double ours_ms = t.elapsed_ms();
  taubin.threaded = false;
  t.reset();
  mesh::taubin_smooth(m, taubin);
  const double serial_ms = t.elapsed_ms();
  // OpenMesh: one smooth() iteration is a single Jacobi Laplacian pass; a Taubin iteration is two passes.
  mesh::detail::OmTriMesh om = mesh::detail::to_openmesh(m);
  t.reset();
  {
    OpenMesh::Smoother::JacobiLaplaceSmootherT<mesh::detail::OmTriMesh> smoother(om);
    smoother.initialize(OpenMesh::Smoother::SmootherT<mesh::detail::OmTriMesh>::Tangential_and_Normal,
                        OpenMesh::Smoother::SmootherT<mesh::detail::OmTriMesh>::C0);
    smoother.smooth(unsigned(2 * iterations));
  }
  const double om_ms = t.elapsed_ms();
  const auto [vtk_ms, vtk_tris] = vtk("windowed-sinc", ply, iterations);
  std::printf("  Taubin (ours, %d lambda|mu iterations)     %9.1f ms  %7.1f M vertex-iterations/s\n", iterations, ours_ms,
              v * iterations / ours_ms * 1e-3);
  std::printf("  Taubin (ours, serial path)                 %9.1f ms  %7.1f M vertex-iterations/s\n", serial_ms,
              v * iterations / serial_ms * 1e-3);
  std::printf("  OpenMesh JacobiLaplace (%d passes, serial)  %9.1f ms  ratio OpenMesh/ours %.2f (target >= 2), "
              "OpenMesh/ours-serial %.2f\n",
              2 * iterations, om_ms, om_ms / ours_ms, om_ms / serial_ms);
  if (vtk_ms > 0)
    std::printf("  VTK WindowedSinc (%d iterations)            %9.1f ms  %7.1f M vertex-iterations/s, ratio ours/VTK "
                "throughput %.2f\n",
                iterations, vtk_ms, v * iterations / vtk_ms * 1e-3, vtk_ms / ours_ms);

  bench_decimation(m, ply);
  std::filesystem::remove(ply);
}

}  // namespace

/// Throughput of one plain meshopt_simplify call (the keep_topology = false path) to 10 % on a 5 M-triangle
/// closed surface (the size of three full-resolution MRI iso-surfaces).
void throughput_note() {
  const TriMesh torus = mesh::make_torus(100.0, 30.0, 2048, 1280);
  std::vector<unsigned> kept(3 * torus.triangle_count());
  Timer t;
  kept.resize(meshopt_simplify(kept.data(), reinterpret_cast<const unsigned*>(torus.triangles.data()), kept.size(),
                               &torus.positions[0].x, torus.vertex_count(), sizeof(Vec3f), kept.size() / 10, FLT_MAX,
                               0, nullptr));
  const double ms = t.elapsed_ms();
  std::printf("\nplain meshopt_simplify, torus %zu triangles -> %zu: %.0f ms, %.1f M input triangles/s\n",
              torus.triangle_count(), kept.size() / 3, ms, double(torus.triangle_count()) / ms * 1e-3);
}

int main(int argc, char** argv) {
  raysift::keep_freed_buffers_for_reuse();  // as the raysift program (core/heap_policy.h)
  const int iterations = argc > 1 ? std::max(1, std::atoi(argv[1])) : 20;
  std::printf("threads: TBB default; load: see uptime\n");
  const volume::Volume engine = volume::load_vdb(raysift::bench::bundled_dataset("engine_ct.vdb"));
  for (const double iso : {80.0, 150.0})
    bench_mesh("engine CT iso " + std::to_string(int(iso)) + " (marching cubes)", volume::extract_isosurface(engine, iso),
          iterations);
  bench_mesh("MRI iso 60 (marching cubes)",
        volume::extract_isosurface(volume::load_vdb(raysift::bench::bundled_dataset("mri_head.vdb")), 60.0), iterations);
  volume::BlobsOptions blobs;
  blobs.grid.dims = {256, 256, 256};
  blobs.count = 24;
  blobs.sigma_voxels = 14.0;
  bench_mesh("blobs 256^3 iso 0.5 (marching cubes)", volume::extract_isosurface(volume::make_blobs(blobs), 0.5), iterations);
  throughput_note();
  return 0;
}
