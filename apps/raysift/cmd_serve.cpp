// raysift serve: the volume in the browser (docs/serve.md). Loads the volume and TF once, then serves the embedded
// page and one rendering session per WebSocket until Ctrl-C/SIGTERM; --stats is written on the way out.
#include <csignal>
#include <filesystem>
#include <iostream>
#include <memory>

#include "apps/raysift/command.h"
#include "apps/raysift/guard_flags.h"
#include "apps/raysift/render_session.h"
#include "apps/raysift/volume_input.h"
#include "core/errors.h"
#include "server/http_server.h"
#include "server/viewer_session.h"
#include "volume/histogram.h"
#include "volume/raycaster.h"

namespace raysift::app {
namespace {

struct ServeCliOptions {
  VolumeFlags input;
  std::string host = "127.0.0.1";
  int port = 8080;
  double target_fps = 10;
};

bool is_loopback(const std::string& host) { return host == "127.0.0.1" || host == "::1"; }

void serve(const ServeCliOptions& o, const CommonOptions& common) {
  VolumeInput input = load_volume_input(o.input, common.scene_path, common, "serve", volume::EmptyGrid::Allow);
  if (!input.tf) throw UsageError("serve needs --tf TF.json or a --scene with a 'transfer_function'; see --help");
  const std::string host = o.host == "localhost" ? "127.0.0.1" : o.host;
  const server::PngEncoder encoder;
  server::ServeStats stats;
  server::ServeScene scene;
  scene.base = std::make_shared<const RenderSession>(input.volume, *input.tf);
  scene.volume_name = std::filesystem::path(input.volume_path).filename().string();
  scene.grid_name = input.info.name;
  scene.histogram = volume::compute_histogram(scene.base->volume());
  scene.camera = input.scene.camera ? *input.scene.camera : volume::fit_camera(input.volume, CameraSpec{}.width,
                                                                                 CameraSpec{}.height);
  scene.target_fps = o.target_fps;
  scene.encoder = &encoder;
  scene.stats = &stats;

  server::HttpServerOptions options;
  options.host = host;
  options.port = o.port;
  options.on_listening = [&](int port) {
    const std::string url_host = host.find(':') != std::string::npos ? "[" + host + "]" : host;
    if (!is_loopback(host) && !common.quiet)
      std::cerr << "raysift: warning: listening on " << host << ": there is no authentication, anyone who can "
                << "reach this address can use the server\n";
    std::cout << "raysift serve: http://" << url_host << ":" << port << "/ (Ctrl-C stops)" << std::endl;
  };
  const int signo = server::run_http_server(options, [&scene](server::MessageSink sink) -> std::unique_ptr<server::ConnectionHandler> {
    return std::make_unique<server::ViewerSession>(scene, std::move(sink));
  });
  Json out = stats.to_json();
  out["host"] = host;
  out["target_fps"] = o.target_fps;
  write_stats_if_requested(common, out);
  if (!common.quiet)
    std::cerr << "raysift serve: stopped by " << (signo == SIGTERM ? "SIGTERM" : "SIGINT") << " after "
              << out["frames_served"] << " frames\n";
}

RegisterCommand reg(
    "serve", "explore a volume in the browser: budgeted frames while the camera or TF moves, refinement when still",
    [](CLI::App& sub, CommonOptions& common) -> RunFunction {
      auto o = std::make_shared<ServeCliOptions>();
      add_volume_flags(sub, o->input, "transfer function the viewers start with");
      sub.add_option("--host", o->host,
                     "IP address to listen on; anything but 127.0.0.1/::1 lets other machines in (no authentication)")
          ->capture_default_str();
      sub.add_option("--port", o->port, "TCP port; 0 = a free one (the printed URL names it)")
          ->check(CLI::Range(0, 65535))
          ->capture_default_str();
      sub.add_option("--target-fps", o->target_fps, "frame rate a new viewer starts with (frames/s)")
          ->check(CLI::Range(0.1, 120.0))
          ->capture_default_str();
      add_non_finite_flag(sub, common);
      sub.footer("Examples:\n  raysift serve --scene datasets/engine_ct_scene.json      # then open the printed URL\n"
                 "  raysift serve volume.vdb --tf tf.json --port 0 --target-fps 20 --stats serve.json\n"
                 "  raysift serve --scene s.json --host 0.0.0.0    # other machines too: no authentication\n"
                 "Protocol and frame scheduling: docs/serve.md\n");
      return [o, &common] { serve(*o, common); };
    });

}  // namespace
}  // namespace raysift::app
