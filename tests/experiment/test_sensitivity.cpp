// The probe force's derivatives by implicit differentiation (experiment/Sensitivity.h) against
// central finite differences of whole equilibria (each a new tissue at E ± ε, p ± ε, h ± ε,
// brought to rest, placed and indented), on a small turgid tissue, for each bending model.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "experiment/Sensitivity.h"
#include "solver/Newton.h"
#include "tissue/Refine.h"
#include "tissue/Shapes.h"

using namespace tp;

namespace {

struct Params {
  double E = 50, p = 0.2, h = 0.2;
  BendingModel bending = BendingModel::Koiter;
  bool materialSite = true;
  bool refined = false;  // the box refined twice within 4 µm of the site
};

IndentationSettings settings(bool materialSite) {
  IndentationSettings s;
  s.probeRadius = 1.0;
  if (materialSite)
    s.restSite = Vec3(7.9, 7.3, 10.0);  // a material point of the top wall, off its diagonals
  else
    s.site = Vec3(7.9, 7.3, 10.6);  // a point in space: the surface point nearest to it
  s.axis = Vec3(0, 0, -1);          // held, as an AFM's
  s.maxDepth = 0.3;
  s.steps = 3;
  return s;
}

std::shared_ptr<const CellComplex> tissue(bool refined) {
  static const auto cc = std::make_shared<const CellComplex>(boxTissue(3, 3, 2, 5.0));
  static const auto fine =
      std::make_shared<const CellComplex>(refineNear(*cc, Vec3(7.9, 7.3, 10.0), 4.0, 2));
  return refined ? fine : cc;
}

Material material(const Params& q) {
  Material m;
  m.youngModulus = q.E;
  m.poissonRatio = 0.3;
  m.thickness = q.h;
  m.bending = q.bending;
  return m;
}

// The force at `depth`, and (when asked) its sensitivities there.
double forceAt(const Params& q, double depth, ForceSensitivity* sens = nullptr) {
  Model model(tissue(q.refined), material(q));
  model.setUniformPressure(q.p);
  SolverOptions so;
  so.tolerance = 1e-11;
  Indentation ind(model, settings(q.materialSite), so);
  const SolveReport rest = ind.prepare();
  EXPECT_TRUE(rest.converged) << rest.message;
  // The turgid state's response taken before indenting, as a fit does once per curve.
  const TurgidResponse turgid = sens ? turgidResponse(ind) : TurgidResponse{};
  CurvePoint pt;
  for (int k = 1; k <= 3; ++k) {
    pt = ind.goToDepth(depth * k / 3.0);
    EXPECT_TRUE(pt.converged) << ind.lastMessage();
  }
  if (sens) {
    EXPECT_TRUE(turgid.ok);
    // On the refined tissue the adjoint is solved by conjugate gradients on the factor held
    // from the last solve, when that factor is of a nearby state (EquilibriumSolver::
    // tangentSolve), else by a factorisation. Which one the depth steps leave depends on their
    // path (since the first Newton iteration of a start far from the solution solves to
    // pcgTolerance, the depth steps here end on CG, their last factor from an earlier state, and
    // the adjoint factorises); the factor is refreshed at the state reached, as after a depth
    // step that ends with a factorisation, so that the CG path is the one checked.
    if (q.refined) {
      auto* solver = dynamic_cast<StaticSolver*>(&ind.solver());
      if (solver)
        solver->timeFactorization();
      else
        ADD_FAILURE() << "the indentation's solver is not Newton's";
    }
    const SolverTotals before = ind.solver().totals();
    *sens = forceSensitivity(ind, &turgid);
    // One linear solve (the adjoint): on the refined tissue by conjugate gradients, no
    // factorisation of its own; on the coarse box a factorisation costs fewer operations than
    // two CG iterations (EquilibriumSolver::tangentSolve), so it is one.
    if (q.refined) {
      EXPECT_EQ(ind.solver().totals().factorizations, before.factorizations);
      EXPECT_GT(ind.solver().totals().pcgIterations, before.pcgIterations);
    }
    // The same as computing the turgid response at this point.
    const ForceSensitivity own = forceSensitivity(ind);
    EXPECT_TRUE(own.ok);
    EXPECT_NEAR(own.dE, sens->dE, 1e-9 * std::abs(own.dE));
    EXPECT_NEAR(own.dp, sens->dp, 1e-9 * std::abs(own.dp) + 1e-15);
    EXPECT_NEAR(own.dh, sens->dh, 1e-9 * std::abs(own.dh));
    EXPECT_NEAR(own.dDepth, sens->dDepth, 1e-9 * std::abs(own.dDepth));
  }
  return pt.force;
}

void check(BendingModel bending, double pressure = 0.2, bool materialSite = true,
           bool refined = false) {
  Params q;
  q.refined = refined;
  q.bending = bending;
  q.p = pressure;
  q.materialSite = materialSite;
  ForceSensitivity s;
  const double F = forceAt(q, 0.3, &s);
  ASSERT_TRUE(s.ok);
  EXPECT_NEAR(s.force, F, 1e-12 * std::abs(F));
  ASSERT_GT(F, 0.01);
  auto central = [&](auto set, double x, double rel) {
    const double e = x != 0 ? rel * x : 1e-4;  // (p = 0: an absolute step)
    Params a = q, b = q;
    set(a, x + e);
    set(b, x - e);
    return (forceAt(a, 0.3) - forceAt(b, 0.3)) / (2 * e);
  };
  const double fdE = central([](Params& p, double v) { p.E = v; }, q.E, 1e-3);
  const double fdP = central([](Params& p, double v) { p.p = v; }, q.p, 1e-3);
  const double fdH = central([](Params& p, double v) { p.h = v; }, q.h, 1e-3);
  const double fdD = (forceAt(q, 0.3 + 1e-4) - forceAt(q, 0.3 - 1e-4)) / 2e-4;
  std::printf(
      "  F = %.6g uN; dF/dE %.6g (FD %.6g), dF/dp %.6g (FD %.6g), dF/dh %.6g (FD %.6g), "
      "dF/dd %.6g (FD %.6g)\n",
      F, s.dE, fdE, s.dp, fdP, s.dh, fdH, s.dDepth, fdD);
  // Each derivative matters (F's logarithmic derivative in each parameter is above 0.05), so a
  // relative agreement of 1e-5 (as issue 13 asks) is a real check; without the first-contact shift
  // dF/dp was 4 % off, without the contact law's scaling with E h dF/dE and dF/dh 2.4 %.
  EXPECT_NEAR(s.dE, fdE, 1e-5 * std::abs(fdE));
  EXPECT_NEAR(s.dp, fdP, 1e-5 * std::abs(fdP));
  EXPECT_NEAR(s.dh, fdH, 1e-5 * std::abs(fdH));
  EXPECT_NEAR(s.dDepth, fdD, 1e-5 * std::abs(fdD));
  EXPECT_GT(std::abs(s.dE) * q.E, 0.05 * F);
  if (q.p > 0) {
    EXPECT_GT(std::abs(s.dp) * q.p, 0.05 * F);
  }
  EXPECT_GT(std::abs(s.dh) * q.h, 0.05 * F);
}

}  // namespace

TEST(ForceSensitivity, KoiterMatchesFiniteDifferencesOfWholeEquilibria) {
  check(BendingModel::Koiter);
}
TEST(ForceSensitivity, HingeMatchesFiniteDifferencesOfWholeEquilibria) {
  check(BendingModel::Hinge);
}
TEST(ForceSensitivity, SiteGivenInSpaceMatchesFiniteDifferencesOfWholeEquilibria) {
  check(BendingModel::Koiter, 0.2, false);
}
TEST(ForceSensitivity, PlasmolysedMatchesFiniteDifferencesOfWholeEquilibria) {
  check(BendingModel::Koiter, 0.0);
}
TEST(ForceSensitivity, RefinedTissueSolvedByConjugateGradientsMatchesFiniteDifferences) {
  check(BendingModel::Koiter, 0.2, true, true);
}
