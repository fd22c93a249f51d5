#include "mesh/detail/quadric_collapse.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "mesh/mesh_analysis.h"

namespace raysift::mesh::detail {

namespace {

using Face = std::array<std::uint32_t, 3>;
constexpr std::uint32_t kNone = ~std::uint32_t(0);
/// A collapse may not leave a face below this quality (2 sqrt(3) |cross| / sum of squared edges, 1 =
/// equilateral) unless that face was already worse.
constexpr double kMinQuality = 0.01;

/// Symmetric 4x4 plane quadric, upper triangle (xx xy xz xw yy yz yw zz zw ww), plus the area it covers.
struct Quadric {
  double q[10] = {};
  double area = 0;

  void add_plane(const Vec3d& n, double d, double w) {
    const double c[4] = {n.x, n.y, n.z, d};
    int k = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = i; j < 4; ++j) q[k++] += w * c[i] * c[j];
    area += w;
  }
  Quadric operator+(const Quadric& o) const {
    Quadric s;
    for (int k = 0; k < 10; ++k) s.q[k] = q[k] + o.q[k];
    s.area = area + o.area;
    return s;
  }
  Vec3d mul3(const Vec3d& p) const {  // the 3x3 part times p
    return {q[0] * p.x + q[1] * p.y + q[2] * p.z, q[1] * p.x + q[4] * p.y + q[5] * p.z,
            q[2] * p.x + q[5] * p.y + q[7] * p.z};
  }
  Vec3d linear() const { return {q[3], q[6], q[8]}; }
  double error(const Vec3d& p) const { return std::max(0.0, dot(p, mul3(p)) + 2 * dot(p, linear()) + q[9]); }
};

/// The unconstrained minimiser of Q, if the 3x3 system is well conditioned and it lies within one edge length
/// of the edge's midpoint; else the minimiser on the segment a-b (rank-deficient: flat or cylindrical).
Vec3d optimal_position(const Quadric& Q, const Vec3d& a, const Vec3d& b) {
  const double* q = Q.q;
  const double c0 = q[4] * q[7] - q[5] * q[5], c1 = q[2] * q[5] - q[1] * q[7], c2 = q[1] * q[5] - q[2] * q[4];
  const double det = q[0] * c0 + q[1] * c1 + q[2] * c2, trace = q[0] + q[4] + q[7];
  const Vec3d e = b - a, mid = (a + b) * 0.5;
  if (std::abs(det) > 1e-7 * trace * trace * trace) {
    const Vec3d r = -Q.linear();
    // Cramer's rule through the adjugate of the symmetric 3x3 matrix.
    const Vec3d p = Vec3d(c0 * r.x + c1 * r.y + c2 * r.z,
                          c1 * r.x + (q[0] * q[7] - q[2] * q[2]) * r.y + (q[1] * q[2] - q[0] * q[5]) * r.z,
                          c2 * r.x + (q[1] * q[2] - q[0] * q[5]) * r.y + (q[0] * q[4] - q[1] * q[1]) * r.z) /
                    det;
    if (dot(p - mid, p - mid) <= dot(e, e)) return p;
  }
  const double eae = dot(e, Q.mul3(e));
  const double t = eae > 0 ? std::clamp(-(dot(e, Q.mul3(a)) + dot(e, Q.linear())) / eae, 0.0, 1.0) : 0.5;
  return a + e * t;
}

double quality(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& n) {
  const double sum = dot(b - a, b - a) + dot(c - b, c - b) + dot(a - c, a - c);
  return sum > 0 ? 2 * std::sqrt(3.0) * length(n) / sum : 0;
}

/// A heap entry (16 bytes: the heap is memory-bound): collapse `removed` into `kept`. key = the cost as float
/// bits (monotonic for costs >= 0) above the removed vertex's id: one integer comparison orders by cost, ties
/// by id. Valid while the sum of both vertices' versions is unchanged (versions only grow, so an unchanged sum
/// means both are unchanged).
struct Candidate {
  std::uint64_t key;
  std::uint32_t kept, versions;
  std::uint32_t removed() const { return std::uint32_t(key); }
};

/// Min-heap with 4 children per node: half the depth of a binary heap, siblings on adjacent cache lines (the
/// heap was the hot spot: most pops are stale entries).
class QuadHeap {
  static constexpr std::size_t kArity = 4;

