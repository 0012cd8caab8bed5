#include "mesh/Topology.h"

#include <algorithm>
#include <cstdint>
#include <unordered_map>

namespace tp {

namespace {

Hinge makeHinge(const CellComplex& cc, int a, int b, int tA, int tB) {
  auto opposite = [&](int t) {
    const auto& tri = cc.triangles[t];
    for (int k = 0; k < 3; ++k)
      if (tri[k] != a && tri[k] != b) return tri[k];
    return -1;
  };
  // Order the edge as it runs in triangle A's winding, so A = (x0, x1, x2).
  const auto& tri = cc.triangles[tA];
  int x0 = a, x1 = b;
  for (int k = 0; k < 3; ++k)
    if (tri[k] == b && tri[(k + 1) % 3] == a) std::swap(x0, x1);
  Hinge h;
  h.v = {x0, x1, opposite(tA), opposite(tB)};
  h.triA = tA;
  h.triB = tB;
  return h;
}

}  // namespace

Topology buildTopology(const CellComplex& cc) {
  Topology topo;
  std::unordered_map<std::uint64_t, int> edgeIndex;
  edgeIndex.reserve(cc.triangles.size() * 2);
  topo.vertexTriangles.resize(cc.vertexCount());
  for (int t = 0; t < cc.triangleCount(); ++t) {
    const auto& tri = cc.triangles[t];
    for (int k = 0; k < 3; ++k) {
      topo.vertexTriangles[tri[k]].push_back(t);
      int a = tri[k], b = tri[(k + 1) % 3];
      if (a > b) std::swap(a, b);
      const std::uint64_t key = (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
      auto [it, inserted] = edgeIndex.emplace(key, static_cast<int>(topo.edges.size()));
      if (inserted) {
        topo.edges.push_back({a, b});
        topo.edgeTriangles.emplace_back();
      }
      topo.edgeTriangles[it->second].push_back(t);
    }
    if (cc.isOuterTriangle(t)) topo.outerTriangles.push_back(t);
  }
  for (size_t e = 0; e < topo.edges.size(); ++e) {
    const auto& tris = topo.edgeTriangles[e];
    const auto [a, b] = topo.edges[e];
    if (tris.size() == 2) {
      topo.hinges.push_back(makeHinge(cc, a, b, tris[0], tris[1]));
    } else if (tris.size() > 2) {
      std::vector<int> outer;
      for (int t : tris)
        if (cc.isOuterTriangle(t)) outer.push_back(t);
      if (outer.size() == 2) topo.hinges.push_back(makeHinge(cc, a, b, outer[0], outer[1]));
    }
  }
  return topo;
}

}  // namespace tp
