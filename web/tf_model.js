// The transfer function as the page edits it: opacity nodes {x, a, mid, sharp} (ParaView's "Points") and
// colour nodes {x, r, g, b} (ParaView's "RGBPoints"). The server and `raysift render --tf` read the
// ParaView preset form this module writes (docs/transfer_function.md), so the page sends, exports and
// imports one format, and what it sends is exactly what the CLI reads from the exported file.

/// Colour maps defined in the page: [t, r, g, b] with t in 0..1, stretched over the opacity nodes' domain.
export const COLOR_MAPS = {
  "Grayscale": [[0, 0, 0, 0], [1, 1, 1, 1]],
  "Cool to Warm": [[0, 0.231, 0.299, 0.754], [0.5, 0.865, 0.865, 0.865], [1, 0.706, 0.016, 0.150]],
  "Viridis": [[0, 0.267, 0.005, 0.329], [0.25, 0.229, 0.322, 0.546], [0.5, 0.128, 0.567, 0.551],
              [0.75, 0.369, 0.789, 0.383], [1, 0.993, 0.906, 0.144]],
  "Inferno": [[0, 0.001, 0.000, 0.014], [0.25, 0.341, 0.062, 0.429], [0.5, 0.735, 0.216, 0.330],
              [0.75, 0.978, 0.557, 0.035], [1, 0.988, 0.998, 0.645]],
  "Black-Body": [[0, 0, 0, 0], [0.39, 0.9, 0.2, 0.0], [0.58, 0.9, 0.6, 0.1], [0.84, 1, 1, 0.5], [1, 1, 1, 1]],
  "Bone": [[0, 0, 0, 0], [0.375, 0.329, 0.329, 0.455], [0.75, 0.651, 0.784, 0.784], [1, 1, 1, 1]],
};

const clamp01 = (v) => Math.max(0, Math.min(1, v));

function check_finite(values, what) {
  if (!Array.isArray(values) || values.some((v) => typeof v !== "number" || !Number.isFinite(v)))
    throw new Error(`${what} must be an array of finite numbers`);
}

/// Parses a ParaView preset (a list whose first entry holds RGBPoints and optional Points) or the raysift
/// plain form {"points": [[x, r, g, b, a], ...]}. Throws an Error naming the problem.
export function tf_from_json(json) {
  if (json && !Array.isArray(json) && Array.isArray(json.points)) return tf_from_plain(json.points);
  if (!Array.isArray(json) || json.length === 0 || typeof json[0] !== "object")
    throw new Error("expected a ParaView preset (a non-empty list) or {\"points\": [...]}");
  const preset = json[0];
  check_finite(preset.RGBPoints, "RGBPoints");
  if (preset.RGBPoints.length < 4 || preset.RGBPoints.length % 4 !== 0)
    throw new Error("RGBPoints must hold x, r, g, b quadruples");
  const colors = [];
  for (let i = 0; i < preset.RGBPoints.length; i += 4) {
    const [x, r, g, b] = preset.RGBPoints.slice(i, i + 4);
    colors.push({ x, r, g, b });
  }
  let opacity;
  if (preset.Points !== undefined) {
    check_finite(preset.Points, "Points");
    if (preset.Points.length < 4 || preset.Points.length % 4 !== 0)
      throw new Error("Points must hold x, opacity, midpoint, sharpness quadruples");
    opacity = [];
    for (let i = 0; i < preset.Points.length; i += 4) {
      const [x, a, mid, sharp] = preset.Points.slice(i, i + 4);
      opacity.push({ x, a, mid, sharp });
    }
  } else {  // ParaView's default: a linear 0 -> 1 ramp over the colour range
    opacity = [{ x: colors[0].x, a: 0, mid: 0.5, sharp: 0 },
               { x: colors[colors.length - 1].x, a: 1, mid: 0.5, sharp: 0 }];
  }
  const tf = { name: typeof preset.Name === "string" ? preset.Name : "imported", opacity, colors };
  validate(tf);
  return tf;
}

function tf_from_plain(points) {
  const tf = { name: "raysift", opacity: [], colors: [] };
  for (const p of points) {
    check_finite(p, "each point");
    if (p.length !== 5) throw new Error("each point must be [x, r, g, b, a]");
    tf.colors.push({ x: p[0], r: p[1], g: p[2], b: p[3] });
    tf.opacity.push({ x: p[0], a: p[4], mid: 0.5, sharp: 0 });
  }
  validate(tf);
  return tf;
}

