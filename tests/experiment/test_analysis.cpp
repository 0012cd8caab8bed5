// Reading a curve as experimentalists do (experiment/Analysis.h): the Hertz fit recovers the
// modulus of a curve made with the Hertz law, and ignores what is not a loading equilibrium.
#include <gtest/gtest.h>

#include <cmath>
#include <tuple>
#include <vector>

#include "experiment/Analysis.h"

using namespace tp;

namespace {
// F = (4/3) E/(1 − ν²) √R δ^{3/2} (Hertz, a sphere of radius R on an elastic half-space).
double hertzForce(double E, double nu, double R, double depth) {
  return 4.0 / 3.0 * E / (1 - nu * nu) * std::sqrt(R) * std::pow(depth, 1.5);
}
}  // namespace

TEST(Analysis, HertzFitRecoversTheModulusOfAHertzCurve) {
  for (const auto& [E, nu, R] : {std::tuple{2.5, 0.3, 1.5}, std::tuple{40.0, 0.49, 0.25}}) {
    std::vector<CurvePoint> curve{{0.0, 0.0, 0, 0.0, true, false}};
    for (int i = 1; i <= 10; ++i) {
      const double d = 0.05 * i;
      curve.push_back({d, hertzForce(E, nu, R, d), 1, 1e-10, true, false});
    }
    // Not loading equilibria: a failed point (NaN force), an unloading point with a force the
    // fit would notice, a point that did not converge.
    curve.push_back({0.6, std::nan(""), 3, 1.0, false, false});
    curve.push_back({0.4, 1e3, 1, 1e-10, true, true});
    curve.push_back({0.3, -5.0, 60, 1e-2, false, false});
    EXPECT_NEAR(hertzApparentModulus(curve, R, nu), E, 1e-12 * E);
    // The secant stiffness is that of the last converged loading point (0.5 µm).
    EXPECT_NEAR(secantStiffness(curve), hertzForce(E, nu, R, 0.5) / 0.5, 1e-12 * E);
  }
}

TEST(Analysis, NoUsablePointGivesNaN) {
  const std::vector<CurvePoint> none{{0.0, 0.0, 0, 0.0, true, false},
                                     {0.1, 2.0, 1, 1e-10, false, false}};
  EXPECT_TRUE(std::isnan(hertzApparentModulus(none, 1.0, 0.3)));
  EXPECT_TRUE(std::isnan(secantStiffness(none)));
  EXPECT_TRUE(std::isnan(hertzApparentModulus({{0.1, 2.0, 1, 0, true, false}}, 0.0, 0.3)));
}
