#include "mpi/kd_split.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace raysift::mpi {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
using Leaves = std::vector<volume::LeafCount>;

std::uint64_t count(const Leaves& leaves) {
  std::uint64_t n = 0;
  for (const auto& l : leaves) n += l.active;
  return n;
}

/// The plane on `axis` (a leaf origin) whose lower side holds the count closest to total·left_ranks/ranks;
/// false when all leaves share one position on that axis.
bool best_plane(Leaves& leaves, int axis, int left_ranks, int ranks, int& plane, double& error) {
  std::sort(leaves.begin(), leaves.end(), [axis](const auto& a, const auto& b) { return a.origin[axis] < b.origin[axis]; });
  const double total = double(count(leaves)), target = total * left_ranks / ranks;
  double below = 0;
  bool found = false;
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    if (i > 0 && leaves[i].origin[axis] != leaves[i - 1].origin[axis] && std::abs(below - target) < error) {
      error = std::abs(below - target);
      plane = leaves[i].origin[axis];
      found = true;
    }
    below += leaves[i].active;
  }
  return found;
}

struct Builder {
  KdSplit& out;
  const volume::VdbLayout& layout;
  int ghost;

  int build(Leaves leaves, Vec3d lo, Vec3d hi, int ranks) {
    const int id = int(out.nodes.size());
    out.nodes.emplace_back();
    if (ranks == 1) return leaf(id, leaves, lo, hi);
    const int left_ranks = ranks / 2;
    // Longest extent of the leaves first; the other axes when every leaf sits in one slab of that axis.
    Vec3i span_lo{INT32_MAX, INT32_MAX, INT32_MAX}, span_hi{INT32_MIN, INT32_MIN, INT32_MIN};
    for (const auto& l : leaves) span_lo = min(span_lo, l.origin), span_hi = max(span_hi, l.origin);
    int axes[3] = {0, 1, 2};
    std::stable_sort(axes, axes + 3, [&](int a, int b) { return span_hi[a] - span_lo[a] > span_hi[b] - span_lo[b]; });
    int axis = axes[0], plane = 0;
    double error = kInf;
    bool found = false;
    for (int a : axes)
      if (!found && best_plane(leaves, a, left_ranks, ranks, plane, error)) found = true, axis = a;
    // Not splittable: every leaf goes left, the right ranks get empty bricks beyond it.
    if (!found) plane = leaves.empty() ? 0 : span_hi[axis] + 8;
    Leaves below, above;
    for (const auto& l : leaves) (l.origin[axis] < plane ? below : above).push_back(l);
    Vec3d left_hi = hi, right_lo = lo;
    left_hi[axis] = right_lo[axis] = double(plane);
    const int left = build(std::move(below), lo, left_hi, left_ranks);
    const int right = build(std::move(above), right_lo, hi, ranks - left_ranks);
    out.nodes[id].axis = axis;
    out.nodes[id].plane = double(plane);
    out.nodes[id].left = left;
    out.nodes[id].right = right;
    return id;
  }

  int leaf(int id, const Leaves& leaves, const Vec3d& lo, const Vec3d& hi) {
    Brick b;
    b.own_lo = lo;
    b.own_hi = hi;
    b.active_voxels = count(leaves);
    for (int a = 0; a < 3; ++a) {  // voxels lo..hi-1 of the planes, plus the ghosts, inside the active bbox
      b.read_lo[a] = std::isinf(lo[a]) ? layout.index_min[a] : std::max(layout.index_min[a], int(lo[a]) - ghost);
      b.read_hi[a] = std::isinf(hi[a]) ? layout.index_max[a] : std::min(layout.index_max[a], int(hi[a]) - 1 + ghost);
    }
    for (const auto& l : layout.leaves) {
      bool touches = true;
      for (int a = 0; a < 3; ++a) touches = touches && l.origin[a] <= b.read_hi[a] && l.origin[a] + 7 >= b.read_lo[a];
      if (touches) b.read_voxels_bound += l.active;
    }
    out.nodes[id].brick = int(out.bricks.size());
    out.bricks.push_back(b);
    return id;
  }
};

Json vec_json(const Vec3d& v) {  // ±infinity has no JSON number: null stands for it (the sign is the side's)
  Json j = Json::array();
  for (int a = 0; a < 3; ++a) j.push_back(std::isinf(v[a]) ? Json(nullptr) : Json(v[a]));
  return j;
}
Vec3d vec_from(const Json& j, double inf) {
  Vec3d v;
  for (int a = 0; a < 3; ++a) v[a] = j[a].is_null() ? inf : j[a].get<double>();
  return v;
}

}  // namespace

KdSplit kd_split(const volume::VdbLayout& layout, int n, int ghost) {
  KdSplit out;
  Builder builder{out, layout, ghost};
  builder.build(layout.leaves, {-kInf, -kInf, -kInf}, {kInf, kInf, kInf}, std::max(n, 1));
  return out;
}

std::vector<int> visibility_order(const KdSplit& split, const Vec3d& eye_is) {
  std::vector<int> order, stack{0};
  while (!stack.empty()) {
    const KdNode& node = split.nodes[std::size_t(stack.back())];
    stack.pop_back();
    if (node.axis < 0) {
      order.push_back(node.brick);
      continue;
    }
    const bool eye_below = eye_is[node.axis] < node.plane;
    stack.push_back(eye_below ? node.right : node.left);  // the far half, visited after the near one
    stack.push_back(eye_below ? node.left : node.right);
  }
  return order;
}

Json kd_split_to_json(const KdSplit& split) {
  Json bricks = Json::array(), nodes = Json::array();
  for (const Brick& b : split.bricks)
    bricks.push_back({{"own_lo", vec_json(b.own_lo)},
                      {"own_hi", vec_json(b.own_hi)},
                      {"read_lo", {b.read_lo.x, b.read_lo.y, b.read_lo.z}},
                      {"read_hi", {b.read_hi.x, b.read_hi.y, b.read_hi.z}},
                      {"active_voxels", b.active_voxels},
                      {"read_voxels_bound", b.read_voxels_bound}});
  for (const KdNode& n : split.nodes)
    nodes.push_back({n.axis, n.plane, n.left, n.right, n.brick});
  return {{"bricks", bricks}, {"nodes", nodes}};
}

KdSplit kd_split_from_json(const Json& j) {
  KdSplit split;
  for (const Json& b : j["bricks"]) {
    Brick brick;
    brick.own_lo = vec_from(b["own_lo"], -kInf);
    brick.own_hi = vec_from(b["own_hi"], kInf);
    for (int a = 0; a < 3; ++a) brick.read_lo[a] = b["read_lo"][a], brick.read_hi[a] = b["read_hi"][a];
    brick.active_voxels = b["active_voxels"];
    brick.read_voxels_bound = b["read_voxels_bound"];
    split.bricks.push_back(brick);
  }
  for (const Json& n : j["nodes"]) split.nodes.push_back({n[0], n[1], n[2], n[3], n[4]});
  return split;
}

}  // namespace raysift::mpi
