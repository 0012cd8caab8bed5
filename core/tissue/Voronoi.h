#pragma once
// A tissue as the Voronoi cells of seed points (cell centres), closed by "ghost" seeds: each
// boundary seed's mirror image across the tissue's surface, whose shared Voronoi face is the
// tangent plane there. The faces between real cells become inner walls, the faces between a real
// cell and a ghost become outer walls (on the surface, or on the clamped base). Computed with
// voro++; shared vertices are welded, edges shorter than a threshold collapsed, outer vertices
// moved onto the smooth surface, and every wall triangulated. Units: µm.

#include <functional>
#include <vector>

#include "mesh/CellComplex.h"

namespace tp {

enum class BoundaryKind { Surface, Base };

struct VoronoiOptions {
  double collapseLength = 0;  // µm; edges shorter than this are collapsed (0: none)
  /// Moves a vertex of the outer surface onto the smooth surface (optional).
  std::function<Vec3(const Vec3&)> projectToSurface;
  double baseZ = 0;           // the base plane (µm); its vertices are clamped
};

struct VoronoiReport {
  int collapsedEdges = 0;
  int skippedCollapses = 0;  // short edges left because collapsing would pinch a wall
  int removedWalls = 0;      // walls that vanished under collapses
  int dissolvedVertices = 0; // passes that removed kinks (vertices with two neighbours)
  double seconds = 0;
};

/// Builds the tissue. `labels` names the cells (one per seed; empty: 1, 2, ...). Throws
/// std::runtime_error if a real cell is not enclosed by ghosts (it reaches the bounding box).
CellComplex buildVoronoiTissue(const std::vector<Vec3>& seeds, const std::vector<int>& labels,
                               const std::vector<Vec3>& ghosts,
                               const std::vector<BoundaryKind>& ghostKinds,
                               const VoronoiOptions& options, VoronoiReport* report = nullptr);

/// Centroid and volume of the Voronoi cell of every seed, the ghosts bounding them (for Lloyd
/// relaxation and volume checks). Throws like buildVoronoiTissue.
void voronoiCentroids(const std::vector<Vec3>& seeds, const std::vector<Vec3>& ghosts,
                      std::vector<Vec3>& centroids, std::vector<double>& volumes);

/// Pairs of cells (dense indices, a < b) sharing a wall of area above `minArea` (µm²).
std::vector<std::pair<int, int>> wallAdjacency(const CellComplex& cc, double minArea);

}  // namespace tp
