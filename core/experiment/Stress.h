#pragma once
// Stress read-out per triangle and per wall: in-plane Cauchy stress (MPa), principal values,
// von Mises, strain-energy density (membrane part, MPa = pJ/µm³) and bending energy per area.

#include <vector>

#include "io/Vtu.h"
#include "mechanics/Model.h"

namespace tp {

struct WallStress {
  double area = 0;              // µm², current
  Mat3 meanCauchy = Mat3::Zero();  // area-weighted mean of the triangles' Cauchy tensors (MPa)
  double principalMax = 0;      // principal values of meanCauchy in the wall's mean plane (MPa)
  double principalMin = 0;
  double vonMises = 0;          // of the mean tensor (MPa)
  double energyDensity = 0;     // area-weighted mean membrane strain-energy density (MPa)
};

struct StressField {
  std::vector<MembraneStress> triangles;
  std::vector<double> bendingEnergyDensity;  // per triangle, bending energy / (h · rest area), MPa
  std::vector<WallStress> walls;
};

StressField computeStress(const Model& model, const Points& x);

/// The fields of a state for export (VTU): per vertex the displacement from the turgid state and
/// from rest (µm); per triangle the Cauchy stress (9 components), the minimum principal stress
/// and every colour quantity of experiment/Quantities.h (MPa) but the displacement.
struct StateFields {
  std::vector<VtuField> points, triangles;
};
StateFields stateFields(const Model& model, const Points& x, const Points& turgid);

}  // namespace tp
