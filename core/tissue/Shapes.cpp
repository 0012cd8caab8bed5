#include "tissue/Shapes.h"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <stdexcept>

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

namespace tp {

CellComplex latticeDisc(double a, int rings, double clampedWidth, int cell) {
  if (rings < 1 || !(a > 0) || clampedWidth < 0)
    throw std::invalid_argument("latticeDisc: need a > 0, rings >= 1, clampedWidth >= 0");
  const double l = a / rings;
  const Eigen::Vector2d e1(l, 0), e2(0.5 * l, 0.5 * std::sqrt(3.0) * l);
  const double rGen = a + clampedWidth + 2 * l;
  const int N = static_cast<int>(std::ceil(2 * rGen / l)) + 2;
  std::map<std::pair<int, int>, int> index;
  std::vector<Vec3> pts;
  std::vector<std::uint8_t> fixed;
  auto add = [&](int i, int j) {
    Eigen::Vector2d p = i * e1 + j * e2;
    const double r = p.norm();
    if (r > rGen) return;
    if (std::abs(r - a) < l / 3) p *= a / r;  // snap the rim band onto the circle
    index[{i, j}] = static_cast<int>(pts.size());
    pts.emplace_back(p.x(), p.y(), 0.0);
    fixed.push_back(p.norm() >= a * (1 - 1e-12) ? 1 : 0);
  };
  add(0, 0);
  for (int j = -N; j <= N; ++j)
    for (int i = -N; i <= N; ++i)
      if (i != 0 || j != 0) add(i, j);
  std::vector<Eigen::Vector3i> tris;
  auto tryTri = [&](std::pair<int, int> A, std::pair<int, int> B, std::pair<int, int> C) {
    const auto ia = index.find(A), ib = index.find(B), ic = index.find(C);
    if (ia == index.end() || ib == index.end() || ic == index.end()) return;
    const int v[3] = {ia->second, ib->second, ic->second};
    const bool anyFree = !fixed[v[0]] || !fixed[v[1]] || !fixed[v[2]];
    const double rc = ((pts[v[0]] + pts[v[1]] + pts[v[2]]) / 3).norm();
    if (clampedWidth > 0 ? rc <= a + clampedWidth : anyFree) tris.emplace_back(v[0], v[1], v[2]);
  };
  for (int j = -N; j < N; ++j)
    for (int i = -N; i < N; ++i) {
      tryTri({i, j}, {i + 1, j}, {i, j + 1});
      tryTri({i + 1, j}, {i + 1, j + 1}, {i, j + 1});
    }
  // Keep only the vertices the triangles use (vertex 0, the centre, stays first).
  std::vector<int> remap(pts.size(), -1);
  remap[0] = 0;
  int count = 1;
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k)
      if (remap[t[k]] < 0) remap[t[k]] = count++;
  CellComplex cc;
  cc.rest.resize(3, count);
  cc.fixed.assign(count, 0);
  for (size_t v = 0; v < pts.size(); ++v)
    if (remap[v] >= 0) {
      cc.rest.col(remap[v]) = pts[v];
      cc.fixed[remap[v]] = fixed[v];
    }
  for (auto& t : tris) t = Eigen::Vector3i(remap[t[0]], remap[t[1]], remap[t[2]]);
  if (cell >= 0) {
    cc.cellLabels.resize(cell + 1);
    for (int c = 0; c <= cell; ++c) cc.cellLabels[c] = c;
  }
  cc.addWall(tris, cell, -1);
  return cc;
}

