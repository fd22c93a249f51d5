#pragma once
/// \file Sort-last compositing over MPI: binary swap (Ma et al. 1994) on the ranks' premultiplied RGBA images,
/// in a given front-to-back order, then a gather of the pieces to rank 0.
#include <cstddef>
#include <vector>

namespace raysift::mpi {

/// Premultiplied "over": front + (1 − front.a)·back, per channel; `front` and `back` hold `pixels` RGBA quads.
void composite_over(float* front, const float* back, std::size_t pixels);

/// Collective. `rgba` = this rank's premultiplied image (4 floats per pixel, every rank the same size);
/// `order` = all ranks, front to back. Returns on rank 0 the composite of all images in that order, elsewhere
/// an empty vector. N not a power of two: with P the largest power of two <= N, the first 2(N − P) ranks of
/// the order fold pairwise (the back one sends its whole image to the front one), then P ranks binary-swap:
/// log2 P rounds, each exchanging half of the current piece with the partner; finally rank 0 gathers the P
/// pieces. Per rank that is about (1 − 1/P) + 1/P image sizes sent, plus one image for a folding rank.
std::vector<float> composite_sort_last(std::vector<float> rgba, const std::vector<int>& order);

}  // namespace raysift::mpi
