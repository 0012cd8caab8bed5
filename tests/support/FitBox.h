#pragma once
// The tissue and settings the fit tests read curves on: a box of 3 × 3 × 2 cells 5 µm across,
// indented on its top wall (ν = 0.3, h = 0.2 µm, a 1 µm probe held along −z at a material point,
// 8 steps to 0.4 µm), on the tissue as given, with equilibria to 1e-11 — as the fit solves, so
// that a synthetic curve is as exact as its model.
#include <memory>

#include "experiment/Experiment.h"
#include "tissue/Shapes.h"

namespace tp::test {

inline std::shared_ptr<const CellComplex> fitBox() {
  static const auto cc = std::make_shared<const CellComplex>(boxTissue(3, 3, 2, 5.0));
  return cc;
}

inline ExperimentSettings fitBoxSettings(double E, double p) {
  ExperimentSettings s;
  s.material.youngModulus = E;
  s.material.poissonRatio = 0.3;
  s.material.thickness = 0.2;
  s.pressure = p;
  s.indentation.probeRadius = 1.0;
  s.indentation.restSite = Vec3(7.9, 7.3, 10.0);  // a material point of the top wall
  // The axis held, as an AFM's: by default it would be the surface normal of the turgid state
  // at the starting values, and a synthetic curve made at other values would not be the
  // model's own (measured: the fit then stops 5e-4 off in p).
  s.indentation.axis = Vec3(0, 0, -1);
  s.indentation.maxDepth = 0.4;
  s.indentation.steps = 8;
  s.mesh.automatic = false;
  s.mesh.level = 0;
  s.mesh.estimateError = false;
  s.solver.tolerance = 1e-11;
  return s;
}

}  // namespace tp::test
