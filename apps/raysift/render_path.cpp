#include "apps/raysift/render_path.h"

#include <filesystem>
#include <iostream>

#include "apps/raysift/sampling_stats.h"
#include "core/file_util.h"
#include "core/image.h"
#include "sampling/camera_path.h"

namespace raysift::app {

void render_path(const PathCliOptions& p, const RenderCliOptions& o, const RenderInputs& in, const CommonOptions& common) {
  sampling::PathRenderRequest request;
  request.camera_path = p.camera_path;
  request.options.sampling = in.sampled.sampling;
  request.options.features.lines = in.sampled.features;
  request.options.features.use_saliency = p.use_saliency;
  request.options.target_fps = p.target_fps;
  request.options.compare_full = p.compare_full;
  request.geometry = in.sampled.geometry;
  request.feature_mesh = in.sampled.feature_mesh;
  request.feature_cache = in.sampled.feature_cache;
  // Frames stream out one by one, each atomically; the manifest, written last, marks a complete sequence, so a
  // stale one from an earlier run must not outlive the first new frame.
  const std::string manifest = sampling::frame_manifest_name(o.out);
  std::error_code ec;
  std::filesystem::remove(manifest, ec);
  const sampling::PathRenderResult r = sampling::run_path_request(
      in.volume, *in.tf, in.options, in.camera, request, [&](const sampling::PathFrame& frame, const ImageRGBA& image) {
        const std::string name = sampling::frame_file_name(o.out, frame.index);
        if (file_extension(name) != ".png") return write_image(name, image);
        ImageRGBA opaque = image;  // composited colour: show it opaque, as a single frame does
        for (Rgba& px : opaque.pixels) px.a = 1.0f;
        write_image(name, opaque);
      });
  Json stats = path_stats_json(r.frames, p.target_fps);
  stats["camera_path"] = p.camera_path;
  stats["frame_files"] = {sampling::frame_file_name(o.out, 0), sampling::frame_file_name(o.out, int(r.frames.size()) - 1)};
  stats["times_ms"] = {{"features_setup", r.features_setup_ms}, {"total", r.total_ms}};
  stats["mode"] = o.mode;
  Json files = Json::array();
  for (const sampling::PathFrame& f : r.frames) files.push_back(sampling::frame_file_name(o.out, f.index));
  write_json_file(manifest, {{"camera_path", p.camera_path}, {"frames", r.frames.size()}, {"files", files}});
  stats["manifest"] = manifest;
  if (common.verbose)
    std::cerr << "rendered " << r.frames.size() << " frames to " << o.out << " in " << r.total_ms << " ms\n";
  write_stats_if_requested(common, stats);
}

}  // namespace raysift::app
