// One WebSocket session with `raysift serve` (docs/serve.md): the server's text messages, the frame
// header + binary image pairs drawn onto a canvas, and the numbers the status shows. The page opens one
// session for the main view and, for the split view, a second one in subsample mode.

const RATE_WINDOW_MS = 1000;
const LATENCY_KEEP = 500;
const CAMERA_ANSWER_WAIT_MS = 1000;
const CLIENT_MS_KEEP = 8;            // frames whose decode + display time the page reports  // a camera message unanswered this long no longer holds the next one back

export function percentile(values, p) {
  if (values.length === 0) return null;
  const sorted = [...values].sort((a, b) => a - b);
  return sorted[Math.min(sorted.length - 1, Math.floor((p / 100) * sorted.length))];
}

function latency_summary(values) {
  return {
    last: values.length ? values[values.length - 1] : null,
    p50: percentile(values, 50), p95: percentile(values, 95),
    max: values.length ? Math.max(...values) : null, count: values.length,
  };
}

export class Session {
  /// handlers: hello(msg), frame(meta), camera_answered(), tf_applied(msg), features_ready(), error(text),
  /// closed(text).
  constructor(url, canvas, handlers) {
    this.canvas = canvas;
    this.handlers = handlers;
    this.pending_meta = null;
    this.draw_chain = Promise.resolve();
    this.sent_camera = new Map();    // seq -> performance.now() when sent, until a frame reflects it
    this.in_flight = null;           // {seq, sent} of the last camera message until a frame header reflects it
    this.header_at = null;           // performance.now() when the pending frame's header arrived
    this.client_ms = [];             // recent header -> drawn times (decode + display), newest last
    this.latencies_ms = [];          // camera message -> first pixels drawn that reflect it
    this.reflected_latencies_ms = []; // the same, only for the message each frame was rendered from
    this.draw_times = [];            // performance.now() of recent draws, for the achieved rate
    this.drag = null;                // {start, draws: [t...]} while (or after) the user drags
    this.frames = 0;
    this.last = null;                // the last drawn frame's header
    this.ws = new WebSocket(url);
    this.ws.binaryType = "blob";
    this.ws.onmessage = (e) => this.receive(e.data);
    this.ws.onclose = (e) => handlers.closed?.(`connection closed (${e.code}${e.reason ? ": " + e.reason : ""})`);
  }

  is_open() { return this.ws.readyState === WebSocket.OPEN; }

  /// The page's decode + display time per frame, sent with each camera message so that the server keeps it out of
  /// the render budget (docs/serve.md): the largest of the last CLIENT_MS_KEEP frames, since a camera message's
  /// latency pays it in full.
  client_time_ms() { return this.client_ms.length ? Math.max(...this.client_ms) : 0; }

  send(message) {
    if (!this.is_open()) return;
    if (message.type === "camera" && message.seq !== undefined) {
      const now = performance.now();
      this.sent_camera.set(message.seq, now);
      this.in_flight = { seq: message.seq, sent: now };
    }
    this.ws.send(JSON.stringify(message));
  }

  /// Flow control [choice]: one camera message in flight. The page sends the next camera when a frame header
  /// reflects the last one (handlers.camera_answered), so the server never holds a queued camera behind a frame
  /// (each message's latency is then one frame, not up to two: docs/serve-page.md).
  camera_in_flight() {
    return this.in_flight !== null && performance.now() - this.in_flight.sent < CAMERA_ANSWER_WAIT_MS;
  }

  close() { this.ws.onclose = null; this.ws.close(); }

  receive(data) {
    if (data instanceof Blob) return this.receive_image(data);
    let msg;
    try { msg = JSON.parse(data); } catch { return this.handlers.error?.("unreadable message from the server"); }
    switch (msg.type) {
      case "hello": return this.handlers.hello?.(msg);
      case "frame":
        this.pending_meta = msg;
        this.header_at = performance.now();
        if (this.in_flight && typeof msg.camera_seq === "number" && msg.camera_seq >= this.in_flight.seq) {
          this.in_flight = null;
          this.handlers.camera_answered?.();
        }
        return;
      case "tf_applied": return this.handlers.tf_applied?.(msg);
      case "features_ready": return this.handlers.features_ready?.();
      case "error": return this.handlers.error?.(msg.message);
      default: return undefined;  // a newer server's message: the protocol only adds types
    }
  }

