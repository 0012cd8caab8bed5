// Fitting with the automatic mesh: the mesh a fit ends on is the one the fitted values need,
// as the automatic refinement chooses it there (core/experiment/Fit.cpp). Slow (about a minute
// on one thread): the turgid curve's meshes are levels 2 to 4 of a small box tissue.
#include <gtest/gtest.h>

#include <cstdio>

#include "experiment/Fit.h"
#include "support/FitBox.h"

using namespace tp;

namespace {

std::shared_ptr<const CellComplex> fitMeshTissue() { return test::fitBox(); }

// The automatic mesh from level `first` with a 5 % tolerance, else as the fit tests' settings.
ExperimentSettings automaticAt(double E, double p, int first) {
  ExperimentSettings s = test::fitBoxSettings(E, p);
  s.mesh.automatic = true;
  s.mesh.level = first;
  s.mesh.estimateError = true;
  s.mesh.tolerance = 0.05;
  return s;
}

// The curve the automatic mesh gives at (E, p), and the level it chose and its error.
MeasuredCurve automaticCurve(double E, double p, int first, int& level, MeshError& error) {
  Experiment e(fitMeshTissue(), automaticAt(E, p, first));
  const ExperimentResult r = e.run();
  EXPECT_TRUE(r.complete) << r.message;
  level = r.site ? r.site->level : -1;
  error = r.error;
  MeasuredCurve m;
  m.name = p > 0 ? "turgid" : "plasmolysed";
  for (const CurvePoint& pt : r.curve) {
    m.depth.push_back(pt.depth);
    m.force.push_back(pt.force);
  }
  return m;
}

}  // namespace

TEST(FitMesh, TheAutomaticMeshIsTheOneTheFittedValuesNeed) {
  // With the automatic mesh the search starts on its first level and the mesh is checked at
  // the values found, refined and searched again where they need it. Curves made by the
  // automatic mesh at the truth are then fitted on the truth's own meshes: the values come back
  // to the solver's precision, and each curve reports the level the automatic mesh chooses at
  // the truth — not the level of the starting values, which is another one here (a turgor of a
  // thousandth of E needs a finer mesh than one of 0.005 E on this tissue at 5 %).
  const int first = 2;
  int levelTruth[2], levelStart = -1;
  MeshError errorTruth[2], errorStart;
  const MeasuredCurve turgid = automaticCurve(60, 0.3, first, levelTruth[0], errorTruth[0]);
  const MeasuredCurve plasmolysed = automaticCurve(60, 0.0, first, levelTruth[1], errorTruth[1]);
  automaticCurve(100, 0.1, first, levelStart, errorStart);
  std::printf("  levels at the truth %d, %d (errors %.4g, %.4g); the turgid one at the start %d\n",
              levelTruth[0], levelTruth[1], errorTruth[0].relative, errorTruth[1].relative,
              levelStart);
  ASSERT_NE(levelStart, levelTruth[0]);  // else this test would not tell the two apart
  FitSettings fs;
  fs.start = automaticAt(100, 0.1, first);
  const FitResult r =
      fitCurves(fitMeshTissue(), fs, {FitCurve{turgid, {}, {}}, FitCurve{plasmolysed, {}, 0.0}});
  std::printf("  %s\n  E = %.8g, p = %.8g, %d evaluations, levels %d, %d (errors %.4g, %.4g)\n",
              r.message.c_str(), r.find("E")->value, r.find("p")->value, r.evaluations,
              r.curves[0].meshLevel, r.curves[1].meshLevel, r.curves[0].meshError.relative,
              r.curves[1].meshError.relative);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_NEAR(r.find("E")->value, 60.0, 60.0 * 1e-5);
  EXPECT_NEAR(r.find("p")->value, 0.3, 0.3 * 1e-5);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(r.curves[i].meshLevel, levelTruth[i]) << i;
    ASSERT_TRUE(r.curves[i].meshError.estimated()) << i;
    EXPECT_LE(r.curves[i].meshError.relative, 0.05) << i;
    // The same estimate as the automatic mesh's at the truth (from the same pair of levels;
    // the end values solved to 1e-11 there and 1e-10 here, from other starts).
    EXPECT_NEAR(r.curves[i].meshError.relative, errorTruth[i].relative,
                1e-3 * errorTruth[i].relative)
        << i << ": " << r.curves[i].meshError.method << " against " << errorTruth[i].method;
  }
}
