// Following a dragged probe (core/experiment/Drag.h) on a small turgid tissue: bounded steps
// toward the depth asked, an adaptive step, reversal, the solver's tolerance left as it was,
// failures retried smaller and then reported, and the renewed chord of each step's first
// direction (the same equilibria for fewer assemblies).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "experiment/Drag.h"
#include "tissue/Shapes.h"

using namespace tp;

namespace {

struct DragTissue {
  std::shared_ptr<CellComplex> cc = std::make_shared<CellComplex>(boxTissue(3, 3, 2, 5.0));
  Material mat;
  std::unique_ptr<Model> model;
  std::unique_ptr<Indentation> ind;
  explicit DragTissue(SolverOptions solver = {}) {
    mat.youngModulus = 50;
    mat.poissonRatio = 0.3;
    mat.thickness = 0.2;
    model = std::make_unique<Model>(cc, mat);
    model->setUniformPressure(0.2);
    IndentationSettings s;
    s.probeRadius = 1.0;
    s.site = Vec3(7.5, 7.5, 10.2);  // above the middle of the top
    ind = std::make_unique<Indentation>(*model, s, solver);
    EXPECT_TRUE(ind->prepare().converged);
  }
};

// Follows `depth` until the follower says it is there; returns the steps' largest move.
double followDrag(DragFollower& drag, Indentation& ind, double depth, int& calls,
              CurvePoint* last = nullptr) {
  double largest = 0;
  for (calls = 0; calls < 200; ++calls) {
    const double before = ind.depth();
    const DragStep s = drag.toward(ind, depth);
    EXPECT_FALSE(s.failed()) << ind.lastMessage();
    EXPECT_TRUE(s.point.converged);
    EXPECT_LE(s.point.residual, drag.options().tolerance);
    largest = std::max(largest, std::abs(s.point.depth - before));
    if (last) *last = s.point;
    if (!s.more) break;
  }
  return largest;
}

}  // namespace

TEST(DragFollower, StepsBoundedTowardTheDepthAskedAndTheStepGrows) {
  DragTissue f;
  const double tolerance = f.ind->solver().options().tolerance;
  DragFollower drag;
  const double radius = 1.0, first = drag.options().startRadii * radius;
  // The first call moves the first step exactly, and says there is more to go.
  const DragStep s = drag.toward(*f.ind, 0.5);
  ASSERT_TRUE(s.point.converged) << f.ind->lastMessage();
  EXPECT_TRUE(s.more);
  EXPECT_NEAR(s.point.depth, first, 1e-15);
  EXPECT_EQ(f.ind->solver().options().tolerance, tolerance);  // only during the step
  int calls = 0;
  CurvePoint there;
  const double largest = followDrag(drag, *f.ind, 0.5, calls, &there);
  EXPECT_EQ(f.ind->depth(), 0.5);
  EXPECT_LE(largest, drag.options().maxRadii * radius * (1 + 1e-12));
  // Steps of one iteration grow the step by half, steps of more halve it: the 0.475 µm left
  // took fewer calls than steps of the first size would (19).
  EXPECT_GT(drag.step(), first);
  EXPECT_LT(calls + 1, 19) << calls;  // 15 here (7 when steps of two iterations grew too)
  EXPECT_EQ(f.ind->solver().options().tolerance, tolerance);
  // The equilibrium reached is the curve's at that depth (the drag's 1e-7 residual against
  // the solver's 1e-8: forces within 1e-5 of each other).
  DragTissue g;
  const CurvePoint direct = g.ind->goToDepth(0.5);
  ASSERT_TRUE(direct.converged);
  EXPECT_NEAR(there.force, direct.force, 1e-5 * direct.force);
}

TEST(DragFollower, ReversesAndRetracesTheCurve) {
  DragTissue f;
  DragFollower drag;
  int calls = 0;
  followDrag(drag, *f.ind, 0.4, calls);
  ASSERT_EQ(f.ind->depth(), 0.4);
  CurvePoint back;
  followDrag(drag, *f.ind, 0.1, calls, &back);
  EXPECT_EQ(f.ind->depth(), 0.1);
  EXPECT_TRUE(back.unloading);
  DragTissue g;
  const CurvePoint direct = g.ind->goToDepth(0.1);
  ASSERT_TRUE(direct.converged);
  EXPECT_NEAR(back.force, direct.force, 1e-5 * direct.force);  // elastic: no memory of the way
  // reset() starts the next drag from the first step again.
  drag.reset();
  EXPECT_EQ(drag.step(), 0.0);
  const DragStep s = drag.toward(*f.ind, 0.3);
  EXPECT_NEAR(s.point.depth, 0.1 + drag.options().startRadii, 1e-12);
}

