#pragma once
// Local refinement near the probe: red-green refinement of the triangles within a radius of a
// point, repeated for a number of levels. A red triangle is split into four similar ones at its
// edge midpoints; a neighbour left with one split edge is closed by a green bisection (two
// triangles), which is undone before the next level so that green triangles are never refined
// again (their angles stay at least half of their parent's). A triangle with two split edges, or
// with an edge whose half is split again, is refined red. No hanging nodes remain; every edge
// is split the same way for all the walls sharing it (junction edges included). Units: µm.

#include "mesh/CellComplex.h"

namespace tp {

struct RefineReport {
  int levels = 0;
  int redTriangles = 0;    // red splits performed
  int greenTriangles = 0;  // green closures in the result
  int addedVertices = 0;
  double minAngleDeg = 0;  // of the result
};

/// Refines every triangle within `radius` of `center` (rest positions) `levels` times.
CellComplex refineNear(const CellComplex& cc, const Vec3& center, double radius, int levels,
                       RefineReport* report = nullptr);

}  // namespace tp
