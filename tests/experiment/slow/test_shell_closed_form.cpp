// Shell closed forms with Koiter bending on curved, faceted meshes (DESIGN.md §4): the point
// load on a thin sphere, unpressurised (Reissner) and pressurised (Vella et al. 2012), on a
// structured and an irregular cap. The facets make these converge at first order, so the meshes
// go to 120 rings (about a minute each): ctest label "slow", run by CI.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mechanics/Model.h"
#include "solver/Newton.h"
#include "support/ConvergenceCheck.h"
#include "tissue/Shapes.h"

using namespace tp;
using std::numbers::pi;
using tp::test::expectConverging;
using tp::test::report;

namespace {

Material koiter(double E, double nu, double h) {
  Material m;
  m.youngModulus = E;
  m.poissonRatio = nu;
  m.thickness = h;
  m.bending = BendingModel::Koiter;
  return m;
}

// A flat disc of radius capRadius mapped onto the sphere of radius R around the +z pole at equal
// geodesic distance (as sphericalCap maps its lattice): the irregular twin of sphericalCap.
CellComplex capFromDisc(CellComplex cc, double R, double capRadius) {
  const double phiMax = std::asin(capRadius / R);
  for (int v = 0; v < cc.vertexCount(); ++v) {
    const double x = cc.rest(0, v), y = cc.rest(1, v);
    const double phi = phiMax * std::hypot(x, y) / capRadius, th = std::atan2(y, x);
    cc.rest.col(v) = R * Vec3(std::sin(phi) * std::cos(th), std::sin(phi) * std::sin(th), std::cos(phi));
  }
  return cc;
}

// Point-load stiffness of a spherical cap (clamped six decay lengths from the pole, where the
// load no longer reaches), inflated first by p when p > 0: F/δ at the pole for a small F.
double capStiffness(const CellComplex& base, const Material& mat, double p, double F) {
  auto cc = std::make_shared<CellComplex>(base);
  Model m(cc, mat);
  if (p > 0) m.setUniformPressure(p);
  Points x = cc->rest;
  StaticSolver solver(m);
  if (p > 0) {
    const SolveReport rep = solver.solve(x);
    EXPECT_TRUE(rep.converged) << rep.message;
  }
  const double z0 = x(2, 0);
  m.setPointForces({{0, Vec3(0, 0, -F)}});
  const SolveReport rep = solver.solve(x);
  EXPECT_TRUE(rep.converged) << rep.message;
  return F / (z0 - x(2, 0));
}

}  // namespace

// Unpressurised thin sphere under a point load (Reissner): F/δ = 4 E h² / (R √(3(1 − ν²))),
// for δ ≪ h. The load is local (decay length ~ √(Rh)), so a spherical cap clamped six √(Rh)
// from the pole stands for the whole sphere; on the structured cap and on an irregular one
// (Delaunay of random points), with Koiter bending.
TEST(ClosedForm, ReissnerPointLoadOnSphere) {
  const double R = 10, E = 100, h = 0.1, nu = 0.3;
  const double k = 4 * E * h * h / (R * std::sqrt(3 * (1 - nu * nu)));
  const double F = 1e-3 * h * k;
  const Material mat = koiter(E, nu, h);
  const double cap = 6 * std::sqrt(R * h);
  for (bool irregular : {false, true}) {
    std::vector<double> errors;
    for (int rings : {30, 60, 120}) {
      const CellComplex cc = irregular ? capFromDisc(delaunayDisc(cap, cap / rings, 5 + rings), R, cap)
                                       : sphericalCap(R, cap, rings);
      const double stiffness = capStiffness(cc, mat, 0.0, F);
      report(irregular ? "Reissner F/delta, irregular" : "Reissner F/delta", rings, stiffness, k);
      errors.push_back(stiffness / k - 1);
    }
    expectConverging(errors, 0.02, 0.02, irregular ? "Reissner sphere, irregular" : "Reissner sphere");
  }
}

// Pressurised thin sphere under a point load (Vella et al., "The indentation of pressurized
// elastic shells: from polymer gels to yeast cells", J. R. Soc. Interface 9, 2012): the linear
// shallow-shell equation B∇⁴w − T∇²w + Y w/R² = F δ with the membrane tension T = pR/2 of the
// inflated shell (B = D, Y = E h) gives, by Hankel transform, w(0) = (F/2π)∫ k dk/(Bk⁴ + Tk² +
// Y/R²), i.e. for τ = pR²/(4√(BY)) > 1
//   F/δ = (4π √(BY)/R) √(τ² − 1) / arccosh τ
// (8√(BY)/R, Reissner's, as τ → 0). R is the inflated radius. τ = 2, structured and irregular.
TEST(ClosedForm, VellaPressurisedSpherePointLoad) {
  const double R0 = 10, E = 100, h = 0.1, nu = 0.3, tau = 2.0;
  const Material mat = koiter(E, nu, h);
  const double B = mat.bendingRigidity(), Y = E * h;
  const double p = 4 * tau * std::sqrt(B * Y) / (R0 * R0);
  const double R = R0 * (1 + p * R0 * (1 - nu) / (2 * E * h));  // inflated (small strain)
  const double tauR = p * R * R / (4 * std::sqrt(B * Y));
  const double k = 4 * pi * std::sqrt(B * Y) / R * std::sqrt(tauR * tauR - 1) / std::acosh(tauR);
  const double F = 1e-3 * h * k;
  const double cap = 6 * std::sqrt(R0 * h);
  for (bool irregular : {false, true}) {
    std::vector<double> errors;
    for (int rings : {30, 60, 120}) {
      const CellComplex base = irregular ? delaunayDisc(cap, cap / rings, 9 + rings, 0, /*cell=*/0)
                                         : latticeDisc(cap, rings, 0, /*cell=*/0);
      // The cell lies below the cap (the disc's +z normal points out of it): p inflates it.
      const double stiffness = capStiffness(capFromDisc(base, R0, cap), mat, p, F);
      report(irregular ? "Vella F/delta, irregular" : "Vella F/delta", rings, stiffness, k);
      errors.push_back(stiffness / k - 1);
    }
    // The finest caps are within 2 % (+0.23 % structured, −0.21 % irregular, measured), but the
    // sequence crosses zero at 120 rings, so the observed order (about 1) is pre-asymptotic and
    // its Richardson limit (+3 %, +5 %) is only a bound: it is held to 6 %. A fourth structured
    // cap (240 rings, 50 s; measured 2026-12-05, not run here) gave +1.37 %, order 1.46 from
    // 60/120/240 and a limit of +2.0 %: the discretisation converges to about 2 % above this
    // closed form, a linear shallow-shell result that leaves out terms of relative order
    // pR/(Eh) (2.4 % here; the inflation's strain is 0.85 %).
    expectConverging(errors, 0.02, 0.06, irregular ? "Vella sphere, irregular" : "Vella sphere");
  }
}