TEST(DragFollower, AFailedStepIsRetriedSmallerThenReported) {
  DragTissue f;
  f.ind->solver().options().maxIterations = 0;  // no step can converge now
  const double tolerance = f.ind->solver().options().tolerance;
  const Points before = f.ind->state();
  DragFollower drag;
  const double radius = 1.0;
  int retries = 0;
  DragStep s;
  for (; retries < 20; ++retries) {
    s = drag.toward(*f.ind, 0.5);
    EXPECT_FALSE(s.point.converged);
    if (!s.more) break;
  }
  // Halved from 0.025 to the 0.01 floor: two retries, then the failure.
  EXPECT_EQ(retries, 2);
  EXPECT_TRUE(s.failed());
  EXPECT_NEAR(drag.step(), drag.options().minRadii * radius, 1e-15);
  EXPECT_EQ(f.ind->depth(), 0.0);  // nothing moved
  EXPECT_EQ((f.ind->state() - before).norm(), 0.0);
  EXPECT_NE(f.ind->lastMessage().find("no equilibrium"), std::string::npos) << f.ind->lastMessage();
  EXPECT_EQ(f.ind->solver().options().tolerance, tolerance);
}

TEST(DragFollower, TheProbeChangesTheTangentOnlyThroughTheContactTerm) {
  // What the renewed chord of a drag step rests on (SolverOptions::renewedChordFirst): at the
  // same positions, moving the probe changes the tangent by the contact term's part alone,
  // K(x, p') = K(x, p) − C(x, p) + C(x, p'), to rounding.
  DragTissue f;
  ASSERT_TRUE(f.ind->goToDepth(0.3).converged);
  Model& m = *f.model;
  const Points x = f.ind->state();
  const Probe p = *m.probe(), moved{p.center + 0.05 * f.ind->placement().axis, p.radius};
  const EvalOptions all{.hessian = true}, contact{.hessian = true, .onlyTerm = m.contactTerm()};
  ASSERT_GE(m.contactTerm(), 0);
  Evaluation K, C, K2, C2;
  m.evaluate(x, K, all);
  m.evaluate(x, C, contact);
  m.setProbe(moved);
  m.evaluate(x, K2, all);
  m.evaluate(x, C2, contact);
  m.setProbe(p);
  ASSERT_GT(K.contactTriangles, 0);
  double scale = 0, contactChange = 0, mismatch = 0;
  for (size_t i = 0; i < K.hessian.size(); ++i) {
    scale = std::max(scale, std::abs(K.hessian[i]));
    contactChange = std::max(contactChange, std::abs(C2.hessian[i] - C.hessian[i]));
    mismatch =
        std::max(mismatch, std::abs(K2.hessian[i] - (K.hessian[i] - C.hessian[i] + C2.hessian[i])));
  }
  EXPECT_GT(contactChange, 1e-3 * scale);  // the probe's move does change the tangent
  EXPECT_LE(mismatch, 1e-12 * scale);
}

TEST(DragFollower, RenewedChordsSaveAssembliesAndKeepTheEquilibria) {
  // Down to 0.4 µm and back to 0.1 µm, with each step's first direction on the held tangent
  // (contact part renewed, the default) and with a new assembly for it: the same forces where
  // both end (each within the drag's 1e-7 residual), fewer assemblies per equilibrium with it.
  double force[2][2];
  double assembliesPerEquilibrium[2];
  for (int renewed = 0; renewed < 2; ++renewed) {
    DragTissue f;
    DragOptions o;
    o.renewedChord = renewed == 1;
    DragFollower drag(o);
    const SolverTotals before = f.ind->solver().totals();
    int calls = 0, equilibria = 0;
    CurvePoint end;
    followDrag(drag, *f.ind, 0.4, calls, &end);
    equilibria += calls + 1;
    force[renewed][0] = end.force;
    followDrag(drag, *f.ind, 0.1, calls, &end);
    equilibria += calls + 1;
    force[renewed][1] = end.force;
    const SolverTotals& after = f.ind->solver().totals();
    EXPECT_EQ(after.renewedChords > before.renewedChords, renewed == 1);
    assembliesPerEquilibrium[renewed] = double(after.assemblies - before.assemblies) / equilibria;
    EXPECT_FALSE(f.ind->solver().options().renewedChordFirst);  // only during the steps
  }
  EXPECT_NEAR(force[1][0], force[0][0], 1e-5 * force[0][0]);
  EXPECT_NEAR(force[1][1], force[0][1], 1e-5 * force[0][1]);
  EXPECT_LT(assembliesPerEquilibrium[1], 0.8 * assembliesPerEquilibrium[0])
      << assembliesPerEquilibrium[1] << " against " << assembliesPerEquilibrium[0];
}
