#include "tissue/Refine.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <stdexcept>

#include "mechanics/Contact.h"
#include "mesh/Topology.h"

namespace tp {

namespace {

using EdgeKey = std::pair<int, int>;
EdgeKey key(int a, int b) { return std::minmax(a, b); }

struct Tri {
  int v[3];
  int wall;
  int origin;  // the base triangle it subdivides
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
      add(Tri{{cc.triangles[t][0], cc.triangles[t][1], cc.triangles[t][2]}, cc.triangleWall[t], t});
  }

  /// One pass: red-refines the live triangles `mark` selects (given the triangle's three rest
  /// positions), closes the result conformingly, and returns how many were marked.
  template <class Mark>
  int pass(Mark&& mark) {
    // Undo the green closures of the previous pass.
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
      if (mark(pos_[tr.v[0]], pos_[tr.v[1]], pos_[tr.v[2]], tr.wall))
        marked.push_back(static_cast<int>(t));
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
        GreenPair g{tr, {add(Tri{{a, m, c}, tr.wall, tr.origin}),
                         add(Tri{{m, b, c}, tr.wall, tr.origin})}};
        greens_.push_back(g);
        break;
      }
    }
    return static_cast<int>(marked.size());
  }

  /// The base triangle of each live triangle, in the order result() lists them.
  std::vector<int> origins() const {
    std::vector<int> out;
    for (const auto& t : tris_)
      if (t.alive) out.push_back(t.origin);
    return out;
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

  /// The two vertices each added vertex is the midpoint of, in order of creation.
  std::vector<std::array<int, 2>> parents(int baseVertices) const {
    std::vector<std::array<int, 2>> out(pos_.size() - baseVertices);
    for (const auto& [edge, m] : mid_) out[m - baseVertices] = {edge.first, edge.second};
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
    for (const Tri& child :
         {Tri{{a, ab, ca}, tr.wall, tr.origin}, Tri{{ab, b, bc}, tr.wall, tr.origin},
          Tri{{ca, bc, c}, tr.wall, tr.origin}, Tri{{ab, bc, ca}, tr.wall, tr.origin}})
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

// The refiner's tissue after `levels` passes, with the parent of every new vertex, the base
// triangle of every triangle, and the report.
RefinedComplex collect(Refiner& r, const CellComplex& cc, int levels) {
  RefinedComplex out;
  out.complex = r.result(cc, out.report);
  out.parents = r.parents(cc.vertexCount());
  out.baseTriangle = r.origins();
  out.report.levels = levels;
  out.report.redTriangles = r.reds;
  out.report.minAngleDeg = minAngle(out.complex);
  return out;
}

}  // namespace

RefinedComplex refineWithin(const CellComplex& cc, const Vec3& center, double radius,
                            int levels) {
  if (levels < 0) throw std::invalid_argument("refinement level must be >= 0");
  if (!(radius > 0) || !center.allFinite())
    throw std::invalid_argument("refinement needs a positive radius and a finite centre");
  if (levels == 0) return unrefined(cc);
  Refiner r(cc);
  for (int l = 0; l < levels; ++l)
    r.pass([&](const Vec3& a, const Vec3& b, const Vec3& c, int) {
      return pointTriangleDistance2(center, a, b, c, nullptr, nullptr, nullptr) <= radius * radius;
    });
  return collect(r, cc, levels);
}

CellComplex refineNear(const CellComplex& cc, const Vec3& center, double radius, int levels,
                       RefineReport* report) {
  RefinedComplex r = refineWithin(cc, center, radius, levels);
  if (report) *report = r.report;
  return std::move(r.complex);
}

}  // namespace tp