 public:
  bool empty() const { return a_.empty(); }
  const Candidate& top() const { return a_[0]; }
  /// Appends without ordering; call heapify() before the next pop.
  void append(const Candidate& c) { a_.push_back(c); }
  void heapify() {
    for (std::size_t i = a_.size() / kArity + 1; i-- > 0;) sift_down(i);
  }
  void push(const Candidate& c) {
    std::size_t i = a_.size();
    a_.push_back(c);
    while (i > 0 && a_[(i - 1) / kArity].key > c.key) a_[i] = a_[(i - 1) / kArity], i = (i - 1) / kArity;
    a_[i] = c;
  }
  std::size_t size() const { return a_.size(); }
  /// Drops the entries `stale` says are stale and restores the heap order.
  template <typename Stale>
  void compact(Stale stale) {
    a_.erase(std::remove_if(a_.begin(), a_.end(), stale), a_.end());
    heapify();
  }
  Candidate pop() {
    const Candidate top = a_[0];
    a_[0] = a_.back();
    a_.pop_back();
    if (!a_.empty()) sift_down(0);
    return top;
  }

 private:
  void sift_down(std::size_t i) {
    const Candidate c = a_[i];
    const std::size_t n = a_.size();
    for (;;) {
      const std::size_t first = kArity * i + 1;
      if (first >= n) break;
      // The next level is a cache miss per step: fetch all four children's children while comparing.
      for (std::size_t j = first; j < std::min(first + kArity, n); ++j)
        if (kArity * j + 1 < n) __builtin_prefetch(&a_[kArity * j + 1]);
      std::size_t best = first;
      for (std::size_t j = first + 1; j < std::min(first + kArity, n); ++j)
        if (a_[j].key < a_[best].key) best = j;
      if (a_[best].key >= c.key) break;
      a_[i] = a_[best];
      i = best;
    }
    a_[i] = c;
  }

  std::vector<Candidate> a_;
};

std::uint64_t heap_key(double cost, std::uint32_t removed) {
  const float c = float(cost);
  std::uint32_t bits;
  std::memcpy(&bits, &c, sizeof bits);
  return std::uint64_t(bits) << 32 | removed;
}

/// vertex -> its live faces, in one flat pool (no per-vertex allocation in the collapse loop): each vertex owns
/// a slot of `cap` entries; a list that outgrows its slot moves to the end of the pool with twice the room
/// (the old slot is abandoned: the pool stays within a small multiple of 3F).
class Incidence {
 public:
  void init(const std::vector<Face>& faces, std::size_t vertices) {
    slots_.assign(vertices, Slot{});
    for (const Face& t : faces)
      for (const std::uint32_t v : t) ++slots_[v].cap;
    std::uint32_t offset = 0;
    for (Slot& s : slots_) s.begin = offset, s.cap += 2, offset += s.cap;  // slack for the first merges
    pool_.resize(offset);
    for (std::uint32_t f = 0; f < faces.size(); ++f)
      for (const std::uint32_t v : faces[f]) push(v, f);
  }
  const std::uint32_t* begin(std::uint32_t v) const { return pool_.data() + slots_[v].begin; }
  const std::uint32_t* end(std::uint32_t v) const { return begin(v) + slots_[v].size; }
  std::uint32_t size(std::uint32_t v) const { return slots_[v].size; }
  void push(std::uint32_t v, std::uint32_t f) {
    Slot& s = slots_[v];
    if (s.size == s.cap) {
      const std::uint32_t moved = std::uint32_t(pool_.size());
      pool_.resize(pool_.size() + 2 * s.cap);
      std::copy_n(pool_.data() + s.begin, s.size, pool_.data() + moved);
      s.begin = moved, s.cap *= 2;
    }
    pool_[s.begin + s.size++] = f;
  }
  /// Removes f from v's list (order not kept). \pre f is in it.
  void erase(std::uint32_t v, std::uint32_t f) {
    Slot& s = slots_[v];
    std::uint32_t* list = pool_.data() + s.begin;
    *std::find(list, list + s.size, f) = list[s.size - 1];
    --s.size;
  }
  void clear(std::uint32_t v) { slots_[v].size = 0; }

