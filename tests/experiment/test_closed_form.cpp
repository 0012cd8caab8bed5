// Closed-form checks (DESIGN.md §4) on meshes the tests build themselves. Each check runs on a
// sequence of refined meshes: the error must shrink with refinement (the mesh-convergence
// argument) and the finest mesh must be within the stated tolerance.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
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

Material makeMaterial(double E, double nu, double h, BendingModel b) {
  Material m;
  m.youngModulus = E;
  m.poissonRatio = nu;
  m.thickness = h;
  m.bending = b;
  return m;
}

}  // namespace

// Thin sphere inflated by p: ΔR/R = p R (1 − ν) / (2 E h) (small strain).
TEST(ClosedForm, InflatedThinSphere) {
  const double R = 10, E = 100, nu = 0.3, h = 0.05;
  const double expected = 1e-4;  // ΔR/R
  const double p = expected * 2 * E * h / (R * (1 - nu));
  std::vector<double> errors;
  for (int level : {3, 4, 5}) {
    auto cc = std::make_shared<CellComplex>(octaSphere(R, level));
    Model m(cc, makeMaterial(E, nu, h, BendingModel::Hinge));
    m.setUniformPressure(p);
    // Remove the six rigid motions with constraints that radial growth satisfies: the poles keep
    // x and y, the point on +x keeps y and z.
    std::vector<std::uint8_t> fixed(3 * cc->vertexCount(), 0);
    for (int v = 0; v < cc->vertexCount(); ++v) {
      const Vec3 X = cc->rest.col(v) / R;
      if (std::abs(std::abs(X.z()) - 1) < 1e-12) fixed[3 * v] = fixed[3 * v + 1] = 1;
      if (std::abs(X.x() - 1) < 1e-12) fixed[3 * v + 1] = fixed[3 * v + 2] = 1;
    }
    m.setFixedDofs(fixed);
    Points x = cc->rest;
    StaticSolver solver(m);
    const SolveReport rep = solver.solve(x);
    ASSERT_TRUE(rep.converged) << rep.message;
    double mean = 0;
    for (int v = 0; v < cc->vertexCount(); ++v) mean += x.col(v).norm() / R - 1;
    mean /= cc->vertexCount();
    report("sphere dR/R", level, mean, expected);
    errors.push_back(mean / expected - 1);
  }
  expectConverging(errors, 0.01, 0.005, "inflated sphere");
}

// Clamped circular plate, small central point load: δ = F a² / (16 π D).
TEST(ClosedForm, ClampedPlatePointLoad) {
  const double a = 10, E = 100, nu = 0.3, h = 0.1;
  const Material mat = makeMaterial(E, nu, h, BendingModel::Hinge);
  const double D = mat.bendingRigidity();
  const double delta = 1e-3 * h;  // linear regime: δ ≪ h
  const double F = delta * 16 * pi * D / (a * a);
  std::vector<double> errors;
  for (int rings : {8, 16, 32, 64}) {
    // Clamped triangles outside r = a make the edge built-in (zero slope).
    auto cc = std::make_shared<CellComplex>(latticeDisc(a, rings, 3 * a / rings));
    Model m(cc, mat);
    m.setPointForces({{0, Vec3(0, 0, -F)}});
    Points x = cc->rest;
    StaticSolver solver(m);
    const SolveReport rep = solver.solve(x);
    ASSERT_TRUE(rep.converged) << rep.message;
    const double d = -x(2, 0);
    report("plate point load deflection", rings, d, delta);
    errors.push_back(d / delta - 1);
  }
  expectConverging(errors, 0.02, 0.01, "clamped plate, point load");
}

