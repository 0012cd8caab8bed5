#pragma once
// The values of a stiffness map the outer surface can be coloured by (after core's quantities
// in the colour menu): keys for sessions, names and units for the colour bar. The index is
// tp::MapField::Value.

#include <string>

#include "experiment/Map.h"

namespace tp::gui {

struct MapValueInfo {
  const char* key;   // "map_stiffness": sessions
  const char* name;  // "stiffness map: secant stiffness"
  const char* unit;  // "µN/µm"
};

inline const MapValueInfo& mapValueInfo(int v) {
  static const MapValueInfo table[MapField::kValueCount] = {
      {"map_stiffness", "stiffness map: secant stiffness", "µN/µm"},
      {"map_force", "stiffness map: force", "µN"},
      {"map_hertz", "stiffness map: Hertz apparent modulus", "MPa"},
  };
  return table[v];
}

/// The map value with this key, or −1.
inline int mapValueIndex(const std::string& key) {
  for (int v = 0; v < MapField::kValueCount; ++v)
    if (key == mapValueInfo(v).key) return v;
  return -1;
}

}  // namespace tp::gui
