#pragma once
// Wall material. Units: E in MPa (= µN/µm²), thickness in µm, ν dimensionless.

#include <stdexcept>
#include <string>

namespace tp {

enum class BendingModel {
  Koiter,  // Kirchhoff–Love plate energy with the wall's ν, rotation-free triangles (default;
           // mechanics/PlateBending.h)
  Hinge,   // discrete-shell hinges with rest angles, calibrated to D (no Poisson coupling)
  Linear,  // Volino & Magnenat-Thalmann 2006 linear bending vector (the published model)
  None,
};

BendingModel parseBendingModel(const std::string& name);  // "koiter" | "hinge" | "linear" | "none"
std::string toString(BendingModel m);

/// How walls meeting at a junction edge share rotation under Koiter bending
/// (mechanics/PlateBending.h): hinged (they pivot freely; the epidermis stays one sheet) or rigid
/// (the angles between them are kept).
enum class JunctionRule { Hinged, Rigid };
JunctionRule parseJunctionRule(const std::string& name);  // "hinged" | "rigid"
std::string toString(JunctionRule r);

struct Material {
  double youngModulus = 100.0;  // E, MPa (the defaults of every front end)
  double poissonRatio = 0.49;  // ν
  double thickness = 0.2;      // h, µm
  BendingModel bending = BendingModel::Koiter;
  JunctionRule junctions = JunctionRule::Hinged;

  /// Plane-stress Lamé constants (MPa): μ = E/(2(1+ν)), λ* = Eν/(1−ν²).
  double mu() const { return youngModulus / (2.0 * (1.0 + poissonRatio)); }
  double lambdaPlaneStress() const {
    return youngModulus * poissonRatio / (1.0 - poissonRatio * poissonRatio);
  }
  /// Plate bending rigidity D = E h³ / (12 (1 − ν²)) (µN·µm).
  double bendingRigidity() const {
    return youngModulus * thickness * thickness * thickness /
           (12.0 * (1.0 - poissonRatio * poissonRatio));
  }
  /// Throws std::invalid_argument naming the offending value.
  void validate() const;
};

}  // namespace tp
