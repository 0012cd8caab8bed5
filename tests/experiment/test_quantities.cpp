// The colour quantities' table (experiment/Quantities.h): the changes from the turgid state are
// the differences of the two states' read-outs, zero at the turgid state; the displacement is
// the mean of the corners' distances; keys round-trip; the VTU export carries every quantity.
#include <gtest/gtest.h>

#include <set>

#include "experiment/Quantities.h"
#include "support/ModelDerivatives.h"
#include "tissue/Shapes.h"

using namespace tp;

TEST(Quantities, ChangesFromTurgidAreDifferencesAndVanishThere) {
  auto cc = std::make_shared<CellComplex>(boxTissue(2, 1, 1, 1.0));
  const Model m(cc, Material{});
  const Points turgid = test::perturbedRest(*cc, 0.03, 1), x = test::perturbedRest(*cc, 0.05, 2);
  const StressField st = computeStress(m, x), st0 = computeStress(m, turgid);
  const auto v = triangleQuantities({&st, &st0, cc.get(), &x, &turgid});
  const auto at0 = triangleQuantities({&st0, &st0, cc.get(), &turgid, &turgid});
  const int T = cc->triangleCount();
  double largest = 0;
  for (int t = 0; t < T; ++t) {
    EXPECT_EQ(v[int(Quantity::VonMisesChange)][t], st.triangles[t].vonMises - st0.triangles[t].vonMises);
    EXPECT_EQ(v[int(Quantity::PrincipalMaxChange)][t],
              st.triangles[t].principalMax - st0.triangles[t].principalMax);
    EXPECT_EQ(v[int(Quantity::VonMises)][t], st.triangles[t].vonMises);
    EXPECT_EQ(at0[int(Quantity::VonMisesChange)][t], 0.0);
    EXPECT_EQ(at0[int(Quantity::Displacement)][t], 0.0);
    const auto& tri = cc->triangles[t];
    double d = 0;
    for (int k = 0; k < 3; ++k) d += (x.col(tri[k]) - turgid.col(tri[k])).norm();
    EXPECT_NEAR(v[int(Quantity::Displacement)][t], d / 3, 1e-15);
    largest = std::max(largest, std::abs(v[int(Quantity::VonMisesChange)][t]));
  }
  EXPECT_GT(largest, 0.1);  // the states differ by strains of a few percent: MPa-sized changes
  // Without the turgid state the changes are 0, not garbage.
  const auto none = triangleQuantities({&st, nullptr, cc.get(), &x, nullptr});
  for (int t = 0; t < T; ++t) EXPECT_EQ(none[int(Quantity::VonMisesChange)][t], 0.0);
}

TEST(Quantities, KeysRoundTripAndTheExportCarriesEveryQuantity) {
  std::set<std::string> keys;
  for (int q = 0; q < kQuantityCount; ++q) {
    const QuantityInfo& info = quantityInfo(Quantity(q));
    EXPECT_EQ(quantityIndex(info.key), q);
    keys.insert(info.key);
  }
  EXPECT_EQ(static_cast<int>(keys.size()), kQuantityCount);
  EXPECT_EQ(quantityIndex("no_such_quantity"), -1);

  auto cc = std::make_shared<CellComplex>(boxTissue(1, 1, 1, 1.0));
  const Model m(cc, Material{});
  const Points turgid = test::perturbedRest(*cc, 0.02, 3), x = test::perturbedRest(*cc, 0.04, 4);
  const StateFields f = stateFields(m, x, turgid);
  std::set<std::string> names;
  for (const auto& field : f.triangles) {
    EXPECT_EQ(static_cast<int>(field.values.size()), field.components * cc->triangleCount()) << field.name;
    names.insert(field.name);
  }
  for (int q = 0; q < kQuantityCount; ++q) {
    if (Quantity(q) == Quantity::Displacement) continue;  // a vector per point instead
    const QuantityInfo& info = quantityInfo(Quantity(q));
    EXPECT_TRUE(names.count(std::string(info.key) + "_" + info.unit)) << info.key;
  }
  EXPECT_TRUE(names.count("cauchy_stress_MPa"));
}
