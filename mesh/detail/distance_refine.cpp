#include "mesh/detail/distance_refine.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/parallel.h"

namespace raysift::mesh::detail {

namespace {

/// Barycentric weights of the 7 samples of a face: vertices, edge midpoints, centroid.
constexpr double kWeights[7][3] = {{1, 0, 0},     {0, 1, 0},     {0, 0, 1},
                                   {0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5},
                                   {1.0 / 3, 1.0 / 3, 1.0 / 3}};
constexpr double kSteps[3] = {1.0, 0.5, 0.25};

/// fn(i) for i in [0, n) in parallel; each i writes only its own slot, so any thread count gives the same result.
template <typename Fn>
void for_each_index(std::size_t n, const Fn& fn) {
  parallel_for_each(n, fn, true, std::size_t(256));
}

class Refiner {
 public:
  Refiner(const TriangleGrid& grid, TriMesh& mesh, const std::vector<char>& locked)
      : grid_(grid), mesh_(mesh), locked_(locked), p_(mesh.positions.begin(), mesh.positions.end()) {
    first_.assign(p_.size() + 1, 0);
    for (const auto& t : mesh.triangles)
      for (const std::uint32_t v : t) ++first_[v + 1];
    for (std::size_t v = 0; v < p_.size(); ++v) first_[v + 1] += first_[v];
    faces_of_.resize(first_.back());
    std::vector<std::uint32_t> fill(first_.begin(), first_.end() - 1);
    for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f)
      for (const std::uint32_t v : mesh.triangles[f]) faces_of_[fill[v]++] = f;
  }

  RefineResult run() {
    const std::size_t faces = mesh_.triangles.size();
    vertex_distance_.resize(p_.size());
    err_.resize(faces);
    for_each_index(p_.size(), [&](std::size_t v) { vertex_distance_[v] = distance(p_[v]); });
    for_each_index(faces, [&](std::size_t f) { err_[f] = face_error(std::uint32_t(f)); });
    heap_.reserve(faces);
    for (std::uint32_t f = 0; f < faces; ++f) heap_.push_back({err_[f].d, f});
    std::make_heap(heap_.begin(), heap_.end());
    RefineResult result;
    result.before = heap_.front().first;
    // Each kept move lowers every face it touches below the current maximum; the cap only guards against a
    // long creep of tiny gains.
    for (std::size_t limit = faces / 4 + 64; result.moves < limit && !heap_.empty();) {
      std::pop_heap(heap_.begin(), heap_.end());
      const auto [d, f] = heap_.back();
      heap_.pop_back();
      if (d != err_[f].d) continue;  // superseded by a later entry
      if (!improve(f)) {
        heap_.push_back({d, f});
        break;
      }
      ++result.moves;
    }
    result.after = heap_.empty() ? 0 : std::max_element(heap_.begin(), heap_.end())->first;
    for (std::size_t v = 0; v < p_.size(); ++v) mesh_.positions[v] = Vec3f(p_[v]);
    return result;
  }

 private:
  struct FaceError {
    double d = -1;
    int sample = 0;
  };

  /// +inf when farther than cap.
  double distance(const Vec3d& p, double cap = 1e300) const { return std::sqrt(grid_.nearest(p, cap).distance2); }

  Vec3d sample(std::uint32_t f, int k) const {
    const auto& t = mesh_.triangles[f];
    return p_[t[0]] * kWeights[k][0] + p_[t[1]] * kWeights[k][1] + p_[t[2]] * kWeights[k][2];
  }

  FaceError face_error(std::uint32_t f, double cap = 1e300) const {
    FaceError e;
    for (int k = 0; k < 7; ++k) {
      const double d = k < 3 ? vertex_distance_[mesh_.triangles[f][k]] : distance(sample(f, k), cap);
      if (d > e.d) e = {d, k};
    }
    return e;
  }

