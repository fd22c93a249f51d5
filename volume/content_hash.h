#pragma once
/// \file Content hash of a Volume: what marching cubes and the samplers see, not how it is stored. Key
/// decision: hash the index->world transform, the background, every active voxel (leaf origin, active mask,
/// active values; inactive voxels read as the background, so their stored values are left out) and every
/// active tile, in tree order. Leaves are hashed in parallel and their digests combined in leaf order, so
/// the result does not depend on the thread count.
#include "core/hash.h"
#include "volume/volume.h"

namespace raysift::volume {

/// Equal grids (same transform, background, active voxels, values and active tiles) give equal digests.
/// A different leaf/tile split of the same values (a pruned vs an unpruned grid) may give a different
/// digest; for a cache key that only costs a miss. Values are hashed by their bits.
/// \param threaded hash leaves in parallel (false: the serial path, same result).
Hash128 content_hash(const Volume& volume, bool threaded = true);

}  // namespace raysift::volume
