#include "tissue/Voronoi.h"

#include <voro++.hh>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

namespace tp {

namespace {

struct RawWall {
  std::vector<int> loop;  // global vertex ids, wound outward from `cell`
  int cell = -1;          // real seed index
  int neighbor = -1;      // real seed index, or −1 for a ghost
  BoundaryKind kind = BoundaryKind::Surface;
};

// Welds points closer than tol through a hash grid of cell size tol.
class Welder {
 public:
  explicit Welder(double tol) : tol_(tol) {}
  int add(const Vec3& p) {
    const long long ix = std::llround(std::floor(p.x() / tol_));
    const long long iy = std::llround(std::floor(p.y() / tol_));
    const long long iz = std::llround(std::floor(p.z() / tol_));
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dz = -1; dz <= 1; ++dz) {
          const auto it = grid_.find(key(ix + dx, iy + dy, iz + dz));
          if (it == grid_.end()) continue;
          for (int id : it->second)
            if ((points_[id] - p).norm() < tol_) return id;
        }
    const int id = static_cast<int>(points_.size());
    points_.push_back(p);
    grid_[key(ix, iy, iz)].push_back(id);
    return id;
  }
  std::vector<Vec3>& points() { return points_; }

 private:
  static long long key(long long x, long long y, long long z) {
    return (x * 73856093LL) ^ (y * 19349663LL) ^ (z * 83492791LL);
  }
  double tol_;
  std::vector<Vec3> points_;
  std::unordered_map<long long, std::vector<int>> grid_;
};

Vec3 newellNormal(const std::vector<Vec3>& P, const std::vector<int>& loop) {
  Vec3 n = Vec3::Zero();
  for (size_t i = 0; i < loop.size(); ++i) n += P[loop[i]].cross(P[loop[(i + 1) % loop.size()]]);
  return n;
}

void removeRepeats(std::vector<int>& loop) {
  std::vector<int> out;
  for (int v : loop)
    if (out.empty() || out.back() != v) out.push_back(v);
  while (out.size() > 1 && out.front() == out.back()) out.pop_back();
  loop.swap(out);
}

// A voro++ container holding the seeds (ids 0..n-1) and the ghosts (ids n..).
std::unique_ptr<voro::container> makeContainer(const std::vector<Vec3>& seeds,
                                               const std::vector<Vec3>& ghosts, double* diagOut) {
  Vec3 lo = seeds[0], hi = seeds[0];
  for (const auto& p : seeds) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  for (const auto& p : ghosts) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const double diag = (hi - lo).norm();
  lo.array() -= 0.05 * diag + 1.0;
  hi.array() += 0.05 * diag + 1.0;
  const int total = static_cast<int>(seeds.size() + ghosts.size());
  const Vec3 ext = hi - lo;
  const double blockSize = std::cbrt(ext.prod() / std::max(1, total) * 5.0);
  auto blocks = [&](double e) { return std::max(1, static_cast<int>(e / blockSize)); };
  auto con = std::make_unique<voro::container>(lo.x(), hi.x(), lo.y(), hi.y(), lo.z(), hi.z(),
                                               blocks(ext.x()), blocks(ext.y()), blocks(ext.z()),
                                               false, false, false, 8);
  const int n = static_cast<int>(seeds.size());
  for (int i = 0; i < n; ++i) con->put(i, seeds[i].x(), seeds[i].y(), seeds[i].z());
  for (size_t g = 0; g < ghosts.size(); ++g)
    con->put(n + static_cast<int>(g), ghosts[g].x(), ghosts[g].y(), ghosts[g].z());
  if (diagOut) *diagOut = diag;
  return con;
}

}  // namespace

