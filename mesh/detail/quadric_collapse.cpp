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

/// Min-heap of vertices with 4 children per node, keyed by each vertex's cheapest collapse: key = the cost as
/// float bits (monotonic for costs >= 0) above the vertex id, so one integer comparison orders by cost, ties by
/// id, and the id is the key's low word. Indexed (a vertex's slot is known), so a key changes in place: no
/// stale entries (the former edge heap popped 3.1 M stale entries for 384 K collapses on engine iso 143).
class VertexHeap {
  static constexpr std::uint32_t kArity = 4;
  static constexpr std::uint32_t kAbsent = ~std::uint32_t(0);

 public:
  explicit VertexHeap(std::size_t vertices) : slot_(vertices, kAbsent) {}
  bool empty() const { return a_.empty(); }
  std::uint32_t top() const { return std::uint32_t(a_[0]); }
  std::uint64_t key(std::uint32_t v) const { return slot_[v] == kAbsent ? ~std::uint64_t(0) : a_[slot_[v]]; }
  /// Appends without ordering; call heapify() before the first top().
  void append(std::uint64_t key) {
    slot_[std::uint32_t(key)] = std::uint32_t(a_.size());
    a_.push_back(key);
  }
  void heapify() {
    for (std::size_t i = a_.size() / kArity + 1; i-- > 0;) sift_down(std::uint32_t(i));
  }
  /// Inserts the vertex of `key` or changes its key.
  void set(std::uint64_t key) {
    const std::uint32_t v = std::uint32_t(key);
    if (slot_[v] == kAbsent) {
      append(key);
      sift_up(slot_[v]);
      return;
    }
    const std::uint64_t old = a_[slot_[v]];
    a_[slot_[v]] = key;
    if (key < old) sift_up(slot_[v]);
    else sift_down(slot_[v]);
  }
  void erase(std::uint32_t v) {
    const std::uint32_t i = slot_[v];
    if (i == kAbsent) return;
    slot_[v] = kAbsent;
    const std::uint64_t last = a_.back();
    a_.pop_back();
    if (i == a_.size()) return;
    place(i, last);
    if (i > 0 && last < a_[(i - 1) / kArity]) sift_up(i);
    else sift_down(i);
  }

 private:
  void place(std::uint32_t i, std::uint64_t key) {
    a_[i] = key;
    slot_[std::uint32_t(key)] = i;
  }
  void sift_up(std::uint32_t i) {
    const std::uint64_t k = a_[i];
    while (i > 0 && a_[(i - 1) / kArity] > k) place(i, a_[(i - 1) / kArity]), i = (i - 1) / kArity;
    place(i, k);
  }
  void sift_down(std::uint32_t i) {
    const std::uint64_t k = a_[i];
    const std::size_t n = a_.size();
    for (;;) {
      const std::size_t first = std::size_t(kArity) * i + 1;
      if (first >= n) break;
      std::size_t best = first;
      for (std::size_t j = first + 1; j < std::min<std::size_t>(first + kArity, n); ++j)
        if (a_[j] < a_[best]) best = j;
      if (a_[best] >= k) break;
      place(i, a_[best]);
      i = std::uint32_t(best);
    }
    place(i, k);
  }

  std::vector<std::uint64_t> a_;
  std::vector<std::uint32_t> slot_;  ///< vertex -> its index in a_, kAbsent when it has no candidate
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
      : faces_(mesh.triangles), heap_(mesh.vertex_count()), alive_faces_(faces_.size()), options_(options) {
    const std::size_t n = mesh.vertex_count();
    verts_.resize(n);
    best_kept_.assign(n, kNone);
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
    while (alive_faces_ > options_.target_faces && !heap_.empty()) {
      const std::uint32_t removed = heap_.top(), kept = best_kept_[removed];
      const Vec3d p = placement(removed, kept, verts_[removed].quadric + verts_[kept].quadric);
      if (!can_collapse(removed, kept, p)) {
        park(removed, kept);
        park(kept, removed);
        refresh(removed);
        continue;
      }
      collapse(removed, kept, p);
      ++result.collapses;
    }
    result.locked_vertices =
        std::size_t(std::count_if(verts_.begin(), verts_.end(), [](const Vertex& v) { return v.locked; }));
    result.mesh = compact();
    return result;
  }

 private:
  static constexpr std::uint64_t kNoKey = ~std::uint64_t(0);

  /// Every vertex's cheapest collapse (each interior edge is evaluated once, at the end it would remove).
  void fill_heap() {
    for (std::uint32_t v = 0; v < verts_.size(); ++v) {
      neighbours(v, ring_w_);
      if (const std::uint64_t key = cheapest(v, ring_w_); key != kNoKey) heap_.append(key);
    }
    heap_.heapify();
  }

  /// The end a collapse of edge (a, b) removes: never a locked one (a locked vertex neither moves nor goes),
  /// else the higher id; kNone when both are locked.
  std::uint32_t removed_end(std::uint32_t a, std::uint32_t b) const {
    if (verts_[a].locked) return verts_[b].locked ? kNone : b;
    return verts_[b].locked || a > b ? a : b;
  }

  /// Heap key of collapsing `removed` into `kept`; kNoKey when the error bound refuses it.
  std::uint64_t edge_key(std::uint32_t removed, std::uint32_t kept) const {
    const Quadric q = verts_[removed].quadric + verts_[kept].quadric;
    const double cost = q.error(placement(removed, kept, q));
    const double limit = options_.max_rms_error;
    if (limit > 0 && cost > limit * limit * q.area) return kNoKey;
    return heap_key(cost, removed);
  }

