// Mesh preparation speed on marching-cubes output (engine CT iso 80 and 256^3 Gaussian blobs iso 0.5), in
// one run: our Taubin smoothing vs OpenMesh JacobiLaplaceSmootherT and VTK vtkWindowedSincPolyDataFilter
// (vertex-iterations per second), and our OpenMesh-based decimation vs VTK vtkQuadricDecimation to the same
// face count. Usage: mesh_prep_bench [ITERATIONS] (default 20 smoothing iterations)
#include <OpenMesh/Tools/Smoother/JacobiLaplaceSmootherT.hh>

#include <cstdio>
#include <filesystem>
#include <string>

#include "core/timer.h"
#include "mesh/decimation.h"
#include "mesh/detail/openmesh_convert.h"
#include "mesh/mesh_io.h"
#include "mesh/smoothing.h"
#include "volume/generate.h"
#include "volume/import.h"
#include "volume/marching_cubes.h"

namespace {

using namespace raysift;

/// Runs one mode of bench/vtk_reference.py and returns {ms, triangles}; ms < 0 if VTK is unavailable.
std::pair<double, long> vtk(const std::string& mode, const std::string& ply, long arg) {
  const std::string cmd = "/usr/bin/python3 " RAYSIFT_SOURCE_DIR "/bench/vtk_reference.py " + mode + " " + ply + " " +
                          std::to_string(arg) + " 1 2>/dev/null";
  FILE* pipe = popen(cmd.c_str(), "r");
  double ms = -1;
  long triangles = 0;
  if (!pipe || std::fscanf(pipe, "ms=%lf triangles=%ld", &ms, &triangles) != 2) ms = -1;
  if (pipe) pclose(pipe);
  return {ms, triangles};
}

void bench(const std::string& label, const mesh::TriMesh& m, int iterations) {
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

  mesh::DecimationOptions dec;
  dec.ratio = 0.1;
  t.reset();
  const std::size_t faces = mesh::decimate(m, dec).mesh.triangle_count();
  const double dec_ms = t.elapsed_ms();
  const auto [vtk_dec_ms, vtk_dec_tris] = vtk("quadric-decimation", ply, long(faces));
  std::printf("  decimation (ours = OpenMesh Decimater) to %zu faces %9.1f ms", faces, dec_ms);
  if (vtk_dec_ms > 0)
    std::printf(" | VTK QuadricDecimation to %ld faces %9.1f ms | ratio ours/VTK %.2f", vtk_dec_tris, vtk_dec_ms,
                dec_ms / vtk_dec_ms);
  std::printf("\n");
  std::filesystem::remove(ply);
}

}  // namespace

int main(int argc, char** argv) {
  const int iterations = argc > 1 ? std::max(1, std::atoi(argv[1])) : 20;
  const std::string engine_raw = "/work/shared/datasets/engine_ct_256x256x128_u8.raw.gz";
  if (std::filesystem::exists(engine_raw)) {
    volume::RawLayout layout;
    layout.dims = {256, 256, 128};
    bench("engine CT iso 80 (marching cubes)", volume::extract_isosurface(volume::import_raw(engine_raw, layout), 80.0),
          iterations);
  }
  volume::BlobsOptions blobs;
  blobs.grid.dims = {256, 256, 256};
  blobs.count = 24;
  blobs.sigma_voxels = 14.0;
  bench("blobs 256^3 iso 0.5 (marching cubes)", volume::extract_isosurface(volume::make_blobs(blobs), 0.5), iterations);
  return 0;
}
