#include "server/viewer_session.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdlib>

#include "core/camera.h"
#include "core/errors.h"
#include "core/timer.h"
#include "server/jpeg_encoder.h"
#include "volume/iso_values.h"

namespace raysift::server {
namespace {

const std::vector<std::string> kModes{"prioritized", "subsample", "full"};
const std::vector<std::string> kShows{"image", "traced", "importance"};

const std::vector<std::string>& image_formats() {
  static const std::vector<std::string> formats =
      jpeg_available() ? std::vector<std::string>{"png", "jpeg"} : std::vector<std::string>{"png"};
  return formats;
}

std::string one_of(const Json& m, const char* key, const std::vector<std::string>& allowed) {
  const std::string v = m.at(key).get<std::string>();
  for (const std::string& a : allowed)
    if (v == a) return v;
  std::string list;
  for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
  throw InvalidInput(std::string(key) + " must be one of " + list + ", got \"" + v + "\"");
}

std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ",") + n;
  return s.empty() ? "none" : s;
}

/// The iso-values the TF implies over the volume's histogram (what the feature geometry extracts); none for a TF
/// that shows nothing.
Json iso_values_json(const volume::Histogram& histogram, const volume::TransferFunction& tf) {
  Json values = Json::array();
  try {
    for (const volume::IsoValue& v : volume::select_iso_values(histogram, tf)) values.push_back(v.value);
  } catch (const InvalidInput&) {
  }
  return values;
}

/// The shortest decimal that reads back as `f`: 0.3f goes out as 0.3, not 0.30000001192092896, and a TF the page
/// sends back unchanged is the same TF.
double shortest(float f) {
  char text[32];
  const std::to_chars_result r = std::to_chars(text, text + sizeof text, f);
  return std::strtod(std::string(text, r.ptr).c_str(), nullptr);
}

Json tf_json(const volume::TransferFunction& tf) {
  Json points = Json::array();
  for (const volume::TfPoint& p : tf.points())
    points.push_back({p.x, shortest(p.r), shortest(p.g), shortest(p.b), shortest(p.a)});
  return {{"points", points}};
}

Json error_json(const std::string& message) { return {{"type", "error"}, {"message", message}}; }

}  // namespace

ViewerSession::ViewerSession(const ServeScene& scene, MessageSink sink) : scene_(scene), sink_(std::move(sink)) {
  view_.camera = scene.camera;
  view_.settings.target_fps = scene.target_fps;
  view_.render = scene.base;
  scene_.stats->client_connected();
  sink_.text(hello().dump());
  render_thread_ = std::thread([this] { render_loop(); });
  geometry_thread_ = std::thread([this] { geometry_loop(); });
}

ViewerSession::~ViewerSession() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  cancel_ = true;
  geometry_cancel_ = true;
  cv_.notify_all();
  render_thread_.join();
  geometry_thread_.join();
  scene_.stats->client_disconnected();
}

Json ViewerSession::hello() const {
  const volume::Histogram& h = scene_.histogram;
  return {{"type", "hello"},
          {"volume",
           {{"name", scene_.volume_name},
            {"grid", scene_.grid_name},
            {"value_range", {h.min, h.max}},
            {"histogram", {{"range", {h.min, h.max}}, {"counts", h.counts}}}}},
          {"camera", camera_spec_to_json(view_.camera)},
          {"transfer_function", tf_json(view_.render->tf())},
          {"settings",
           {{"mode", view_.settings.mode},
            {"target_fps", view_.settings.target_fps},
            {"features", view_.settings.features},
            {"show", view_.settings.show},
            {"format", view_.settings.format}}},
          {"iso_values", iso_values_json(h, view_.render->tf())},
          {"image_format", view_.settings.format},
          {"image_formats", image_formats()}};
}

void ViewerSession::on_text(const std::string& message) {
  try {
    apply(Json::parse(message));
  } catch (const Json::parse_error& e) {
    sink_.text(error_json(std::string("malformed JSON: ") + e.what()).dump());
  } catch (const std::exception& e) {  // InvalidInput, or a field of the wrong JSON type
    sink_.text(error_json(e.what()).dump());
  }
}

void ViewerSession::apply(const Json& message) {
  if (!message.is_object() || !message.contains("type") || !message["type"].is_string())
    throw InvalidInput("expected a JSON object with a string \"type\", got " + message.dump().substr(0, 200));
  const std::string type = message["type"].get<std::string>();
  if (type == "camera") return apply_camera(message);
  if (type == "tf") return apply_tf(message);
  if (type == "settings") return apply_settings(message);
  throw InvalidInput("unknown message type \"" + type + "\"; expected camera, tf or settings");
}

