#pragma once
// The quantities a state is coloured by (the application's colour menu, its colour bar and
// sessions) and exported with (VTU cell data), per triangle, in one table. A new quantity is one
// enum value and one row in Quantities.cpp. Units: MPa for stresses and energy densities, µm for
// displacements.

#include <string>
#include <vector>

#include "experiment/Stress.h"

namespace tp {

enum class Quantity : int {
  VonMises,
  PrincipalMax,
  EnergyDensity,
  BendingEnergyDensity,
  Displacement,
  VonMisesChange,
  PrincipalMaxChange,
};
inline constexpr int kQuantityCount = 7;

/// What a quantity is computed from: the state and, once the site is prepared, the turgid state
/// (the rest state under turgor, before the probe) and its stress.
struct QuantityInputs {
  const StressField* stress = nullptr;        // at the state (null: no model yet)
  const StressField* turgidStress = nullptr;  // at the turgid state
  const CellComplex* complex = nullptr;
  const Points* x = nullptr;
  const Points* turgid = nullptr;
};

struct QuantityInfo {
  const char* key;   // "von_mises": sessions, settings, VTU array names (key_unit)
  const char* name;  // "von Mises stress"
  const char* unit;  // "MPa"
  bool change;       // a change from the turgid state: signed, coloured about zero
  /// The value on triangle t; 0 where its inputs are missing.
  double (*value)(const QuantityInputs&, int t);
};

const QuantityInfo& quantityInfo(Quantity q);
/// The quantity with this key, or −1.
int quantityIndex(const std::string& key);

/// Every quantity on every triangle: values[q][t].
std::vector<std::vector<double>> triangleQuantities(const QuantityInputs& in);

}  // namespace tp
