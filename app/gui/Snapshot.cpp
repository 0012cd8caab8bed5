#include "Snapshot.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>
#include <utility>

namespace tp::gui {

std::vector<std::uint32_t> wallOutlineEdges(const CellComplex& cc, int* outerEdges) {
  // Count each undirected edge within its wall; an edge used once is on the wall's boundary.
  std::vector<std::vector<int>> wallTriangles(cc.walls.size());
  for (int t = 0; t < cc.triangleCount(); ++t) wallTriangles[cc.triangleWall[t]].push_back(t);
  // (outer flag inverted, a, b): sorting puts the edges of outer walls first.
  std::vector<std::tuple<int, int, int>> boundary;
  std::vector<std::pair<int, int>> edges;
  for (size_t w = 0; w < wallTriangles.size(); ++w) {
    const auto& tris = wallTriangles[w];
    const int inner = cc.walls[w].neighbor >= 0 ? 1 : 0;
    edges.clear();
    for (int t : tris)
      for (int k = 0; k < 3; ++k) {
        const int a = cc.triangles[t][k], b = cc.triangles[t][(k + 1) % 3];
        edges.emplace_back(std::min(a, b), std::max(a, b));
      }
    std::sort(edges.begin(), edges.end());
    for (size_t i = 0; i < edges.size();) {
      size_t j = i;
      while (j < edges.size() && edges[j] == edges[i]) ++j;
      if (j - i == 1) boundary.emplace_back(inner, edges[i].first, edges[i].second);
      i = j;
    }
  }
  // A junction edge bounds several walls: draw it once, as an outer edge if any of them is.
  std::sort(boundary.begin(), boundary.end());
  std::vector<std::uint32_t> out;
  out.reserve(2 * boundary.size());
  std::set<std::pair<int, int>> seen;
  int outer = 0;
  for (const auto& [inner, a, b] : boundary) {
    if (!seen.insert({a, b}).second) continue;
    if (!inner) ++outer;
    out.push_back(static_cast<std::uint32_t>(a));
    out.push_back(static_cast<std::uint32_t>(b));
  }
  if (outerEdges) *outerEdges = outer;
  return out;
}

std::vector<std::uint32_t> triangleEdges(const CellComplex& cc, int* outerEdges) {
  std::set<std::pair<int, int>> seen;
  std::vector<std::uint32_t> outer, inner;
  for (int pass = 0; pass < 2; ++pass)
    for (int t = 0; t < cc.triangleCount(); ++t) {
      if (cc.isOuterTriangle(t) != (pass == 0)) continue;
      for (int k = 0; k < 3; ++k) {
        const int a = cc.triangles[t][k], b = cc.triangles[t][(k + 1) % 3];
        if (!seen.insert(std::minmax(a, b)).second) continue;
        auto& out = pass == 0 ? outer : inner;
        out.push_back(static_cast<std::uint32_t>(a));
        out.push_back(static_cast<std::uint32_t>(b));
      }
    }
  if (outerEdges) *outerEdges = static_cast<int>(outer.size() / 2);
  outer.insert(outer.end(), inner.begin(), inner.end());
  return outer;
}

std::shared_ptr<const TissueGeometry> makeTissueGeometry(const CellComplex& cc, int generation,
                                                         const std::string& path, double cellSize,
                                                         int meshLevel) {
  auto g = std::make_shared<TissueGeometry>();
  g->generation = generation;
  g->path = path;
  const int T = cc.triangleCount();
  g->triangles.reserve(3 * T);
  g->triangleCell.resize(T);
  g->triangleNeighbor.resize(T);
  g->outer.resize(T);
  g->clampedTriangle.resize(T);
  for (int t = 0; t < T; ++t) {
    const auto& tri = cc.triangles[t];
    for (int k = 0; k < 3; ++k) g->triangles.push_back(static_cast<std::uint32_t>(tri[k]));
    const Wall& w = cc.walls[cc.triangleWall[t]];
    g->triangleCell[t] = w.cell;
    g->triangleNeighbor[t] = w.neighbor;
    g->outer[t] = cc.isOuterTriangle(t) ? 1 : 0;
    g->clampedTriangle[t] = cc.fixed[tri[0]] && cc.fixed[tri[1]] && cc.fixed[tri[2]];
  }
  g->clampedVertex = cc.fixed;
  g->vertexWall.assign(cc.vertexCount(), -2);  // −2: no triangle seen yet
  for (int t = 0; t < T; ++t)
    for (int k = 0; k < 3; ++k) {
      int& w = g->vertexWall[cc.triangles[t][k]];
      const int wall = cc.triangleWall[t];
      w = w == -2 ? wall : (w == wall ? w : -1);
    }
  for (int& w : g->vertexWall) w = std::max(w, -1);
  g->outlineEdges = wallOutlineEdges(cc, &g->outerOutlineEdges);
  g->cellLabels = cc.cellLabels;
  g->meanCellSize = cellSize;
  g->meshEdges = triangleEdges(cc, &g->outerMeshEdges);
  g->rest.assign(cc.rest.data(), cc.rest.data() + cc.rest.size());
  g->meshLevel = meshLevel;
  return g;
}

}  // namespace tp::gui
