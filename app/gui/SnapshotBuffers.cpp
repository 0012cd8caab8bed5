#include "SnapshotBuffers.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace tp::gui {

void SnapshotBuffers::build(const Snapshot& s, Field field, const ColorMap& map) {
  static const std::vector<float> none;
  build(s, s.empty() ? none : s.fields[static_cast<int>(field)], map);
}

void SnapshotBuffers::build(const Snapshot& s, const std::vector<float>& values,
                            const ColorMap& map) {
  triangles_.clear();
  lines_.clear();
  mesh_.clear();
  glyphs_.clear();
  contact_.clear();
  outerGlyphVertices_ = 0;
  outerTriangleVertices_ = outerLineVertices_ = outerMeshVertices_ = 0;
  points_.clear();
  bounds_.setEmpty();
  if (s.empty()) return;
  const TissueGeometry& g = *s.geometry;
  const auto& x = s.positions;
  auto vertex = [&](std::uint32_t v) {
    return Eigen::Vector3f(x[3 * v], x[3 * v + 1], x[3 * v + 2]);
  };
  for (int v = 0; v < g.vertexCount(); ++v) bounds_.extend(vertex(v).cast<double>());

  const int T = g.triangleCount();
  triangles_.resize(static_cast<size_t>(T) * 3 * kTriangleStride);
  float* out = triangles_.data();
  std::vector<int> order;  // outer triangles first
  order.reserve(T);
  for (int t = 0; t < T; ++t)
    if (g.outer[t]) order.push_back(t);
  outerTriangleVertices_ = 3 * static_cast<int>(order.size());
  for (int t = 0; t < T; ++t)
    if (!g.outer[t]) order.push_back(t);
  // Smooth shading inside each wall: at a vertex all of whose triangles are of one wall, the
  // area-weighted mean of their normals (Gouraud's vertex normal); on outlines the triangle's own.
  // The triangles of a wall are wound alike (core/mesh/CellComplex.h), so their normals agree.
  const bool smooth = g.vertexWall.size() == static_cast<size_t>(g.vertexCount());
  std::vector<Eigen::Vector3f> vertexNormal(smooth ? g.vertexCount() : 0, Eigen::Vector3f::Zero());
  if (smooth)
    for (int t = 0; t < T; ++t) {
      const std::uint32_t* v = &g.triangles[3 * t];
      const Eigen::Vector3f n = (vertex(v[1]) - vertex(v[0])).cross(vertex(v[2]) - vertex(v[0]));
      for (int k = 0; k < 3; ++k)
        if (g.vertexWall[v[k]] >= 0) vertexNormal[v[k]] += n;  // |n| = twice the area
    }
  for (int t : order) {
    const Eigen::Vector3f a = vertex(g.triangles[3 * t]), b = vertex(g.triangles[3 * t + 1]),
                          c = vertex(g.triangles[3 * t + 2]);
    Eigen::Vector3f n = (b - a).cross(c - a);
    const float len = n.norm();
    n = len > 0 ? Eigen::Vector3f(n / len) : Eigen::Vector3f::UnitZ();
    Eigen::Vector3f corner[3] = {n, n, n};
    if (smooth)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = g.triangles[3 * t + k];
        const float m = vertexNormal[v].norm();
        if (g.vertexWall[v] >= 0 && m > 0) corner[k] = vertexNormal[v] / m;
      }
    const double value =
        t < static_cast<int>(values.size()) ? values[t] : std::numeric_limits<double>::quiet_NaN();
    const Eigen::Vector3f rgb = map.color(value);
    const float flags = float((g.clampedTriangle[t] ? kClamped : 0) | (g.outer[t] ? kOuter : 0));
    const Eigen::Vector3f* corners[3] = {&a, &b, &c};
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f* p = corners[k];
      out[0] = p->x(), out[1] = p->y(), out[2] = p->z();
      out[3] = corner[k].x(), out[4] = corner[k].y(), out[5] = corner[k].z();
      out[6] = rgb.x(), out[7] = rgb.y(), out[8] = rgb.z();
      out[9] = float(g.triangleCell[t]), out[10] = float(g.triangleNeighbor[t]);
      out[11] = flags;
      out += kTriangleStride;
    }
  }

  if (s.principalAxes.size() == 3 * static_cast<size_t>(T)) {
    std::vector<float> magnitude(T);
    for (int t = 0; t < T; ++t)
      magnitude[t] = Eigen::Map<const Eigen::Vector3f>(&s.principalAxes[3 * t]).norm();
    std::vector<float> sorted = magnitude;
    const size_t k = static_cast<size_t>(0.995 * (T - 1));
    std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
    const float top = sorted[k];
    glyphs_.reserve(6 * static_cast<size_t>(T));
    for (size_t i = 0; i < order.size(); ++i) {
      const int t = order[i];
      if (static_cast<int>(i) * 3 == outerTriangleVertices_) outerGlyphVertices_ = glyphVertexCount();
      if (!(top > 0) || !(magnitude[t] > 0)) continue;
      const Eigen::Vector3f a = vertex(g.triangles[3 * t]), b = vertex(g.triangles[3 * t + 1]),
                            c = vertex(g.triangles[3 * t + 2]);
      const float area = 0.5f * (b - a).cross(c - a).norm();
      const Eigen::Vector3f d = Eigen::Map<const Eigen::Vector3f>(&s.principalAxes[3 * t]);
      const float half = 0.4f * std::sqrt(area) * std::min(1.0f, magnitude[t] / top);
      const Eigen::Vector3f m = (a + b + c) / 3.0f, p = m - half * d / magnitude[t],
                            q = m + half * d / magnitude[t];
      glyphs_.insert(glyphs_.end(), {p.x(), p.y(), p.z(), q.x(), q.y(), q.z()});
    }
    if (3 * static_cast<int>(order.size()) == outerTriangleVertices_)
      outerGlyphVertices_ = glyphVertexCount();  // every triangle is outer
  }

  // The contact patch's boundary: each edge of a pressed triangle, once per pressed triangle
  // using it; those used once bound the patch.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> patchEdges;
  for (int t : s.contactTriangles) {
    if (t < 0 || t >= T) continue;
    for (int k = 0; k < 3; ++k)
      ++patchEdges[std::minmax(g.triangles[3 * t + k], g.triangles[3 * t + (k + 1) % 3])];
  }
  for (const auto& [edge, uses] : patchEdges)
    if (uses == 1)
      for (std::uint32_t v : {edge.first, edge.second}) {
        const Eigen::Vector3f p = vertex(v);
        contact_.insert(contact_.end(), {p.x(), p.y(), p.z()});
      }

  lines_.reserve(g.outlineEdges.size() * 3);
  outerLineVertices_ = 2 * g.outerOutlineEdges;
  for (std::uint32_t v : g.outlineEdges) {
    const Eigen::Vector3f p = vertex(v);
    lines_.insert(lines_.end(), {p.x(), p.y(), p.z()});
  }
  mesh_.reserve(g.meshEdges.size() * 3);
  outerMeshVertices_ = 2 * g.outerMeshEdges;
  for (std::uint32_t v : g.meshEdges) {
    const Eigen::Vector3f p = vertex(v);
    mesh_.insert(mesh_.end(), {p.x(), p.y(), p.z()});
  }
  for (int v = 0; v < g.vertexCount(); ++v)
    if (g.clampedVertex[v]) {
      const Eigen::Vector3f p = vertex(v);
      points_.insert(points_.end(), {p.x(), p.y(), p.z()});
    }
}

