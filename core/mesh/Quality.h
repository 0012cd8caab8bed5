#pragma once
// Size and quality figures of a cell complex (for `tissueprobe-cli info` and reports).

#include <string>

#include "mesh/CellComplex.h"

namespace tp {

struct MeshQuality {
  int vertices = 0, triangles = 0, walls = 0, cells = 0;
  int clampedVertices = 0, outerTriangles = 0;
  double minAngleDeg = 0, maxAngleDeg = 0;  // over all triangles
  double meanEdge = 0, minEdge = 0;         // µm
  double volume = 0;                        // µm³, sum of cell volumes
  double outerArea = 0;                     // µm²
  Vec3 bboxMin = Vec3::Zero(), bboxMax = Vec3::Zero();
  ValidityReport validity;
};

MeshQuality measureQuality(const CellComplex& cc);
/// Why a tissue cannot be simulated as it is (empty when it can): invalid cells (with a hint when
/// the file is a surface of open cells, as MorphoGraphX and openalea L1 meshes are), or nothing
/// clamped (the tissue would move as a rigid body).
std::string simulationProblem(const CellComplex& cc);

/// Multi-line human-readable report.
std::string formatQuality(const MeshQuality& q);

}  // namespace tp
