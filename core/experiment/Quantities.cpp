#include "experiment/Quantities.h"

#include <array>

namespace tp {

namespace {

double vonMises(const QuantityInputs& in, int t) {
  return in.stress ? in.stress->triangles[t].vonMises : 0.0;
}
double principalMax(const QuantityInputs& in, int t) {
  return in.stress ? in.stress->triangles[t].principalMax : 0.0;
}
double energyDensity(const QuantityInputs& in, int t) {
  return in.stress ? in.stress->triangles[t].energyDensity : 0.0;
}
double bendingEnergyDensity(const QuantityInputs& in, int t) {
  return in.stress ? in.stress->bendingEnergyDensity[t] : 0.0;
}
// Mean of the corners' displacement magnitudes from the turgid state.
double displacement(const QuantityInputs& in, int t) {
  if (!in.x || !in.turgid || in.turgid->cols() != in.x->cols()) return 0.0;
  const auto& tri = in.complex->triangles[t];
  double d = 0;
  for (int k = 0; k < 3; ++k) d += (in.x->col(tri[k]) - in.turgid->col(tri[k])).norm();
  return d / 3.0;
}
// The stress the probe adds: the state's minus the turgid state's, triangle by triangle (the
// same mesh). Turgor stresses every wall by ~10 MPa; the probe changes them by a few.
double vonMisesChange(const QuantityInputs& in, int t) {
  if (!in.stress || !in.turgidStress) return 0.0;
  return in.stress->triangles[t].vonMises - in.turgidStress->triangles[t].vonMises;
}
double principalMaxChange(const QuantityInputs& in, int t) {
  if (!in.stress || !in.turgidStress) return 0.0;
  return in.stress->triangles[t].principalMax - in.turgidStress->triangles[t].principalMax;
}

const std::array<QuantityInfo, kQuantityCount> kTable{{
    {"von_mises", "von Mises stress", "MPa", false, vonMises},
    {"principal_max", "max principal stress", "MPa", false, principalMax},
    {"strain_energy_density", "strain-energy density", "MPa", false, energyDensity},
    {"bending_energy_density", "bending-energy density", "MPa", false, bendingEnergyDensity},
    {"displacement", "displacement from turgid", "µm", false, displacement},
    {"von_mises_change", "von Mises change from turgid", "MPa", true, vonMisesChange},
    {"principal_max_change", "max principal change from turgid", "MPa", true, principalMaxChange},
}};

}  // namespace

const QuantityInfo& quantityInfo(Quantity q) { return kTable.at(static_cast<size_t>(q)); }

int quantityIndex(const std::string& key) {
  for (int i = 0; i < kQuantityCount; ++i)
    if (key == kTable[i].key) return i;
  return -1;
}

std::vector<std::vector<double>> triangleQuantities(const QuantityInputs& in) {
  const int T = in.complex ? in.complex->triangleCount() : 0;
  std::vector<std::vector<double>> v(kQuantityCount, std::vector<double>(T, 0.0));
  for (int q = 0; q < kQuantityCount; ++q)
    for (int t = 0; t < T; ++t) v[q][t] = kTable[q].value(in, t);
  return v;
}

}  // namespace tp
