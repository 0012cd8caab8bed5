#pragma once
// The cell complex: a tissue of polyhedral cells whose walls are triangulated polygons.
// Units: µm. Conventions: every triangle of a wall is wound counter-clockwise seen from outside
// `Wall::cell`, i.e. its right-hand normal points out of that cell and into `Wall::neighbor`
// (-1 = outside the tissue). A wall with cell == -1 belongs to an open sheet (no pressure).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace tp {

/// Largest coordinate magnitude a reader accepts (µm): beyond 1 m nothing is a tissue, and
/// volumes (x³) and CGAL's constructions would overflow or degenerate.
inline constexpr double kMaxCoordinate = 1e6;

using Vec3 = Eigen::Vector3d;
using Points = Eigen::Matrix3Xd;  // 3 x #V, one column per vertex (µm)

struct Wall {
  std::vector<int> polygon;  // boundary loop (vertex indices); empty if the wall was given as triangles
  int cell = -1;             // dense cell index the normal points out of; -1 = none (sheet)
  int neighbor = -1;         // dense cell index on the other side; -1 = outside the tissue
};

struct CellComplex {
  Points rest;                              // 3 x V rest positions (µm)
  std::vector<std::uint8_t> fixed;          // V, 1 = clamped vertex
  std::vector<Eigen::Vector3i> triangles;   // T, wound as stated above
  std::vector<int> triangleWall;            // T, wall of each triangle
  std::vector<Wall> walls;                  // W
  std::vector<int> cellLabels;              // C, user-facing label of each dense cell index

  int vertexCount() const { return static_cast<int>(rest.cols()); }
  int triangleCount() const { return static_cast<int>(triangles.size()); }
  int wallCount() const { return static_cast<int>(walls.size()); }
  int cellCount() const { return static_cast<int>(cellLabels.size()); }

  /// Appends a wall made of the given triangles (already wound) and returns its index.
  int addWall(const std::vector<Eigen::Vector3i>& tris, int cell, int neighbor,
              std::vector<int> polygon = {});
  /// Appends a planar or nearly planar polygon wall, triangulated by ear clipping.
  int addPolygonWall(const std::vector<int>& polygon, int cell, int neighbor);

  /// True when the triangle lies on the tissue's outer surface (nothing on its far side).
  bool isOuterTriangle(int t) const { return walls[triangleWall[t]].neighbor < 0; }
};

/// A predicate on a candidate diagonal (two vertex indices) of a polygon being triangulated.
using DiagonalFilter = std::function<bool(int, int)>;

/// Triangulates a simple polygon (vertex indices into `points`) with n − 2 triangles in its
/// best-fit plane (Newell normal): for a convex polygon the triangulation with the largest
/// smallest angle, otherwise ear clipping taking the best-shaped ear. Diagonals the filter
/// rejects are avoided when possible. The triangles keep the polygon's winding. Throws on fewer
/// than 3 vertices.
std::vector<Eigen::Vector3i> triangulatePolygon(const Points& points, const std::vector<int>& polygon,
                                                const DiagonalFilter& allowDiagonal = {});

/// Signed volume of each cell at positions x (µm³), positive when the walls are wound outward.
std::vector<double> cellVolumes(const CellComplex& cc, const Points& x);
/// The typical cell size L = cube root of the mean rest volume of the cells (µm); 0 without cells.
double meanCellSize(const CellComplex& cc);
/// Area of each triangle at positions x (µm²).
std::vector<double> triangleAreas(const CellComplex& cc, const Points& x);

/// Result of checking a cell complex; `ok()` when there are no errors.
struct ValidityReport {
  std::vector<std::string> errors;  // the first 50 messages
  int errorCount = 0;               // all of them
  std::vector<std::string> warnings;
  int openCells = 0;            // cells whose boundary has free edges
  int misorientedCells = 0;     // cells with an edge used twice in the same direction
  int nonManifoldEdges = 0;     // edges of one cell shared by more than two of its triangles
  int degenerateTriangles = 0;  // zero-area triangles
  bool ok() const { return errors.empty(); }
  std::string summary() const;
};

/// Checks indices, orientation and closedness of every cell (a cell whose open boundary is entirely
/// clamped is accepted, as for a pressurised membrane clamped at its rim).
ValidityReport checkValidity(const CellComplex& cc);

}  // namespace tp