void voronoiCentroids(const std::vector<Vec3>& seeds, const std::vector<Vec3>& ghosts,
                      std::vector<Vec3>& centroids, std::vector<double>& volumes) {
  const int n = static_cast<int>(seeds.size());
  if (n == 0) throw std::invalid_argument("no seeds");
  auto con = makeContainer(seeds, ghosts, nullptr);
  centroids.assign(n, Vec3::Zero());
  volumes.assign(n, -1.0);
  voro::c_loop_all loop(*con);
  voro::voronoicell_neighbor cell;
  std::vector<int> neigh;
  if (loop.start()) do {
      const int id = loop.pid();
      if (id >= n || !con->compute_cell(cell, loop)) continue;
      cell.neighbors(neigh);
      for (int o : neigh)
        if (o < 0)
          throw std::runtime_error("cell of seed " + std::to_string(id) +
                                   " is not enclosed by the closing surface");
      double x, y, z, cx, cy, cz;
      loop.pos(x, y, z);
      cell.centroid(cx, cy, cz);
      centroids[id] = Vec3(x + cx, y + cy, z + cz);
      volumes[id] = cell.volume();
    } while (loop.inc());
  for (int i = 0; i < n; ++i)
    if (volumes[i] < 0) throw std::runtime_error("seed " + std::to_string(i) + " has no cell");
}

namespace {

// The walls of the Voronoi cells before they become a CellComplex: the stages of
// buildVoronoiTissue below pass it along.
struct RawTissue {
  std::vector<Vec3> points;    // welded Voronoi vertices (µm)
  std::vector<RawWall> walls;  // each wound outward from its cell
  std::vector<int> flags;      // per point: kSurface | kBase
  static constexpr int kSurface = 1, kBase = 2;
};

// Stage 1: every real cell from voro++, its faces wound outward, vertices welded across cells;
// each inner wall once (from its lower seed), each boundary wall with its ghost's kind.
RawTissue computeCells(const std::vector<Vec3>& seeds, const std::vector<int>& labels,
                       const std::vector<Vec3>& ghosts,
                       const std::vector<BoundaryKind>& ghostKinds) {
  const int n = static_cast<int>(seeds.size());
  double diag = 0;
  auto conPtr = makeContainer(seeds, ghosts, &diag);
  voro::container& con = *conPtr;
  Welder welder(1e-8 * diag);
  RawTissue raw;
  std::vector<int> seen(n, 0);
  voro::c_loop_all loop(con);
  voro::voronoicell_neighbor cell;
  std::vector<double> verts;
  std::vector<int> faceVerts, neigh;
  if (loop.start()) do {
      const int id = loop.pid();
      if (id >= n) continue;
      if (!con.compute_cell(cell, loop))
        throw std::runtime_error("voro++ could not compute the cell of seed " + std::to_string(id));
      seen[id] = 1;
      double x, y, z;
      loop.pos(x, y, z);
      cell.vertices(x, y, z, verts);
      cell.face_vertices(faceVerts);
      cell.neighbors(neigh);
      std::vector<int> ids(verts.size() / 3);
      for (size_t v = 0; v < ids.size(); ++v)
        ids[v] = welder.add(Vec3(verts[3 * v], verts[3 * v + 1], verts[3 * v + 2]));
      size_t k = 0;
      for (size_t f = 0; f < neigh.size(); ++f) {
        const int count = faceVerts[k++];
        std::vector<int> faceLoop(count);
        for (int j = 0; j < count; ++j) faceLoop[j] = ids[faceVerts[k++]];
        const int other = neigh[f];
        if (other < 0)
          throw std::runtime_error("cell " + std::to_string(labels.empty() ? id + 1 : labels[id]) +
                                   " is not enclosed by the closing surface (it reaches the "
                                   "bounding box)");
        if (other < n && other < id) continue;  // each inner wall once, from its lower seed
        RawWall w;
        w.loop = std::move(faceLoop);
        w.cell = id;
        w.neighbor = other < n ? other : -1;
        if (other >= n) w.kind = ghostKinds[other - n];
        raw.walls.push_back(std::move(w));
      }
    } while (loop.inc());
  for (int i = 0; i < n; ++i)
    if (!seen[i])
      throw std::runtime_error("seed " + std::to_string(i) + " lies outside the bounding box");

  raw.points = std::move(welder.points());
  const std::vector<Vec3>& P = raw.points;
  for (auto& w : raw.walls) {
    removeRepeats(w.loop);
    // Wind outward from the cell: its seed lies on the inner side of the (convex) cell's face.
    if (w.loop.size() >= 3) {
      Vec3 c = Vec3::Zero();
      for (int v : w.loop) c += P[v];
      c /= static_cast<double>(w.loop.size());
      if (newellNormal(P, w.loop).dot(c - seeds[w.cell]) < 0) std::reverse(w.loop.begin(), w.loop.end());
    }
  }
  // Vertex flags: kSurface on the outer surface, kBase on the base (both on its rim).
  raw.flags.assign(P.size(), 0);
  for (const auto& w : raw.walls)
    if (w.neighbor < 0)
      for (int v : w.loop) raw.flags[v] |= w.kind == BoundaryKind::Base ? RawTissue::kBase : RawTissue::kSurface;
  return raw;
}

// Union-find over points, with path halving.
struct Merges {
  std::vector<int> parent;
  explicit Merges(int count) : parent(count) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  }
};

