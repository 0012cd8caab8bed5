#include "tissue/Refine.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <numbers>
#include <set>
#include <stdexcept>

#include "mechanics/Contact.h"

namespace tp {

namespace {

using EdgeKey = std::pair<int, int>;
EdgeKey key(int a, int b) { return std::minmax(a, b); }

struct Tri {
  int v[3];
  int wall;
  bool alive = true;
};

struct GreenPair {
  Tri parent;
  int child[2];
};

class Refiner {
 public:
  explicit Refiner(const CellComplex& cc) {
    for (int v = 0; v < cc.vertexCount(); ++v) pos_.push_back(cc.rest.col(v));
    fixed_ = cc.fixed;
    for (int t = 0; t < cc.triangleCount(); ++t)
      add(Tri{{cc.triangles[t][0], cc.triangles[t][1], cc.triangles[t][2]}, cc.triangleWall[t]});
  }

  void level(const Vec3& center, double radius) {
    // Undo the green closures of the previous level.
    for (const auto& g : greens_) {
      kill(g.child[0]);
      kill(g.child[1]);
      add(g.parent);
    }
    greens_.clear();
    std::deque<int> queue;
    std::vector<int> marked;
    for (size_t t = 0; t < tris_.size(); ++t) {
      if (!tris_[t].alive) continue;
      const Tri& tr = tris_[t];
      const double d2 = pointTriangleDistance2(center, pos_[tr.v[0]], pos_[tr.v[1]], pos_[tr.v[2]],
                                               nullptr, nullptr, nullptr);
      if (d2 <= radius * radius) marked.push_back(static_cast<int>(t));
    }
    for (int t : marked)
      if (tris_[t].alive) red(t, queue);
    for (size_t t = 0; t < tris_.size(); ++t)
      if (tris_[t].alive) queue.push_back(static_cast<int>(t));
    // Closure: two split edges, or a split edge whose half is split again, make a triangle red.
    while (!queue.empty()) {
      const int t = queue.front();
      queue.pop_front();
      if (!tris_[t].alive) continue;
      int split = 0;
      bool deep = false;
      for (int k = 0; k < 3; ++k) {
        const int a = tris_[t].v[k], b = tris_[t].v[(k + 1) % 3];
        const auto it = mid_.find(key(a, b));
        if (it == mid_.end()) continue;
        ++split;
        if (mid_.count(key(a, it->second)) || mid_.count(key(it->second, b))) deep = true;
      }
      if (split >= 2 || deep) red(t, queue);
    }
    // Green closure of the triangles left with one split edge.
    const size_t count = tris_.size();
    for (size_t t = 0; t < count; ++t) {
      if (!tris_[t].alive) continue;
      for (int k = 0; k < 3; ++k) {
        const Tri tr = tris_[t];
        const int a = tr.v[k], b = tr.v[(k + 1) % 3], c = tr.v[(k + 2) % 3];
        const auto it = mid_.find(key(a, b));
        if (it == mid_.end()) continue;
        const int m = it->second;
        kill(static_cast<int>(t));
        GreenPair g{tr, {add(Tri{{a, m, c}, tr.wall}), add(Tri{{m, b, c}, tr.wall})}};
        greens_.push_back(g);
        break;
      }
    }
  }

  CellComplex result(const CellComplex& original, RefineReport& rep) const {
    CellComplex out;
    out.rest.resize(3, static_cast<int>(pos_.size()));
    for (size_t v = 0; v < pos_.size(); ++v) out.rest.col(v) = pos_[v];
    out.fixed = fixed_;
    out.cellLabels = original.cellLabels;
    out.walls = original.walls;
    // Wall outlines follow the splits of their edges.
    for (auto& w : out.walls) {
      if (w.polygon.empty()) continue;
      std::vector<int> loop;
      for (size_t i = 0; i < w.polygon.size(); ++i) expand(w.polygon[i], w.polygon[(i + 1) % w.polygon.size()], loop);
      w.polygon = loop;
    }
    for (const auto& t : tris_)
      if (t.alive) {
        out.triangles.emplace_back(t.v[0], t.v[1], t.v[2]);
        out.triangleWall.push_back(t.wall);
      }
    rep.greenTriangles = 2 * static_cast<int>(greens_.size());
    rep.addedVertices = static_cast<int>(pos_.size()) - original.vertexCount();
    return out;
  }

