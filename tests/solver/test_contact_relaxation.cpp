// The contact patch's own solves (solver/ContactRelaxation.h): the row index of a pattern, the
// local tangent block and its block Gauss–Seidel correction, the relaxation of the pressed
// vertices, and a Newton solve with them against one without.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "experiment/Experiment.h"
#include "mechanics/Model.h"
#include "solver/ContactRelaxation.h"
#include "solver/Newton.h"
#include "support/SmallMeristem.h"

using namespace tp;

namespace {

// The small meristem, turgid (0.8 MPa), with a 1 µm probe pressed `depth` into its top along −z
// (contact law as Indentation sets it: onset over a tenth of the radius); x its equilibrium.
struct Pressed {
  std::shared_ptr<const CellComplex> cc = test::smallMeristem();
  Model model{cc, Material{}};
  StaticSolver solver{model};
  Points x;
  Vec3 top;
  double radius = 1.0;

  explicit Pressed(double depth) {
    model.setUniformPressure(0.8);
    x = cc->rest;
    EXPECT_TRUE(solver.solve(x).converged);
    int v = 0;
    for (int i = 0; i < x.cols(); ++i)
      if (x(2, i) > x(2, v)) v = i;
    top = x.col(v);
    ContactLaw law = model.contactLaw();
    law.smoothing = 0.1 * radius;
    model.setContactLaw(law);
    // Pressed in two steps, as a curve would be.
    for (double d : {0.5 * depth, depth}) {
      setDepth(d);
      EXPECT_TRUE(solver.solve(x).converged) << "at " << d;
    }
  }
  void setDepth(double d) { model.setProbe({top + Vec3(0, 0, radius + 1e-3 - d), radius}); }
};

double localNorm(const Model& m, const std::vector<int>& unknowns, const Eigen::VectorXd& g) {
  double s = 0;
  for (int i : unknowns)
    if (i < m.dofs().freeCount()) s += std::pow(g[m.dofs().freeDofs()[i]], 2);
  return std::sqrt(s);
}

}  // namespace

TEST(ContactRelaxation, PatternRowsListEveryEntryAboveTheDiagonalOnce) {
  Pressed p(0.2);
  const SparsePattern& P = p.model.pattern();
  PatternRows rows;
  rows.build(P);
  ASSERT_TRUE(rows.builtFor(P));
  EXPECT_EQ(static_cast<int>(rows.col.size()), P.nnz() - P.n);  // all but the diagonal
  for (int i = 0; i < P.n; ++i)
    for (int e = rows.start[i]; e < rows.start[i + 1]; ++e) {
      ASSERT_GT(rows.col[e], i);
      ASSERT_EQ(P.find(i, rows.col[e]), rows.pos[e]);
      if (e > rows.start[i]) {
        ASSERT_LT(rows.col[e - 1], rows.col[e]);
      }
    }
}

TEST(ContactRelaxation, LocalTangentIsTheBlockAndItsCorrectionSolvesTheLocalRows) {
  Pressed p(0.2);
  const Model& m = p.model;
  const SparsePattern& P = m.pattern();
  PatternRows rows;
  rows.build(P);
  Evaluation ev;
  m.evaluate(p.x, ev, true);
  const std::vector<int> L = pressedUnknowns(m, p.x, rows);
  // The pressed triangles' vertices, and Koiter's edge unknowns (after the positions) with them.
  const int n = m.dofs().freeCount();
  const auto positions = std::count_if(L.begin(), L.end(), [&](int i) { return i < n; });
  EXPECT_GE(positions, 9);
  EXPECT_GT(static_cast<long>(L.size()), positions);
  LocalTangent T;
  ASSERT_TRUE(T.build(rows, ev.hessian, L, true));
  const int k = T.size();
  for (int a = 0; a < k; ++a)
    for (int b = 0; b < k; ++b) {
      const int i = std::min(L[a], L[b]), j = std::max(L[a], L[b]);
      const int pos = P.find(i, j);
      ASSERT_EQ(T.block()(a, b), pos >= 0 ? ev.hessian[pos] : 0.0) << a << ", " << b;
    }
  // y − A E w against the whole matrix's product.
  Eigen::VectorXd w = Eigen::VectorXd::LinSpaced(k, -1.0, 2.0), full = Eigen::VectorXd::Zero(P.n);
  for (int a = 0; a < k; ++a) full[L[a]] = w[a];
  Eigen::VectorXd Aw(P.n), y = Eigen::VectorXd::Zero(P.n);
  symmetricMultiply(P, ev.hessian, full.data(), Aw.data());
  T.subtractProduct(w, y);
  EXPECT_LE((y + Aw).norm(), 1e-12 * Aw.norm());
  // After the correction r − A z vanishes on the local rows, from any z.
  Eigen::VectorXd r = Eigen::VectorXd::Ones(P.n), z = Eigen::VectorXd::Constant(P.n, 0.01);
  T.correct(r, z);
  Eigen::VectorXd Az(P.n);
  symmetricMultiply(P, ev.hessian, z.data(), Az.data());
  double local = 0, scale = 0;
  for (int i : L) {
    local = std::max(local, std::abs(r[i] - Az[i]));
    scale = std::max(scale, std::abs(Az[i]));
  }
  EXPECT_LE(local, 1e-9 * scale);
  // Too large a block is refused rather than solved densely.
  std::vector<int> many(LocalTangent::kMaxSize + 1);
  for (int i = 0; i < static_cast<int>(many.size()); ++i) many[i] = i;
  EXPECT_FALSE(T.build(rows, ev.hessian, many, true));
  EXPECT_FALSE(T.active());
}

