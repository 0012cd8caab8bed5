#pragma once
// A tissue from the centroids of real cells (as the study did from a segmented confocal image):
// the Voronoi cells of the centroids, closed by a surface reconstructed around them — the alpha
// shape of the centroids (CGAL), pushed outward by half a cell — and cut by a clamped base plane.
// Cell labels are kept. Units: µm.

#include <optional>

#include "io/Centroids.h"
#include "mesh/CellComplex.h"
#include "tissue/Voronoi.h"

namespace tp {

struct RealTissueOptions {
  double cellSize = 0;          // µm; 0: 1.1 × the median nearest-neighbour distance
  double alphaFactor = 4.0;     // × CGAL's optimal alpha (smallest giving one solid), smooths
  double offset = -1;           // µm the surface is pushed outward; < 0: half a cell
  std::optional<double> baseZ;  // clamped base plane (µm); default: lowest centroid + one cell
  double collapseFraction = 0.08;
};

struct RealTissueReport {
  double cellSize = 0, alpha = 0, baseZ = 0;
  int surfaceTriangles = 0;   // of the alpha shape
  int droppedBelowBase = 0;   // centroids under the base plane (their cells are not built)
  std::vector<int> keptRows;  // for each cell of the tissue, its row in the table
  VoronoiReport voronoi;
  ValidityReport validity;
  double seconds = 0;
};

/// Throws std::invalid_argument for unusable input, std::runtime_error if the tissue cannot be
/// closed. The result is checked with checkValidity (reported, not thrown).
CellComplex tissueFromCentroids(const CentroidTable& table, const RealTissueOptions& options,
                                RealTissueReport* report = nullptr);

/// Pearson correlation of two equally long samples.
double correlation(const std::vector<double>& a, const std::vector<double>& b);

}  // namespace tp
