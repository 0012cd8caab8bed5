// Fitting E and p to force–indentation curves: a curve simulated at known values is read back
// from other starting values, and noise is covered by the reported intervals.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "experiment/Fit.h"
#include "experiment/Sensitivity.h"
#include "support/FitBox.h"

using namespace tp;

namespace {

std::shared_ptr<const CellComplex> tissue() { return test::fitBox(); }
ExperimentSettings settings(double E, double p) { return test::fitBoxSettings(E, p); }

// The model's own curve at (E, p), as a measured curve; `noise` adds ±noise·F alternately.
MeasuredCurve synthetic(double E, double p, double noise = 0, int steps = 8) {
  ExperimentSettings es = settings(E, p);
  es.indentation.steps = steps;
  Experiment e(tissue(), es);
  const ExperimentResult r = e.run();
  EXPECT_TRUE(r.complete) << r.message;
  MeasuredCurve m;
  m.name = "synthetic";
  int k = 0;
  for (const CurvePoint& pt : r.curve) {
    m.depth.push_back(pt.depth);
    m.force.push_back(pt.force * (1 + noise * ((k++ % 2) ? 1 : -1)));
  }
  return m;
}

}  // namespace

TEST(Fit, ATurgidCurveAloneCannotTellModulusFromTurgorAndSaysSo) {
  // On this tissue a turgid curve is nearly a function of one combination of E and p: the fit
  // finds a point of the valley and must say that E and p are not separated.
  FitSettings fs;
  fs.start = settings(100, 0.8);
  const FitResult r = fitCurves(tissue(), fs, {FitCurve{synthetic(60, 0.3), {}, {}}});
  std::printf("  %s\n  E = %.6g, p = %.6g, corr %.4f\n  %s\n", r.message.c_str(),
              r.find("E")->value, r.find("p")->value, r.correlation(0, 1), r.advice.c_str());
  EXPECT_LT(r.rms, 1e-4 * r.rmsStart);             // it fits the curve...
  EXPECT_GT(std::abs(r.correlation(0, 1)), 0.95);  // ...but not the values apart
  EXPECT_FALSE(r.identifiable);
  EXPECT_NE(r.advice.find("E and p cannot be told apart"), std::string::npos);
  EXPECT_NE(r.advice.find("plasmolysed curve"), std::string::npos);
}

TEST(Fit, TurgidAndPlasmolysedCurvesTogetherRecoverModulusAndTurgor) {
  FitSettings fs;
  fs.start = settings(100, 0.8);  // far from the truth (60, 0.3)
  const FitResult r = fitCurves(
      tissue(), fs, {FitCurve{synthetic(60, 0.3), {}, {}}, FitCurve{synthetic(60, 0.0), {}, 0.0}});
  std::printf(
      "  %s\n  E = %.8g +- %.2g MPa, p = %.8g +- %.2g MPa, corr %.3f, rms %.3g uN (start "
      "%.3g), %d evaluations\n",
      r.message.c_str(), r.find("E")->value, r.find("E")->error, r.find("p")->value,
      r.find("p")->error, r.correlation(0, 1), r.rms, r.rmsStart, r.evaluations);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_NEAR(r.find("E")->value, 60.0, 60.0 * 1e-5);
  EXPECT_NEAR(r.find("p")->value, 0.3, 0.3 * 1e-5);
  EXPECT_TRUE(r.identifiable) << r.advice;
  EXPECT_TRUE(r.find("E")->fitted);
  EXPECT_FALSE(r.find("h")->fitted);
  EXPECT_EQ(r.find("h")->value, 0.2);
  EXPECT_LT(r.rms, 1e-6 * r.rmsStart);
  EXPECT_GT(r.rmsStart, 0.1);  // the start was far off
  ASSERT_EQ(r.curves.size(), 2u);
  EXPECT_EQ(r.curves[0].depth.size(), 9u);                        // depth 0 and the eight steps
  EXPECT_GT(r.curves[0].hertzModulus, r.curves[1].hertzModulus);  // turgor stiffens
  EXPECT_LT(std::abs(r.correlation(0, 1)), 0.95);
}

