#pragma once
// The small meristem the quick tests indent: 60 cells, a dome 30 µm across and 12 µm high on a
// 4 µm stem, seed 3 (what `tissueprobe-cli build --generate --cells 60 --diameter 30
// --cap-height 12 --stem-height 4 --seed 3` makes), built once per test program.
#include <memory>

#include "tissue/Meristem.h"

namespace tp::test {

inline std::shared_ptr<const CellComplex> smallMeristem() {
  static const auto cc = [] {
    MeristemParams p;
    p.cells = 60;
    p.shape.radius = 15;
    p.shape.capHeight = 12;
    p.shape.stemHeight = 4;
    p.seed = 3;
    return std::make_shared<const CellComplex>(generateMeristem(p));
  }();
  return cc;
}

}  // namespace tp::test