 private:
  struct Slot {
    std::uint32_t begin = 0, size = 0, cap = 0;
  };
  std::vector<Slot> slots_;
  std::vector<std::uint32_t> pool_;
};

/// A range-for view of one vertex's faces.
struct FaceRange {
  const std::uint32_t *b, *e;
  const std::uint32_t* begin() const { return b; }
  const std::uint32_t* end() const { return e; }
};

class Collapser {
 public:
  Collapser(const TriMesh& mesh, const CollapseOptions& options)
      : faces_(mesh.triangles), alive_faces_(faces_.size()), options_(options) {
    const std::size_t n = mesh.vertex_count();
    verts_.resize(n);
    version_.assign(n, 0);
    for (std::size_t v = 0; v < n; ++v) verts_[v].position = Vec3d(mesh.positions[v]);
    incident_.init(faces_, n);
    mark_.assign(n, 0);
    parked_.resize(n);
    const std::vector<VertexKind> kinds = classify_vertices(mesh);
    for (std::size_t v = 0; v < n; ++v)
      verts_[v].locked = kinds[v] == VertexKind::Boundary || kinds[v] == VertexKind::NonManifold;
    for (std::uint32_t f = 0; f < faces_.size(); ++f) {
      const Face& t = faces_[f];
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
        for (const std::uint32_t v : t) verts_[v].locked = true;
      const Vec3d a = verts_[t[0]].position, n2 = cross(verts_[t[1]].position - a, verts_[t[2]].position - a);
      const double len = length(n2);
      if (!(len > 0)) continue;
      const Vec3d normal = n2 / len;
      for (const std::uint32_t v : t) verts_[v].quadric.add_plane(normal, -dot(normal, a), 0.5 * len);
    }
    cos_limit_ = std::cos(options.max_normal_deviation_deg * M_PI / 180.0);
  }

  CollapseResult run() {
    CollapseResult result;
    fill_heap();
    // An empty heap means every edge left is refused in the current state (refused ones are parked until
    // their neighbourhood changes), so there is nothing more to try.
    std::size_t swept_size = 0;
    const auto stale = [&](const Candidate& c) { return version_[c.removed()] + version_[c.kept] != c.versions; };
    while (alive_faces_ > options_.target_faces && !heap_.empty()) {
      // Most entries go stale (every collapse re-pushes the kept vertex's edges): once the heap exceeds 1.6
      // entries per face (a closed mesh has 1.5 edges per face), drop them in one sweep instead of popping each.
      // Asking for F/2 entries added since the last sweep keeps a sweep's O(heap) cost per entry constant
      // even if few are stale.
      if (heap_.size() > alive_faces_ * 8 / 5 && heap_.size() >= swept_size + alive_faces_ / 2) {
        heap_.compact(stale);
        swept_size = heap_.size();
      }
      const Candidate c = heap_.pop();
      if (!heap_.empty()) prefetch_vertex(heap_.top().removed()), prefetch_vertex(heap_.top().kept);
      const std::uint32_t removed = c.removed();
      if (stale(c)) continue;
      const Vec3d p = placement(removed, c.kept, verts_[removed].quadric + verts_[c.kept].quadric);
      if (!can_collapse(removed, c.kept, p)) {
        park(removed, c.kept);
        park(c.kept, removed);
        continue;
      }
      collapse(removed, c.kept, p);
      ++result.collapses;
    }
    result.locked_vertices =
        std::size_t(std::count_if(verts_.begin(), verts_.end(), [](const Vertex& v) { return v.locked; }));
    result.mesh = compact();
    return result;
  }

 private:
  /// Every interior edge once (a -> b with a < b in some face; a consistently oriented manifold has it once).
  void fill_heap() {
    for (const Face& t : faces_) {
      if (t[0] == kNone) continue;
      for (int k = 0; k < 3; ++k)
        if (t[k] < t[(k + 1) % 3]) push_edge(t[k], t[(k + 1) % 3]);
    }
    heap_.heapify();
  }

