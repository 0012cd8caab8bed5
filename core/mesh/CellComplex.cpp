#include "mesh/CellComplex.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace tp {

int CellComplex::addWall(const std::vector<Eigen::Vector3i>& tris, int cell, int neighbor,
                         std::vector<int> polygon) {
  const int w = wallCount();
  walls.push_back(Wall{std::move(polygon), cell, neighbor});
  for (const auto& t : tris) {
    triangles.push_back(t);
    triangleWall.push_back(w);
  }
  return w;
}

int CellComplex::addPolygonWall(const std::vector<int>& polygon, int cell, int neighbor) {
  return addWall(triangulatePolygon(rest, polygon), cell, neighbor, polygon);
}

namespace {

double minAngle2(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  auto angle = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    const Eigen::Vector2d u = q - p, v = r - p;
    return std::atan2(std::abs(u.x() * v.y() - u.y() * v.x()), u.dot(v));
  };
  return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

bool insideTriangle(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                    const Eigen::Vector2d& c, double eps) {
  return cross2(b - a, p - a) > eps && cross2(c - b, p - b) > eps && cross2(a - c, p - c) > eps;
}

}  // namespace

std::vector<Eigen::Vector3i> triangulatePolygon(const Points& points,
                                                const std::vector<int>& polygon,
                                                const DiagonalFilter& allowDiagonal) {
  const int n = static_cast<int>(polygon.size());
  if (n < 3) throw std::invalid_argument("polygon with fewer than 3 vertices");
  if (n == 3) return {Eigen::Vector3i(polygon[0], polygon[1], polygon[2])};

  // Newell normal: robust best-fit plane normal that follows the polygon's winding.
  Vec3 normal = Vec3::Zero();
  Vec3 centre = Vec3::Zero();
  for (int i = 0; i < n; ++i) {
    const Vec3 p = points.col(polygon[i]);
    const Vec3 q = points.col(polygon[(i + 1) % n]);
    normal += Vec3((p.y() - q.y()) * (p.z() + q.z()), (p.z() - q.z()) * (p.x() + q.x()),
                   (p.x() - q.x()) * (p.y() + q.y()));
    centre += p;
  }
  centre /= n;
  std::vector<Eigen::Vector3i> out;
  if (normal.norm() == 0.0) {  // degenerate polygon: fan, nothing better exists
    for (int i = 1; i + 1 < n; ++i) out.emplace_back(polygon[0], polygon[i], polygon[i + 1]);
    return out;
  }
  normal.normalize();
  const Vec3 u = normal.unitOrthogonal();
  const Vec3 v = normal.cross(u);  // (u, v, normal) right-handed: polygon is counter-clockwise
  std::vector<Eigen::Vector2d> p2(n);
  double scale = 0;
  for (int i = 0; i < n; ++i) {
    const Vec3 d = points.col(polygon[i]) - centre;
    p2[i] = Eigen::Vector2d(d.dot(u), d.dot(v));
    scale = std::max(scale, p2[i].norm());
  }
  const double eps = 1e-12 * scale * scale;

  // Convex polygon (Voronoi walls): the triangulation that maximises the smallest angle, by dynamic
  // programming over diagonals (O(n³), n is small).
  bool convex = n <= 64;
  for (int i = 0; i < n && convex; ++i)
    if (cross2(p2[(i + 1) % n] - p2[i], p2[(i + 2) % n] - p2[(i + 1) % n]) < -eps) convex = false;
  auto allowed = [&](int i, int j) {  // polygon positions i < j
    if (j - i < 2 || (i == 0 && j == n - 1) || !allowDiagonal) return true;
    return allowDiagonal(polygon[i], polygon[j]);
  };
  if (convex) {
    std::vector<double> best(n * n, 1e300);
    std::vector<int> split(n * n, -1);
    for (int gap = 2; gap < n; ++gap)
      for (int i = 0; i + gap < n; ++i) {
        const int j = i + gap;
        double value = -1;
        for (int k = i + 1; k < j; ++k) {
          // Rejected diagonals count as the worst shape, so they are used only if unavoidable.
          const double penalty = allowed(i, k) && allowed(k, j) ? 0.0 : -10.0;
          const double score = penalty + std::min({k == i + 1 ? 1e300 : best[i * n + k],
                                         k + 1 == j ? 1e300 : best[k * n + j],
                                         minAngle2(p2[i], p2[k], p2[j])});
          if (score > value) {
            value = score;
            split[i * n + j] = k;
          }
        }
        best[i * n + j] = value;
      }
    std::vector<std::pair<int, int>> stack = {{0, n - 1}};
    while (!stack.empty()) {
      const auto [i, j] = stack.back();
      stack.pop_back();
      if (j - i < 2) continue;
      const int k = split[i * n + j];
      out.emplace_back(polygon[i], polygon[k], polygon[j]);
      stack.push_back({i, k});
      stack.push_back({k, j});
    }
    return out;
  }

  // General polygon: ear clipping, taking the best-shaped ear (largest minimum angle) each time.
  std::vector<int> idx(n);
  for (int i = 0; i < n; ++i) idx[i] = i;
  while (idx.size() > 3) {
    const int m = static_cast<int>(idx.size());
    int best = -1;
    double bestAngle = -1;
    for (int k = 0; k < m; ++k) {
      const int a = idx[(k + m - 1) % m], b = idx[k], c = idx[(k + 1) % m];
      if (cross2(p2[b] - p2[a], p2[c] - p2[b]) <= eps) continue;  // reflex or flat corner
      if (m > 3 && allowDiagonal && !allowDiagonal(polygon[a], polygon[c])) continue;
      bool empty = true;
      for (int j = 0; j < m && empty; ++j) {
        const int q = idx[j];
        if (q == a || q == b || q == c) continue;
        if (insideTriangle(p2[q], p2[a], p2[b], p2[c], -eps)) empty = false;
      }
      if (!empty) continue;
      const double ang = minAngle2(p2[a], p2[b], p2[c]);
      if (ang > bestAngle) {
        bestAngle = ang;
        best = k;
      }
    }
    if (best < 0) {  // only flat or reflex corners left (numerically degenerate): clip any corner
      best = 0;
      double bestCross = -1e300;
      for (int k = 0; k < m; ++k) {
        const int a = idx[(k + m - 1) % m], b = idx[k], c = idx[(k + 1) % m];
        const double cr = cross2(p2[b] - p2[a], p2[c] - p2[b]);
        if (cr > bestCross) {
          bestCross = cr;
          best = k;
        }
      }
    }
    const int a = idx[(best + m - 1) % m], b = idx[best], c = idx[(best + 1) % m];
    out.emplace_back(polygon[a], polygon[b], polygon[c]);
    idx.erase(idx.begin() + best);
  }
  out.emplace_back(polygon[idx[0]], polygon[idx[1]], polygon[idx[2]]);
  return out;
}

