// The raysift serve page: wires the camera, the TF editor, the settings and the status to the server
// sessions (one for the main view, a second in subsample mode for the split view). The numbers the status
// shows are also window.raysiftStats, which the browser test (tests/browser/browser_test.py) reads.
import { OrbitCamera } from "./camera.js";
import { Session } from "./session.js";
import { TfEditor } from "./tf_editor.js";
import { COLOR_MAPS, apply_color_map, denormalize, tf_from_json, tf_to_preset } from "./tf_model.js";

const $ = (id) => document.getElementById(id);
const WS_URL = `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/ws`;
const MAX_SIDE_PX = 1920;    // the render size follows the view, capped here
const TF_SEND_MS = 100;      // TF messages while dragging a node, at most this often
const ORBIT_RAD_PER_PX = 0.01;
const KEY_ORBIT_RAD = (5 * Math.PI) / 180;
const KEY_PAN_PX = 20;
const ZOOM_STEP = 1.1;
const MODES = ["prioritized", "full", "subsample"];

const state = {
  volume: null, camera: null, seq: 0, camera_dirty: false, camera_timer: null, camera_sent_at: -Infinity,
  last_camera: null,
  settings: null, tf: null, home_tf: null, last_tf_preset: null, tf_timer: null, tf_pending: false,
  tf_sent: 0, tf_applied: 0, iso_values: [], features_ready: null, errors: [], sub: null,
};

const editor = new TfEditor($("tf-canvas"), (tf, is_final) => { state.tf = tf; schedule_tf(is_final); });
const main_session = new Session(WS_URL, $("main-canvas"), {
  hello: on_hello,
  frame: () => update_labels(),
  camera_answered: () => pump_camera(),  // the main view's last camera is rendered: the next may go
  tf_applied: (msg) => {
    state.tf_applied += 1;
    state.features_ready = !!msg.features_ready;
    set_iso_values(msg.iso_values || []);
  },
  features_ready: () => { state.features_ready = true; },
  error: (text) => show_message(`server: ${text}`, true),
  closed: (text) => { $("connection").textContent = text; },
});

function show_message(text, is_error = false) {
  const p = $("message");
  p.textContent = text;
  p.classList.toggle("error", is_error);
  if (is_error) state.errors.push(text);
}

function on_hello(msg) {
  $("volume-name").textContent = msg.volume.name;
  state.volume = msg.volume;
  state.camera = new OrbitCamera(msg.camera);
  state.settings = { format: msg.image_format || "png", ...msg.settings };
  const formats = msg.image_formats || [state.settings.format];  // what this server can encode
  for (const option of $("format").options) option.disabled = !formats.includes(option.value);
  show_settings();
  // [choice] JPEG frames when the server has them: PNG encoding takes most of a frame period (docs/serve-page.md);
  // choose PNG for frames byte-equal to `raysift render -o x.png`.
  if (formats.includes("jpeg") && state.settings.format !== "jpeg") {
    $("format").value = "jpeg";
    send_settings();
  }
  try {
    state.home_tf = tf_from_json(msg.transfer_function);
  } catch (err) {
    show_message(`the server's transfer function: ${err.message}`, true);
    const [lo, hi] = msg.volume.value_range;
    state.home_tf = { name: "ramp", opacity: [{ x: lo, a: 0, mid: 0.5, sharp: 0 }, { x: hi, a: 1, mid: 0.5, sharp: 0 }],
                      colors: [{ x: lo, r: 0, g: 0, b: 0 }, { x: hi, r: 1, g: 1, b: 1 }] };
  }
  state.tf = state.home_tf;
  $("tf-name").value = state.tf.name;
  editor.set(state.tf, { histogram: msg.volume.histogram, iso_values: msg.iso_values || [] });
  set_iso_values(msg.iso_values || []);
  schedule_camera();
}

// --- camera -------------------------------------------------------------------------------------------
/// The view's size in device pixels; in the split, the largest rectangle of the scene camera's aspect inside
/// it, so that the two narrow halves keep the scene's framing instead of cropping its sides.
function render_size() {
  const rect = $("main-view").getBoundingClientRect();
  let w = rect.width * devicePixelRatio, h = rect.height * devicePixelRatio;
  if (state.sub && state.camera.home.width > 0 && state.camera.home.height > 0) {
    const aspect = state.camera.home.width / state.camera.home.height;
    if (w / h < aspect) h = w / aspect;
    else w = h * aspect;
  }
  const s = Math.min(1, MAX_SIDE_PX / Math.max(w, h, 1));
  return [Math.max(16, Math.round(w * s)), Math.max(16, Math.round(h * s))];
}