TEST(Fit, NoisyCurvesAreCoveredByTheReportedIntervals) {
  FitSettings fs;
  fs.start = settings(100, 0.8);
  const FitResult r = fitCurves(
      tissue(), fs,
      {FitCurve{synthetic(60, 0.3, 0.02), {}, {}}, FitCurve{synthetic(60, 0.0, 0.02), {}, 0.0}});
  ASSERT_TRUE(r.converged) << r.message;
  const FitValue& E = *r.find("E");
  const FitValue& p = *r.find("p");
  std::printf("  E = %.5g +- %.2g MPa, p = %.5g +- %.2g MPa, corr %.3f, rms %.3g uN\n", E.value,
              E.error, p.value, p.error, r.correlation(0, 1), r.rms);
  EXPECT_GT(E.error, 0);
  EXPECT_GT(p.error, 0);
  EXPECT_LT(std::abs(E.value - 60.0), 3 * E.error);
  EXPECT_LT(std::abs(p.value - 0.3), 3 * p.error);
  EXPECT_GT(r.rms, 0.02 * 0.5 * r.curves[1].measured.back() * 0.1);  // the noise is seen
}

TEST(Fit, ForcesScaleWithModulusAndTurgorTogether) {
  // Every energy term is linear in E at fixed p/E (membrane ∝ E h, bending ∝ E h³, contact
  // κ ∝ E h, turgor ∝ p): the curve at (2.5 E, 2.5 p) is 2.5 times the curve at (E, p), which the
  // fit's variable projection relies on. Turgid and plasmolysed.
  for (const double p : {0.3, 0.0}) {
    const MeasuredCurve a = synthetic(60, p), b = synthetic(150, 2.5 * p);
    ASSERT_EQ(a.force.size(), b.force.size());
    ASSERT_GT(a.force.back(), 0.1);
    for (size_t k = 0; k < a.force.size(); ++k) {
      EXPECT_DOUBLE_EQ(a.depth[k], b.depth[k]);
      EXPECT_NEAR(b.force[k], 2.5 * a.force[k], 1e-8 * b.force.back())
          << "p " << p << ", point " << k;
    }
  }
}

TEST(Fit, FactoringOutTheModulusChangesNeitherTheFitNorItsIntervals) {
  // The search over p/E with E in closed form (the default) and the search over E and p
  // together reach the same minimum with the same Jacobian there: same values, standard errors
  // and correlation, on noisy curves with their contact points fitted too.
  FitSettings fs;
  fs.start = settings(100, 0.8);
  fs.fitOffset = true;
  const std::vector<FitCurve> curves = {FitCurve{synthetic(60, 0.3, 0.02), {}, {}},
                                        FitCurve{synthetic(60, 0.0, 0.02), {}, 0.0}};
  const FitResult scaled = fitCurves(tissue(), fs, curves);
  fs.factorOutModulus = false;
  const FitResult joint = fitCurves(tissue(), fs, curves);
  ASSERT_TRUE(scaled.converged) << scaled.message;
  ASSERT_TRUE(joint.converged) << joint.message;
  std::printf(
      "  factored out: %d evaluations, E %.6g +- %.3g, p %.6g +- %.3g\n"
      "  joint:        %d evaluations, E %.6g +- %.3g, p %.6g +- %.3g\n",
      scaled.evaluations, scaled.find("E")->value, scaled.find("E")->error, scaled.find("p")->value,
      scaled.find("p")->error, joint.evaluations, joint.find("E")->value, joint.find("E")->error,
      joint.find("p")->value, joint.find("p")->error);
  for (const std::string key : {"E", "p", "offset_1", "offset_2"}) {
    const FitValue &a = *scaled.find(key), &b = *joint.find(key);
    // Both minimise the same cost to Ceres' function tolerance: well inside a standard error.
    EXPECT_NEAR(a.value, b.value, 0.01 * b.error) << key;
    EXPECT_NEAR(a.error, b.error, 0.01 * b.error) << key;
  }
  EXPECT_NEAR(scaled.correlation(0, 1), joint.correlation(0, 1), 1e-3);
  EXPECT_NEAR(scaled.rms, joint.rms, 1e-4 * joint.rms);
}

