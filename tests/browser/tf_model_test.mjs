// Unit tests of the page's transfer-function model (web/tf_model.js) under Node's test runner:
// the preset and plain forms docs/transfer_function.md defines, the page's edits keeping x strictly
// increasing, and the rejections. Run: node --experimental-default-type=module --test tests/browser/
import assert from "node:assert/strict";
import test from "node:test";
import { COLOR_MAPS, apply_color_map, denormalize, insert_node, move_node, remove_node, tf_from_json, tf_to_preset }
  from "../../web/tf_model.js";

const PLAIN = { points: [[0, 0, 0, 0, 0], [80, 0.1, 0.2, 0.3, 0], [150, 0.8, 0.8, 0.7, 0.8], [255, 1, 1, 1, 1]] };

test("the plain form becomes colour and opacity nodes at the same x", () => {
  const tf = tf_from_json(PLAIN);
  assert.deepEqual(tf.opacity.map((n) => [n.x, n.a, n.mid, n.sharp]), [[0, 0, 0.5, 0], [80, 0, 0.5, 0], [150, 0.8, 0.5, 0], [255, 1, 0.5, 0]]);
  assert.deepEqual(tf.colors[1], { x: 80, r: 0.1, g: 0.2, b: 0.3 });
});

test("a preset round-trips through the form the page sends", () => {
  const preset = [{ Name: "p", ColorSpace: "RGB", RGBPoints: [0, 0, 0, 1, 0.1 + 0.2, 1, 0, 0],
                    Points: [0, 0, 0.5, 0, 0.1 + 0.2, 0.7, 0.25, 0.5] }];
  assert.deepEqual(tf_to_preset(tf_from_json(preset)), preset);
  // JSON text keeps every double exactly, so the server and the CLI read the same numbers.
  assert.deepEqual(JSON.parse(JSON.stringify(tf_to_preset(tf_from_json(preset)))), preset);
});

test("a preset without Points gets ParaView's linear 0 to 1 ramp over the colour range", () => {
  const tf = tf_from_json([{ RGBPoints: [10, 0, 0, 0, 20, 1, 1, 1] }]);
  assert.deepEqual(tf.opacity.map((n) => [n.x, n.a]), [[10, 0], [20, 1]]);
});

test("malformed input is rejected with the problem named", () => {
  assert.throws(() => tf_from_json({ bad: 1 }), /ParaView preset/);
  assert.throws(() => tf_from_json([]), /ParaView preset/);
  assert.throws(() => tf_from_json([{ RGBPoints: [0, 0, 0] }]), /quadruples/);
  assert.throws(() => tf_from_json([{ RGBPoints: [0, 0, 0, 0, 0, 1, 1, 1] }]), /increase strictly/);
  assert.throws(() => tf_from_json([{ RGBPoints: [0, 0, 0, 2, 1, 1, 1, 1] }]), /\[0, 1\]/);
  assert.throws(() => tf_from_json({ points: [[0, 0, 0, 0, Number.NaN]] }), /finite/);
  assert.throws(() => tf_from_json({ points: [[0, 0, 0, 0]] }), /\[x, r, g, b, a\]/);
});

test("dragging a node keeps x strictly between its neighbours and opacity in [0, 1]", () => {
  const tf = tf_from_json(PLAIN);
  const moved = move_node(tf, 1, 500, 7);
  assert.ok(moved.opacity[1].x < moved.opacity[2].x && moved.opacity[1].x > moved.opacity[0].x);
  assert.equal(moved.opacity[1].a, 1);
  assert.equal(move_node(tf, 0, -1e9, -3).opacity[0].x, -1e9);  // an end node may widen the domain
  assert.equal(move_node(tf, 0, -1e9, -3).opacity[0].a, 0);
  assert.equal(tf.opacity[1].x, 80, "the edit does not change the original");
});

test("inserting and removing nodes", () => {
  const tf = tf_from_json(PLAIN);
  const { tf: added, index } = insert_node(tf, 100, 0.3);
  assert.equal(index, 2);
  assert.deepEqual(added.opacity.map((n) => n.x), [0, 80, 100, 150, 255]);
  assert.equal(insert_node(tf, 80, 0.3), null, "an existing x is not duplicated");
  assert.equal(remove_node(added, 2).opacity.length, 4);
  const two = tf_from_json({ points: [[0, 0, 0, 0, 0], [1, 1, 1, 1, 1]] });
  assert.equal(remove_node(two, 0), two, "two nodes stay");
});

test("colour maps stretch over the opacity domain; normalised presets map onto the data range", () => {
  const tf = apply_color_map(tf_from_json(PLAIN), "Cool to Warm");
  const map = COLOR_MAPS["Cool to Warm"];
  assert.deepEqual(tf.colors.map((n) => n.x), [0, 127.5, 255]);
  assert.deepEqual(tf.colors.map((n) => [n.r, n.g, n.b]), map.map(([, r, g, b]) => [r, g, b]));
  const d = denormalize(tf_from_json([{ RGBPoints: [0, 0, 0, 0, 1, 1, 1, 1], Points: [0, 0, 0.5, 0, 0.5, 1, 0.5, 0] }]), 10, 30);
  assert.deepEqual(d.opacity.map((n) => n.x), [10, 20]);
  assert.deepEqual(d.colors.map((n) => n.x), [10, 30]);
});