CellComplex delaunayDisc(double a, double spacing, unsigned seed, double clampedWidth, int cell) {
  if (!(a > 0) || !(spacing > 0) || spacing > a || clampedWidth < 0)
    throw std::invalid_argument("delaunayDisc: need 0 < spacing <= a, clampedWidth >= 0");
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, K>;
  using Tds = CGAL::Triangulation_data_structure_2<Vb>;
  using Delaunay = CGAL::Delaunay_triangulation_2<K, Tds>;
  std::vector<Eigen::Vector2d> pts{Eigen::Vector2d::Zero()};
  auto ring = [&](double r) {
    const int n = std::max(6, static_cast<int>(std::round(2 * std::numbers::pi * r / spacing)));
    for (int i = 0; i < n; ++i) {
      const double t = 2 * std::numbers::pi * i / n;
      pts.emplace_back(r * std::cos(t), r * std::sin(t));
    }
  };
  ring(a);
  const double outer = a + clampedWidth;
  if (clampedWidth > 0) ring(outer);
  // Dart throwing on a background grid of cell spacing/2 (at most one point per cell).
  const double minDist = 0.7 * spacing, cellSize = 0.5 * minDist;
  const int G = static_cast<int>(std::ceil(2 * outer / cellSize)) + 1;
  std::vector<int> grid(static_cast<size_t>(G) * G, -1);
  auto cellOf = [&](const Eigen::Vector2d& p) {
    return std::pair<int, int>(static_cast<int>((p.x() + outer) / cellSize),
                               static_cast<int>((p.y() + outer) / cellSize));
  };
  auto farEnough = [&](const Eigen::Vector2d& p) {
    const auto [ci, cj] = cellOf(p);
    for (int j = std::max(0, cj - 3); j <= std::min(G - 1, cj + 3); ++j)
      for (int i = std::max(0, ci - 3); i <= std::min(G - 1, ci + 3); ++i) {
        const int q = grid[static_cast<size_t>(j) * G + i];
        if (q >= 0 && (pts[q] - p).norm() < minDist) return false;
      }
    return true;
  };
  auto insert = [&](int q) {
    const auto [ci, cj] = cellOf(pts[q]);
    grid[static_cast<size_t>(cj) * G + ci] = q;
  };
  for (int q = 0; q < static_cast<int>(pts.size()); ++q) insert(q);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-outer, outer);
  const int tries = 40 * static_cast<int>(std::pow(outer / spacing, 2)) + 100;
  for (int k = 0; k < tries; ++k) {
    const Eigen::Vector2d p(u(rng), u(rng));
    const double r = p.norm();
    if (r > outer - 0.5 * minDist || std::abs(r - a) < 0.5 * minDist || !farEnough(p)) continue;
    pts.push_back(p);
    insert(static_cast<int>(pts.size()) - 1);
  }
  std::vector<std::pair<K::Point_2, int>> input;
  for (int q = 0; q < static_cast<int>(pts.size()); ++q)
    input.emplace_back(K::Point_2(pts[q].x(), pts[q].y()), q);
  Delaunay dt(input.begin(), input.end());
  CellComplex cc;
  cc.rest.resize(3, static_cast<int>(pts.size()));
  cc.fixed.assign(pts.size(), 0);
  for (size_t q = 0; q < pts.size(); ++q) {
    cc.rest.col(static_cast<int>(q)) = Vec3(pts[q].x(), pts[q].y(), 0.0);
    cc.fixed[q] = pts[q].norm() >= a * (1 - 1e-12) ? 1 : 0;
  }
  std::vector<Eigen::Vector3i> tris;
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    const int v[3] = {f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()};
    const bool anyFree = !cc.fixed[v[0]] || !cc.fixed[v[1]] || !cc.fixed[v[2]];
    if (clampedWidth > 0 || anyFree) tris.emplace_back(v[0], v[1], v[2]);  // CGAL: counter-clockwise
  }
  if (cell >= 0) {
    cc.cellLabels.resize(cell + 1);
    for (int c = 0; c <= cell; ++c) cc.cellLabels[c] = c;
  }
  cc.addWall(tris, cell, -1);
  return cc;
}

CellComplex octaSphere(double R, int level) {
  std::vector<Vec3> pts = {Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(),
                           -Vec3::UnitY(), Vec3::UnitZ(), -Vec3::UnitZ()};
  std::vector<Eigen::Vector3i> tris;
  for (int sx : {1, -1})
    for (int sy : {1, -1})
      for (int sz : {1, -1}) {
        const int X = sx > 0 ? 0 : 1, Y = sy > 0 ? 2 : 3, Z = sz > 0 ? 4 : 5;
        if (sx * sy * sz > 0) tris.emplace_back(X, Y, Z);
        else tris.emplace_back(X, Z, Y);
      }
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      pts.push_back((pts[a] + pts[b]).normalized());
      return mid[key] = static_cast<int>(pts.size()) - 1;
    };
    std::vector<Eigen::Vector3i> next;
    for (const auto& t : tris) {
      const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      next.emplace_back(t[0], ab, ca);
      next.emplace_back(ab, t[1], bc);
      next.emplace_back(ca, bc, t[2]);
      next.emplace_back(ab, bc, ca);
    }
    tris.swap(next);
  }
  CellComplex cc;
  cc.rest.resize(3, static_cast<int>(pts.size()));
  for (size_t i = 0; i < pts.size(); ++i) cc.rest.col(i) = R * pts[i].normalized();
  cc.fixed.assign(pts.size(), 0);
  cc.cellLabels = {0};
  cc.addWall(tris, 0, -1);
  return cc;
}