// Would merging a and b pinch a wall (a and b in one wall but not adjacent there, so that the
// loop would touch itself), or fold two edges onto one (a vertex adjacent to both that does not
// close a triangular wall a-b-c, which the collapse removes: the link condition)?
bool collapseWouldFold(const RawTissue& raw, const std::vector<std::vector<int>>& vertexWalls,
                       Merges& m, int a, int b) {
  for (int w : vertexWalls[a]) {
    const auto& lp = raw.walls[w].loop;
    const int size = static_cast<int>(lp.size());
    std::vector<int> pos;
    for (int i = 0; i < size; ++i) {
      const int r = m.find(lp[i]);
      if (r == a || r == b) pos.push_back(i);
    }
    // Positions of a and b (after earlier merges) must form one run around the loop.
    if (pos.size() >= 2) {
      int runs = 0;
      for (size_t q = 0; q < pos.size(); ++q) {
        const int rp = m.find(lp[(pos[q] + size - 1) % size]);
        if (rp != a && rp != b) ++runs;
      }
      if (runs > 1) return true;
    }
  }
  auto neighbours = [&](int v, std::vector<int>& out, std::vector<int>& tri) {
    for (int w : vertexWalls[v]) {
      std::vector<int> lp;
      for (int x : raw.walls[w].loop) {
        const int r = m.find(x);
        if (lp.empty() || lp.back() != r) lp.push_back(r);
      }
      while (lp.size() > 1 && lp.front() == lp.back()) lp.pop_back();
      const int size = static_cast<int>(lp.size());
      for (int i = 0; i < size; ++i)
        if (lp[i] == v) {
          out.push_back(lp[(i + 1) % size]);
          out.push_back(lp[(i + size - 1) % size]);
        }
      if (size == 3) tri.insert(tri.end(), lp.begin(), lp.end());
    }
  };
  std::vector<int> na, nb, tri, dummy;
  neighbours(a, na, tri);
  neighbours(b, nb, dummy);
  for (int c : na) {
    if (c == a || c == b || std::find(nb.begin(), nb.end(), c) == nb.end()) continue;
    bool closesTriangle = false;
    for (size_t t = 0; t + 2 < tri.size() && !closesTriangle; t += 3) {
      const int* q = &tri[t];
      const bool hasA = q[0] == a || q[1] == a || q[2] == a;
      const bool hasB = q[0] == b || q[1] == b || q[2] == b;
      const bool hasC = q[0] == c || q[1] == c || q[2] == c;
      closesTriangle = hasA && hasB && hasC;
    }
    if (!closesTriangle) return true;
  }
  return false;
}

