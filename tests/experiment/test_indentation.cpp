// The indentation protocol on a small turgid tissue: rest state, placement, curves under depth and
// force control, unloading, failure handling.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "experiment/Indentation.h"
#include "tissue/Shapes.h"

using namespace tp;

namespace {

struct Fixture {
  std::shared_ptr<CellComplex> cc;
  Material mat;
  std::unique_ptr<Model> model;
  Fixture(double pressure = 0.2) {
    cc = std::make_shared<CellComplex>(boxTissue(3, 3, 2, 5.0));
    mat.youngModulus = 50;
    mat.poissonRatio = 0.3;
    mat.thickness = 0.2;
    model = std::make_unique<Model>(cc, mat);
    model->setUniformPressure(pressure);
  }
};

IndentationSettings settings(double depth, int steps, bool unload) {
  IndentationSettings s;
  s.probeRadius = 1.0;
  s.site = Vec3(7.5, 7.5, 10.2);  // just above the middle of the top
  s.maxDepth = depth;
  s.steps = steps;
  s.unload = unload;
  return s;
}

}  // namespace

TEST(Indentation, TurgidRestStateAndPlacement) {
  Fixture f;
  Indentation ind(*f.model, settings(0.5, 5, false));
  const SolveReport rep = ind.prepare();
  ASSERT_TRUE(rep.converged) << rep.message;
  // Turgor inflates the cells.
  const auto v0 = cellVolumes(*f.cc, f.cc->rest);
  const auto v1 = cellVolumes(*f.cc, ind.turgidState());
  for (size_t c = 0; c < v0.size(); ++c) EXPECT_GT(v1[c], v0[c]);
  // The site is on the top surface, the axis points down, and the probe just touches.
  const ProbePlacement& pl = ind.placement();
  EXPECT_NEAR(pl.site.x(), 7.5, 0.05);
  EXPECT_NEAR(pl.site.y(), 7.5, 0.05);
  EXPECT_GT(pl.site.z(), 10.0);  // bulged above the rest top z = 10
  EXPECT_LT(pl.axis.z(), -0.99);
  EXPECT_NEAR((pl.contactCenter - pl.site).norm(), 1.0, 1e-6);
  Evaluation ev;
  f.model->evaluate(ind.turgidState(), ev, false);
  EXPECT_LT(ev.energy.contact, 1e-20);  // touching, not pressing
}

TEST(Indentation, ForceRisesWithDepthAndLoadingEqualsUnloading) {
  Fixture f;
  Indentation ind(*f.model, settings(0.6, 6, true));
  ASSERT_TRUE(ind.prepare().converged);
  const auto curve = ind.run();
  ASSERT_EQ(curve.size(), 13u);  // contact point + 6 loading + 6 unloading
  for (const auto& p : curve) {
    EXPECT_TRUE(p.converged);
    EXPECT_LT(p.residual, 1e-8);
  }
  for (int k = 1; k <= 6; ++k) EXPECT_GT(curve[k].force, curve[k - 1].force) << k;
  EXPECT_NEAR(curve[6].depth, 0.6, 1e-12);
  // Elastic: unloading retraces loading at the same depths.
  for (int k = 0; k < 6; ++k) {
    const CurvePoint& up = curve[k];
    const CurvePoint& down = curve[12 - k];
    EXPECT_NEAR(up.depth, down.depth, 1e-12);
    EXPECT_NEAR(down.force, up.force, 1e-6 * curve[6].force + 1e-12) << "depth " << up.depth;
  }
  EXPECT_TRUE(curve[7].unloading);
}

TEST(Indentation, ThePredictorChangesTheStartNotTheCurve) {
  // Each step starts from the extrapolation of the last equilibria, or from the last one with
  // the probe moved (the published method): the same equilibria, the first in fewer iterations.
  std::vector<CurvePoint> curves[2];
  for (int predictor = 0; predictor < 2; ++predictor) {
    Fixture f;
    IndentationSettings s = settings(0.6, 12, false);
    s.predictor = predictor == 1;
    Indentation ind(*f.model, s);
    ASSERT_TRUE(ind.prepare().converged);
    curves[predictor] = ind.run();
  }
  ASSERT_EQ(curves[0].size(), curves[1].size());
  int iterations[2] = {0, 0};
  for (size_t k = 0; k < curves[0].size(); ++k) {
    ASSERT_TRUE(curves[0][k].converged && curves[1][k].converged);
    EXPECT_NEAR(curves[1][k].force, curves[0][k].force, 1e-7 * curves[0].back().force) << k;
    for (int p = 0; p < 2; ++p) iterations[p] += curves[p][k].iterations;
  }
  EXPECT_LT(iterations[1], iterations[0]);
}

