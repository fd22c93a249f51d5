#pragma once
/// \file One viewer of `raysift serve`: the protocol of docs/serve.md on one WebSocket (camera, tf and settings in;
/// hello, frame + image, tf_applied, features_ready and error out), its own camera, TF and settings, a render
/// thread and a feature-geometry thread.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "apps/raysift/render_session.h"
#include "core/json_io.h"
#include "server/connection.h"
#include "server/frame_renderer.h"
#include "server/png_encoder.h"
#include "server/serve_stats.h"
#include "volume/histogram.h"

namespace raysift::server {

/// A budgeted frame's render budget: the period less the last frames' encode + send (`overhead_ms`), their overrun
/// and the client's decode + display time (a camera message's latency pays all of them), the client's share capped
/// at a quarter period (a slow client cannot take the render's time), and never below a tenth of the period.
double frame_budget_ms(double period_ms, double overhead_ms, double overrun_ms, double client_ms);

/// What every viewer shares, built once by `raysift serve`.
struct ServeScene {
  std::shared_ptr<const app::RenderSession> base;  ///< volume, startup TF, bricks, feature cache
  std::string volume_name;       ///< the file's name, e.g. "engine_ct.vdb"
  std::string grid_name;         ///< the grid rendered, e.g. "density"
  volume::Histogram histogram;   ///< of the active voxels, for the page's TF editor and the iso-values
  CameraSpec camera;             ///< a new viewer's camera (the scene's, else the volume's fitted one)
  double target_fps = 10;        ///< a new viewer's rate
  int max_image_side = 4096;     ///< a camera message asking for more is an error
  const PngEncoder* encoder = nullptr;
  ServeStats* stats = nullptr;
};

class ViewerSession : public ConnectionHandler {
 public:
  /// Sends the hello and starts rendering the scene's camera. `scene` must outlive the session.
  ViewerSession(const ServeScene& scene, MessageSink sink);
  ~ViewerSession() override;  ///< stops both threads (a running full render is cancelled)
  /// A malformed or unknown message is answered with {"type":"error","message":...}; nothing else changes.
  void on_text(const std::string& message) override;

  struct Settings {
    std::string mode = "prioritized";  ///< prioritized | subsample | full
    double target_fps = 10;
    std::vector<std::string> features = sampling::feature_list_entries(sampling::kDefaultFeatures);
    std::string show = "image";        ///< image | traced | importance
    std::string format = "png";        ///< png (byte-equal to the CLI's) | jpeg (when jpeg_available())
  };
  /// What a frame is rendered from; every change bumps `version`.
  struct View {
    CameraSpec camera;
    Json camera_seq;  ///< the client's "seq" of the last camera message, null before one
    double client_ms = 0;  ///< the client's decode + display time per frame ("client_ms"), kept out of the budget
    Settings settings;
    std::shared_ptr<const app::RenderSession> render;  ///< this viewer's TF
    std::shared_ptr<const sampling::FeatureGeometry> geometry;  ///< may still be an older TF's
    std::uint64_t version = 1;
  };

 private:
  void apply(const Json& message);
  void apply_camera(const Json& message);
  void apply_tf(const Json& message);
  void apply_settings(const Json& message);
  Json hello() const;
  void render_loop();
  void geometry_loop();
  /// Waits until the view changed, refinement is pending (not before `refine_after`), or the session stops
  /// (then false).
  bool next_view(std::uint64_t rendered, bool converged, std::chrono::steady_clock::time_point refine_after,
                 View& view);
  bool superseded(std::uint64_t version);
  void bump_version();  ///< \pre mutex_ held
  bool send_frame(const RenderedFrame& frame, const View& view, double budget_ms);

  const ServeScene& scene_;
  MessageSink sink_;
  std::mutex mutex_;
  std::condition_variable cv_;
  View view_;
  bool stopping_ = false;
  std::uint64_t geometry_wanted_ = 1;  ///< bumped by each TF; the geometry thread builds for the newest
  std::atomic<bool> cancel_{false}, geometry_cancel_{false};
  std::atomic<std::uint64_t> latest_version_{1};  ///< view_.version, read by a refinement's full render
  std::uint64_t frame_seq_ = 0;
  std::thread render_thread_, geometry_thread_;
};

}  // namespace raysift::server