// Stage 2: collapse edges shorter than `length` (Voronoi slivers from nearly co-spherical
// seeds), shortest first, unless the collapse would fold the walls. A collapse keeps the
// position of the end with more flags, so the boundary stays where it is.
void collapseShortEdges(RawTissue& raw, double length, VoronoiReport& rep) {
  std::vector<Vec3>& P = raw.points;
  const int V = static_cast<int>(P.size());
  auto flagCount = [](int k) { return (k & 1) + ((k >> 1) & 1); };
  Merges m(V);
  std::vector<std::vector<int>> vertexWalls(V);
  for (size_t w = 0; w < raw.walls.size(); ++w)
    for (int v : raw.walls[w].loop) vertexWalls[v].push_back(static_cast<int>(w));
  std::vector<std::pair<double, std::pair<int, int>>> edges;
  for (const auto& w : raw.walls)
    for (size_t i = 0; i < w.loop.size(); ++i) {
      const int a = w.loop[i], b = w.loop[(i + 1) % w.loop.size()];
      const double len = (P[a] - P[b]).norm();
      if (a < b && len < length) edges.push_back({len, {a, b}});
    }
  std::sort(edges.begin(), edges.end());
  for (const auto& [len0, ab] : edges) {
    const int a = m.find(ab.first), b = m.find(ab.second);
    if (a == b || (P[a] - P[b]).norm() >= length) continue;
    if (collapseWouldFold(raw, vertexWalls, m, a, b)) {
      ++rep.skippedCollapses;
      continue;
    }
    Vec3 merged = 0.5 * (P[a] + P[b]);
    if (flagCount(raw.flags[a]) > flagCount(raw.flags[b])) merged = P[a];
    if (flagCount(raw.flags[b]) > flagCount(raw.flags[a])) merged = P[b];
    m.parent[b] = a;
    P[a] = merged;
    raw.flags[a] |= raw.flags[b];
    vertexWalls[a].insert(vertexWalls[a].end(), vertexWalls[b].begin(), vertexWalls[b].end());
    ++rep.collapsedEdges;
  }
  for (auto& w : raw.walls) {
    for (int& v : w.loop) v = m.find(v);
    removeRepeats(w.loop);
  }
}

void dropDegenerateWalls(RawTissue& raw) {
  raw.walls.erase(std::remove_if(raw.walls.begin(), raw.walls.end(),
                                 [](const RawWall& w) { return w.loop.size() < 3; }),
                  raw.walls.end());
}

// Stage 3: a vertex with only two neighbours (left where a wall between two others vanished)
// is a kink in the middle of their common boundary: drop it, or both walls would triangulate
// the same sliver there and overlap. Repeated until none is left.
void dissolveKinks(RawTissue& raw, VoronoiReport& rep) {
  const int V = static_cast<int>(raw.points.size());
  for (bool changed = true; changed;) {
    changed = false;
    std::vector<std::vector<int>> nbr(V);
    for (const auto& w : raw.walls)
      for (size_t i = 0; i < w.loop.size(); ++i) {
        const int a = w.loop[i], b = w.loop[(i + 1) % w.loop.size()];
        nbr[a].push_back(b);
        nbr[b].push_back(a);
      }
    std::vector<char> drop(V, 0);
    for (int v = 0; v < V; ++v) {
      auto& l = nbr[v];
      std::sort(l.begin(), l.end());
      l.erase(std::unique(l.begin(), l.end()), l.end());
      if (l.size() == 2) drop[v] = 1;
    }
    for (auto& w : raw.walls) {
      const size_t m = w.loop.size();
      w.loop.erase(std::remove_if(w.loop.begin(), w.loop.end(), [&](int v) { return drop[v]; }),
                   w.loop.end());
      if (w.loop.size() != m) changed = true;
    }
    if (changed) {
      ++rep.dissolvedVertices;
      dropDegenerateWalls(raw);
    }
  }
}

