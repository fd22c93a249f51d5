#include "sampling/refinement.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "core/errors.h"
#include "core/parallel.h"
#include "core/timer.h"
#include "sampling/ray_order.h"
#include "sampling/reconstruction.h"

namespace raysift::sampling {
namespace {

// Below this a round's parallel trace does not amortise its start-up; above it the priorities react late.
constexpr std::size_t kMinRound = 256;

// Priorities are kept in log-spaced buckets (kBucketsPerOctave per factor 2) instead of a heap: O(1) per
// candidate, and first-in first-out inside a bucket, which is deterministic because candidates are offered
// serially in a fixed order.
constexpr int kBucketsPerOctave = 16, kBuckets = 24 * kBucketsPerOctave;

int bucket_of(float priority) {
  const int b = int(std::floor(-std::log2(std::max(priority, 1e-30f)) * float(kBucketsPerOctave)));
  return std::min(kBuckets - 1, std::max(0, b + 2 * kBucketsPerOctave));  // priorities up to 4 get bucket >= 0
}

// Ascending order of `keys`: LSD radix sort, 11 bits a pass over the bits in use, for the large rounds (the
// same order std::sort gives: it is a sort of plain integers).
void sort_keys(std::vector<std::uint64_t>& keys) {
  if (keys.size() < 1024) {
    std::sort(keys.begin(), keys.end());
    return;
  }
  std::uint64_t used = 0;
  for (std::uint64_t k : keys) used |= k;
  std::vector<std::uint64_t> tmp(keys.size());
  for (int shift = 0; shift < 64 && (used >> shift) != 0; shift += 11) {
    std::array<std::size_t, 2049> start{};
    for (std::uint64_t k : keys) ++start[((k >> shift) & 2047u) + 1];
    for (std::size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
    for (std::uint64_t k : keys) tmp[start[(k >> shift) & 2047u]++] = k;
    keys.swap(tmp);
  }
}

// Sorts [first, last) by key(pixel), each key computed once (the keys hash, so a comparator would rehash).
template <typename It, typename Key>
void sort_by_key(It first, It last, const Key& key) {
  std::vector<std::uint64_t> keyed;
  keyed.reserve(std::size_t(last - first));
  for (It it = first; it != last; ++it) keyed.push_back(key(*it));
  sort_keys(keyed);
  for (std::uint64_t k : keyed) *first++ = std::uint32_t(k & 0xFFFFFFFFu);
}

class BucketQueue {
 public:
  explicit BucketQueue(std::uint64_t seed) : buckets_(kBuckets), seed_(seed) {}
  void push(int b, std::uint32_t pixel) {  ///< b = bucket_of(priority)
    buckets_[b].push_back(pixel);
    top_ = std::min(top_, b);
    ++size_;
  }
  // Up to `count` pixels, highest buckets first. A bucket's waiting pixels are served in hashed order,
  // not in the (scan) order they were offered in, so a bucket cut short is spread over the frame.
  std::vector<std::uint32_t> pop(std::size_t count) {
    std::vector<std::uint32_t> out;
    out.reserve(std::min(count, size_));
    while (out.size() < count && size_ > 0) {
      std::vector<std::uint32_t>& bucket = buckets_[top_];
      std::size_t& next = next_[top_];
      if (next == bucket.size()) {
        ++top_;
        continue;
      }
      // Each entry is sorted once: those offered since the bucket was last served, among themselves.
      std::size_t& sorted = sorted_[top_];
      if (sorted < bucket.size()) {
        const std::size_t from = std::max(sorted, next);
        sort_by_key(bucket.begin() + std::ptrdiff_t(from), bucket.end(),
                    [this](std::uint32_t p) { return std::uint64_t(pixel_hash(p, seed_)) << 32 | p; });
        sorted = bucket.size();
      }
      const std::size_t take = std::min(count - out.size(), bucket.size() - next);
      out.insert(out.end(), bucket.begin() + std::ptrdiff_t(next), bucket.begin() + std::ptrdiff_t(next + take));
      next += take;
      size_ -= take;
    }
    return out;
  }
  std::size_t size() const { return size_; }

 private:
  std::vector<std::vector<std::uint32_t>> buckets_;
  std::array<std::size_t, kBuckets> next_{}, sorted_{};
  std::uint64_t seed_;
  int top_ = kBuckets - 1;
  std::size_t size_ = 0;
};

// Offsets from a pixel of `level` >= 1 to its parents, and (negated) from a parent to its children there; opposite
// parents are adjacent (0-1, 2-3), as affine_residual() pairs them.
std::array<std::array<int, 2>, 4> parent_offsets(int level, int spacing) {
  const int d = parent_offset(level, spacing);
  if (level % 2 == 1) return {{{-d, -d}, {d, d}, {d, -d}, {-d, d}}};
  return {{{-d, 0}, {d, 0}, {0, -d}, {0, d}}};
}

// What an offer reads of a traced parent: its record()ed values in 1/255 steps (read only for traced pixels:
// state_ says which). In an image of their own: a child's parents are close to each other, so in 4-byte pixels
// they often share a cache line, which 16-byte records with the offers (as before) never did.
using Percept = std::array<std::uint8_t, 4>;

// A pixel's values as the contrast sees them: RGB through a square root (close to sRGB), alpha, quantised to
// 1/255 (finer than any floor worth setting). A background pixel's image value is 0, so its percept is 0.
Percept percept_of(const Rgba& c) {
  // std::lround of x in [0, 255] without the libm call (a third of a ranked level's set-up): the fraction x - floor(x)
  // is exact in float, so comparing it with 0.5 rounds half away from zero exactly as lround does.
  auto code = [](float v) {
    const float x = 255.0f * std::min(1.0f, std::max(0.0f, v));
    const int whole = int(x);
    return std::uint8_t(whole + (x - float(whole) >= 0.5f ? 1 : 0));
  };
  return {code(std::sqrt(std::max(0.0f, c.r))), code(std::sqrt(std::max(0.0f, c.g))), code(std::sqrt(std::max(0.0f, c.b))),
          code(c.a)};
}

// The contrast of a cell's corners: the largest per-channel spread of their percepts, alpha weighted by
// RefinementOptions::alpha_weight, in [0, 1]. Integer steps until the end; no corner leaves hi < lo, contrast 0.
class CornerSpread {
 public:
  void add(const Percept& c) {
    for (int k = 0; k < 4; ++k) {
      lo_[k] = std::min(lo_[k], int(c[k]));
      hi_[k] = std::max(hi_[k], int(c[k]));
    }
  }
  float contrast(float alpha_weight) const {
    int spread = 0;
    for (int k = 0; k < 3; ++k) spread = std::max(spread, hi_[k] - lo_[k]);
    return std::max(float(spread), alpha_weight * float(hi_[3] - lo_[3])) * (1.0f / 255.0f);
  }

 private:
  std::array<int, 4> lo_{255, 255, 255, 255}, hi_{0, 0, 0, 0};
};

// How far a cell's four parents (opposite ones adjacent, as parent_offsets() lists them) are from an affine image,
// which every interpolation rule reproduces exactly: half the largest per-channel difference of the two pairs'
// sums, alpha weighted as in CornerSpread, in [0, 1]. A smooth shading gradient has a large contrast but no
// residual. A straight edge parallel to a pair's axis is affine on the four parents; the next level's cells, whose
// parents lie on both sides of it, see it.
float affine_residual(const std::array<Percept, 4>& parents, float alpha_weight) {
  const Percept &a = parents[0], &b = parents[1], &c = parents[2], &d = parents[3];
  int colour = 0;
  for (int k = 0; k < 3; ++k) colour = std::max(colour, std::abs(int(a[k]) + int(b[k]) - int(c[k]) - int(d[k])));
  const int alpha = std::abs(int(a[3]) + int(b[3]) - int(c[3]) - int(d[3]));
  return std::max(float(colour), alpha_weight * float(alpha)) * (0.5f / 255.0f);
}

// What an offer reads and writes of the child. The offers outlive the frame (frame_buffer, next_epoch): `priority`
// counts only when the epoch is the frame's, so a new frame bumps the epoch instead of clearing 10 MB.
struct Offer {
  std::uint32_t epoch = 0;  ///< frame that last wrote `priority`
  float priority = 0;       ///< highest priority offered so far in frame `epoch`
};

// This thread's w x h image of P, contents unspecified: the refinement's 17 MB of state (at 1440x900) is
// reused from frame to frame, as a fresh allocation costs a page fault every 4 KB.
template <typename P>
Image<P>& frame_buffer(int w, int h) {
  thread_local Image<P> buffer;
  if (buffer.width != w || buffer.height != h) buffer = Image<P>(w, h);
  return buffer;
}

// This thread's offers and the epoch of a new frame over them.
std::uint32_t next_epoch(Image<Offer>& offers) {
  thread_local const Offer* owner = nullptr;
  thread_local std::uint32_t epoch = 0;
  if (owner != offers.pixels.data() || ++epoch == 0) {  // new buffer, or the counter wrapped: clear once
    std::fill(offers.pixels.begin(), offers.pixels.end(), Offer{});
    owner = offers.pixels.data();
    epoch = 1;
  }
  return epoch;
}

// A candidate whose corners are known, with its known parents.
struct Ready {
  std::uint32_t pixel;
  int level;
  int known;  ///< parents[0, known)
  unsigned background;  ///< bit i: parents[i] is background
  std::array<std::uint32_t, 4> parents;
};

// A candidate pixel and the priority its parents give it now.
struct Candidate {
  std::uint32_t pixel;
  float priority;
  int bucket;  ///< bucket_of(priority), computed in the parallel part
};

// Runs chunk(first, last, out) over [0, n) in fixed chunks in parallel and concatenates the outputs in chunk
// order, so the result does not depend on the thread count.
template <typename Chunk>
std::vector<Candidate> gather(std::size_t n, std::size_t chunk_size, const Chunk& chunk) {
  std::vector<std::vector<Candidate>> parts((n + chunk_size - 1) / chunk_size);
  parallel_chunks(n, chunk_size, [&](std::size_t c, std::size_t first, std::size_t last) { chunk(first, last, parts[c]); });
  std::vector<Candidate> out;
  for (const std::vector<Candidate>& part : parts) out.insert(out.end(), part.begin(), part.end());
  return out;
}

// Offers are evaluated in parallel and fed to the queue serially. This is exact: between two rounds no offer
// changes what another offer reads (the traced set and the samples are fixed), so a candidate offered twice in a
// round gets the same priority twice, and the queue sorts what a bucket received between two serves by hash.
class Refiner {
 public:
  Refiner(const ImageF& importance, const FractalPattern& pattern, const RefinementOptions& options,
          std::uint64_t seed, ImageRGBA& image, ImageMask& traced)
      : imp_(importance), pattern_(pattern), options_(options), image_(image), traced_(traced),
        percepts_(frame_buffer<Percept>(importance.width, importance.height)),
        offers_(frame_buffer<Offer>(importance.width, importance.height)), epoch_(next_epoch(offers_)),
        state_(frame_buffer<std::uint8_t>(importance.width, importance.height)), queue_(seed) {
    // One pass over the S x S blocks, block by block: the state mask and which blocks hold background or object
    // pixels. Per pixel, only compares and byte stores (a block index per pixel cost a division each).
    const int s = pattern_.base_spacing, w = imp_.width, h = imp_.height, bw = (w + s - 1) / s, bh = (h + s - 1) / s;
    Image<std::uint8_t> has_background(bw, bh, 0), has_object(bw, bh, 0);
    parallel_rows(bh, [&](int by) {
      for (int bx = 0; bx < bw; ++bx) {
        std::uint8_t background = 0, object = 0;
        for (int y = by * s; y < std::min(h, (by + 1) * s); ++y) {
          // Raw pointers: through the byte stores the compiler would reload every captured reference per pixel.
          const float* imp = &imp_.pixels[std::size_t(y) * std::size_t(w)];
          const std::uint8_t* traced = &traced_.pixels[std::size_t(y) * std::size_t(w)];
          std::uint8_t* state = &state_.pixels[std::size_t(y) * std::size_t(w)];
          const int x1 = std::min(w, (bx + 1) * s);
          for (int x = bx * s; x < x1; ++x) {
            const std::uint8_t is_background = imp[x] < 0 ? 1 : 0;
            state[x] = is_background ? kKnown | kBackground : traced[x] ? kKnown : 0;
            background |= is_background;
            object |= is_background ^ 1;
          }
        }
        has_background(bx, by) = background;
        has_object(bx, by) = object;
      }
    });
    mark_open_blocks(has_background);
    // Orphans are object pixels: open blocks of pure background (most of them, around a compact object) hold none.
    orphan_blocks_ = open_;
    for (std::size_t b = 0; b < orphan_blocks_.size(); ++b) orphan_blocks_.pixels[b] &= has_object.pixels[b];
    for (int l = 0; l < int(level_share_.size()); ++l) level_share_[l] = std::ldexp(1.0f, -l);
  }

  // Candidates no traced parent will offer: every in-image parent is background.
  // Their parents lie within S/2, so only open blocks (see mark_open_blocks) with object pixels can hold them.
  void offer_orphans() {
    const int s = pattern_.base_spacing;
    push(gather(std::size_t(orphan_blocks_.height), 2, [this, s](std::size_t by0, std::size_t by1,
                                                                 std::vector<Candidate>& out) {
      std::vector<Ready> ready;
      for (int by = int(by0); by < int(by1); ++by)
        for (int bx = 0; bx < orphan_blocks_.width; ++bx) {
          if (!orphan_blocks_(bx, by)) continue;
          for (int y = by * s; y < std::min(imp_.height, (by + 1) * s); ++y)
            for (int x = bx * s; x < std::min(imp_.width, (bx + 1) * s); ++x) {
              const int level = pattern_.level(x, y);
              if (level == 0 || imp_(x, y) < 0) continue;
              bool orphan = true;
              for (const auto& o : parent_offsets(level, s)) {
                const int px = x + o[0], py = y + o[1];
                orphan = orphan && (px < 0 || py < 0 || px >= imp_.width || py >= imp_.height || imp_(px, py) < 0);
              }
              if (orphan) list_ready(x, y, level, ready, kNoSource);
            }
        }
      for (const Ready& r : ready) evaluate(r, out);
    }));
  }

  // `pixels` were traced: marks and record()s them, then (with `offer`) offers the children they may have
  // completed. The last round skips the offers: nothing would pop them.
  void add_traced(const std::vector<std::uint32_t>& pixels, bool offer = true) {
    parallel_for_each(pixels.size(), [&](std::size_t i) {
      traced_.pixels[pixels[i]] = 1;
      state_.pixels[pixels[i]] |= offer ? kKnown | kFresh : kKnown;
      if (offer) record(pixels[i]);
    }, true, std::size_t(1024));
    if (!offer) return;
    std::vector<Candidate> candidates =
        gather(pixels.size(), 1024, [&](std::size_t first, std::size_t last, std::vector<Candidate>& out) {
          evaluate_all(last - first, [&](std::size_t i, std::vector<Ready>& ready) { children(pixels[first + i], ready); },
                       out);
        });
    parallel_for_each(pixels.size(), [&](std::size_t i) { state_.pixels[pixels[i]] &= std::uint8_t(~kFresh); }, true,
                      std::size_t(1024));
    push(candidates);
  }

  // The best `count` waiting candidates; stale entries (a pixel re-offered at a higher priority, or taken) skipped.
  std::vector<std::uint32_t> pop(std::size_t count) {
    std::vector<std::uint32_t> batch;
    while (batch.size() < count && queue_.size() > 0)
      for (std::uint32_t p : queue_.pop(count - batch.size()))
        if (!(state_.pixels[p] & kTaken)) {
          state_.pixels[p] |= kTaken;
          batch.push_back(p);
        }
    return batch;
  }

  std::size_t waiting() const { return queue_.size(); }

  // 1 on background and traced pixels.
  void known_mask(ImageMask& out) const {
    out = ImageMask(imp_.width, imp_.height, 0);
    parallel_rows(imp_.height, [&](int y) {
      std::uint8_t* known = &out.pixels[std::size_t(y) * std::size_t(imp_.width)];
      const std::uint8_t* state = &state_.pixels[std::size_t(y) * std::size_t(imp_.width)];
      for (int x = 0; x < out.width; ++x) known[x] = state[x] & kKnown;
    });
  }

 private:
  void record(std::uint32_t pixel) { percepts_.pixels[pixel] = percept_of(image_.pixels[pixel]); }

  // open_(bx, by) = 1 where the S x S blocks around block (bx, by) hold background (`has`) or reach past the
  // image: the only places where a corner can be known without being traced.
  void mark_open_blocks(const Image<std::uint8_t>& has) {
    const int bw = has.width, bh = has.height;
    open_ = Image<std::uint8_t>(bw, bh, 0);
    for (int by = 0; by < bh; ++by)
      for (int bx = 0; bx < bw; ++bx) {
        bool open = false;
        for (int j = by - 1; j <= by + 1; ++j)
          for (int i = bx - 1; i <= bx + 1; ++i) open = open || i < 0 || j < 0 || i >= bw || j >= bh || has(i, j);
        open_(bx, by) = open ? 1 : 0;
      }
  }

  // After `pixel` was traced: the children it may have completed, at every finer level. A child three or more
  // levels finer has corners finer than `pixel`, which were traced after it (a pixel is only a candidate once its
  // corners are known), unless a corner is background or outside the image: only open blocks ask beyond lq + 2.
  void children(std::uint32_t pixel, std::vector<Ready>& ready) const {
    const int w = imp_.width, qx = int(pixel % std::uint32_t(w)), qy = int(pixel / std::uint32_t(w));
    const int lq = fractal_level(qx, qy, pattern_.base_spacing);
    const bool open = open_(qx >> block_shift_, qy >> block_shift_) != 0;
    const int end = open ? pattern_.num_levels : std::min(pattern_.num_levels, lq + 3);
    for (int level = lq + 1; level < end; ++level)
      for (const auto& o : parent_offsets(level, pattern_.base_spacing)) {
        const int x = qx - o[0], y = qy - o[1];
        if (x >= 0 && y >= 0 && x < w && y < imp_.height && fractal_level(x, y, pattern_.base_spacing) == level)
          list_ready(x, y, level, ready, pixel);
      }
  }

  // Whether traced pixel (px, py) lists its children of `level` (see children()).
  bool lists(int px, int py, int level) const {
    return open_(px >> block_shift_, py >> block_shift_) != 0 ||
           level < fractal_level(px, py, pattern_.base_spacing) + 3;
  }

  // Appends (x, y) of `level` to `ready` unless it is known, taken or waits for a corner, decided on the small
  // state_ mask alone (most children asked about wait for a corner), and prefetches the percepts and the offer its
  // priority reads: these are scattered, and a chunk's priorities are computed after all its children are listed.
  // `source` is the traced parent asking (kNoSource: none). A child whose several parents were traced in one round
  // is listed once, by the lowest-index one: the duplicates would get the same priority and push() would drop them.
  // The record is written in place: built on the stack, its narrow stores were reloaded as one wide copy into
  // the vector, a store-forwarding stall per child (perf: a fifth of the offers' time).
  void list_ready(int x, int y, int level, std::vector<Ready>& ready, std::uint32_t source) const {
    if (state_(x, y) != 0) return;
    const int lattice_mask = 2 * parent_offset(level, pattern_.base_spacing) - 1;
    Ready& r = ready.emplace_back();
    r.pixel = std::uint32_t(y) * std::uint32_t(imp_.width) + std::uint32_t(x);
    r.level = level;
    r.known = 0;
    r.background = 0;
    for (const auto& o : parent_offsets(level, pattern_.base_spacing)) {
      const int px = x + o[0], py = y + o[1];
      if (px < 0 || py < 0 || px >= imp_.width || py >= imp_.height) continue;
      const std::uint32_t parent = std::uint32_t(py) * std::uint32_t(imp_.width) + std::uint32_t(px);
      const std::uint8_t parent_state = state_.pixels[parent];
      if (parent < source && (parent_state & kFresh) && lists(px, py, level)) {
        ready.pop_back();  // that parent lists it
        return;
      }
      // Required: the corners of the square cell being split (for an edge midpoint, the edge's two ends).
      // The squares' centres beside an edge midpoint only add contrast: requiring them would let a flat
      // neighbour cell block the refinement of an edge cell.
      if (!(parent_state & kKnown)) {
        if ((px & lattice_mask) == 0 && (py & lattice_mask) == 0) {
          ready.pop_back();  // offered again when it is traced
          return;
        }
        continue;
      }
      r.background |= parent_state & kBackground ? 1u << r.known : 0u;
      r.parents[std::size_t(r.known++)] = parent;
    }
    for (int i = 0; i < r.known; ++i) __builtin_prefetch(&percepts_.pixels[r.parents[std::size_t(i)]]);
    __builtin_prefetch(&offers_.pixels[r.pixel]);
    __builtin_prefetch(&imp_.pixels[r.pixel]);
  }

  // Appends `r` with its priority unless it would not be pushed.
  void evaluate(const Ready& r, std::vector<Candidate>& out) const {
    CornerSpread spread;
    for (int i = 0; i < r.known; ++i) spread.add((r.background >> i) & 1 ? Percept{} : percepts_.pixels[r.parents[i]]);
    const float contrast = spread.contrast(options_.alpha_weight);
    const float priority =
        (contrast + options_.floor + options_.line_weight * imp_.pixels[r.pixel]) * level_share_[r.level];
    if (priority <= 1.05f * offered(offers_.pixels[r.pixel])) return;  // see push()
    out.push_back({r.pixel, priority, bucket_of(priority)});
  }

  // Lists the candidates of `count` sources with list(source, ready), then evaluates them, a few sources at a
  // time so what was prefetched is still cached.
  template <typename List>
  void evaluate_all(std::size_t count, const List& list, std::vector<Candidate>& out) const {
    std::vector<Ready> ready;
    for (std::size_t first = 0; first < count; first += 64) {
      ready.clear();
      for (std::size_t i = first; i < std::min(count, first + 64); ++i) list(i, ready);
      for (const Ready& r : ready) evaluate(r, out);
    }
  }

  void push(const std::vector<Candidate>& candidates) {
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      const Candidate& c = candidates[i];
      if (i + 16 < candidates.size()) __builtin_prefetch(&offers_.pixels[candidates[i + 16].pixel]);
      // Offered again when another parent was traced: only a clearly higher priority is worth a second entry.
      Offer& offer = offers_.pixels[c.pixel];
      if (c.priority <= 1.05f * offered(offer)) continue;
      queue_.push(c.bucket, c.pixel);
      offer.priority = c.priority;
      offer.epoch = epoch_;
    }
  }

  float offered(const Offer& offer) const { return offer.epoch == epoch_ ? offer.priority : 0.0f; }

  const ImageF& imp_;
  const FractalPattern& pattern_;
  const RefinementOptions& options_;
  ImageRGBA& image_;
  ImageMask& traced_;
  Image<Percept>& percepts_;
  Image<Offer>& offers_;
  std::uint32_t epoch_;
  static constexpr std::uint8_t kKnown = 1, kTaken = 2, kBackground = 4, kFresh = 8;
  static constexpr std::uint32_t kNoSource = 0xFFFFFFFFu;
  /// kKnown: background or traced (kBackground: background); kTaken: popped for tracing; kFresh: traced in the
  /// round whose offers are being listed
  ImageMask& state_;
  BucketQueue queue_;
  const int block_shift_ = __builtin_ctz(unsigned(pattern_.base_spacing));  ///< log2 S: x >> it is x's block column
  Image<std::uint8_t> open_;  ///< per S x S block, see mark_open_blocks()
  Image<std::uint8_t> orphan_blocks_;  ///< open blocks holding an object pixel: where offer_orphans() looks
  std::array<float, 16> level_share_;  ///< 2^-level, the share of the frame one ray of a level covers
};

// A round in 16x16 tiles, tile rows top to bottom: the caster traces each group of kRayGroup rays together,
// and a compact group shares volume blocks (scan order would stretch a group of sparse rays along a row).
void in_tile_order(std::vector<std::uint32_t>& batch, int width) {
  sort_by_key(batch.begin(), batch.end(), [width](std::uint32_t p) {
    const std::uint32_t x = p % std::uint32_t(width), y = p / std::uint32_t(width);
    return std::uint64_t((y / 16) * 4096u + x / 16) << 32 | p;
  });
}

// A budgeted batch in tiles of `tile` px (neighbouring rays share volume blocks), the tiles in a hashed order, so
// the prefix the deadline leaves is spread over the frame rather than its top rows.
void in_hashed_tile_order(std::vector<std::uint32_t>& batch, int width, std::uint64_t seed, std::uint32_t tile = 16) {
  sort_by_key(batch.begin(), batch.end(), [width, seed, tile](std::uint32_t p) {
    const std::uint32_t x = p % std::uint32_t(width), y = p / std::uint32_t(width);
    return std::uint64_t(pixel_hash((y / tile) * 4096u + x / tile, seed)) << 32 | p;
  });
}

// Rays to launch in the next round: an eighth of what is left, so late rounds see the early rounds' samples.
std::size_t round_size(std::size_t rays, std::size_t done) {
  const std::size_t left = rays - done;
  return std::min(left, std::max(kMinRound, left / 8));
}

// The object pixels of `level` >= 1, row-major. With h its parent distance they are, in units of h, the points
// with both coordinates odd (odd levels: square centres) or exactly one odd (even levels: diamond centres), so
// only those are visited (the finest levels have h = 1).
std::vector<std::uint32_t> level_pixels(const ImageF& importance, const FractalPattern& pattern, int level) {
  const int h = parent_offset(level, pattern.base_spacing);
  std::vector<std::uint32_t> out;
  for (int row = 0; row * h < importance.height; ++row) {
    const int y = row * h;
    // Odd levels: odd rows, odd columns. Even levels: odd rows, even columns; even rows, odd columns.
    if (level % 2 == 1 && row % 2 == 0) continue;
    const int first = level % 2 == 1 || row % 2 == 0 ? h : 0;
    for (int x = first; x < importance.width; x += 2 * h)
      if (importance(x, y) >= 0) out.push_back(std::uint32_t(y) * std::uint32_t(importance.width) + std::uint32_t(x));
  }
  return out;
}

// Uniform levels (RefinementOptions::uniform_share) go down to the 2-px lattice at most (level 4 for S = 8): finer
// levels would cost a pass over every pixel. Uniform coverage is what makes a regular grid strong on shaded
// texture, and a whole level is traced as one coherent batch without the refinement's per-ray bookkeeping.
constexpr int kFinestUniformLevel = 4;

int last_uniform_level(const FractalPattern& pattern) { return std::min(pattern.num_levels - 1, kFinestUniformLevel); }

// With a ray count: levels 1 .. k, k the largest whose rays with level 0's fit the share of the count.
std::vector<std::uint32_t> uniform_levels(const ImageF& importance, const FractalPattern& pattern, double share,
                                          std::size_t level0, std::size_t rays, int& whole) {
  std::vector<std::uint32_t> out;
  std::size_t count = level0;
  for (int level = 1; level <= last_uniform_level(pattern) && share > 0; ++level) {
    const std::vector<std::uint32_t> pixels = level_pixels(importance, pattern, level);
    count += pixels.size();
    if (double(count) > share * double(rays)) break;
    out.insert(out.end(), pixels.begin(), pixels.end());
    whole = level;
  }
  return out;
}

// Under a deadline: level by level, each traced whole if, at the rate of the level traced last, its rays with
// those traced so far fit the share of the rays the time left holds. Level 0's own rate is a poor guide (a
// sparse lattice on cold caches): it decided the 4-px lattice either way from run to run on the same view. Each
// level in 64x64 tiles in a hashed order, so that a cut leaves a prefix spread over the frame while a group of
// rays stays within a tile (in 16x16 tiles a group of level-1 rays spans 8 scattered tiles). \return the rays
// traced; `rays_per_ms` ends as the last level's rate, `whole` as the last level traced whole.
std::vector<std::uint32_t> trace_uniform_levels_until(const ImageF& importance, const FractalPattern& pattern,
                                                      double share, const RefinementStop& stop, std::uint64_t seed,
                                                      const TraceBatch& trace, ImageRGBA& image, std::size_t level0,
                                                      double& rays_per_ms, int& whole) {
  std::vector<std::uint32_t> out;
  const int w = importance.width;
  for (int level = 1; level <= last_uniform_level(pattern) && share > 0; ++level) {
    std::vector<std::uint32_t> pixels = level_pixels(importance, pattern, level);
    const double start = (*stop.now)();
    const double done = double(level0 + out.size());
    if (done + double(pixels.size()) > share * (done + (stop.deadline_ms - start) * rays_per_ms)) break;
    in_hashed_tile_order(pixels, w, seed, 64);
    const std::size_t traced = trace_until(pixels, trace, image, *stop.now, stop.deadline_ms);
    out.insert(out.end(), pixels.begin(), pixels.begin() + std::ptrdiff_t(traced));
    if (traced < pixels.size()) break;
    whole = level;
    rays_per_ms = double(traced) / std::max(1e-3, (*stop.now)() - start);
  }
  return out;
}

// Traces level 0 and the uniform levels, what the refinement starts from, and returns them. With a ray count they
// are one coherent batch. Under a deadline level 0 goes first (the frame's floor: `level0_overran` if it alone
// overran), then the uniform levels level by level; `rays_per_ms` is the rate of the last of them.
std::vector<std::uint32_t> trace_first(const ImageF& importance, const FractalPattern& pattern,
                                       const RefinementOptions& options, const RefinementStop& stop,
                                       std::uint64_t seed, const TraceBatch& trace, ImageRGBA& image,
                                       RefinementResult& result, double& rays_per_ms, int& whole) {
  const int w = importance.width, h = importance.height;
  std::vector<std::uint32_t> level0;
  for (int y = 0; y < h; y += pattern.base_spacing)
    for (int x = 0; x < w; x += pattern.base_spacing)
      if (importance(x, y) >= 0) level0.push_back(std::uint32_t(y) * std::uint32_t(w) + std::uint32_t(x));
  result.level0 = level0.size();
  if (!stop.now) {
    const std::vector<std::uint32_t> uniform =
        uniform_levels(importance, pattern, options.uniform_share, level0.size(), stop.rays, whole);
    level0.insert(level0.end(), uniform.begin(), uniform.end());
    in_tile_order(level0, w);
    trace_all(level0, trace, image);
    result.rays = level0.size();
    return level0;
  }
  in_tile_order(level0, w);
  const double level0_start = (*stop.now)();
  trace_all(level0, trace, image);
  const double now_ms = (*stop.now)();
  rays_per_ms = double(level0.size()) / std::max(1e-3, now_ms - level0_start);
  result.level0_overran = now_ms > stop.deadline_ms;
  if (!result.level0_overran) {
    const std::vector<std::uint32_t> uniform = trace_uniform_levels_until(
        importance, pattern, options.uniform_share, stop, seed, trace, image, level0.size(), rays_per_ms, whole);
    level0.insert(level0.end(), uniform.begin(), uniform.end());
  }
  result.rays = level0.size();
  return level0;
}


// Under a deadline, after the uniform levels: `pixels`, the object pixels of `level`, all of whose parents are
// traced (the levels before it were traced whole) or background, ranked once by the affine residual of those
// parents plus the line importance (the floor and level share of the refiner's priority are the same for all; the
// residual measured better than the refiner's contrast here, the contrast better in the rounds, docs/prioritized.md
// session 14), and traced in that order in slices of a quarter of what the time left holds, each in hashed tile
// order, until the deadline. No rounds and no offers: every priority is known before the first ray
// (docs/prioritized.md, "Budget mode without rounds"). \return the pixels traced; `rays_per_ms` ends as the rate of
// the last slice.
std::vector<std::uint32_t> trace_ranked_until(const std::vector<std::uint32_t>& pixels, int level,
                                              const ImageF& importance, const FractalPattern& pattern,
                                              const RefinementOptions& options, const RefinementStop& stop,
                                              std::uint64_t seed, const TraceBatch& trace, ImageRGBA& image,
                                              double& rays_per_ms) {
  const int w = importance.width, h = importance.height;
  const auto offsets = parent_offsets(level, pattern.base_spacing);
  // Key: the priority quantised to 2^-18 (descending), a hashed tie-break, the pixel.
  std::vector<std::uint64_t> keys(pixels.size());
  parallel_for_each(pixels.size(), [&](std::size_t i) {
    const std::uint32_t p = pixels[i];
    const int x = int(p % std::uint32_t(w)), y = int(p / std::uint32_t(w));
    // A background parent's image value, and percept, is 0. A cell cut by the image border has no affine test:
    // half the contrast of the parents inside stands in (the residual of a step at one corner).
    std::array<Percept, 4> parents{};
    CornerSpread spread;
    bool inside = true;
    for (std::size_t k = 0; k < 4; ++k) {
      const int px = x + offsets[k][0], py = y + offsets[k][1];
      if (px < 0 || py < 0 || px >= w || py >= h) {
        inside = false;
        continue;
      }
      parents[k] = percept_of(image(px, py));
      spread.add(parents[k]);
    }
    const float error =
        inside ? affine_residual(parents, options.alpha_weight) : 0.5f * spread.contrast(options.alpha_weight);
    const float priority = std::min(3.9f, error + options.line_weight * importance.pixels[p]);
    const auto rank = std::uint32_t(0xFFFFFu - std::uint32_t(priority * float(1 << 18)));
    keys[i] = std::uint64_t(rank << 12 | (pixel_hash(p, seed) & 0xFFFu)) << 32 | p;
  }, true, std::size_t(4096));
  sort_keys(keys);
  std::vector<std::uint32_t> traced;
  for (std::size_t done = 0; done < keys.size();) {
    const double ms = stop.deadline_ms - (*stop.now)();
    if (ms <= 0) break;
    const std::size_t slice = std::min(keys.size() - done, std::max(kMinRound, std::size_t(ms * rays_per_ms) / 4));
    std::vector<std::uint32_t> batch;
    for (std::size_t k = done; k < done + slice; ++k) batch.push_back(std::uint32_t(keys[k] & 0xFFFFFFFFu));
    in_hashed_tile_order(batch, w, seed);
    const double start = (*stop.now)();
    const std::size_t n = trace_until(batch, trace, image, *stop.now, stop.deadline_ms);
    traced.insert(traced.end(), batch.begin(), batch.begin() + std::ptrdiff_t(n));
    done += slice;
    if (n < slice) break;
    rays_per_ms = double(n) / std::max(1e-3, (*stop.now)() - start);
  }
  return traced;
}

}  // namespace

RefinementResult trace_refined(const ImageF& importance, const FractalPattern& pattern,
                               const RefinementOptions& options, const RefinementStop& stop, std::uint64_t seed,
                               const TraceBatch& trace, ImageRGBA& image, ImageMask& traced, ImageMask* known) {
  const int w = importance.width;
  RefinementResult result;
  double rays_per_ms = 0;  // under a deadline: the rate of the level traced last, on the stop's own clock
  int whole = 0;
  const std::vector<std::uint32_t> first =
      trace_first(importance, pattern, options, stop, seed, trace, image, result, rays_per_ms, whole);
  if (stop.now) {
    for (std::uint32_t p : first) traced.pixels[p] = 1;
    // Level by level while the time lasts: a level traced whole makes the next one's parents known.
    for (int level = whole + 1; level < pattern.num_levels && !result.level0_overran; ++level) {
      const std::vector<std::uint32_t> pixels = level_pixels(importance, pattern, level);
      const std::vector<std::uint32_t> more =
          trace_ranked_until(pixels, level, importance, pattern, options, stop, seed, trace, image, rays_per_ms);
      for (std::uint32_t p : more) traced.pixels[p] = 1;
      result.rays += more.size();
      if (more.size() < pixels.size()) break;
    }
    if (known) *known = background_known(importance, &traced);
    return result;
  }

  Refiner refiner(importance, pattern, options, seed, image, traced);
  refiner.add_traced(first);  // marks level 0 and the uniform levels traced before the orphans are looked for
  refiner.offer_orphans();
  while (refiner.waiting() > 0 && result.rays < stop.rays) {
    // At most a quarter of the waiting candidates per round, so every round is a choice among them and an
    // edge can be followed down several levels (one per round) before the rays are spent on breadth.
    std::vector<std::uint32_t> batch =
        refiner.pop(std::min(round_size(stop.rays, result.rays), std::max<std::size_t>(1, refiner.waiting() / 4)));
    if (batch.empty()) break;  // only stale entries were left
    in_tile_order(batch, w);
    trace_all(batch, trace, image);
    const bool last = result.rays + batch.size() >= stop.rays;
    refiner.add_traced(batch, !last);
    result.rays += batch.size();
  }
  if (known) refiner.known_mask(*known);
  return result;
}

}  // namespace raysift::sampling
