#pragma once
// The floral-meristem generator: a dome (flower bud on a short stem) filled with polyhedral cells,
// the Voronoi cells of seeds arranged as in a meristem (an epidermal layer L1 of flatter cells,
// the L2 layer under it, inner cells), closed by the dome's surface, its base clamped to the stem.
// Units: µm.

#include <cstdint>

#include "mesh/CellComplex.h"
#include "tissue/Voronoi.h"

namespace tp {

/// A surface of revolution about the z axis: a cylinder of radius R from z = 0 to z = stemHeight,
/// capped by half an ellipsoid of semi-axes R (horizontal) and capHeight (vertical). The base
/// z = 0 is the cut through the stem.
struct DomeShape {
  double radius = 40;      // R (µm): the dome is 2R across
  double stemHeight = 8;   // µm
  double capHeight = 34;   // µm

  double height() const { return stemHeight + capHeight; }
  double volume() const;   // µm³, exact
  double area() const;     // µm², the lateral surface and the cap (the base excluded)
  bool contains(const Vec3& p) const;
  /// Closest point of the lateral surface or the cap (not the base); its outward normal.
  Vec3 closestPoint(const Vec3& p, Vec3* normal = nullptr) const;
  /// Signed distance to that surface, positive inside.
  double depth(const Vec3& p) const;
};

/// The largest tissue the builders make (cells): about 100k vertices.
inline constexpr int kMaxCells = 20000;

struct MeristemParams {
  DomeShape shape;
  int cells = 500;                 // target cell count (reached to within a few percent)
  std::uint32_t seed = 1;          // random seed: the same seed gives the same tissue
  double l1Thickness = 4.0;        // µm, epidermal (L1) cells
  double l2Thickness = 5.0;        // µm, L2 cells
  int relaxIterations = 10;        // Lloyd iterations towards centroidal cells (layers kept)
  double collapseFraction = 0.08;  // edges shorter than this × cell size are collapsed
  bool requireValid = true;        // throw if the result fails checkValidity (else only report it)
};

struct MeristemReport {
  int cells = 0, l1Cells = 0, l2Cells = 0, innerCells = 0;
  double cellSpacing = 0;  // µm, lateral spacing of the seeds
  double seconds = 0;      // time to generate
  VoronoiReport voronoi;
  ValidityReport validity;
};

/// Generates the tissue (throws std::invalid_argument for impossible parameters).
CellComplex generateMeristem(const MeristemParams& params, MeristemReport* report = nullptr);

}  // namespace tp
