// The opacity-curve editor: the volume's histogram (log scale) behind the opacity nodes, the colour the TF
// gives each value as a strip under it, and the TF's iso-values as dashed lines. Drag a node to move it,
// press on empty space to add one, right-click a node (or select it and press Delete) to remove it.
import { color_at, insert_node, move_node, remove_node } from "./tf_model.js";

const NODE_RADIUS = 5;
const STRIP_PX = 14;

export class TfEditor {
  /// on_change(tf, is_final) is called while dragging (is_final false) and when a gesture ends.
  constructor(canvas, on_change) {
    this.canvas = canvas;
    this.on_change = on_change;
    this.tf = null;
    this.histogram = null;
    this.iso_values = [];
    this.selected = -1;
    this.dragging = false;
    canvas.addEventListener("pointerdown", (e) => this.pointer_down(e));
    canvas.addEventListener("pointermove", (e) => this.pointer_move(e));
    canvas.addEventListener("pointerup", (e) => this.pointer_up(e));
    canvas.addEventListener("pointercancel", (e) => this.pointer_up(e));
    canvas.addEventListener("contextmenu", (e) => this.context_menu(e));
    new ResizeObserver(() => this.draw()).observe(canvas);
  }

  set(tf, { histogram = this.histogram, iso_values = this.iso_values } = {}) {
    this.tf = tf;
    this.histogram = histogram;
    this.iso_values = iso_values;
    if (this.selected >= tf.opacity.length) this.selected = -1;
    this.draw();
  }

  /// The value axis: the histogram's range, widened to hold every node.
  domain() {
    let lo = this.histogram ? this.histogram.range[0] : this.tf.opacity[0].x;
    let hi = this.histogram ? this.histogram.range[1] : this.tf.opacity[this.tf.opacity.length - 1].x;
    for (const n of this.tf.opacity) { lo = Math.min(lo, n.x); hi = Math.max(hi, n.x); }
    return hi > lo ? [lo, hi] : [lo, lo + 1];
  }

  plot_height() { return this.canvas.height - STRIP_PX; }
  x_to_px(x) { const [lo, hi] = this.domain(); return ((x - lo) / (hi - lo)) * this.canvas.width; }
  px_to_x(px) { const [lo, hi] = this.domain(); return lo + (px / this.canvas.width) * (hi - lo); }
  a_to_py(a) { return (1 - a) * (this.plot_height() - 2 * NODE_RADIUS) + NODE_RADIUS; }
  py_to_a(py) { return 1 - (py - NODE_RADIUS) / (this.plot_height() - 2 * NODE_RADIUS); }

  /// A node's position in CSS pixels relative to the viewport (the browser test drags it).
  node_client_position(i) {
    const rect = this.canvas.getBoundingClientRect();
    const n = this.tf.opacity[i];
    return { x: rect.left + (this.x_to_px(n.x) * rect.width) / this.canvas.width,
             y: rect.top + (this.a_to_py(n.a) * rect.height) / this.canvas.height };
  }

  event_px(e) {
    const rect = this.canvas.getBoundingClientRect();
    return [((e.clientX - rect.left) * this.canvas.width) / rect.width,
            ((e.clientY - rect.top) * this.canvas.height) / rect.height];
  }

  node_at(px, py) {
    let best = -1, best_d = 2 * NODE_RADIUS + 3;
    this.tf.opacity.forEach((n, i) => {
      const d = Math.hypot(this.x_to_px(n.x) - px, this.a_to_py(n.a) - py);
      if (d < best_d) { best = i; best_d = d; }
    });
    return best;
  }

  pointer_down(e) {
    if (!this.tf || e.button !== 0) return;
    const [px, py] = this.event_px(e);
    let i = this.node_at(px, py);
    if (i < 0) {
      const inserted = insert_node(this.tf, this.px_to_x(px), this.py_to_a(py));
      if (!inserted) return;
      this.tf = inserted.tf;
      i = inserted.index;
      this.on_change(this.tf, false);
    }
    this.selected = i;
    this.dragging = true;
    this.canvas.setPointerCapture(e.pointerId);
    this.draw();
  }

