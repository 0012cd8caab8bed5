#include "Picking.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "Snapshot.h"

namespace tp::gui {

namespace {

constexpr int kLeafSize = 8;

bool rayHitsBox(const Ray& ray, const Eigen::Vector3d& inv, const Eigen::AlignedBox3f& box,
                double maxT) {
  // Slab test; inv = 1/direction (±inf for axis-parallel rays is fine with IEEE arithmetic).
  double t0 = 0, t1 = maxT;
  for (int k = 0; k < 3; ++k) {
    double a = (box.min()[k] - ray.origin[k]) * inv[k];
    double b = (box.max()[k] - ray.origin[k]) * inv[k];
    if (a > b) std::swap(a, b);
    if (std::isnan(a) || std::isnan(b)) continue;  // 0·inf: the ray lies in a slab plane
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace

Eigen::Vector3f Picker::corner(int t, int k) const {
  const std::uint32_t v = triangles_[3 * t + k];
  return {positions_[3 * v], positions_[3 * v + 1], positions_[3 * v + 2]};
}

void Picker::build(const std::vector<std::uint32_t>& triangles,
                   const std::vector<float>& positions) {
  triangles_ = triangles;
  positions_ = positions;
  nodes_.clear();
  const int T = static_cast<int>(triangles_.size() / 3);
  order_.resize(T);
  for (int t = 0; t < T; ++t) order_[t] = t;
  if (T == 0) return;
  std::vector<Eigen::Vector3f> centroids(T);
  for (int t = 0; t < T; ++t) centroids[t] = (corner(t, 0) + corner(t, 1) + corner(t, 2)) / 3.0f;
  nodes_.reserve(2 * T / kLeafSize + 2);
  buildNode(0, T, centroids);
}

int Picker::buildNode(int first, int count, std::vector<Eigen::Vector3f>& centroids) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back({});
  Eigen::AlignedBox3f box, centres;
  for (int i = first; i < first + count; ++i) {
    for (int k = 0; k < 3; ++k) box.extend(corner(order_[i], k));
    centres.extend(centroids[order_[i]]);
  }
  nodes_[index].box = box;
  if (count <= kLeafSize) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  // Median split along the longest extent of the centroids.
  int axis = 0;
  centres.diagonal().maxCoeff(&axis);
  const int mid = first + count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + first + count,
                   [&](int a, int b) { return centroids[a][axis] < centroids[b][axis]; });
  const int left = buildNode(first, mid - first, centroids);
  const int right = buildNode(mid, first + count - mid, centroids);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

void Picker::update(const std::vector<float>& positions) {
  if (positions.size() != positions_.size()) {
    build(triangles_, positions);
    return;
  }
  positions_ = positions;
  // Children come after their parent in nodes_, so a backward sweep refits bottom-up.
  for (int i = static_cast<int>(nodes_.size()) - 1; i >= 0; --i) {
    Node& n = nodes_[i];
    n.box.setEmpty();
    if (n.count > 0) {
      for (int j = n.first; j < n.first + n.count; ++j)
        for (int k = 0; k < 3; ++k) n.box.extend(corner(order_[j], k));
    } else {
      n.box.extend(nodes_[n.left].box);
      n.box.extend(nodes_[n.right].box);
    }
  }
}

bool Picker::intersect(const Ray& ray, int t, Hit& hit) const {
  // Möller–Trumbore in double precision, both sides of the triangle.
  const Eigen::Vector3d a = corner(t, 0).cast<double>(), b = corner(t, 1).cast<double>(),
                        c = corner(t, 2).cast<double>();
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d p = ray.direction.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-14 * e1.squaredNorm() * e2.norm()) return false;
  const double inv = 1.0 / det;
  const Eigen::Vector3d s = ray.origin - a;
  const double u = s.dot(p) * inv;
  if (u < 0 || u > 1) return false;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = ray.direction.dot(q) * inv;
  if (v < 0 || u + v > 1) return false;
  const double dist = e2.dot(q) * inv;
  if (!(dist > 0)) return false;
  hit.triangle = t;
  hit.distance = dist;
  hit.point = ray.origin + dist * ray.direction;
  hit.barycentric = {1 - u - v, u, v};
  hit.frontFacing = ray.direction.dot(e1.cross(e2)) < 0;
  return true;
}

std::optional<Hit> Picker::pick(const Ray& ray, const std::function<bool(int)>& accept,
                                const std::optional<ClipPlane>& clip) const {
  if (nodes_.empty()) return std::nullopt;
  const Eigen::Vector3d inv = ray.direction.cwiseInverse();
  std::optional<Hit> best;
  double bestT = std::numeric_limits<double>::infinity();
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!rayHitsBox(ray, inv, n.box, bestT)) continue;
    if (n.count == 0) {
      if (top + 2 > 128) continue;  // deeper than any median-split tree of < 2^60 triangles
      stack[top++] = n.left;
      stack[top++] = n.right;
      continue;
    }
    for (int j = n.first; j < n.first + n.count; ++j) {
      Hit h;
      const int t = order_[j];
      if (!intersect(ray, t, h) || h.distance >= bestT) continue;
      if (clip && !clip->keeps(h.point)) continue;
      if (accept && !accept(t)) continue;
      bestT = h.distance;
      best = h;
    }
  }
  return best;
}

int cellUnderCursor(const TissueGeometry& g, const Hit& hit) {
  if (hit.triangle < 0 || hit.triangle >= g.triangleCount()) return -1;
  const int cell = g.triangleCell[hit.triangle], neighbor = g.triangleNeighbor[hit.triangle];
  if (g.outer[hit.triangle] || neighbor < 0) return cell;
  // The normal points out of `cell` into `neighbor`: a front-facing hit is seen from `neighbor`.
  return hit.frontFacing ? neighbor : cell;
}

}  // namespace tp::gui