/// The camera changed: it goes out through pump_camera().
function schedule_camera() {
  if (!state.camera) return;
  state.camera_dirty = true;
  pump_camera();
}

/// Flow control and pacing [choice]: the newest camera goes out when none is in flight (the last one's frame header
/// arrived, Session.camera_in_flight) and a frame period has passed since the last one went. So the server never
/// holds a queued camera behind a frame, and a message carries the mouse position of its own send time rather than
/// one a period old (docs/serve-page.md, "Latency").
function pump_camera() {
  if (!state.camera_dirty || state.camera_timer !== null || main_session.camera_in_flight()) return;
  const period_ms = state.settings ? 1000 / state.settings.target_fps : 0;
  const wait_ms = Math.max(0, state.camera_sent_at + period_ms - performance.now());
  state.camera_timer = setTimeout(() => {
    state.camera_timer = null;
    if (state.camera_dirty && !main_session.camera_in_flight()) send_camera();
  }, wait_ms);
}

/// Both sessions get the same message.
function send_camera() {
  state.camera_dirty = false;
  state.camera_sent_at = performance.now();
  const [w, h] = render_size();
  state.seq += 1;
  state.last_camera = { ...state.camera.message(w, h, state.seq), client_ms: main_session.client_time_ms() };
  main_session.send(state.last_camera);
  state.sub?.send(state.last_camera);
}

const pointers = new Map();   // pointerId -> {x, y}
let drag_kind = null;

function canvas_height_css() { return $("main-canvas").getBoundingClientRect().height || 1; }

function begin_drag(e) {
  if (!state.camera) return;
  e.currentTarget.setPointerCapture(e.pointerId);
  pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
  if (pointers.size === 1) {
    drag_kind = e.button === 1 || e.button === 2 || e.shiftKey ? "pan" : "orbit";
    main_session.begin_drag(state.seq + 1);
    state.sub?.begin_drag(state.seq + 1);
  }
  $("main-canvas").focus();
}

function move_drag(e) {
  const p = pointers.get(e.pointerId);
  if (!p) return;
  if (pointers.size === 1) {
    const dx = e.clientX - p.x, dy = e.clientY - p.y;
    if (drag_kind === "pan") state.camera.pan(dx, dy, canvas_height_css());
    else state.camera.orbit(-dx * ORBIT_RAD_PER_PX, dy * ORBIT_RAD_PER_PX);
  } else if (pointers.size === 2) {  // two fingers: the centroid pans, the spread zooms
    const [a, b] = [...pointers.values()];
    const other = a === p ? b : a;
    const before = Math.hypot(p.x - other.x, p.y - other.y);
    const after = Math.hypot(e.clientX - other.x, e.clientY - other.y);
    state.camera.pan((e.clientX - p.x) / 2, (e.clientY - p.y) / 2, canvas_height_css());
    if (before > 0 && after > 0) state.camera.zoom(before / after);
  }
  p.x = e.clientX;
  p.y = e.clientY;
  schedule_camera();
}

function end_drag(e) {
  if (!pointers.delete(e.pointerId) || pointers.size > 0) return;
  main_session.end_drag();
  state.sub?.end_drag();
}

const views = $("views");
views.addEventListener("pointerdown", begin_drag);
views.addEventListener("pointermove", move_drag);
views.addEventListener("pointerup", end_drag);
views.addEventListener("pointercancel", end_drag);
views.addEventListener("contextmenu", (e) => e.preventDefault());
views.addEventListener("wheel", (e) => {
  e.preventDefault();
  if (!state.camera) return;
  state.camera.zoom(Math.exp(e.deltaY * 0.001));
  schedule_camera();
}, { passive: false });

let resize_timer = null;
new ResizeObserver(() => {
  clearTimeout(resize_timer);
  resize_timer = setTimeout(() => {
    const [w, h] = render_size();
    if (state.last_camera && (state.last_camera.width !== w || state.last_camera.height !== h)) schedule_camera();
  }, 100);
}).observe($("main-view"));

// --- settings and the split view -------------------------------------------------------------------------
function show_settings() {
  const s = state.settings;
  $("mode").value = s.mode;
  $("target-fps").value = s.target_fps;
  $("show").value = s.show || "image";
  $("format").value = s.format;
  $("features").value = (s.features || []).join(",");
}

function read_settings() {
  const fps = Number($("target-fps").value);
  return {
    mode: $("mode").value,
    target_fps: Number.isFinite(fps) && fps > 0 ? fps : state.settings.target_fps,
    features: $("features").value.split(",").map((f) => f.trim()).filter((f) => f.length > 0),
    show: $("show").value,
    format: $("format").value,
  };
}