  /// v's cheapest collapse that is not parked, over `ring` (its distinct neighbours) with v as the removed end
  /// (ties: the lower kept id); sets best_kept_[v].
  std::uint64_t cheapest(std::uint32_t v, const std::vector<std::uint32_t>& ring) {
    std::uint64_t best = kNoKey;
    if (verts_[v].locked) return best;
    for (const std::uint32_t k : ring) prefetch_vertex(k);  // mostly cold: start every load before the first use
    for (const std::uint32_t k : ring) {
      if (removed_end(v, k) != v || is_parked(v, k)) continue;
      const std::uint64_t key = edge_key(v, k);
      if (key < best || (key == best && key != kNoKey && k < best_kept_[v])) best = key, best_kept_[v] = k;
    }
    return best;
  }

  /// Re-derives v's heap entry from all its edges.
  void refresh(std::uint32_t v) {
    neighbours(v, ring_w_);
    set_key(v, cheapest(v, ring_w_));
  }
  void set_key(std::uint32_t v, std::uint64_t key) {
    if (key == kNoKey) heap_.erase(v);
    else heap_.set(key);
  }

  /// Edge (r, k), r the removed end, became cheaper or eligible while r's other edges kept their costs.
  void relax(std::uint32_t r, std::uint32_t k) {
    if (is_parked(r, k)) return;
    const std::uint64_t key = edge_key(r, k), current = heap_.key(r);
    if (key < current || (key == current && key != kNoKey && k < best_kept_[r])) {
      best_kept_[r] = k;
      heap_.set(key);
    }
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

  /// Distinct neighbours of v, in no particular order: the heap's keys are distinct (they hold the vertex id), so
  /// its top, and with it the result, does not depend on the order of the key updates.
  void neighbours(std::uint32_t v, std::vector<std::uint32_t>& out) {
    out.clear();
    for_each_neighbour(v, [&](std::uint32_t w) { out.push_back(w); });
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
    parked_[u].clear();
    verts_[u].parked = false;
    verts_[v].position = p;
    verts_[v].quadric = verts_[v].quadric + verts_[u].quadric;
    neighbours(v, ring_v_);
    // Each update reads a neighbour's record, a likely cache miss: start all of them at once.
    for (const std::uint32_t w : ring_v_) prefetch_vertex(w);
    // The faces around v and its neighbours changed: their refused collapses get another chance.
    unpark(v);
    for (const std::uint32_t w : ring_v_) unpark(w);
    // Only v moved: its own collapses and each neighbour's collapse into v changed cost, and the neighbours'
    // collapses into u are gone.
    heap_.erase(u);
    set_key(v, cheapest(v, ring_v_));
    for (const std::uint32_t w : ring_v_) {
      if (removed_end(w, v) != w) continue;
      if (best_kept_[w] != u && best_kept_[w] != v) {
        relax(w, v);
        continue;
      }
      // w's cheapest collapse went (into u) or changed (into v): if the one into v is not dearer than the old
      // key, every other edge of w is at least that and it wins; else all of w's edges decide.
      const std::uint64_t key = is_parked(w, v) ? kNoKey : edge_key(w, v), old = heap_.key(w);
      if (key != kNoKey && (key < old || (key == old && best_kept_[w] == v))) {
        best_kept_[w] = v;
        heap_.set(key);
      } else {
        refresh(w);
      }
    }
  }

  bool is_parked(std::uint32_t w, std::uint32_t x) const {
    return verts_[w].parked && std::find(parked_[w].begin(), parked_[w].end(), x) != parked_[w].end();
  }

  void park(std::uint32_t w, std::uint32_t x) {
    verts_[w].parked = true;
    std::vector<std::uint32_t>& list = parked_[w];
    if (std::find(list.begin(), list.end(), x) == list.end()) list.push_back(x);
  }

  /// Makes w's refused collapses eligible again (dropping them from the other ends' lists too) and offers
  /// those that are still edges to the vertex they would remove.
  void unpark(std::uint32_t w) {
    if (!verts_[w].parked) return;  // the common case, answered from the record the updates load anyway
    verts_[w].parked = false;
    unparked_.swap(parked_[w]);
    parked_[w].clear();
    for (const std::uint32_t x : unparked_) {
      std::vector<std::uint32_t>& other = parked_[x];
      const auto it = std::find(other.begin(), other.end(), w);
      if (it != other.end()) *it = other.back(), other.pop_back(), verts_[x].parked = !other.empty();
      if (!std::any_of(incident_.begin(w), incident_.end(w), [&](std::uint32_t f) { return has(faces_[f], x); }))
        continue;
      const std::uint32_t r = removed_end(w, x);
      if (r != kNone) relax(r, r == w ? x : w);
    }
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
  std::vector<std::uint32_t> best_kept_;  ///< vertex -> the kept end of its cheapest collapse (its heap key)
  std::vector<Face> faces_;  ///< {kNone, kNone, kNone} once collapsed away
  Incidence incident_;  ///< vertex -> its live faces
  std::vector<std::uint64_t> mark_;  ///< per-vertex scratch marks (for_each_neighbour)
  std::uint64_t mark_counter_ = 0;
  std::vector<std::vector<std::uint32_t>> parked_;  ///< vertex -> other ends of its refused collapses
  VertexHeap heap_;
  std::vector<std::uint32_t> ring_v_, ring_w_, unparked_;  ///< scratch
  std::size_t alive_faces_;
  CollapseOptions options_;
  double cos_limit_ = 0;
};

}  // namespace

CollapseResult quadric_collapse(const TriMesh& mesh, const CollapseOptions& options) {
  return Collapser(mesh, options).run();
}

}  // namespace raysift::mesh::detail
