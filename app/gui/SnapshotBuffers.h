#pragma once
// Turns a Snapshot into the interleaved vertex arrays the GPU draws: one flat-shaded vertex
// triple per triangle (its colour from the chosen field through the colour map), the wall
// outlines and the mesh's edges as line segments and the clamped vertices as points. Plain arrays of floats, no GL
// context needed (GlRenderer uploads them), so the conversion is unit-tested. Units: µm.

#include <Eigen/Geometry>
#include <utility>
#include <vector>

#include "ColorMap.h"
#include "Snapshot.h"

namespace tp::gui {

class SnapshotBuffers {
 public:
  // One triangle vertex: position (3), flat normal (3, not oriented), colour (3, RGB in [0, 1]),
  // the wall's two dense cells (2, −1 = none) and flags (1): kClamped | kOuter.
  static constexpr int kTriangleStride = 12;
  static constexpr int kPositionOffset = 0, kNormalOffset = 3, kColorOffset = 6, kCellsOffset = 9,
                       kFlagsOffset = 11;
  static constexpr int kClamped = 1, kOuter = 2;
  static constexpr int kLineStride = 3;  // lines and points: position only

  /// Rebuilds every array from the snapshot (empty snapshot: empty arrays).
  void build(const Snapshot& snapshot, Field field, const ColorMap& map);
  /// The same with the colours from `values` (one per triangle; NaN or missing: no colour).
  void build(const Snapshot& snapshot, const std::vector<float>& values, const ColorMap& map);

  /// Outer-surface triangles come first: when nothing cuts the tissue only they can be seen
  /// (the outer surface is closed), so the renderer draws just them.
  const std::vector<float>& triangleVertices() const { return triangles_; }
  int outerTriangleVertexCount() const { return outerTriangleVertices_; }
  int outerLineVertexCount() const { return outerLineVertices_; }
  int triangleVertexCount() const { return static_cast<int>(triangles_.size()) / kTriangleStride; }
  const std::vector<float>& lineVertices() const { return lines_; }
  int lineVertexCount() const { return static_cast<int>(lines_.size()) / kLineStride; }
  /// Every triangle edge (the mesh), outer-surface edges first.
  const std::vector<float>& meshVertices() const { return mesh_; }
  /// Principal-stress glyphs: per triangle a segment through its centroid along the direction
  /// of its largest principal stress, its length up to 0.8 √area in proportion to |σ₁| (of the
  /// largest |σ₁| on the tissue, past its 0.5 % most extreme triangles); outer surface first.
  const std::vector<float>& glyphVertices() const { return glyphs_; }
  int glyphVertexCount() const { return static_cast<int>(glyphs_.size()) / kLineStride; }
  int outerGlyphVertexCount() const { return outerGlyphVertices_; }
  /// The contact patch's outline: the edges of the triangles the probe presses that are not
  /// shared by two of them (Snapshot::contactTriangles), as segments.
  const std::vector<float>& contactVertices() const { return contact_; }
  int contactVertexCount() const { return static_cast<int>(contact_.size()) / kLineStride; }
  int meshVertexCount() const { return static_cast<int>(mesh_.size()) / kLineStride; }
  int outerMeshVertexCount() const { return outerMeshVertices_; }
  const std::vector<float>& clampedPoints() const { return points_; }
  int clampedPointCount() const { return static_cast<int>(points_.size()) / kLineStride; }
  /// Bounding box of the positions (µm).
  const Eigen::AlignedBox3d& bounds() const { return bounds_; }

 private:
  std::vector<float> triangles_, lines_, mesh_, points_, glyphs_, contact_;
  int outerGlyphVertices_ = 0;
  int outerTriangleVertices_ = 0, outerLineVertices_ = 0, outerMeshVertices_ = 0;
  Eigen::AlignedBox3d bounds_;
};

/// A unit sphere: an icosahedron subdivided `subdivisions` times, as triangles with 6 floats per
/// vertex (position, equal to the outward normal).
std::vector<float> unitSphereMesh(int subdivisions);

/// Values below this magnitude (in the field's unit: MPa or µm) are numerical noise.
inline constexpr double kNoiseFloor = 1e-6;

/// The automatic colour range of a field and the extremes of its finite values.
struct AutoRange {
  double lo = 0, hi = 1;          // the colour bar's ends
  double dataLo = 0, dataHi = 1;  // the smallest and largest values (may lie outside)
  bool clippedLow() const { return dataLo < lo - 1e-9 * (hi - lo); }
  bool clippedHigh() const { return dataHi > hi + 1e-9 * (hi - lo); }
};

/// The automatic colour range of a field: [min, max] of its finite values, except that stresses
/// and energy densities leave out the 0.1 % of triangles at either end (slivers); all values
/// below kNoiseFloor in magnitude give [0, kNoiseFloor] (or ±kNoiseFloor); for a diverging map
/// and values of both signs, symmetric about zero so that zero sits at the neutral colour.
AutoRange autoRange(const Snapshot& snapshot, Field field, bool diverging);
/// The same for any values; `robust` leaves out the 0.1 % at either end.
AutoRange autoRange(const std::vector<float>& values, bool robust, bool diverging);

}  // namespace tp::gui