TEST(Indentation, ForceControlGivesTheSameCurveAsDepthControl) {
  Fixture f;
  Indentation byDepth(*f.model, settings(0.6, 4, false));
  ASSERT_TRUE(byDepth.prepare().converged);
  const auto dcurve = byDepth.run();

  Fixture g;
  IndentationSettings s = settings(0.6, 4, false);
  s.control = Control::Force;
  Indentation byForce(*g.model, s);
  ASSERT_TRUE(byForce.prepare().converged);
  for (size_t k = 1; k < dcurve.size(); ++k) {
    const CurvePoint p = byForce.applyForce(dcurve[k].force);
    ASSERT_TRUE(p.converged) << byForce.lastMessage();
    EXPECT_NEAR(p.depth, dcurve[k].depth, 1e-6 * dcurve.back().depth) << "force " << dcurve[k].force;
    EXPECT_NEAR(p.force, dcurve[k].force, 1e-7 * dcurve.back().force);
  }
}

TEST(Indentation, WorkEqualsEnergyChange) {
  // Conservative system: ∫ F dδ from first contact equals the rise of the total potential energy.
  Fixture f;
  Indentation ind(*f.model, settings(0.4, 40, false));
  ASSERT_TRUE(ind.prepare().converged);
  const double w0 = f.model->energy(ind.turgidState());
  const auto curve = ind.run();
  double work = 0;
  for (size_t k = 1; k < curve.size(); ++k)
    work += 0.5 * (curve[k].force + curve[k - 1].force) * (curve[k].depth - curve[k - 1].depth);
  const double w1 = f.model->energy(ind.state());
  EXPECT_NEAR(work, w1 - w0, 2e-3 * work);
}

TEST(Indentation, SmallProbeOnAFaceIsCaught) {
  // A probe far smaller than the triangles, over the middle of one of them.
  Fixture f;
  IndentationSettings s = settings(0.05, 2, false);
  s.probeRadius = 0.05;
  s.site = Vec3(6.7, 6.2, 10.2);
  Indentation ind(*f.model, s);
  ASSERT_TRUE(ind.prepare().converged);
  const auto curve = ind.run();
  ASSERT_TRUE(curve.back().converged) << ind.lastMessage();
  EXPECT_GT(curve.back().force, 0.0);
  // The probe centre is above the surface it pushed: it did not slip through.
  Evaluation ev;
  f.model->evaluate(ind.state(), ev, false);
  EXPECT_GT(ev.contactTriangles, 0);
}

TEST(Indentation, UnconvergedStepIsReportedAndStateKept) {
  Fixture f;
  SolverOptions tight;
  tight.maxIterations = 1;  // cannot converge a real step
  IndentationSettings s = settings(0.5, 1, false);
  s.maxSubdivisions = 1;
  Indentation ind(*f.model, s, tight);
  // The turgid state needs more than one iteration too: prepare reports the failure.
  const SolveReport rep = ind.prepare();
  EXPECT_FALSE(rep.converged);
  EXPECT_FALSE(ind.prepared());
  EXPECT_FALSE(ind.lastMessage().empty());

  Indentation good(*f.model, settings(0.5, 1, false));
  ASSERT_TRUE(good.prepare().converged);
  const Points before = good.state();
  good.solver().options().maxIterations = 1;
  const CurvePoint p = good.goToDepth(0.5);
  EXPECT_FALSE(p.converged);
  EXPECT_TRUE(std::isnan(p.force));
  EXPECT_EQ(good.depth(), 0.0);
  EXPECT_EQ((good.state() - before).norm(), 0.0);
  EXPECT_NE(good.lastMessage().find("no equilibrium at depth"), std::string::npos)
      << good.lastMessage();
}

TEST(Indentation, ObliqueAxisAndSiteAwayFromTop) {
  Fixture f;
  IndentationSettings s = settings(0.3, 3, false);
  s.site = Vec3(100.0, 7.5, 5.0);  // nearest point: the +x side wall
  Indentation ind(*f.model, s);
  ASSERT_TRUE(ind.prepare().converged);
  EXPECT_GT(ind.placement().site.x(), 15.0 - 1e-9);
  EXPECT_LT(ind.placement().axis.x(), -0.99);  // inward normal of the side wall
  const auto curve = ind.run();
  ASSERT_TRUE(curve.back().converged);
  EXPECT_GT(curve.back().force, 0.0);
}