function validate(tf) {
  for (const [nodes, what] of [[tf.opacity, "opacity"], [tf.colors, "colour"]]) {
    if (nodes.length < 1) throw new Error(`no ${what} nodes`);
    for (let i = 1; i < nodes.length; ++i)
      if (!(nodes[i].x > nodes[i - 1].x)) throw new Error(`${what} node x values must increase strictly`);
  }
  const in01 = (v) => v >= 0 && v <= 1;
  if (!tf.opacity.every((n) => in01(n.a) && in01(n.mid) && in01(n.sharp)))
    throw new Error("opacity, midpoint and sharpness must lie in [0, 1]");
  if (!tf.colors.every((n) => in01(n.r) && in01(n.g) && in01(n.b))) throw new Error("colours must lie in [0, 1]");
}

/// Maps a preset stored over 0..1 onto the data range [lo, hi].
export function denormalize(tf, lo, hi) {
  const map = (x) => lo + x * (hi - lo);
  return { ...tf, opacity: tf.opacity.map((n) => ({ ...n, x: map(n.x) })),
           colors: tf.colors.map((n) => ({ ...n, x: map(n.x) })) };
}

/// The one-entry ParaView preset the page sends and exports.
export function tf_to_preset(tf) {
  return [{
    Name: tf.name, ColorSpace: "RGB",
    RGBPoints: tf.colors.flatMap((n) => [n.x, n.r, n.g, n.b]),
    Points: tf.opacity.flatMap((n) => [n.x, n.a, n.mid, n.sharp]),
  }];
}

/// Piecewise-linear interpolation over nodes sorted by x, clamped at the ends.
function interpolate(nodes, x, keys) {
  if (x <= nodes[0].x) return keys.map((k) => nodes[0][k]);
  const last = nodes[nodes.length - 1];
  if (x >= last.x) return keys.map((k) => last[k]);
  let i = 1;
  while (nodes[i].x < x) ++i;
  const a = nodes[i - 1], b = nodes[i], t = (x - a.x) / (b.x - a.x);
  return keys.map((k) => a[k] + t * (b[k] - a[k]));
}

export const color_at = (tf, x) => interpolate(tf.colors, x, ["r", "g", "b"]);
/// Linear between nodes (the editor's drawing; midpoint/sharpness other than 0.5/0 are kept and sent, and the
/// server follows VTK's curve for them).
export const opacity_at = (tf, x) => interpolate(tf.opacity, x, ["a"])[0];

/// Replaces the colour nodes with a page colour map stretched over the opacity domain.
export function apply_color_map(tf, map_name) {
  const lo = tf.opacity[0].x, hi = tf.opacity[tf.opacity.length - 1].x;
  const span = hi > lo ? hi - lo : 1;
  const colors = COLOR_MAPS[map_name].map(([t, r, g, b]) => ({ x: lo + t * span, r, g, b }));
  return { ...tf, colors };
}

/// Moves opacity node i to (x, a), keeping x strictly between its neighbours.
export function move_node(tf, i, x, a) {
  const nodes = tf.opacity.map((n) => ({ ...n }));
  const gap = 1e-6 * Math.max(1, Math.abs(x));
  const lo = i > 0 ? nodes[i - 1].x + gap : -Infinity;
  const hi = i + 1 < nodes.length ? nodes[i + 1].x - gap : Infinity;
  nodes[i].x = Math.max(lo, Math.min(hi, x));
  nodes[i].a = clamp01(a);
  return { ...tf, opacity: nodes };
}

/// Inserts an opacity node at x (returns the new tf and the node's index), or null if x is taken.
export function insert_node(tf, x, a) {
  if (tf.opacity.some((n) => n.x === x)) return null;
  const nodes = [...tf.opacity, { x, a: clamp01(a), mid: 0.5, sharp: 0 }].sort((p, q) => p.x - q.x);
  return { tf: { ...tf, opacity: nodes }, index: nodes.findIndex((n) => n.x === x) };
}

/// Removes opacity node i unless only two remain.
export function remove_node(tf, i) {
  if (tf.opacity.length <= 2) return tf;
  return { ...tf, opacity: tf.opacity.filter((_, j) => j !== i) };
}