TEST(Fit, ForcesBetweenTheSimulatedDepthsAreTheirInterpolantToATenThousandth) {
  // 41 points a curve, simulated at 10 depths and interpolated between them (the default), and
  // at every point: the same values, each within a thousandth of the truth, and the exact
  // curves fitted to a ten-thousandth of their force by the interpolant.
  FitSettings fs;
  fs.start = settings(100, 0.8);
  fs.maxPoints = 41;
  const std::vector<FitCurve> curves = {FitCurve{synthetic(60, 0.3, 0, 40), {}, {}},
                                        FitCurve{synthetic(60, 0.0, 0, 40), {}, 0.0}};
  const FitResult nodes = fitCurves(tissue(), fs, curves);
  fs.simulatedDepths = 0;
  const FitResult every = fitCurves(tissue(), fs, curves);
  ASSERT_TRUE(nodes.converged) << nodes.message;
  ASSERT_TRUE(every.converged) << every.message;
  std::printf("  10 depths: E %.7g, p %.7g, rms %.3g uN\n  40 depths: E %.7g, p %.7g, rms %.3g uN\n",
              nodes.find("E")->value, nodes.find("p")->value, nodes.rms, every.find("E")->value,
              every.find("p")->value, every.rms);
  ASSERT_EQ(nodes.curves.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(nodes.curves[i].depth.size(), 41u);
    EXPECT_EQ(nodes.curves[i].simulatedDepths, 10);  // depth 0 has no force: 40 positive
    EXPECT_EQ(every.curves[i].simulatedDepths, 40);
    EXPECT_LT(nodes.rms, 1e-4 * nodes.curves[i].measured.back());
  }
  for (const std::string key : {"E", "p"}) {
    const double truth = key == "E" ? 60.0 : 0.3;
    EXPECT_NEAR(nodes.find(key)->value, truth, 1e-3 * truth) << key;
    EXPECT_NEAR(every.find(key)->value, truth, 1e-5 * truth) << key;
  }
}

TEST(Fit, TheSplineThroughTheSimulatedDepthsReproducesCubics) {
  // Not-a-knot splines are exact for cubics (on uneven nodes too), parabolas through three
  // nodes for quadratics, lines through two for lines; a fit's forces at the points are these
  // weights times the nodes' forces, and so are their derivatives.
  const std::vector<double> t = {0.01, 0.05, 0.12, 0.16, 0.25, 0.31, 0.38, 0.41, 0.47, 0.5};
  std::vector<double> x;
  for (int i = 0; i <= 36; ++i) x.push_back(0.01 + 0.49 * i / 36.0);
  auto check = [&](const std::vector<double>& nodes, auto&& f) {
    const Eigen::MatrixXd W = splineWeights(nodes, x);
    ASSERT_EQ(W.rows(), static_cast<Eigen::Index>(x.size()));
    ASSERT_EQ(W.cols(), static_cast<Eigen::Index>(nodes.size()));
    Eigen::VectorXd y(nodes.size());
    for (size_t j = 0; j < nodes.size(); ++j) y[j] = f(nodes[j]);
    for (size_t i = 0; i < x.size(); ++i) {
      EXPECT_NEAR(W.row(i).dot(y), f(x[i]), 1e-12) << nodes.size() << " nodes, x " << x[i];
      EXPECT_NEAR(W.row(i).sum(), 1.0, 1e-12);  // constants too
    }
  };
  check(t, [](double d) { return 3 - 2 * d + 40 * d * d - 75 * d * d * d; });
  check({0.01, 0.2, 0.5}, [](double d) { return 1 + d - 7 * d * d; });
  check({0.01, 0.5}, [](double d) { return 2 - 3 * d; });
  // At the nodes themselves the weights are exactly those of the node (a curve simulated at its
  // own points keeps its values to the last bit).
  for (const std::vector<double>& nodes : {t, std::vector<double>{0.01, 0.2, 0.5}}) {
    const Eigen::MatrixXd Wn = splineWeights(nodes, nodes);
    EXPECT_EQ(Wn, Eigen::MatrixXd::Identity(nodes.size(), nodes.size())) << nodes.size();
  }
  // And not a quartic: the test can tell an exact reproduction from a near one.
  const Eigen::MatrixXd W = splineWeights(t, x);
  Eigen::VectorXd y(t.size());
  for (size_t j = 0; j < t.size(); ++j) y[j] = std::pow(t[j], 4);
  double worst = 0;
  for (size_t i = 0; i < x.size(); ++i)
    worst = std::max(worst, std::abs(W.row(i).dot(y) - std::pow(x[i], 4)));
  EXPECT_GT(worst, 1e-8);
  EXPECT_LT(worst, 1e-4);
}

TEST(Fit, NothingToFitOrNoDepthIsRefused) {
  FitSettings fs;
  fs.start = settings(100, 0.8);
  fs.fitE = fs.fitP = false;
  MeasuredCurve m;
  m.name = "m.csv";
  m.depth = {0.1, 0.2};
  m.force = {1, 2};
  EXPECT_THROW(fitCurves(tissue(), fs, {FitCurve{m, {}, {}}}), std::invalid_argument);
  fs.fitE = true;
  m.depth = {-0.1, 0.0};
  try {
    fitCurves(tissue(), fs, {FitCurve{m, {}, {}}});
    FAIL() << "a curve without a positive depth was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("m.csv: no point at a positive depth"), std::string::npos);
  }
}
