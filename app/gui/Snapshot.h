#pragma once
// What the simulation worker hands to the window: an immutable picture of one state of the
// tissue. The topology (TissueGeometry) changes only when a tissue is loaded or refined and is
// shared read-only between snapshots; positions, per-triangle fields and the probe come with
// every snapshot, which travels BY VALUE through queued signals. Units: µm, MPa, µN.

#include <QMetaType>

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "Parameters.h"
#include "experiment/Indentation.h"
#include "experiment/Quantities.h"
#include "mesh/CellComplex.h"

namespace tp::gui {

/// The drawable topology of one tissue. Vertex and triangle indices are those of the model.
struct TissueGeometry {
  int generation = 0;                         // new for every load or refinement
  std::string path;                           // file the tissue came from
  std::vector<std::uint32_t> triangles;       // 3T vertex indices
  std::vector<int> triangleCell;              // T, dense cell the normal points out of (-1 none)
  std::vector<int> triangleNeighbor;          // T, dense cell on the other side (-1 outside)
  std::vector<std::uint8_t> outer;            // T, 1 = on the outer surface
  std::vector<std::uint8_t> clampedTriangle;  // T, 1 = its three vertices are clamped
  std::vector<std::uint8_t> clampedVertex;    // V, 1 = clamped
  // V: the one wall whose triangles all around a vertex belong to (−1: the vertex is on two
  // walls or more, i.e. on a wall's outline). Shading is smooth across such inner vertices and
  // crisp along the outlines, so a refined wall bulges smoothly and cells keep their edges.
  std::vector<int> vertexWall;
  std::vector<double> rest;                   // 3V rest positions (µm): picks → material points
  std::vector<std::uint32_t> outlineEdges;    // 2E vertex indices: boundaries of the walls,
                                              // those of outer walls first
  int outerOutlineEdges = 0;                  // how many edges come first
  std::vector<std::uint32_t> meshEdges;       // 2E vertex indices: every triangle edge once,
                                              // those of the outer surface first
  int outerMeshEdges = 0;                     // how many edges come first
  int meshLevel = 0;                          // refinement level at the site (0: as loaded)
  std::vector<int> cellLabels;                // C, user-facing label of each dense cell
  double meanCellSize = 0;                    // L = cbrt(rest volume / cells), µm (unrefined)

  int vertexCount() const { return static_cast<int>(clampedVertex.size()); }
  int triangleCount() const { return static_cast<int>(triangleCell.size()); }
  int cellCount() const { return static_cast<int>(cellLabels.size()); }
};

/// Edges used by exactly one triangle of their wall (the wall's boundary loops), each listed once
/// even where several walls meet: the cell outlines to draw. 2E vertex indices.
std::vector<std::uint32_t> wallOutlineEdges(const CellComplex& cc, int* outerEdges = nullptr);
/// L = cbrt(total rest volume / cell count) (µm), 0 without cells.

/// Every edge of the triangles once, those of outer-surface triangles first. 2E vertex indices.
std::vector<std::uint32_t> triangleEdges(const CellComplex& cc, int* outerEdges = nullptr);

std::shared_ptr<const TissueGeometry> makeTissueGeometry(const CellComplex& cc, int generation,
                                                         const std::string& path, double cellSize,
                                                         int meshLevel = 0);

/// Per-triangle quantities a user can colour the walls by.
/// The colour quantities: core's table (experiment/Quantities.h), where a new one goes.
using Field = tp::Quantity;
constexpr int kFieldCount = kQuantityCount;
inline const char* fieldName(Field f) { return quantityInfo(f).name; }  // "von Mises stress"
inline const char* fieldUnit(Field f) { return quantityInfo(f).unit; }  // "MPa" or "µm"
inline const char* fieldKey(Field f) { return quantityInfo(f).key; }    // "von_mises"

struct Snapshot {
  enum class Phase {
    Rest,         // a tissue just loaded, not yet under pressure
    Prepared,     // turgid state, probe touching the surface at depth 0
    Equilibrium,  // an equilibrium with the probe pressed in
  };
  std::shared_ptr<const TissueGeometry> geometry;
  std::vector<float> positions;                        // 3V, µm
  std::vector<float> turgidPositions;                  // 3V, the turgid state (empty at rest)
  std::array<std::vector<float>, kFieldCount> fields;  // T values each, units of fieldUnit
  // 3T: per triangle, the in-plane direction of the largest principal stress times that stress
  // σ₁ (MPa); empty when there is no stress (a tissue at rest before its turgid state).
  std::vector<float> principalAxes;
  std::vector<double> cellVolumes;                     // C, current volumes, µm³
  Phase phase = Phase::Rest;

  // The probe (valid when probeVisible).
  bool probeVisible = false;
  Eigen::Vector3d site = Eigen::Vector3d::Zero();           // on the turgid surface, µm
  Eigen::Vector3d axis = -Eigen::Vector3d::UnitZ();         // unit, into the tissue
  Eigen::Vector3d contactCenter = Eigen::Vector3d::Zero();  // probe centre at first contact, µm
  double probeRadius = 1;                                   // µm
  double depth = 0;                                         // µm, travel from first contact
  double force = 0;                                         // µN
  // The contact patch: the outer triangles the probe presses (Model::touchedTriangles), ascending.
  std::vector<int> contactTriangles;

  SimulationParams params;          // what the state was computed with
  int preparation = 0;              // counts preparations: points of one belong together
  bool newSite = false;             // this preparation chose a new site (a pick, a load)
  std::optional<CurvePoint> point;  // the equilibrium this snapshot shows, if it is one
  bool fromRun = false;             // the point belongs to a scheduled run (not a drag)
  std::string status;               // one line for the status bar
  std::string meshStatus;           // the mesh and its estimated error, for the status bar

  bool empty() const { return !geometry; }
  Eigen::Vector3d probeCenter() const { return contactCenter + depth * axis; }
};

}  // namespace tp::gui

namespace tp::gui {

/// The estimated discretisation error of a curve's deepest point, once it is known.
struct MeshErrorReport {
  int preparation = 0;  // the preparation (site and parameters) the curve belongs to
  bool run = false;     // of the last scheduled run (else of the curve grown by dragging)
  int level = 0;        // the mesh level of the curve
  double at = 0;        // the depth (µm) or force (µN) it is estimated at
  bool force = false;   // `at` is a force
  double relative = -1; // estimated |error| / |value|; < 0 when it could not be estimated
  std::string method;   // how, for tooltips and exports
};

}  // namespace tp::gui

Q_DECLARE_METATYPE(tp::gui::Snapshot)
Q_DECLARE_METATYPE(tp::gui::MeshErrorReport)