// Clamped circular plate under uniform pressure: δ = q a⁴ / (64 D).
TEST(ClosedForm, ClampedPlateUniformPressure) {
  const double a = 10, E = 100, nu = 0.3, h = 0.1;
  const Material mat = makeMaterial(E, nu, h, BendingModel::Hinge);
  const double D = mat.bendingRigidity();
  const double delta = 1e-3 * h;
  const double q = delta * 64 * D / std::pow(a, 4);
  std::vector<double> errors;
  for (int rings : {8, 16, 32, 64}) {
    auto cc = std::make_shared<CellComplex>(latticeDisc(a, rings, 3 * a / rings, /*cell=*/0));
    Model m(cc, mat);
    m.setUniformPressure(q);  // the cell is below the disc: the plate bulges up (+z)
    Points x = cc->rest;
    StaticSolver solver(m);
    const SolveReport rep = solver.solve(x);
    ASSERT_TRUE(rep.converged) << rep.message;
    const double d = x(2, 0);
    report("plate pressure deflection", rings, d, delta);
    errors.push_back(d / delta - 1);
  }
  expectConverging(errors, 0.03, 0.01, "clamped plate, pressure");
}

namespace {

// Membrane (no bending) solved under a prescribed central deflection, starting from a cone so the
// membrane is in tension from the first iteration (a flat, tension-free membrane has no transverse
// stiffness). Returns the reaction force at the centre.
double membraneCentreForce(const CellComplex& base, const Material& mat, double delta,
                           int* iterations) {
  auto cc = std::make_shared<CellComplex>(base);
  cc->fixed[0] = 1;
  Model m(cc, mat);
  Points x = cc->rest;
  double a = 0;
  for (int v = 0; v < x.cols(); ++v) a = std::max(a, x.col(v).head<2>().norm());
  for (int v = 0; v < x.cols(); ++v) x(2, v) = -delta * (1 - x.col(v).head<2>().norm() / a);
  StaticSolver solver(m);
  const SolveReport rep = solver.solve(x);
  EXPECT_TRUE(rep.converged) << rep.message;
  *iterations = rep.iterations;
  return solver.lastEvaluation().gradient[2];  // ∂W/∂z₀ = applied force (negative: downward)
}

}  // namespace

// Clamped circular membrane, central point load, no bending, no pre-tension:
// F = C(ν) E h δ³ / a², C(1/3) = π/3 exactly, C(0.5) ≈ 1.2133.
TEST(ClosedForm, ClampedMembranePointLoad) {
  const double a = 10, E = 100, h = 0.1, delta = 1.0;
  for (const auto& [nu, C] : {std::pair{1.0 / 3.0, pi / 3.0}, std::pair{0.5, 1.2133}}) {
    const Material mat = makeMaterial(E, nu, h, BendingModel::None);
    const double expected = C * E * h * std::pow(delta, 3) / (a * a);
    std::vector<double> errors;
    for (int rings : {8, 16, 32, 64}) {
      int its = 0;
      const double F = -membraneCentreForce(latticeDisc(a, rings), mat, delta, &its);
      report(nu < 0.4 ? "membrane point load, nu=1/3" : "membrane point load, nu=0.5", rings, F,
             expected);
      errors.push_back(F / expected - 1);
    }
    expectConverging(errors, 0.03, 0.02, "clamped membrane, point load");
  }
}

// Inflated clamped circular membrane (Hencky): δ = K(ν) a (q a / (E h))^(1/3), K(0.3) ≈ 0.6534.
TEST(ClosedForm, HenckyInflatedMembrane) {
  const double a = 10, E = 100, h = 0.1, nu = 0.3, K = 0.6534;
  const double q = 3.0e-3;
  const double expected = K * a * std::cbrt(q * a / (E * h));
  const Material mat = makeMaterial(E, nu, h, BendingModel::None);
  std::vector<double> errors;
  for (int rings : {8, 16, 32, 64}) {
    auto cc = std::make_shared<CellComplex>(latticeDisc(a, rings, 0, /*cell=*/0));
    Model m(cc, mat);
    m.setUniformPressure(q);
    Points x = cc->rest;
    for (int v = 0; v < x.cols(); ++v)  // start from a bulge in tension
      x(2, v) = 0.5 * expected * (1 - x.col(v).head<2>().squaredNorm() / (a * a));
    StaticSolver solver(m);
    const SolveReport rep = solver.solve(x);
    ASSERT_TRUE(rep.converged) << rep.message;
    report("Hencky centre deflection", rings, x(2, 0), expected);
    errors.push_back(x(2, 0) / expected - 1);
  }
  expectConverging(errors, 0.01, 0.01, "Hencky membrane");
}