double meanCellSize(const CellComplex& cc) {
  if (cc.cellCount() == 0) return 0;
  double volume = 0;
  for (double v : cellVolumes(cc, cc.rest)) volume += v;
  return volume > 0 ? std::cbrt(volume / cc.cellCount()) : 0.0;
}

std::vector<double> cellVolumes(const CellComplex& cc, const Points& x) {
  std::vector<double> vol(cc.cellCount(), 0.0);
  for (int t = 0; t < cc.triangleCount(); ++t) {
    const auto& tri = cc.triangles[t];
    const Wall& w = cc.walls[cc.triangleWall[t]];
    const double det = x.col(tri[0]).dot(x.col(tri[1]).cross(x.col(tri[2]))) / 6.0;
    if (w.cell >= 0) vol[w.cell] += det;
    if (w.neighbor >= 0) vol[w.neighbor] -= det;
  }
  return vol;
}

std::vector<double> triangleAreas(const CellComplex& cc, const Points& x) {
  std::vector<double> a(cc.triangleCount());
  for (int t = 0; t < cc.triangleCount(); ++t) {
    const auto& tri = cc.triangles[t];
    a[t] = 0.5 * (x.col(tri[1]) - x.col(tri[0])).cross(x.col(tri[2]) - x.col(tri[0])).norm();
  }
  return a;
}

std::string ValidityReport::summary() const {
  std::ostringstream s;
  if (errors.empty()) s << "valid";
  else s << std::max<size_t>(errorCount, errors.size()) << " error(s): " << errors.front();
  if (!warnings.empty()) s << "; " << warnings.size() << " warning(s): " << warnings.front();
  return s.str();
}

