#include "mpi/composite.h"

#include <algorithm>
#include <utility>

#include "core/errors.h"
#include "mpi/session.h"

namespace raysift::mpi {

void composite_over(float* front, const float* back, std::size_t pixels) {
  for (std::size_t i = 0; i < pixels; ++i) {
    float* f = front + 4 * i;
    const float* b = back + 4 * i;
    const float t = 1.0f - f[3];
    for (int c = 0; c < 4; ++c) f[c] += t * b[c];
  }
}

namespace {

struct PixelRange {
  std::size_t begin, end;
};

/// The piece virtual rank `v` holds after `rounds` rounds of binary swap: halved each round, the lower
/// partner keeping the first half.
PixelRange piece(int v, int rounds, std::size_t pixels) {
  PixelRange r{0, pixels};
  for (int s = 0; s < rounds; ++s) {
    const std::size_t mid = r.begin + (r.end - r.begin) / 2;
    r = (v >> s & 1) ? PixelRange{mid, r.end} : PixelRange{r.begin, mid};
  }
  return r;
}

Span<float> floats(std::vector<float>& v, PixelRange r) { return {v.data() + 4 * r.begin, 4 * (r.end - r.begin)}; }
Span<const float> floats(const std::vector<float>& v, PixelRange r) {
  return {v.data() + 4 * r.begin, 4 * (r.end - r.begin)};
}

}  // namespace

std::vector<float> composite_sort_last(std::vector<float> rgba, const std::vector<int>& order) {
  const int n = size();
  RAYSIFT_CHECK_OP(int(order.size()), ==, n);
  if (n == 1) return rgba;
  const std::size_t pixels = rgba.size() / 4;
  const int pos = int(std::find(order.begin(), order.end(), rank()) - order.begin());
  int p = 1, rounds = 0;
  while (2 * p <= n) p *= 2, ++rounds;
  const int extra = n - p;
  // Fold: of the first 2·extra ranks in the order, each back one hands its image to the one in front of it.
  std::vector<float> other(rgba.size());
  if (pos < 2 * extra && pos % 2 == 1) {
    send(order[std::size_t(pos - 1)], rgba);
  } else if (pos < 2 * extra) {
    receive(order[std::size_t(pos + 1)], other);
    composite_over(rgba.data(), other.data(), pixels);
  }
  auto real_rank = [&](int v) { return order[std::size_t(v < extra ? 2 * v : v + extra)]; };
  const bool swaps = !(pos < 2 * extra && pos % 2 == 1);
  const int v = pos < 2 * extra ? pos / 2 : pos - extra;  // place among the P swapping ranks, front to back
  for (int s = 0; swaps && s < rounds; ++s) {
    const PixelRange now = piece(v, s, pixels);
    const std::size_t mid = now.begin + (now.end - now.begin) / 2;
    const bool lower = (v >> s & 1) == 0;  // the lower partner is in front and keeps the first half
    const PixelRange keep = lower ? PixelRange{now.begin, mid} : PixelRange{mid, now.end};
    const PixelRange give = lower ? PixelRange{mid, now.end} : PixelRange{now.begin, mid};
    exchange(real_rank(v ^ (1 << s)), floats(std::as_const(rgba), give), floats(other, keep));
    float* mine = rgba.data() + 4 * keep.begin;
    float* theirs = other.data() + 4 * keep.begin;
    if (lower) {
      composite_over(mine, theirs, keep.end - keep.begin);
    } else {  // theirs is in front: theirs over mine, kept in mine
      composite_over(theirs, mine, keep.end - keep.begin);
      std::copy(theirs, theirs + 4 * (keep.end - keep.begin), mine);
    }
  }
  // Gather the P final pieces on rank 0.
  if (rank() != 0) {
    if (swaps) send(0, floats(std::as_const(rgba), piece(v, rounds, pixels)));
    return {};
  }
  std::vector<float> image(rgba.size());
  for (int u = 0; u < p; ++u) {
    const PixelRange r = piece(u, rounds, pixels);
    if (real_rank(u) == 0) std::copy_n(rgba.data() + 4 * r.begin, 4 * (r.end - r.begin), image.data() + 4 * r.begin);
    else receive(real_rank(u), floats(image, r));
  }
  return image;
}

}  // namespace raysift::mpi