function send_settings() {
  if (!state.settings) return;
  state.settings = read_settings();
  main_session.send({ type: "settings", ...state.settings });
  state.sub?.send({ type: "settings", ...state.settings, mode: "subsample" });
}

for (const id of ["mode", "target-fps", "show", "format", "features"]) $(id).addEventListener("change", send_settings);

function set_split(on) {
  $("split").checked = on;
  $("sub-view").hidden = !on;
  if (!on) {
    state.sub?.close();
    state.sub = null;
  } else if (!state.sub && state.settings) {
    const sub = new Session(WS_URL, $("sub-canvas"), {
      hello: () => {  // mirror the main session: same budget, TF and camera, subsample mode
        sub.send({ type: "settings", ...state.settings, mode: "subsample" });
        if (state.last_tf_preset) sub.send({ type: "tf", transfer_function: state.last_tf_preset });
        if (state.last_camera) sub.send(state.last_camera);
      },
      frame: () => update_labels(),
  camera_answered: () => pump_camera(),  // the main view's last camera is rendered: the next may go
      error: (text) => show_message(`server (subsample view): ${text}`, true),
      closed: (text) => { $("sub-label").textContent = `subsample: ${text}`; },
    });
    state.sub = sub;
  }
  schedule_camera();  // the main view is now narrower or wider
}
$("split").addEventListener("change", (e) => set_split(e.target.checked));

// --- transfer function ------------------------------------------------------------------------------------
function schedule_tf(is_final) {
  state.tf_pending = true;
  if (is_final) send_tf();
  else if (!state.tf_timer) state.tf_timer = setTimeout(send_tf, TF_SEND_MS);
}

function send_tf() {
  clearTimeout(state.tf_timer);
  state.tf_timer = null;
  if (!state.tf_pending) return;
  state.tf_pending = false;
  state.last_tf_preset = tf_to_preset({ ...state.tf, name: $("tf-name").value || state.tf.name });
  const msg = { type: "tf", transfer_function: state.last_tf_preset };
  main_session.send(msg);
  state.sub?.send(msg);
  state.tf_sent += 1;
}

function set_tf(tf) {
  state.tf = tf;
  editor.set(tf);
  schedule_tf(true);
}

function set_iso_values(values) {
  state.iso_values = values;
  editor.set(state.tf, { iso_values: values });
  const list = $("iso-values");
  list.replaceChildren(...values.map((v) => Object.assign(document.createElement("li"), { textContent: v.toPrecision(5) })));
  if (values.length === 0) list.replaceChildren(Object.assign(document.createElement("li"), { textContent: "none" }));
}

for (const name of Object.keys(COLOR_MAPS)) $("color-map").append(new Option(name, name));
$("color-map").addEventListener("change", (e) => {
  if (state.tf && e.target.value) set_tf(apply_color_map(state.tf, e.target.value));
});
$("tf-reset").addEventListener("click", () => { if (state.home_tf) set_tf(state.home_tf); });
$("tf-import").addEventListener("click", () => $("tf-file").click());
$("tf-export").addEventListener("click", export_tf);
$("tf-file").addEventListener("change", async (e) => {
  const file = e.target.files[0];
  e.target.value = "";
  if (!file || !state.volume) return;
  try {
    let tf = tf_from_json(JSON.parse(await file.text()));
    if ($("tf-normalized").checked) tf = denormalize(tf, ...state.volume.value_range);
    $("tf-name").value = tf.name;
    $("color-map").value = "";
    set_tf(tf);
    show_message(`imported ${file.name}`);
  } catch (err) {
    show_message(`${file.name}: ${err.message}`, true);
  }
});

function export_tf() {
  if (!state.tf) return;
  const name = $("tf-name").value || state.tf.name;
  const text = JSON.stringify(tf_to_preset({ ...state.tf, name }), null, 1);
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([text], { type: "application/json" }));
  a.download = `${name.replace(/[^\w.-]+/g, "_")}.json`;
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

// --- keyboard -----------------------------------------------------------------------------------------------
const KEYS = {
  ArrowLeft: (e) => (e.shiftKey ? state.camera.pan(-KEY_PAN_PX, 0, canvas_height_css()) : state.camera.orbit(KEY_ORBIT_RAD, 0)),
  ArrowRight: (e) => (e.shiftKey ? state.camera.pan(KEY_PAN_PX, 0, canvas_height_css()) : state.camera.orbit(-KEY_ORBIT_RAD, 0)),
  ArrowUp: (e) => (e.shiftKey ? state.camera.pan(0, -KEY_PAN_PX, canvas_height_css()) : state.camera.orbit(0, -KEY_ORBIT_RAD)),
  ArrowDown: (e) => (e.shiftKey ? state.camera.pan(0, KEY_PAN_PX, canvas_height_css()) : state.camera.orbit(0, KEY_ORBIT_RAD)),
  "+": () => state.camera.zoom(1 / ZOOM_STEP),
  "=": () => state.camera.zoom(1 / ZOOM_STEP),
  "-": () => state.camera.zoom(ZOOM_STEP),
  r: () => state.camera.reset(),
};