  Vec3d normal(std::uint32_t f) const {
    const auto& t = mesh_.triangles[f];
    return cross(p_[t[1]] - p_[t[0]], p_[t[2]] - p_[t[0]]);
  }

  /// Moves f's worst sample towards its nearest original point through the vertices it depends on.
  bool improve(std::uint32_t f) {
    const auto t = mesh_.triangles[f];
    const int k = err_[f].sample;
    const Vec3d s = sample(f, k);
    const Vec3d delta = grid_.closest_point(s) - s;
    const double bound = err_[f].d;
    std::uint32_t movers[3];
    double weight[3];
    int n = 0;
    for (int j = 0; j < 3; ++j)
      if (kWeights[k][j] > 0 && !locked_[t[j]]) movers[n] = t[j], weight[n++] = kWeights[k][j];
    for (const double step : kSteps)
      if (n > 0 && try_move(movers, n, delta * step, bound)) return true;
    // One vertex alone moves the sample by its weight times the step: scale up to reach the same point.
    for (int i = 0; n > 1 && i < n; ++i)
      for (const double step : kSteps)
        if (try_move(&movers[i], 1, delta * (step / weight[i]), bound)) return true;
    return false;
  }

  /// Applies the move if every face around the moved vertices ends below `bound` without turning by 90
  /// degrees or more; else leaves everything unchanged.
  bool try_move(const std::uint32_t* verts, int n, const Vec3d& step, double bound) {
    affected_.clear();
    for (int i = 0; i < n; ++i)
      affected_.insert(affected_.end(), faces_of_.begin() + first_[verts[i]], faces_of_.begin() + first_[verts[i] + 1]);
    std::sort(affected_.begin(), affected_.end());
    affected_.erase(std::unique(affected_.begin(), affected_.end()), affected_.end());
    normals_.clear();
    for (const std::uint32_t g : affected_) normals_.push_back(normal(g));
    Vec3d saved[3];
    double saved_distance[3];
    for (int i = 0; i < n; ++i) saved[i] = p_[verts[i]], saved_distance[i] = vertex_distance_[verts[i]];
    const auto undo = [&] {
      for (int i = 0; i < n; ++i) p_[verts[i]] = saved[i], vertex_distance_[verts[i]] = saved_distance[i];
      return false;
    };
    for (int i = 0; i < n; ++i) p_[verts[i]] = saved[i] + step;
    for (std::size_t i = 0; i < affected_.size(); ++i)
      if (!(dot(normal(affected_[i]), normals_[i]) > 0)) return undo();
    for (int i = 0; i < n; ++i)
      if (!((vertex_distance_[verts[i]] = distance(p_[verts[i]], bound)) < bound)) return undo();
    errors_.clear();
    for (const std::uint32_t g : affected_) {
      errors_.push_back(face_error(g, bound));
      if (!(errors_.back().d < bound)) return undo();
    }
    for (std::size_t i = 0; i < affected_.size(); ++i) {
      err_[affected_[i]] = errors_[i];
      heap_.push_back({errors_[i].d, affected_[i]});
      std::push_heap(heap_.begin(), heap_.end());
    }
    return true;
  }

  const TriangleGrid& grid_;
  TriMesh& mesh_;
  const std::vector<char>& locked_;
  std::vector<Vec3d> p_;  ///< working positions (double: steps are small against the coordinates)
  std::vector<std::uint32_t> first_, faces_of_;  ///< vertex -> faces (CSR)
  std::vector<double> vertex_distance_;
  std::vector<FaceError> err_;
  std::vector<std::pair<double, std::uint32_t>> heap_;  ///< max-heap of (error, face); stale entries skipped
  std::vector<std::uint32_t> affected_;  ///< scratch
  std::vector<Vec3d> normals_;
  std::vector<FaceError> errors_;
};

}  // namespace

RefineResult refine_distance(const TriangleGrid& original, TriMesh& mesh, const std::vector<char>& locked) {
  return Refiner(original, mesh, locked).run();
}

}  // namespace raysift::mesh::detail