  pointer_move(e) {
    if (!this.dragging) return;
    const [px, py] = this.event_px(e);
    this.tf = move_node(this.tf, this.selected, this.px_to_x(px), this.py_to_a(py));
    this.draw();
    this.on_change(this.tf, false);
  }

  pointer_up(e) {
    if (!this.dragging) return;
    this.dragging = false;
    this.canvas.releasePointerCapture(e.pointerId);
    this.on_change(this.tf, true);
  }

  context_menu(e) {
    e.preventDefault();
    const [px, py] = this.event_px(e);
    const i = this.node_at(px, py);
    if (i >= 0) this.remove(i);
  }

  remove_selected() { if (this.selected >= 0) this.remove(this.selected); }

  remove(i) {
    const before = this.tf.opacity.length;
    this.tf = remove_node(this.tf, i);
    if (this.tf.opacity.length === before) return;
    this.selected = -1;
    this.draw();
    this.on_change(this.tf, true);
  }

  draw() {
    const c = this.canvas;
    const rect = c.getBoundingClientRect();
    const w = Math.max(1, Math.round(rect.width * devicePixelRatio));
    const h = Math.max(1, Math.round(rect.height * devicePixelRatio));
    if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
    const ctx = c.getContext("2d");
    ctx.clearRect(0, 0, w, h);
    if (!this.tf) return;
    this.draw_histogram(ctx);
    this.draw_strip(ctx);
    this.draw_iso_values(ctx);
    this.draw_curve(ctx);
  }

  draw_histogram(ctx) {
    if (!this.histogram || this.histogram.counts.length === 0) return;
    const counts = this.histogram.counts, [lo, hi] = this.histogram.range;
    const log_max = Math.log1p(Math.max(...counts));
    if (!(log_max > 0)) return;
    const bin = (hi - lo) / counts.length, ph = this.plot_height();
    ctx.fillStyle = "rgba(120, 130, 150, 0.45)";
    counts.forEach((count, i) => {
      const x0 = this.x_to_px(lo + i * bin), x1 = this.x_to_px(lo + (i + 1) * bin);
      const bar = (Math.log1p(count) / log_max) * ph;
      ctx.fillRect(x0, ph - bar, Math.max(1, x1 - x0), bar);
    });
  }

  draw_strip(ctx) {
    const top = this.plot_height();
    for (let px = 0; px < this.canvas.width; ++px) {
      const [r, g, b] = color_at(this.tf, this.px_to_x(px + 0.5));
      ctx.fillStyle = `rgb(${255 * r}, ${255 * g}, ${255 * b})`;
      ctx.fillRect(px, top, 1, STRIP_PX);
    }
  }

  draw_iso_values(ctx) {
    ctx.save();
    ctx.strokeStyle = "#e0b040";
    ctx.setLineDash([4, 3]);
    for (const v of this.iso_values) {
      const px = Math.round(this.x_to_px(v)) + 0.5;
      ctx.beginPath(); ctx.moveTo(px, 0); ctx.lineTo(px, this.plot_height()); ctx.stroke();
    }
    ctx.restore();
  }

  draw_curve(ctx) {
    const nodes = this.tf.opacity;
    ctx.strokeStyle = "#f4f4f4";
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    ctx.moveTo(0, this.a_to_py(nodes[0].a));
    for (const n of nodes) ctx.lineTo(this.x_to_px(n.x), this.a_to_py(n.a));
    ctx.lineTo(this.canvas.width, this.a_to_py(nodes[nodes.length - 1].a));
    ctx.stroke();
    nodes.forEach((n, i) => {
      const [r, g, b] = color_at(this.tf, n.x);
      ctx.fillStyle = `rgb(${255 * r}, ${255 * g}, ${255 * b})`;
      ctx.strokeStyle = i === this.selected ? "#ffcc33" : "#202020";
      ctx.lineWidth = i === this.selected ? 2.5 : 1.5;
      ctx.beginPath();
      ctx.arc(this.x_to_px(n.x), this.a_to_py(n.a), NODE_RADIUS * devicePixelRatio, 0, 2 * Math.PI);
      ctx.fill(); ctx.stroke();
    });
  }
}