TEST(ContactRelaxation, RelaxedVerticesTakeTheContactsNonlinearity) {
  // An equilibrium at 0.2 µm, the probe then moved 0.02 µm deeper with the tissue left where it
  // was (the worst predictor): the pressed vertices carry the residual. Relaxed with the tangent
  // of the equilibrium, their residual falls by far more than tenfold and the energy falls.
  Pressed p(0.2);
  Model& m = p.model;
  PatternRows rows;
  rows.build(m.pattern());
  Evaluation ev;
  m.evaluate(p.x, ev, true);
  ContactRelaxation relax;
  relax.hold(m, p.x, ev.hessian, false);
  ASSERT_NE(relax.heldTangent(m), nullptr);
  p.setDepth(0.22);
  m.evaluate(p.x, ev, false);
  const std::vector<int> L = pressedUnknowns(m, p.x, rows);
  const double before = localNorm(m, L, ev.gradient);
  const double energyBefore = ev.energy.total();
  ASSERT_GT(before, 1e-3);
  Points dx;
  ASSERT_TRUE(relax.relax(m, rows, p.x, ev.gradient, 1e-12, dx));
  // Only the pressed vertices moved.
  std::vector<char> moved(p.x.cols(), 0);
  for (int i : L)
    if (i < m.dofs().freeCount()) moved[m.dofs().freeDofs()[i] / 3] = 1;
  for (int v = 0; v < p.x.cols(); ++v)
    if (!moved[v]) {
      ASSERT_EQ(dx.col(v).norm(), 0.0) << v;
    }
  Evaluation after;
  m.evaluate(p.x + dx, after, false);
  const double relaxed = localNorm(m, L, after.gradient);
  EXPECT_LT(relaxed, 0.02 * before) << before << " → " << relaxed;
  std::printf("residual on the pressed vertices: %.3e µN before, %.3e µN relaxed\n", before,
              relaxed);
  EXPECT_LT(after.energy.total(), energyBefore);
  // A different probe radius (another contact law) makes the held tangent unusable.
  m.setProbe({m.probe()->center, 2.0});
  EXPECT_EQ(relax.heldTangent(m), nullptr);
  EXPECT_FALSE(relax.relax(m, rows, p.x, ev.gradient, 1e-12, dx));
}

TEST(ContactRelaxation, CurvesWithAndWithoutItAgreeAndItSavesIterations) {
  // The small meristem at a fixed level 2, 8 steps to 0.4 µm: the same forces to the solver's
  // tolerance (a few 1e-6 of the force, see test_experiment), in fewer Newton iterations.
  ExperimentSettings s;
  s.indentation.maxDepth = 0.4;
  s.indentation.steps = 8;
  s.mesh.automatic = false;
  s.mesh.estimateError = false;
  s.mesh.level = 2;
  ExperimentSettings off = s;
  off.solver.relaxContact = false;
  const ExperimentResult with = Experiment(test::smallMeristem(), s).run();
  const ExperimentResult without = Experiment(test::smallMeristem(), off).run();
  ASSERT_TRUE(with.complete) << with.message;
  ASSERT_TRUE(without.complete) << without.message;
  ASSERT_EQ(with.curve.size(), without.curve.size());
  int itsWith = 0, itsWithout = 0;
  for (size_t i = 1; i < with.curve.size(); ++i) {
    EXPECT_NEAR(with.curve[i].force, without.curve[i].force,
                2e-5 * std::abs(without.curve[i].force))
        << "at " << with.curve[i].depth;
    itsWith += with.curve[i].iterations;
    itsWithout += without.curve[i].iterations;
  }
  EXPECT_LT(itsWith, itsWithout);
  std::printf("Newton iterations for the curve: %d with the contact patch's solves, %d without\n",
              itsWith, itsWithout);
}

TEST(ContactRelaxation, AStartNearTheSolutionTakesAnExactNewtonStepFromTheFirst) {
  // A solve started near the solution (within 1e4 × its tolerance; a fit's points start
  // from the last parameters' equilibria moved to first order) takes the exact tangent from its
  // first iteration: one step, and quadratic convergence far below the tolerance. With the
  // contact Hessian's positive part (the first iteration's choice further away) the step gained
  // only ~100×: 7.7e-8 → 6.7e-10 relative, and a second iteration for 1e-10.
  Pressed p(0.3);
  const Points solved = p.x;
  for (double move : {1e-9, 2e-9}) {  // µm: starts at ~4e-8 and ~8e-8 of the load scale
    SolverOptions o;
    o.tolerance = 1e-10;
    StaticSolver solver(p.model, o);
    Points x = solved;
    p.setDepth(0.3 + move);
    const SolveReport rep = solver.solve(x);
    EXPECT_TRUE(rep.converged) << rep.message;
    EXPECT_EQ(rep.iterations, 1) << "move " << move;
    EXPECT_LT(rep.relativeResidual(), 1e-3 * o.tolerance) << "move " << move;
    p.setDepth(0.3);
  }
}