  /// The kept end is the locked one (a locked vertex neither moves nor goes), else the lower id.
  void push_edge(std::uint32_t a, std::uint32_t b, bool heapify = false) {
    if (verts_[a].locked && verts_[b].locked) return;
    const std::uint32_t kept = verts_[a].locked || (!verts_[b].locked && a < b) ? a : b, removed = kept == a ? b : a;
    const Quadric q = verts_[a].quadric + verts_[b].quadric;
    const double cost = q.error(placement(removed, kept, q));
    const double limit = options_.max_rms_error;
    if (limit > 0 && cost > limit * limit * q.area) return;
    const Candidate c{heap_key(cost, removed), kept, version_[removed] + version_[kept]};
    if (heapify) heap_.push(c);
    else heap_.append(c);
  }

  /// `q` = the summed quadric of both ends.
  Vec3d placement(std::uint32_t removed, std::uint32_t kept, const Quadric& q) const {
    return verts_[kept].locked ? verts_[kept].position : optimal_position(q, verts_[removed].position, verts_[kept].position);
  }

  /// Starts loading v's record (both cache lines) ahead of its use.
  void prefetch_vertex(std::uint32_t v) const {
    __builtin_prefetch(&verts_[v]);
    __builtin_prefetch(reinterpret_cast<const char*>(&verts_[v]) + 64);
  }
  static bool has(const Face& t, std::uint32_t v) { return t[0] == v || t[1] == v || t[2] == v; }
  FaceRange faces_of(std::uint32_t v) const { return {incident_.begin(v), incident_.end(v)}; }

  /// Calls visit(w) once for each distinct neighbour w of v, in no particular order. Each pass takes a fresh mark,
  /// so no clearing is needed.
  template <typename Visit>
  void for_each_neighbour(std::uint32_t v, Visit visit) {
    const std::uint64_t seen = next_mark();
    for (const std::uint32_t f : faces_of(v))
      for (const std::uint32_t w : faces_[f])
        if (w != v && mark_[w] != seen) mark_[w] = seen, visit(w);
  }
  std::uint64_t next_mark() { return ++mark_counter_; }  // 64 bits: never wraps

  /// Sorted distinct neighbours of v.
  void neighbours(std::uint32_t v, std::vector<std::uint32_t>& out) {
    out.clear();
    for_each_neighbour(v, [&](std::uint32_t w) { out.push_back(w); });
    std::sort(out.begin(), out.end());
  }

  /// Link condition for the interior edge (u, v): its two faces' opposite vertices are the only common
  /// neighbours, and each keeps at least three faces if interior (else a tetrahedron would fold flat), one if
  /// locked (a border vertex may end in a single face).
  bool link_condition(std::uint32_t u, std::uint32_t v) {
    int shared = 0;
    for (const std::uint32_t f : faces_of(u))
      if (has(faces_[f], v)) {
        ++shared;
        for (const std::uint32_t w : faces_[f])
          if (w != u && w != v && incident_.size(w) <= (verts_[w].locked ? 1u : 3u)) return false;
      }
    if (shared != 2) return false;
    // Mark u's neighbours, then count v's distinct neighbours that carry the mark (a second mark dedupes).
    for_each_neighbour(u, [](std::uint32_t) {});
    const std::uint64_t of_u = mark_counter_;
    int common = 0;
    const std::uint64_t seen = next_mark();
    for (const std::uint32_t f : faces_of(v))
      for (const std::uint32_t w : faces_[f])
        if (w != v && mark_[w] == of_u) mark_[w] = seen, ++common;
    return common == 2;
  }

  /// No face that survives the move of `moved` to p turns by more than the limit or becomes a sliver.
  bool faces_stay_sound(std::uint32_t moved, std::uint32_t other, const Vec3d& p) const {
    for (const std::uint32_t f : faces_of(moved)) {
      const Face& t = faces_[f];
      if (has(t, other)) continue;
      Vec3d before[3], after[3];
      for (int k = 0; k < 3; ++k) before[k] = after[k] = verts_[t[k]].position, after[k] = t[k] == moved ? p : before[k];
      const Vec3d n0 = cross(before[1] - before[0], before[2] - before[0]);
      const Vec3d n1 = cross(after[1] - after[0], after[2] - after[0]);
      const double q1 = quality(after[0], after[1], after[2], n1);
      if (q1 < kMinQuality && q1 <= quality(before[0], before[1], before[2], n0)) return false;
      if (dot(n0, n1) < cos_limit_ * length(n0) * length(n1)) return false;
    }
    return true;
  }