// Stage 4: the cell complex: the used points compacted, the boundary put on the smooth
// surface and the base plane (clamped), each wall triangulated avoiding diagonals between two
// vertices that another wall of the same cell also holds (two walls would then share an inner
// edge and the cell's surface would fold).
CellComplex assembleComplex(RawTissue& raw, int cells, const std::vector<int>& labels,
                            const VoronoiOptions& options) {
  const int V = static_cast<int>(raw.points.size());
  std::vector<int> remap(V, -1);
  int count = 0;
  for (auto& w : raw.walls)
    for (int& v : w.loop) {
      if (remap[v] < 0) remap[v] = count++;
      v = remap[v];
    }
  CellComplex cc;
  cc.rest.resize(3, count);
  cc.fixed.assign(count, 0);
  for (int v = 0; v < V; ++v) {
    if (remap[v] < 0) continue;
    Vec3 p = raw.points[v];
    if ((raw.flags[v] & RawTissue::kSurface) && options.projectToSurface) p = options.projectToSurface(p);
    if (raw.flags[v] & RawTissue::kBase) {
      p.z() = options.baseZ;
      cc.fixed[remap[v]] = 1;
    }
    cc.rest.col(remap[v]) = p;
  }
  cc.cellLabels.resize(cells);
  for (int i = 0; i < cells; ++i) cc.cellLabels[i] = labels.empty() ? i + 1 : labels[i];
  const auto& walls = raw.walls;
  std::vector<std::vector<int>> wallsOf(count);
  for (size_t w = 0; w < walls.size(); ++w)
    for (int v : walls[w].loop) wallsOf[v].push_back(static_cast<int>(w));
  auto shareCell = [](const RawWall& x, const RawWall& y) {
    return x.cell == y.cell || x.cell == y.neighbor ||
           (x.neighbor >= 0 && (x.neighbor == y.cell || x.neighbor == y.neighbor));
  };
  for (size_t w = 0; w < walls.size(); ++w) {
    const DiagonalFilter filter = [&](int u, int v) {
      for (int o : wallsOf[u])
        if (o != static_cast<int>(w) && shareCell(walls[o], walls[w]) &&
            std::find(wallsOf[v].begin(), wallsOf[v].end(), o) != wallsOf[v].end())
          return false;
      return true;
    };
    cc.addWall(triangulatePolygon(cc.rest, walls[w].loop, filter), walls[w].cell,
               walls[w].neighbor, walls[w].loop);
  }
  return cc;
}

}  // namespace

CellComplex buildVoronoiTissue(const std::vector<Vec3>& seeds, const std::vector<int>& labels,
                               const std::vector<Vec3>& ghosts,
                               const std::vector<BoundaryKind>& ghostKinds,
                               const VoronoiOptions& options, VoronoiReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  const int n = static_cast<int>(seeds.size());
  if (n == 0) throw std::invalid_argument("no seeds");
  if (!labels.empty() && static_cast<int>(labels.size()) != n)
    throw std::invalid_argument("one label per seed expected");
  if (ghostKinds.size() != ghosts.size()) throw std::invalid_argument("one kind per ghost expected");

  RawTissue raw = computeCells(seeds, labels, ghosts, ghostKinds);
  VoronoiReport rep;
  if (options.collapseLength > 0) collapseShortEdges(raw, options.collapseLength, rep);
  const size_t before = raw.walls.size();
  dropDegenerateWalls(raw);
  dissolveKinks(raw, rep);
  rep.removedWalls = static_cast<int>(before - raw.walls.size());
  CellComplex cc = assembleComplex(raw, n, labels, options);
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (report) *report = rep;
  return cc;
}

std::vector<std::pair<int, int>> wallAdjacency(const CellComplex& cc, double minArea) {
  std::map<std::pair<int, int>, double> area;
  const auto a = triangleAreas(cc, cc.rest);
  for (int t = 0; t < cc.triangleCount(); ++t) {
    const Wall& w = cc.walls[cc.triangleWall[t]];
    if (w.cell < 0 || w.neighbor < 0) continue;
    area[std::minmax(w.cell, w.neighbor)] += a[t];
  }
  std::vector<std::pair<int, int>> out;
  for (const auto& [pair, ar] : area)
    if (ar > minArea) out.push_back(pair);
  return out;
}

}  // namespace tp