document.addEventListener("keydown", (e) => {
  if (e.target.matches("input, select, textarea") || e.ctrlKey || e.metaKey || e.altKey || !state.settings) return;
  const show = { 1: "image", 2: "traced", 3: "importance" }[e.key];
  if (KEYS[e.key]) {
    KEYS[e.key](e);
    schedule_camera();
  } else if (show) {
    $("show").value = show;
    send_settings();
  } else if (e.key === "m") {
    $("mode").value = MODES[(MODES.indexOf($("mode").value) + 1) % MODES.length];
    send_settings();
  } else if (e.key === "s") {
    set_split(!$("split").checked);
  } else if (e.key === "i") {
    $("tf-file").click();
  } else if (e.key === "e") {
    export_tf();
  } else if (e.key === "Delete" || e.key === "Backspace") {
    editor.remove_selected();
  } else {
    return;
  }
  e.preventDefault();
});

// --- status -------------------------------------------------------------------------------------------------
const fmt = (v, digits = 1, unit = "") => (v === null || v === undefined ? "–" : `${v.toFixed(digits)}${unit}`);

function frame_label(mode, s) {
  return `${mode}  ${fmt(s.frame_ms, 1, " ms")}  ${fmt(s.rays_traced_pct, 1, " % rays")}` +
         `${s.converged ? "  converged" : ""}`;
}

function update_labels() {
  if (!state.settings) return;
  $("main-label").textContent = frame_label(state.settings.mode, main_session.stats());
  if (state.sub) $("sub-label").textContent = frame_label("subsample", state.sub.stats());
}

function update_status() {
  const s = main_session.stats();
  if (main_session.is_open() && state.settings) $("connection").textContent = `connected, ${state.settings.format} frames`;
  const target = state.settings ? state.settings.target_fps : null;
  $("st-frame").textContent = `${fmt(s.frame_ms, 1, " ms")} (budget ${fmt(s.budget_ms, 1, " ms")})`;
  $("st-fps").textContent = `${fmt(s.fps, 1, " fps")} (target ${fmt(target, 0)})`;
  $("st-rays").textContent = fmt(s.rays_traced_pct, 1, " %");
  $("st-converged").textContent = s.frames === 0 ? "–" : s.converged ? "yes" : "refining";
  const budget = target ? 1000 / target : null;
  $("st-latency").textContent = `${fmt(s.latency_ms.last, 0, " ms")} (p50 ${fmt(s.latency_ms.p50, 0)}, ` +
    `p95 ${fmt(s.latency_ms.p95, 0)} ms; p95 ${fmt(budget && s.latency_ms.p95 / budget, 2, "×")} budget; ` +
    `rendered-from message p95 ${fmt(budget && s.reflected_latency_ms.p95 / budget, 2, "×")})`;
  $("st-drag").textContent = s.drag ? `${fmt(s.drag.fps, 1, " fps")}, interval p50 ` +
    `${fmt(s.drag.interval_p50_ms, 0, " ms")} (${s.drag.frames} frames)` : "–";
  $("st-features").textContent = state.features_ready === null ? "–" : state.features_ready ? "ready" : "building…";
}
setInterval(update_status, 250);

// --- for the browser test -------------------------------------------------------------------------------------
Object.defineProperty(window, "raysiftStats", {
  get: () => ({
    ...main_session.stats(),
    connected: main_session.is_open(),
    target_fps: state.settings ? state.settings.target_fps : null,
    settings_format: state.settings ? state.settings.format : null,
    camera: state.last_camera,
    tf_sent: state.tf_sent, tf_applied: state.tf_applied, iso_values: state.iso_values,
    features_ready: state.features_ready, errors: state.errors.slice(-5),
    subsample: state.sub ? state.sub.stats() : null,
  }),
});

window.raysift = {
  tf_node_position: (i) => editor.node_client_position(i),
  tf_node_count: () => (state.tf ? state.tf.opacity.length : 0),
  tf_preset: () => state.last_tf_preset || tf_to_preset(state.tf),
  /// The main canvas's RGBA pixels, base64 (the test compares them with `raysift render`).
  canvas_rgba: () => {
    const c = $("main-canvas");
    const bytes = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    let text = "";
    for (let i = 0; i < bytes.length; i += 0x8000) text += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
    return { width: c.width, height: c.height, rgba: btoa(text) };
  },
};