namespace tp {

// Distance from x to the segment pq (µm).
static double segmentDistance(const Vec3& x, const Vec3& p, const Vec3& q) {
  const Vec3 d = q - p;
  const double l2 = d.squaredNorm();
  const double t = l2 > 0 ? std::clamp((x - p).dot(d) / l2, 0.0, 1.0) : 0.0;
  return (x - (p + t * d)).norm();
}

double GradedRefinement::targetSize(double distance) const {
  return std::max(finest, finest + (distance - innerRadius) / grading);
}

RefinedComplex refineGraded(const CellComplex& cc, const GradedRefinement& spec) {
  if (!(spec.finest > 0) || !(spec.grading > 0) || !(spec.innerRadius >= 0) ||
      !(spec.outerRadius >= 0) || !spec.center.allFinite() || !(spec.panelSize >= 0) ||
      !(spec.panelFraction >= 0) || !(spec.junctionSize >= 0) || !(spec.junctionRadius >= 0))
    throw std::invalid_argument("graded refinement needs a finite centre, a positive finest size "
                                "and grading, and non-negative radii");
  // The zone: every wall with a triangle within the outer radius, refined whole.
  const double outer2 = spec.outerRadius * spec.outerRadius;
  std::vector<char> zone(cc.wallCount(), 0);
  for (int t = 0; t < cc.triangleCount(); ++t) {
    const auto& tri = cc.triangles[t];
    if (pointTriangleDistance2(spec.center, cc.rest.col(tri[0]), cc.rest.col(tri[1]),
                               cc.rest.col(tri[2]), nullptr, nullptr, nullptr) <= outer2)
      zone[cc.triangleWall[t]] = 1;
  }
  double panel = spec.panelSize;
  if (spec.panelFraction > 0) {
    double longestBase2 = 0;
    for (int t = 0; t < cc.triangleCount(); ++t) {
      if (!zone[cc.triangleWall[t]]) continue;
      const auto& tri = cc.triangles[t];
      for (int k = 0; k < 3; ++k)
        longestBase2 = std::max(
            longestBase2, (cc.rest.col(tri[(k + 1) % 3]) - cc.rest.col(tri[k])).squaredNorm());
    }
    const double cap = spec.panelFraction * std::sqrt(longestBase2);
    if (cap > 0) panel = panel > 0 ? std::min(panel, cap) : cap;
  }
  // The band along the junctions: for every wall of the zone, its edges shared with two or more
  // other walls that come within the band's radius (rest positions; refinement keeps them edges).
  std::vector<std::vector<std::pair<Vec3, Vec3>>> junctions(cc.wallCount());
  const double bandRadius =
      spec.junctionRadius > 0 ? std::min(spec.junctionRadius, spec.outerRadius) : spec.outerRadius;
  if (spec.junctionSize > 0) {
    const Topology topo = buildTopology(cc);
    for (size_t e = 0; e < topo.edges.size(); ++e) {
      std::vector<int> walls;
      for (int t : topo.edgeTriangles[e])
        if (std::find(walls.begin(), walls.end(), cc.triangleWall[t]) == walls.end())
          walls.push_back(cc.triangleWall[t]);
      if (walls.size() < 3) continue;
      const Vec3 p = cc.rest.col(topo.edges[e][0]), q = cc.rest.col(topo.edges[e][1]);
      if (segmentDistance(spec.center, p, q) > bandRadius) continue;
      for (int w : walls)
        if (zone[w]) junctions[w].emplace_back(p, q);
    }
  }
  const auto nearJunction = [&](const Vec3& a, const Vec3& b, const Vec3& c, int wall) {
    for (const auto& [p, q] : junctions[wall])
      for (const Vec3* x : {&a, &b, &c})
        if (segmentDistance(*x, p, q) < spec.junctionSize) return true;
    return false;
  };
  Refiner r(cc);
  int passes = 0;
  for (; passes < spec.maxPasses; ++passes) {
    const int marked = r.pass([&](const Vec3& a, const Vec3& b, const Vec3& c, int wall) {
      if (!zone[wall]) return false;
      const double d2 = pointTriangleDistance2(spec.center, a, b, c, nullptr, nullptr, nullptr);
      const double longest =
          std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
      double target = spec.targetSize(std::sqrt(d2));
      if (panel > 0) target = std::min(target, panel);
      if (spec.junctionSize > 0 && spec.junctionSize < target && d2 <= outer2 &&
          nearJunction(a, b, c, wall))
        target = spec.junctionSize;
      return longest > target * target;
    });
    if (marked == 0) break;
  }
  return collect(r, cc, passes);
}

RefinedComplex refineWalls(const CellComplex& cc, const std::vector<char>& walls, int levels) {
  if (static_cast<int>(walls.size()) != cc.wallCount())
    throw std::invalid_argument("refineWalls: one flag per wall expected");
  Refiner r(cc);
  for (int l = 0; l < levels; ++l)
    r.pass([&](const Vec3&, const Vec3&, const Vec3&, int wall) { return walls[wall] != 0; });
  return collect(r, cc, levels);
}

Points prolongate(const Points& coarse, const std::vector<std::array<int, 2>>& parents) {
  const int V = static_cast<int>(coarse.cols());
  Points fine(3, V + static_cast<int>(parents.size()));
  fine.leftCols(V) = coarse;
  for (size_t i = 0; i < parents.size(); ++i)
    fine.col(V + i) = 0.5 * (fine.col(parents[i][0]) + fine.col(parents[i][1]));
  return fine;
}

RefinedComplex unrefined(const CellComplex& cc) {
  RefinedComplex out;
  out.complex = cc;
  out.baseTriangle.resize(cc.triangleCount());
  for (int t = 0; t < cc.triangleCount(); ++t) out.baseTriangle[t] = t;
  out.report.minAngleDeg = minAngle(cc);
  return out;
}

Points transferPositions(const CellComplex& base, const RefinedComplex& from, const Points& x,
                         const RefinedComplex& to) {
  if (x.cols() != from.complex.vertexCount() ||
      static_cast<int>(from.baseTriangle.size()) != from.complex.triangleCount() ||
      static_cast<int>(to.baseTriangle.size()) != to.complex.triangleCount())
    throw std::invalid_argument("transferPositions: the refinements do not match the positions");
  // The triangles of `from` inside each base triangle.
  std::vector<std::vector<int>> inside(base.triangleCount());
  for (int t = 0; t < from.complex.triangleCount(); ++t) inside[from.baseTriangle[t]].push_back(t);
  const Points& X = from.complex.rest;
  // Barycentric coordinates of p in the plane of (a, b, c).
  auto weights = [](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
    const Vec3 n = (b - a).cross(c - a);
    const double n2 = std::max(n.squaredNorm(), 1e-300);
    Vec3 w((c - b).cross(p - b).dot(n) / n2, (a - c).cross(p - c).dot(n) / n2, 0.0);
    w[2] = 1.0 - w[0] - w[1];
    return w;
  };
  Points out(3, to.complex.vertexCount());
  std::vector<char> done(to.complex.vertexCount(), 0);
  for (int t = 0; t < to.complex.triangleCount(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int v = to.complex.triangles[t][k];
      if (done[v]) continue;
      done[v] = 1;
      const Vec3 p = to.complex.rest.col(v);
      // The triangle of `from`, in the same base triangle, that holds p (the one it is least
      // outside of, against round-off).
      int best = -1;
      double bestOutside = std::numeric_limits<double>::infinity();
      Vec3 bestW = Vec3::Zero();
      for (int f : inside[to.baseTriangle[t]]) {
        const auto& tri = from.complex.triangles[f];
        const Vec3 w = weights(X.col(tri[0]), X.col(tri[1]), X.col(tri[2]), p);
        const double outside = -std::min(0.0, w.minCoeff());
        if (outside < bestOutside) {
          bestOutside = outside;
          best = f;
          bestW = w;
          if (outside == 0) break;
        }
      }
      if (best < 0) throw std::logic_error("transferPositions: a base triangle has no triangle");
      const auto& tri = from.complex.triangles[best];
      out.col(v) = bestW[0] * x.col(tri[0]) + bestW[1] * x.col(tri[1]) + bestW[2] * x.col(tri[2]);
    }
  return out;
}

}  // namespace tp