CellComplex sphericalCap(double R, double capRadius, int rings, int cell) {
  if (!(capRadius < R)) throw std::invalid_argument("sphericalCap: cap radius must be below R");
  CellComplex cc = latticeDisc(capRadius, rings, 0, cell);
  const double phiMax = std::asin(capRadius / R);
  for (int v = 0; v < cc.vertexCount(); ++v) {
    const double x = cc.rest(0, v), y = cc.rest(1, v);
    const double rho = std::hypot(x, y);
    const double phi = phiMax * rho / capRadius, th = std::atan2(y, x);
    cc.rest.col(v) = R * Vec3(std::sin(phi) * std::cos(th), std::sin(phi) * std::sin(th), std::cos(phi));
  }
  return cc;
}

CellComplex flatSheet(double width, double height, double spacing) {
  const int nx = std::max(2, static_cast<int>(std::round(width / spacing)) + 1);
  const double dy = spacing * std::sqrt(3.0) / 2.0;
  const int ny = std::max(2, static_cast<int>(std::round(height / dy)) + 1);
  CellComplex cc;
  cc.rest.resize(3, nx * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      cc.rest.col(j * nx + i) = Vec3(i * spacing + (j % 2) * 0.5 * spacing, j * dy, 0.0);
  cc.fixed.assign(nx * ny, 0);
  std::vector<Eigen::Vector3i> tris;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      if (j % 2 == 0) {
        tris.emplace_back(a, b, c);
        tris.emplace_back(b, d, c);
      } else {
        tris.emplace_back(a, d, c);
        tris.emplace_back(a, b, d);
      }
    }
  cc.addWall(tris, -1, -1);
  return cc;
}

CellComplex boxTissue(int nx, int ny, int nz, double size) {
  if (nx < 1 || ny < 1 || nz < 1 || !(size > 0)) throw std::invalid_argument("boxTissue: bad size");
  CellComplex cc;
  auto vid = [&](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
  auto cid = [&](int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz) return -1;
    return (k * ny + j) * nx + i;
  };
  const int V = (nx + 1) * (ny + 1) * (nz + 1);
  cc.rest.resize(3, V);
  cc.fixed.assign(V, 0);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        cc.rest.col(vid(i, j, k)) = Vec3(i * size, j * size, k * size);
        if (k == 0) cc.fixed[vid(i, j, k)] = 1;
      }
  cc.cellLabels.resize(nx * ny * nz);
  for (size_t c = 0; c < cc.cellLabels.size(); ++c) cc.cellLabels[c] = static_cast<int>(c) + 1;
  // A face between the cells below/behind (lo) and above/in front (hi) along `axis`.
  auto addFace = [&](std::vector<int> quad, int lo, int hi, int axis) {
    if (lo < 0 && hi < 0) return;
    const Vec3 n = (cc.rest.col(quad[1]) - cc.rest.col(quad[0]))
                       .cross(cc.rest.col(quad[2]) - cc.rest.col(quad[0]));
    const bool plus = n[axis] > 0;  // quad normal along +axis?
    int cell = lo, neighbor = hi;
    bool wantPlus = true;  // normal points out of `cell`
    if (lo < 0) {
      cell = hi;
      neighbor = -1;
      wantPlus = false;
    }
    if (plus != wantPlus) std::reverse(quad.begin(), quad.end());
    cc.addPolygonWall(quad, cell, neighbor);
  };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i <= nx; ++i)
        addFace({vid(i, j, k), vid(i, j + 1, k), vid(i, j + 1, k + 1), vid(i, j, k + 1)},
                cid(i - 1, j, k), cid(i, j, k), 0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i < nx; ++i)
        addFace({vid(i, j, k), vid(i + 1, j, k), vid(i + 1, j, k + 1), vid(i, j, k + 1)},
                cid(i, j - 1, k), cid(i, j, k), 1);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        addFace({vid(i, j, k), vid(i + 1, j, k), vid(i + 1, j + 1, k), vid(i, j + 1, k)},
                cid(i, j, k - 1), cid(i, j, k), 2);
  return cc;
}

}  // namespace tp