ValidityReport checkValidity(const CellComplex& cc) {
  ValidityReport r;
  const int V = cc.vertexCount(), T = cc.triangleCount(), W = cc.wallCount(), C = cc.cellCount();
  auto err = [&](const std::string& m) {
    ++r.errorCount;
    if (r.errors.size() < 50) r.errors.push_back(m);
  };
  if (static_cast<int>(cc.fixed.size()) != V) err("fixed flags: size differs from vertex count");
  if (static_cast<int>(cc.triangleWall.size()) != T) err("triangle walls: size differs from count");
  if (!cc.rest.allFinite()) err("vertex positions contain NaN or infinity");
  for (int w = 0; w < W; ++w) {
    const Wall& wall = cc.walls[w];
    if (wall.cell < -1 || wall.cell >= C || wall.neighbor < -1 || wall.neighbor >= C)
      err("wall " + std::to_string(w) + ": cell index out of range");
    if (wall.cell >= 0 && wall.cell == wall.neighbor)
      err("wall " + std::to_string(w) + ": same cell on both sides");
  }
  if (!r.ok()) return r;
  for (int t = 0; t < T; ++t) {
    const auto& tri = cc.triangles[t];
    for (int k = 0; k < 3; ++k)
      if (tri[k] < 0 || tri[k] >= V) {
        err("triangle " + std::to_string(t) + ": vertex index " + std::to_string(tri[k]) +
            " out of range");
        return r;
      }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
      err("triangle " + std::to_string(t) + ": repeated vertex");
      continue;
    }
    if (cc.triangleWall[t] < 0 || cc.triangleWall[t] >= W) {
      err("triangle " + std::to_string(t) + ": wall index out of range");
      return r;
    }
  }
  const auto areas = triangleAreas(cc, cc.rest);
  double meanArea = 0;
  for (double a : areas) meanArea += a;
  meanArea /= std::max(1, T);
  // A zero-area triangle has no rest metric, so its membrane energy is undefined (issue 9: it
  // used to surface as "energy is not finite" mid-solve). Name each one with its vertices.
  for (int t = 0; t < T; ++t)
    if (!(areas[t] > 1e-12 * meanArea)) {
      ++r.degenerateTriangles;
      const auto& tri = cc.triangles[t];
      err("triangle " + std::to_string(t) + " (vertices " + std::to_string(tri[0]) + ", " +
          std::to_string(tri[1]) + ", " + std::to_string(tri[2]) + "): degenerate, area " +
          [&] { std::ostringstream o; o << areas[t]; return o.str(); }() + " µm² (its corners are collinear or coincide)");
    }

  // Per cell: directed edges of its triangles wound outward from the cell.
  std::vector<std::map<std::pair<int, int>, int>> directed(C);
  for (int t = 0; t < T; ++t) {
    const auto& tri = cc.triangles[t];
    const Wall& w = cc.walls[cc.triangleWall[t]];
    for (int side = 0; side < 2; ++side) {
      const int c = side == 0 ? w.cell : w.neighbor;
      if (c < 0) continue;
      for (int k = 0; k < 3; ++k) {
        int a = tri[k], b = tri[(k + 1) % 3];
        if (side == 1) std::swap(a, b);
        ++directed[c][{a, b}];
      }
    }
  }
  const auto vol = cellVolumes(cc, cc.rest);
  for (int c = 0; c < C; ++c) {
    bool open = false, openUnclamped = false, misoriented = false, nonManifold = false;
    if (directed[c].empty()) {
      err("cell " + std::to_string(cc.cellLabels[c]) + ": has no walls");
      continue;
    }
    for (const auto& [e, count] : directed[c]) {
      if (count > 1) misoriented = true;
      const auto rev = directed[c].find({e.second, e.first});
      const int back = rev == directed[c].end() ? 0 : rev->second;
      if (back == 0) {
        open = true;
        if (!cc.fixed[e.first] || !cc.fixed[e.second]) openUnclamped = true;
      } else if (count + back > 2) {
        nonManifold = true;
      }
    }
    const std::string name = "cell " + std::to_string(cc.cellLabels[c]);
    if (misoriented) {
      ++r.misorientedCells;
      err(name + ": walls not consistently oriented (an edge is used twice in one direction)");
    }
    if (nonManifold) {
      ++r.nonManifoldEdges;
      r.warnings.push_back(name + ": an edge is shared by more than two of its triangles");
    }
    if (open) {
      ++r.openCells;
      if (openUnclamped) err(name + ": not closed (its boundary has free, unclamped edges)");
      else r.warnings.push_back(name + ": open, but its rim is clamped");
    }
    if (!open && !misoriented && vol[c] <= 0)
      err(name + ": non-positive volume " + std::to_string(vol[c]) +
          " µm³ (walls wound inward?)");
  }
  return r;
}

}  // namespace tp
