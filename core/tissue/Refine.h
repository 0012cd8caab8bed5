#pragma once
// Local refinement near the probe: red-green refinement of the triangles within a radius of a
// point, repeated for a number of levels. A red triangle is split into four similar ones at its
// edge midpoints; a neighbour left with one split edge is closed by a green bisection (two
// triangles), which is undone before the next level so that green triangles are never refined
// again (their angles stay at least half of their parent's). A triangle with two split edges, or
// with an edge whose half is split again, is refined red. No hanging nodes remain; every edge
// is split the same way for all the walls sharing it (junction edges included). Units: µm.

#include <array>
#include <vector>

#include "mesh/CellComplex.h"

namespace tp {

struct RefineReport {
  int levels = 0;
  int redTriangles = 0;    // red splits performed
  int greenTriangles = 0;  // green closures in the result
  int addedVertices = 0;
  double minAngleDeg = 0;  // of the result
};


/// Graded refinement around a point (the probe's site, rest positions): passes of red-green
/// refinement until every triangle of the walls reaching within `outerRadius` of `center` has
/// its longest rest edge at most targetSize(d) (and panelSize), d its distance from the centre. The target grows linearly with the
/// distance, so the mesh grades from `finest` at the site to the base tissue's size, and the
/// closure rule keeps neighbouring triangles within one level of each other.
struct GradedRefinement {
  Vec3 center = Vec3::Zero();
  double finest = 0.1;       // µm, longest edge within innerRadius of the centre
  double innerRadius = 0;    // µm
  double grading = 4;        // target size grows by 1/grading per µm beyond innerRadius
  double outerRadius = 0;    // µm: the walls reaching within it are refined, whole
  double panelSize = 0;      // µm: longest edge anywhere on those walls (0: no such cap)
  double panelFraction = 0;  // longest edge on those walls at most this fraction of the longest
                             // edge they have in the base (0: no such cap)
  double junctionSize = 0;   // µm: longest edge of the triangles of those walls within
                             // outerRadius of the centre with a corner within junctionSize of
                             // one of their junction edges (edges shared by three or more
                             // walls) that come within junctionRadius of it (0: no such band)
  double junctionRadius = 0;  // µm: the band's junction edges come this near the centre
                              // (0: outerRadius)
  int maxPasses = 16;
  double targetSize(double distance) const;
};

struct RefinedComplex {
  CellComplex complex;
  /// For every added vertex (index base V + i), the two vertices it is the midpoint of; parents
  /// come before children, so positions can be carried over in order (prolongate()).
  std::vector<std::array<int, 2>> parents;
  std::vector<int> baseTriangle;  // for every triangle, the triangle of the base it lies in
  RefineReport report;            // levels = passes made
};

/// The base itself as a refinement of itself (no added vertex; each triangle its own origin).
RefinedComplex unrefined(const CellComplex& cc);

/// Positions x of the refinement `from` of `base`, carried onto another refinement `to` of the
/// same base: every vertex of `to` takes the linear interpolation of x over the triangle of
/// `from` that holds its rest position (within their common base triangle). Exact for the
/// vertices the two share; a guess of a state on a finer (or coarser) mesh of the same tissue.
Points transferPositions(const CellComplex& base, const RefinedComplex& from, const Points& x,
                         const RefinedComplex& to);

RefinedComplex refineGraded(const CellComplex& cc, const GradedRefinement& spec);

/// Splits every triangle of the flagged walls (one flag per wall) `levels` times: a uniform
/// halving of those walls.
RefinedComplex refineWalls(const CellComplex& cc, const std::vector<char>& walls, int levels);

/// Refines every triangle within `radius` of `center` (rest positions) `levels` times: a
/// uniform halving there (with conforming transitions around it).
RefinedComplex refineWithin(const CellComplex& cc, const Vec3& center, double radius, int levels);
/// The same, the complex only.
CellComplex refineNear(const CellComplex& cc, const Vec3& center, double radius, int levels,
                       RefineReport* report = nullptr);

/// Positions of a refined complex from those of its base (3×V): each added vertex at the midpoint
/// of its parents, as the refinement placed it.
Points prolongate(const Points& coarse, const std::vector<std::array<int, 2>>& parents);

}  // namespace tp