void ViewerSession::apply_camera(const Json& message) {
  CameraSpec current;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    current = view_.camera;
  }
  Json merged = camera_spec_to_json(current);  // a message may change only some fields
  for (const char* key : {"eye", "target", "up", "fov_y_deg", "width", "height"})
    if (message.contains(key)) merged[key] = message[key];
  const CameraSpec spec = camera_spec_from_json(merged, "camera message");
  static_cast<void>(Camera{spec});  // \throw InvalidInput for a degenerate camera
  if (spec.width > scene_.max_image_side || spec.height > scene_.max_image_side)
    throw InvalidInput("camera message: width and height must be at most " + std::to_string(scene_.max_image_side) +
                       ", got " + std::to_string(spec.width) + "x" + std::to_string(spec.height));
  const Json seq = message.value("seq", Json());
  if (!seq.is_null() && !seq.is_number()) throw InvalidInput("camera message: seq must be a number, got " + seq.dump());
  const Json client = message.value("client_ms", Json(0.0));
  if (!client.is_number() || !(client.get<double>() >= 0 && client.get<double>() < 1e6))
    throw InvalidInput("camera message: client_ms must be a number of ms >= 0, got " + client.dump());
  const std::lock_guard<std::mutex> lock(mutex_);
  view_.camera = spec;
  view_.camera_seq = seq;
  view_.client_ms = client.get<double>();
  bump_version();
  cv_.notify_all();
}

void ViewerSession::apply_tf(const Json& message) {
  if (!message.contains("transfer_function"))
    throw InvalidInput("tf message needs a \"transfer_function\" (a ParaView preset or {\"points\": [[x,r,g,b,a], ...]})");
  volume::TransferFunction tf = volume::transfer_function_from_json(message["transfer_function"], "tf message");
  auto render = std::make_shared<const app::RenderSession>(scene_.base->with_tf(std::move(tf)));
  const Json applied = {{"type", "tf_applied"}, {"iso_values", iso_values_json(scene_.histogram, render->tf())},
                        {"features_ready", false}};
  const std::lock_guard<std::mutex> lock(mutex_);
  view_.render = std::move(render);  // frames keep the old geometry until the new one is built
  bump_version();
  ++geometry_wanted_;
  geometry_cancel_ = true;  // a build for an older TF is no longer wanted
  sink_.text(applied.dump());  // under the lock: before the geometry thread's features_ready
  cv_.notify_all();
}

void ViewerSession::apply_settings(const Json& message) {
  Settings s;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    s = view_.settings;
  }
  if (message.contains("mode")) s.mode = one_of(message, "mode", kModes);
  if (message.contains("show")) s.show = one_of(message, "show", kShows);
  if (message.contains("target_fps")) {
    s.target_fps = message["target_fps"].get<double>();
    if (!(s.target_fps > 0 && s.target_fps <= 120))
      throw InvalidInput("target_fps must be in (0, 120], got " + message["target_fps"].dump());
  }
  if (message.contains("features")) {
    s.features = message["features"].get<std::vector<std::string>>();
    static_cast<void>(sampling::parse_feature_list(join(s.features)));  // \throw InvalidInput naming the class
  }
  if (message.contains("format")) s.format = one_of(message, "format", image_formats());
  const std::lock_guard<std::mutex> lock(mutex_);
  view_.settings = s;
  bump_version();
  cv_.notify_all();
}

double frame_budget_ms(double period_ms, double overhead_ms, double overrun_ms, double client_ms) {
  return std::max(period_ms - overhead_ms - overrun_ms - std::min(client_ms, 0.25 * period_ms), 0.1 * period_ms);
}

void ViewerSession::bump_version() {
  ++view_.version;
  latest_version_.store(view_.version, std::memory_order_relaxed);
}

bool ViewerSession::next_view(std::uint64_t rendered, bool converged,
                              std::chrono::steady_clock::time_point refine_after, View& view) {
  std::unique_lock<std::mutex> lock(mutex_);
  // During a drag the next camera comes soon after a frame is sent (the page sends it when the frame arrives). A
  // refinement started meanwhile would delay that camera's frame by up to a budget (it is not cancelled
  // mid-frame), so refinement waits until a period has passed since the view's last new frame was sent.
  cv_.wait_until(lock, refine_after, [&] { return stopping_ || view_.version != rendered; });
  cv_.wait(lock, [&] { return stopping_ || view_.version != rendered || !converged; });
  if (stopping_) return false;
  view = view_;
  return true;
}

bool ViewerSession::superseded(std::uint64_t version) {
  const std::lock_guard<std::mutex> lock(mutex_);
  return view_.version != version;
}

