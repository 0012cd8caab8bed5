#include "mechanics/Material.h"

#include <cmath>

namespace tp {

BendingModel parseBendingModel(const std::string& name) {
  if (name == "koiter") return BendingModel::Koiter;
  if (name == "hinge") return BendingModel::Hinge;
  if (name == "linear") return BendingModel::Linear;
  if (name == "none") return BendingModel::None;
  throw std::invalid_argument("unknown bending model '" + name + "' (expected koiter, hinge, linear or none)");
}

std::string toString(BendingModel m) {
  switch (m) {
    case BendingModel::Koiter: return "koiter";
    case BendingModel::Hinge: return "hinge";
    case BendingModel::Linear: return "linear";
    case BendingModel::None: return "none";
  }
  return "?";
}

JunctionRule parseJunctionRule(const std::string& name) {
  if (name == "hinged") return JunctionRule::Hinged;
  if (name == "rigid") return JunctionRule::Rigid;
  throw std::invalid_argument("unknown junction rule '" + name + "' (expected hinged or rigid)");
}

std::string toString(JunctionRule r) { return r == JunctionRule::Rigid ? "rigid" : "hinged"; }

void Material::validate() const {
  if (!(std::isfinite(youngModulus) && youngModulus > 0))
    throw std::invalid_argument("Young's modulus must be positive (got " +
                                std::to_string(youngModulus) + " MPa)");
  if (!(std::isfinite(poissonRatio) && poissonRatio > -1.0 && poissonRatio <= 0.5))
    throw std::invalid_argument("Poisson ratio must lie in (-1, 0.5] (got " +
                                std::to_string(poissonRatio) + ")");
  if (!(std::isfinite(thickness) && thickness > 0))
    throw std::invalid_argument("wall thickness must be positive (got " + std::to_string(thickness) +
                                " µm)");
}

}  // namespace tp
