// Ray-caster benchmark (issue 4), all in one run on the same volume, TF, camera and sample distance:
//   (a) ours (skipping + early termination 0.99) vs the brute-force path (--no-skip, ET 1);
//   (b) VTK's vtkFixedPointVolumeRayCastMapper (bench/vtk_raycast.py under xvfb-run), time ratio;
//   (c) OpenVDB's vdb_render -shadowstep 1000000 (closest to emission-absorption), for reference;
//   (d) volume samples per second per core.
// Usage: raycast_bench [--volume V.vdb] [--tf TF.json] [--camera C.json] [--raw RAW.gz --dims X,Y,Z]
//                      [--width 1440 --height 900] [--step 1] [--threads 2] [--repeats 3] [--no-external]
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/bench_data.h"
#include "core/heap_policy.h"
#include "core/image.h"
#include "core/json_io.h"
#include "core/timer.h"
#include "volume/raycaster.h"
#include "volume/transfer_function.h"
#include "volume/vdb_io.h"

using namespace raysift;

namespace {

struct BenchOptions {
  std::string volume = raysift::bench::bundled_dataset("engine_ct.vdb");
  std::string tf = raysift::bench::bundled_dataset("engine_ct_tf.json");
  std::string camera = raysift::bench::bundled_dataset("engine_ct_camera.json");
  std::string raw = raysift::bench::shared_dataset("engine_ct_256x256x128_u8.raw.gz");
  std::string dims = "256,256,128";
  int width = 1440, height = 900;
  double step = 1.0;
  int threads = 2;
  int repeats = 3;
  bool external = true;
};

struct Timing {
  double setup_ms = 0, trace_ms = 0;
  double trace_cpu_ms = 0;  ///< process CPU time of the trace (all threads): robust on a loaded machine
  std::uint64_t samples = 0;
  volume::RenderResult result;
};

/// Best of `repeats` full renders (the caster is rebuilt each time; its setup is timed separately).
Timing time_ours(const volume::Volume& vol, const volume::TransferFunction& tf, const CameraSpec& cam,
                 const volume::RenderOptions& options, int repeats) {
  Timing best;
  best.trace_ms = 1e300;
  for (int r = 0; r < repeats; ++r) {
    Timer setup;
    const volume::RayCaster caster(vol, tf, cam, options);
    const double setup_ms = setup.elapsed_ms();
    const std::clock_t cpu0 = std::clock();
    Timer trace;
    volume::RenderResult result = volume::render_full(caster);
    const double trace_ms = trace.elapsed_ms();
    const double cpu_ms = double(std::clock() - cpu0) * 1000.0 / CLOCKS_PER_SEC;
    if (trace_ms < best.trace_ms) {
      best.trace_cpu_ms = cpu_ms;
      best.setup_ms = setup_ms;
      best.trace_ms = trace_ms;
      best.samples = result.samples;
      best.result = std::move(result);
    }
  }
  return best;
}

/// Runs a shell command and returns its stdout (empty on failure).
std::string run_capture(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe)) out += buf;
  if (pclose(pipe) != 0) return {};
  return out;
}

double parse_after(const std::string& text, const std::string& key) {
  const auto pos = text.find(key);
  if (pos == std::string::npos) return -1;
  return std::atof(text.c_str() + pos + key.size());
}

}  // namespace