  int reds = 0;

 private:
  // Appends a→…→b (without b) with the midpoints of recursively split edges.
  void expand(int a, int b, std::vector<int>& loop) const {
    const auto it = mid_.find(key(a, b));
    if (it == mid_.end()) {
      loop.push_back(a);
      return;
    }
    expand(a, it->second, loop);
    expand(it->second, b, loop);
  }

  int add(const Tri& t) {
    const int id = static_cast<int>(tris_.size());
    tris_.push_back(t);
    for (int k = 0; k < 3; ++k) edgeTris_[key(t.v[k], t.v[(k + 1) % 3])].insert(id);
    return id;
  }

  void kill(int id) {
    Tri& t = tris_[id];
    t.alive = false;
    for (int k = 0; k < 3; ++k) edgeTris_[key(t.v[k], t.v[(k + 1) % 3])].erase(id);
  }

  int midpoint(int a, int b, std::deque<int>& queue) {
    const auto k = key(a, b);
    const auto it = mid_.find(k);
    if (it != mid_.end()) return it->second;
    const int m = static_cast<int>(pos_.size());
    pos_.push_back(0.5 * (pos_[a] + pos_[b]));
    fixed_.push_back(fixed_[a] && fixed_[b] ? 1 : 0);
    mid_[k] = m;
    parent_[key(a, m)] = k;
    parent_[key(m, b)] = k;
    for (int t : edgeTris_[k]) queue.push_back(t);  // they now have a split edge
    // Triangles still holding an edge this one is half of now have a doubly split edge.
    for (auto p = parent_.find(k); p != parent_.end(); p = parent_.find(p->second))
      for (int t : edgeTris_[p->second]) queue.push_back(t);
    return m;
  }

  void red(int t, std::deque<int>& queue) {
    const Tri tr = tris_[t];
    const int a = tr.v[0], b = tr.v[1], c = tr.v[2];
    const int ab = midpoint(a, b, queue), bc = midpoint(b, c, queue), ca = midpoint(c, a, queue);
    kill(t);
    for (const Tri& child : {Tri{{a, ab, ca}, tr.wall}, Tri{{ab, b, bc}, tr.wall},
                             Tri{{ca, bc, c}, tr.wall}, Tri{{ab, bc, ca}, tr.wall}})
      queue.push_back(add(child));
    ++reds;
  }

  std::vector<Vec3> pos_;
  std::vector<std::uint8_t> fixed_;
  std::vector<Tri> tris_;
  std::map<EdgeKey, std::set<int>> edgeTris_;
  std::map<EdgeKey, int> mid_;
  std::map<EdgeKey, EdgeKey> parent_;  // half edge → the edge it was split from
  std::vector<GreenPair> greens_;
};

double minAngle(const CellComplex& cc) {
  double best = 180;
  for (const auto& t : cc.triangles)
    for (int k = 0; k < 3; ++k) {
      const Vec3 u = cc.rest.col(t[(k + 1) % 3]) - cc.rest.col(t[k]);
      const Vec3 v = cc.rest.col(t[(k + 2) % 3]) - cc.rest.col(t[k]);
      best = std::min(best, std::atan2(u.cross(v).norm(), u.dot(v)) * 180 / std::numbers::pi);
    }
  return best;
}

}  // namespace

CellComplex refineNear(const CellComplex& cc, const Vec3& center, double radius, int levels,
                       RefineReport* report) {
  if (levels < 0) throw std::invalid_argument("refinement level must be >= 0");
  if (!(radius > 0) || !center.allFinite())
    throw std::invalid_argument("refinement needs a positive radius and a finite centre");
  RefineReport rep;
  rep.levels = levels;
  if (levels == 0) {
    rep.minAngleDeg = minAngle(cc);
    if (report) *report = rep;
    return cc;
  }
  Refiner r(cc);
  for (int l = 0; l < levels; ++l) r.level(center, radius);
  CellComplex out = r.result(cc, rep);
  rep.redTriangles = r.reds;
  rep.minAngleDeg = minAngle(out);
  if (report) *report = rep;
  return out;
}

}  // namespace tp