void ViewerSession::render_loop() {
  FrameRenderer renderer;
  std::uint64_t rendered = 0;
  double overhead_ms = 0;  // encode + send of the last frame, taken off the next budget
  double overrun_ms = 0;   // by how much budgeted renders exceed their budget, also taken off: the latency target
  auto next_start = std::chrono::steady_clock::now();
  auto refine_after = next_start;
  View view;
  while (next_view(rendered, renderer.converged(), refine_after, view)) {
    const bool is_new = view.version != rendered;
    const double period_ms = 1000.0 / view.settings.target_fps;
    if (is_new) {  // a drag gets frames at the target rate, not faster: wait out the period, then take the latest
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait_until(lock, next_start, [&] { return stopping_; });
      if (stopping_) return;
      view = view_;
      next_start = std::chrono::steady_clock::now() + std::chrono::microseconds(std::int64_t(period_ms * 1000));
    }
    rendered = view.version;
    const double budget_ms = frame_budget_ms(period_ms, overhead_ms, overrun_ms, view.client_ms);
    FrameRequest request;
    request.render = view.render.get();
    request.camera = view.camera;
    request.geometry = view.geometry.get();
    request.mode = view.settings.mode;
    request.classes = sampling::parse_feature_list(join(view.settings.features));
    request.budget_ms = budget_ms;
    request.cancel = &cancel_;
    request.latest_version = &latest_version_;
    request.version = view.version;
    try {
      const RenderedFrame frame = is_new ? renderer.first_frame(request) : renderer.refine(request);
      if (!is_new && superseded(rendered)) continue;  // a refinement of a view already left: not worth encoding
      const Timer send;
      if (!send_frame(frame, view, view.settings.mode == "full" ? 0.0 : budget_ms)) return;
      const double sent_ms = send.elapsed_ms();
      // A drag's next camera comes when the page has this frame: refinement waits a period for it.
      if (is_new) refine_after = std::chrono::steady_clock::now() + std::chrono::microseconds(std::int64_t(period_ms * 1000));
      overhead_ms = 0.5 * (overhead_ms + sent_ms);  // smoothed: one slow send does not halve a budget
      if (is_new && view.settings.mode == "prioritized" && !frame.converged)
        // Capped: when the fixed costs alone exceed the budget, a smaller budget only loses rays, not time.
        overrun_ms = std::min(0.5 * (overrun_ms + std::max(frame.ms - budget_ms, 0.0)), 0.25 * period_ms);
      scene_.stats->frame_sent(view.settings.mode, frame.ms, frame.ms + sent_ms);
    } catch (const Cancelled&) {
      if (cancel_) return;  // else a refinement superseded by a newer view: the loop renders that one next
    } catch (const std::exception& e) {
      renderer = FrameRenderer();  // nothing to refine until the view changes
      sink_.text(error_json(std::string("frame failed: ") + e.what()).dump());
    }
  }
}

bool ViewerSession::send_frame(const RenderedFrame& frame, const View& view, double budget_ms) {
  std::string show = view.settings.show;
  if (show == "importance" && frame.importance.pixels.empty()) show = "traced";  // full frames have no importance
  const bool jpeg = view.settings.format == "jpeg";
  const ImageF& grey = show == "traced" ? frame.traced : frame.importance;
  std::vector<std::uint8_t> bytes = show == "image" ? (jpeg ? encode_jpeg(frame.image) : scene_.encoder->encode(frame.image))
                                                    : (jpeg ? encode_jpeg(grey) : scene_.encoder->encode(grey));
  const Json message = {{"type", "frame"},          {"seq", ++frame_seq_},
                        {"ms", frame.ms},           {"rays_traced", frame.rays_traced},
                        {"full_rays", frame.full_rays}, {"converged", frame.converged},
                        {"budget_ms", budget_ms},   {"show", show},
                        {"camera_seq", view.camera_seq}, {"mode", view.settings.mode},
                        {"width", frame.image.width}, {"height", frame.image.height},
                        {"format", view.settings.format}};
  return sink_.frame(message.dump(), std::move(bytes));
}

void ViewerSession::geometry_loop() {
  std::uint64_t built = 0;
  for (;;) {
    std::shared_ptr<const app::RenderSession> render;
    CameraSpec camera;
    std::uint64_t wanted = 0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait(lock, [&] { return stopping_ || geometry_wanted_ != built; });
      if (stopping_) return;
      render = view_.render;
      camera = view_.camera;
      wanted = geometry_wanted_;
      geometry_cancel_ = false;
    }
    Json ready = {{"type", "features_ready"}};
    std::shared_ptr<const sampling::FeatureGeometry> geometry;
    try {
      sampling::FeatureGeometryOptions options;
      options.cancel = &geometry_cancel_;
      const isosurface::FeatureView feature_view{camera, features::ImportanceOptions{}.scale};
      geometry = std::make_shared<const sampling::FeatureGeometry>(sampling::feature_geometry_for(
          render->volume(), render->tf(), feature_view, options, "", render->feature_cache()));
      ready["triangles"] = geometry->mesh.triangles.size();
      ready["iso_values"] = geometry->iso_values;
    } catch (const Cancelled&) {
      built = wanted;  // superseded (or stopping): the newer request is picked up above
      continue;
    } catch (const std::exception& e) {  // e.g. a TF that shows nothing: frames go without feature lines
      ready["triangles"] = 0;
      ready["warning"] = e.what();
    }
    const std::lock_guard<std::mutex> lock(mutex_);
    built = wanted;
    if (wanted != geometry_wanted_) continue;  // a newer TF arrived meanwhile
    view_.geometry = std::move(geometry);
    sink_.text(ready.dump());
  }
}

}  // namespace raysift::server