int main(int argc, char** argv) {
  raysift::keep_freed_buffers_for_reuse();  // as the raysift program (core/heap_policy.h)
  BenchOptions o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "raycast_bench: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--volume") o.volume = next();
    else if (a == "--tf") o.tf = next();
    else if (a == "--camera") o.camera = next();
    else if (a == "--raw") o.raw = next();
    else if (a == "--dims") o.dims = next();
    else if (a == "--width") o.width = std::stoi(next());
    else if (a == "--height") o.height = std::stoi(next());
    else if (a == "--step") o.step = std::stod(next());
    else if (a == "--threads") o.threads = std::stoi(next());
    else if (a == "--repeats") o.repeats = std::stoi(next());
    else if (a == "--no-external") o.external = false;
    else {
      std::fprintf(stderr, "raycast_bench: unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  try {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(o.threads));
    const volume::Volume vol = volume::load_vdb(o.volume);
    const volume::TransferFunction tf = volume::load_transfer_function(o.tf);
    CameraSpec cam = camera_spec_from_json(read_json_file(o.camera), o.camera);
    cam.width = o.width;
    cam.height = o.height;

    volume::RenderOptions fast;
    fast.step_voxels = o.step;
    volume::RenderOptions brute = fast;
    brute.skip_empty_space = false;
    brute.early_termination = 1.0;

    std::printf("raycast_bench: %s, %dx%d, step %.3g voxels, %d threads, best of %d\n", o.volume.c_str(), o.width,
                o.height, o.step, o.threads, o.repeats);
    const Timing ours = time_ours(vol, tf, cam, fast, o.repeats);
    const Timing slow = time_ours(vol, tf, cam, brute, std::max(1, o.repeats / 2));
    double max_diff = 0;
    for (std::size_t i = 0; i < ours.result.image.size(); ++i) {
      const Rgba& p = ours.result.image.pixels[i];
      const Rgba& q = slow.result.image.pixels[i];
      max_diff = std::max({max_diff, double(std::abs(p.r - q.r)), double(std::abs(p.g - q.g)),
                           double(std::abs(p.b - q.b))});
    }
    const double per_core = double(ours.samples) / (ours.trace_ms / 1000.0) / o.threads;
    const double per_core_brute = double(slow.samples) / (slow.trace_ms / 1000.0) / o.threads;
    std::printf("%-34s %10s %10s %12s %14s %16s\n", "renderer", "setup ms", "trace ms", "trace cpu ms", "samples",
                "samples/s/core");
    std::printf("%-34s %10.1f %10.1f %12.1f %14llu %16.3g\n", "ours (skip + ET 0.99)", ours.setup_ms, ours.trace_ms,
                ours.trace_cpu_ms, (unsigned long long)ours.samples, per_core);
    std::printf("%-34s %10.1f %10.1f %12.1f %14llu %16.3g\n", "ours brute force (no skip, ET 1)", slow.setup_ms,
                slow.trace_ms, slow.trace_cpu_ms, (unsigned long long)slow.samples, per_core_brute);
    std::printf("(a) speed-up skip+ET vs brute force: %.2fx (target >= 3x); max |diff| %.4f (ET only)\n",
                slow.trace_ms / ours.trace_ms, max_diff);
    const std::string out_dir = std::filesystem::temp_directory_path().string();
    ImageRGBA shown = ours.result.image;
    for (Rgba& p : shown.pixels) p.a = 1.0f;  // composited colour, shown opaque like raysift render
    write_image(out_dir + "/raycast_bench_ours.png", shown);

    if (o.external) {
      const std::string vtk_cmd = "xvfb-run -a /usr/bin/python3 " + std::string(RAYSIFT_SOURCE_DIR) +
                                  "/bench/vtk_raycast.py --raw " + o.raw + " --dims " + o.dims + " --tf " + o.tf +
                                  " --camera " + o.camera + " --width " + std::to_string(o.width) + " --height " +
                                  std::to_string(o.height) + " --step " + std::to_string(o.step) + " --threads " +
                                  std::to_string(o.threads) + " --out " + out_dir + "/raycast_bench_vtk.png 2>&1";
      const std::string vtk_out = run_capture(vtk_cmd);
      const double vtk_ms = parse_after(vtk_out, "vtk_render_ms ");
      if (vtk_ms > 0)
        std::printf("(b) VTK vtkFixedPointVolumeRayCastMapper: %.1f ms; ours/VTK time ratio %.2f (target <= 1.0)\n",
                    vtk_ms, ours.trace_ms / vtk_ms);
      else
        std::printf("(b) VTK run failed (needs python3-vtk9, xvfb): %s\n", vtk_cmd.c_str());

      // vdb_render's horizontal field of view from our vertical one.
      const double fov_x_deg = 2.0 * std::atan(std::tan(0.5 * cam.fov_y_deg * M_PI / 180.0) * o.width / o.height) *
                               180.0 / M_PI;
      char vdb_cmd[2048];
      std::snprintf(vdb_cmd, sizeof vdb_cmd,
                    "vdb_render %s %s/raycast_bench_vdb.ppm -res %dx%d -translate %g,%g,%g -lookat %g,%g,%g "
                    "-up %g,%g,%g -fov %g -step %g -shadowstep 1000000 -cpus %d -v 2>&1",
                    o.volume.c_str(), out_dir.c_str(), o.width, o.height, cam.eye.x, cam.eye.y, cam.eye.z,
                    cam.target.x, cam.target.y, cam.target.z, cam.up.x, cam.up.y, cam.up.z, fov_x_deg, o.step,
                    o.threads);
      // -v prints "...completed in S sec" after reading and again after ray tracing.
      const std::string vdb_out = run_capture(vdb_cmd);
      const auto tracing = vdb_out.find("ray-tracing");
      const double vdb_ms =
          tracing == std::string::npos ? -1 : 1000.0 * parse_after(vdb_out.substr(tracing), "completed in ");
      if (vdb_ms > 0)
        std::printf("(c) vdb_render ray tracing: %.1f ms; ours/vdb_render time ratio %.2f (reference only: "
                    "its fog model differs)\n",
                    vdb_ms, ours.trace_ms / vdb_ms);
      else
        std::printf("(c) vdb_render failed: %s\n", vdb_cmd);
    }
    std::printf("(d) ours: %.3g samples/s/core (skip+ET), %.3g samples/s/core (brute force); per CPU-second "
                "(robust to a loaded machine): %.3g and %.3g\n",
                per_core, per_core_brute, double(ours.samples) / (ours.trace_cpu_ms / 1000.0),
                double(slow.samples) / (slow.trace_cpu_ms / 1000.0));
    std::printf("images: %s/raycast_bench_{ours,vtk}.png, raycast_bench_vdb.ppm\n", out_dir.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "raycast_bench: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