  bool can_collapse(std::uint32_t u, std::uint32_t v, const Vec3d& p) {
    return link_condition(u, v) && faces_stay_sound(u, v, p) && (p == verts_[v].position || faces_stay_sound(v, u, p));
  }

  /// u goes, v moves to p: u's two faces with v die, u's other faces switch to v.
  void collapse(std::uint32_t u, std::uint32_t v, const Vec3d& p) {
    // By index: pushing to v's list may move the pool under u's.
    for (std::uint32_t i = 0; i < incident_.size(u); ++i) {
      const std::uint32_t f = incident_.begin(u)[i];
      Face& t = faces_[f];
      if (has(t, v)) {
        for (const std::uint32_t w : t)
          if (w != u) incident_.erase(w, f);
        t = {kNone, kNone, kNone};
        --alive_faces_;
      } else {
        for (std::uint32_t& w : t) w = w == u ? v : w;
        incident_.push(v, f);
      }
    }
    incident_.clear(u);
    parked_[u] = {};
    verts_[u].parked = false;
    verts_[v].position = p;
    verts_[v].quadric = verts_[v].quadric + verts_[u].quadric;
    ++version_[u];
    ++version_[v];
    neighbours(v, ring_v_);
    // Each push reads a neighbour's record, a likely cache miss: start all of them at once.
    for (const std::uint32_t w : ring_v_) prefetch_vertex(w);
    for (const std::uint32_t w : ring_v_) push_edge(v, w, true);
    // The faces around v and its neighbours changed: their refused collapses get another chance.
    parked_[v].clear();
    verts_[v].parked = false;
    for (const std::uint32_t w : ring_v_) unpark(w);
  }

  void park(std::uint32_t w, std::uint32_t x) {
    verts_[w].parked = true;
    std::vector<std::uint32_t>& list = parked_[w];
    if (std::find(list.begin(), list.end(), x) == list.end()) list.push_back(x);
  }

  void unpark(std::uint32_t w) {
    if (!verts_[w].parked) return;  // the common case, answered from the record the pushes just loaded
    verts_[w].parked = false;
    for (const std::uint32_t x : parked_[w])
      if (std::any_of(incident_.begin(w), incident_.end(w), [&](std::uint32_t f) { return has(faces_[f], x); }))
        push_edge(w, x, true);
    parked_[w].clear();
  }

  TriMesh compact() const {
    TriMesh out;
    std::vector<std::uint32_t> index(verts_.size(), kNone);
    for (const Face& t : faces_) {
      if (t[0] == kNone) continue;
      Face o;
      for (int k = 0; k < 3; ++k) {
        if (index[t[k]] == kNone) {
          index[t[k]] = std::uint32_t(out.positions.size());
          out.positions.push_back(Vec3f(verts_[t[k]].position));
        }
        o[k] = index[t[k]];
      }
      out.triangles.push_back(o);
    }
    return out;
  }

  /// What an edge cost reads about a vertex, in two cache lines (these reads are the main cache misses after
  /// the heap's).
  struct alignas(64) Vertex {
    Quadric quadric;
    Vec3d position;
    bool locked = false;
    bool parked = false;  ///< parked_ of this vertex is not empty
  };
  std::vector<Vertex> verts_;
  /// Bumped when a vertex moves or goes: older heap entries are stale. Apart from verts_: every pop and every
  /// heap sweep reads it, and a compact array stays in cache.
  std::vector<std::uint32_t> version_;
  std::vector<Face> faces_;  ///< {kNone, kNone, kNone} once collapsed away
  Incidence incident_;  ///< vertex -> its live faces
  std::vector<std::uint64_t> mark_;  ///< per-vertex scratch marks (for_each_neighbour)
  std::uint64_t mark_counter_ = 0;
  std::vector<std::vector<std::uint32_t>> parked_;  ///< vertex -> other ends of its refused collapses
  QuadHeap heap_;
  std::vector<std::uint32_t> ring_v_;  ///< scratch
  std::size_t alive_faces_;
  CollapseOptions options_;
  double cos_limit_ = 0;
};

}  // namespace

CollapseResult quadric_collapse(const TriMesh& mesh, const CollapseOptions& options) {
  return Collapser(mesh, options).run();
}

}  // namespace raysift::mesh::detail
