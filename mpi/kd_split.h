#pragma once
/// \file The k-d split of sort-last rendering: the active region cut into N convex bricks with about equal
/// active-voxel counts (8³ leaf granularity), and the bricks' front-to-back order for an eye position.
#include <cstdint>
#include <vector>

#include "core/json_io.h"
#include "core/vec.h"
#include "volume/vdb_brick_io.h"

namespace raysift::mpi {

struct Brick {
  /// Half-open ownership box [own_lo, own_hi) in index space: the split planes, ±infinity on the outside, so
  /// the bricks tile all of space and every sample position belongs to exactly one (volume::SegmentClip).
  Vec3d own_lo, own_hi;
  /// Inclusive voxel box to read: the brick's voxels plus `ghost` layers, within the active bbox.
  Vec3i read_lo, read_hi;
  std::uint64_t active_voxels = 0;  ///< leaf-level count inside the ownership box (ghosts not included)
  std::uint64_t read_voxels_bound = 0;  ///< active voxels of the leaves the read box touches (>= what is loaded)
};

/// A node of the k-d tree: an inner node cuts `axis` at `plane` (left = below); a leaf holds one brick.
struct KdNode {
  int axis = -1;  ///< -1 for a leaf
  double plane = 0;
  int left = -1, right = -1;
  int brick = -1;  ///< leaf only: index into KdSplit::bricks (= the rank that renders it)
};

struct KdSplit {
  std::vector<Brick> bricks;  ///< brick r is rank r's
  std::vector<KdNode> nodes;  ///< nodes[0] is the root
};

/// Ghost layers each brick reads beyond its voxels: trilinear reconstruction reads one voxel past a sample's
/// cell, Phong's central differences one more on each side.
constexpr int kGhostVoxels = 2;

/// Splits the active leaves into `n` >= 1 bricks: at each node the ranks are halved (n/2 left) and the plane,
/// on a leaf boundary across the longest axis of the node's leaves, balances the active counts in that ratio.
/// A node with fewer distinct leaf positions than ranks yields empty bricks (their ranks render nothing).
KdSplit kd_split(const volume::VdbLayout& layout, int n, int ghost = kGhostVoxels);

/// Brick indices front to back for an eye at `eye_is` (index space): at each node the half containing the eye
/// comes first. Exact for convex bricks of a k-d tree and any ray from that eye.
std::vector<int> visibility_order(const KdSplit& split, const Vec3d& eye_is);

Json kd_split_to_json(const KdSplit& split);
KdSplit kd_split_from_json(const Json& j);

}  // namespace raysift::mpi
