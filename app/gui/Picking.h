#pragma once
// Ray casting against the tissue's triangles: which triangle, which cell and which point lie
// under a pixel. A bounding-volume hierarchy over the triangles is built once per topology and
// refitted (bounds only, O(T)) when the positions change, so hovering stays well under a
// millisecond on the default meristem. Units: µm. No GL needed.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "Camera.h"

namespace tp::gui {

struct TissueGeometry;

struct Hit {
  int triangle = -1;
  double distance = 0;                                    // along the ray, µm
  Eigen::Vector3d point = Eigen::Vector3d::Zero();        // µm
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();  // weights of the triangle's corners
  bool frontFacing = false;  // the ray meets the side the triangle's normal points to
};

/// A half-space kept by the section plane: points with n·x + d ≥ 0 are visible.
struct ClipPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0;
  bool keeps(const Eigen::Vector3d& x) const { return normal.dot(x) + offset >= 0; }
};

class Picker {
 public:
  /// `triangles` holds 3T vertex indices, `positions` 3V coordinates (µm).
  void build(const std::vector<std::uint32_t>& triangles, const std::vector<float>& positions);
  /// New positions for the same triangles: the tree is refitted, not rebuilt.
  void update(const std::vector<float>& positions);
  bool empty() const { return nodes_.empty(); }

  /// The nearest hit along the ray, skipping triangles the filter rejects and hits the clip
  /// plane removes (they are not drawn either).
  std::optional<Hit> pick(const Ray& ray, const std::function<bool(int)>& accept = {},
                          const std::optional<ClipPlane>& clip = std::nullopt) const;

 private:
  struct Node {
    Eigen::AlignedBox3f box;
    int first = 0, count = 0;  // leaf: triangle range in order_; inner: count = 0
    int left = -1, right = -1;
  };
  int buildNode(int first, int count, std::vector<Eigen::Vector3f>& centroids);
  Eigen::Vector3f corner(int t, int k) const;
  bool intersect(const Ray& ray, int t, Hit& hit) const;

  std::vector<std::uint32_t> triangles_;
  std::vector<float> positions_;
  std::vector<int> order_;
  std::vector<Node> nodes_;
};

/// The cell a user points at through a hit: on the outer surface the cell behind it; on an inner
/// wall (seen through the section plane) the cell on the viewer's side. −1 if none.
int cellUnderCursor(const TissueGeometry& g, const Hit& hit);

}  // namespace tp::gui
