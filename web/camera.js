// Turntable camera for the raysift page: orbit about the target around the scene's up axis, pan in the
// view plane, zoom along the view direction. The up vector stays the scene camera's, so orbiting never rolls
// the image and the server's look-at basis stays well defined (elevation is clamped short of the poles).
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const normalize = (a) => scale(a, 1 / Math.hypot(a[0], a[1], a[2]));

const MAX_ELEVATION = (89 * Math.PI) / 180;

export class OrbitCamera {
  constructor(spec) {
    this.home = JSON.parse(JSON.stringify(spec));
    this.reset();
  }

  reset() {
    this.eye = [...this.home.eye];
    this.target = [...this.home.target];
    this.up = normalize(this.home.up);
    this.fov_y_deg = this.home.fov_y_deg;
    this.home_distance = Math.hypot(...sub(this.eye, this.target));
  }

  /// Azimuth about the up axis and elevation above the plane normal to it, both in radians.
  orbit(d_azimuth, d_elevation) {
    const offset = sub(this.eye, this.target);
    const r = Math.hypot(...offset);
    const u = this.up;
    const along_up = dot(offset, u);
    const elevation = Math.asin(Math.max(-1, Math.min(1, along_up / r)));
    const h = normalize(sub(offset, scale(u, along_up)));
    const c = Math.cos(d_azimuth), s = Math.sin(d_azimuth);
    const h_rot = add(scale(h, c), scale(cross(u, h), s));
    const el = Math.max(-MAX_ELEVATION, Math.min(MAX_ELEVATION, elevation + d_elevation));
    this.eye = add(this.target, scale(add(scale(h_rot, Math.cos(el)), scale(u, Math.sin(el))), r));
  }

  /// Moves eye and target together so that the point under the cursor follows it (pixels of an image
  /// `height_px` tall; x to the right, y down).
  pan(dx_px, dy_px, height_px) {
    const offset = sub(this.target, this.eye);
    const r = Math.hypot(...offset);
    const forward = scale(offset, 1 / r);
    const right = normalize(cross(forward, this.up));
    const cam_up = cross(right, forward);
    const world_per_px = (2 * r * Math.tan((this.fov_y_deg * Math.PI) / 360)) / height_px;
    const delta = add(scale(right, -dx_px * world_per_px), scale(cam_up, dy_px * world_per_px));
    this.eye = add(this.eye, delta);
    this.target = add(this.target, delta);
  }

  /// factor < 1 moves closer. The distance stays within [1e-3, 1e2] times the scene camera's.
  zoom(factor) {
    const offset = sub(this.eye, this.target);
    const r = Math.hypot(...offset);
    const r_new = Math.max(1e-3 * this.home_distance, Math.min(1e2 * this.home_distance, r * factor));
    this.eye = add(this.target, scale(offset, r_new / r));
  }

  /// The protocol's camera message.
  message(width, height, seq) {
    return {
      type: "camera", eye: this.eye, target: this.target, up: this.up, fov_y_deg: this.fov_y_deg,
      width, height, seq,
    };
  }
}