  receive_image(blob) {
    const meta = this.pending_meta;
    const header_at = this.header_at;
    this.pending_meta = null;
    if (!meta) return this.handlers.error?.("image without a frame header");
    // PNG or JPEG: the decoder sniffs the bytes. Decoded in order; colorSpaceConversion "none" keeps the PNG's 8-bit values exactly (no gamma/profile
    // handling), so the canvas holds the bytes `raysift render -o x.png` writes.
    const decoded = createImageBitmap(blob, { colorSpaceConversion: "none", premultiplyAlpha: "none" });
    this.draw_chain = this.draw_chain.then(() => decoded).then(
      (bitmap) => this.draw(bitmap, meta, header_at),
      (err) => this.handlers.error?.(`could not decode a frame: ${err}`));
  }

  draw(bitmap, meta, header_at) {
    const c = this.canvas;
    if (c.width !== bitmap.width || c.height !== bitmap.height) {
      c.width = bitmap.width;
      c.height = bitmap.height;
    }
    c.getContext("2d").drawImage(bitmap, 0, 0);
    bitmap.close();
    const now = performance.now();
    if (header_at !== null) {
      this.client_ms.push(now - header_at);
      if (this.client_ms.length > CLIENT_MS_KEEP) this.client_ms.shift();
    }
    this.frames += 1;
    this.last = meta;
    this.record_latency(meta.camera_seq, now);
    this.draw_times.push(now);
    while (this.draw_times.length > 0 && now - this.draw_times[0] > RATE_WINDOW_MS) this.draw_times.shift();
    if (this.drag && this.drag.active && meta.camera_seq >= this.drag.first_seq) {
      this.drag.draws.push(now);
      this.drag.frame_ms.push(meta.ms);
      this.drag.budget_ms.push(meta.budget_ms);
    }
    this.handlers.frame?.(meta);
  }

  /// Every camera message up to camera_seq is now on screen: its latency is now - its send time. Messages the
  /// server coalesced (superseded while a frame was in flight) count too, so this is the latency a user feels;
  /// the frame's own message (camera_seq) is kept apart, as the server's part of it.
  record_latency(camera_seq, now) {
    if (typeof camera_seq !== "number") return;
    for (const [seq, sent] of this.sent_camera) {
      if (seq > camera_seq) continue;
      this.latencies_ms.push(now - sent);
      if (seq === camera_seq) this.reflected_latencies_ms.push(now - sent);
      if (this.drag && this.drag.active && seq >= this.drag.first_seq) this.drag.latencies_ms.push(now - sent);
      this.sent_camera.delete(seq);
    }
    for (const list of [this.latencies_ms, this.reflected_latencies_ms])
      if (list.length > LATENCY_KEEP) list.splice(0, list.length - LATENCY_KEEP);
  }

  /// A drag's frame rate counts the frames that reflect its camera messages, from the first to its end.
  begin_drag(first_seq) {
    this.drag = { active: true, first_seq, draws: [], frame_ms: [], budget_ms: [], latencies_ms: [] };
  }
  end_drag() { if (this.drag) this.drag.active = false; }

  stats() {
    const last = this.last;
    const now = performance.now();
    const recent = this.draw_times.filter((t) => now - t <= RATE_WINDOW_MS);  // none once the server idles
    const n = recent.length;
    const fps = n >= 2 ? ((n - 1) * 1000) / (recent[n - 1] - recent[0]) : null;
    return {
      frames: this.frames,
      frame_ms: last ? last.ms : null,
      budget_ms: last ? last.budget_ms : null,
      fps,
      rays_traced_pct: last && last.full_rays > 0 ? (100 * last.rays_traced) / last.full_rays : null,
      converged: last ? !!last.converged : false,
      show: last ? last.show : null,
      seq: last ? last.seq : null,
      camera_seq: last ? last.camera_seq : null,
      latency_ms: latency_summary(this.latencies_ms),
      reflected_latency_ms: latency_summary(this.reflected_latencies_ms),
      drag: this.drag_stats(),
    };
  }

  drag_stats() {
    if (!this.drag) return null;
    const t = this.drag.draws;
    const intervals = t.slice(1).map((v, i) => v - t[i]);
    return {
      active: this.drag.active, frames: t.length,
      fps: t.length >= 2 ? ((t.length - 1) * 1000) / (t[t.length - 1] - t[0]) : null,
      interval_p50_ms: percentile(intervals, 50), interval_p95_ms: percentile(intervals, 95),
      frame_ms_p50: percentile(this.drag.frame_ms, 50), budget_ms_p50: percentile(this.drag.budget_ms, 50),
      frame_ms_p95: percentile(this.drag.frame_ms, 95), latency_ms: latency_summary(this.drag.latencies_ms),
    };
  }
}
