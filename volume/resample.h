#pragma once
/// \file A coarser level of a volume: box-filtered by a power-of-two factor, sparse like its source. Used
/// for feature geometry, which needs no finer cells than the importance buffer's pixels.
#include "volume/volume.h"

namespace raysift::volume {

/// Coarse voxel (I,J,K) holds the mean of the fine voxels [f·I, f·I + f)³ (inactive voxels count as the
/// background) and is active when any of them is. Its index->world map is the fine one composed with
/// p_fine = f·p_coarse + (f − 1)/2, so a coarse voxel sits at the centre of the block it averages and
/// world positions of surfaces stay where they were (up to the filter). factor 1 returns the volume itself.
/// Cost: one pass over the fine leaves, parallel; result identical for any thread count.
/// \throw InvalidInput unless factor is 1, 2, 4 or 8 (a block must lie inside one 8³ leaf).
Volume downsample(const Volume& volume, int factor);

}  // namespace raysift::volume