std::vector<float> unitSphereMesh(int subdivisions) {
  // Icosahedron: the 12 vertices (0, ±1, ±φ) cyclically permuted, then 4:1 splits projected out.
  const float p = 0.5f * (1.0f + std::sqrt(5.0f));
  std::vector<Eigen::Vector3f> v = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0},
                                    {0, -1, p}, {0, 1, p}, {0, -1, -p}, {0, 1, -p},
                                    {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  for (auto& q : v) q.normalize();
  std::vector<Eigen::Vector3i> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return mid[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<Eigen::Vector3i> next;
    next.reserve(4 * f.size());
    for (const auto& t : f) {
      const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      next.insert(next.end(), {{t[0], ab, ca}, {t[1], bc, ab}, {t[2], ca, bc}, {ab, bc, ca}});
    }
    f.swap(next);
  }
  std::vector<float> out;
  out.reserve(f.size() * 18);
  for (auto t : f) {
    // Wind every face counter-clockwise seen from outside (for back-face culling).
    if ((v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).dot(v[t[0]]) < 0) std::swap(t[1], t[2]);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f& q = v[t[k]];
      out.insert(out.end(), {q.x(), q.y(), q.z(), q.x(), q.y(), q.z()});
    }
  }
  return out;
}

AutoRange autoRange(const Snapshot& s, Field field, bool diverging) {
  // Absolute fields (stress, energy density): the 0.1 % of triangles at either end do not set
  // the range, so that a few slivers (75 MPa on the real flower against 15 MPa around them) do
  // not paint the whole tissue one colour. Changes from the turgid state and displacements keep
  // their extremes: there the few triangles under the probe are the signal.
  const bool robust = !quantityInfo(field).change && field != Field::Displacement;
  return autoRange(s.fields[static_cast<int>(field)], robust, diverging);
}

AutoRange autoRange(const std::vector<float>& values, bool robust, bool diverging) {
  std::vector<float> v;
  v.reserve(values.size());
  for (float x : values)
    if (std::isfinite(x)) v.push_back(x);
  AutoRange r;
  if (v.empty()) return r;
  const auto [mn, mx] = std::minmax_element(v.begin(), v.end());
  r.dataLo = *mn;
  r.dataHi = *mx;
  double lo = r.dataLo, hi = r.dataHi;
  const std::size_t k = robust ? v.size() / 1000 : 0;
  if (k > 0) {
    std::nth_element(v.begin(), v.begin() + k, v.end());
    lo = v[k];
    std::nth_element(v.begin(), v.end() - 1 - k, v.end());
    hi = v[v.size() - 1 - k];
  }
  // Numerical noise (stresses of 1e-11 MPa without pressure) is not coloured as a signal.
  if (std::max(std::abs(lo), std::abs(hi)) < kNoiseFloor) {
    lo = lo < 0 || diverging ? -kNoiseFloor : 0.0;
    hi = kNoiseFloor;
  } else if (diverging && lo < 0 && hi > 0) {
    const double m = std::max(-lo, hi);
    lo = -m;
    hi = m;
  }
  r.lo = lo;
  r.hi = hi;
  return r;
}

}  // namespace tp::gui
