// Raw AFM curves to indentation and force: a synthetic approach with a known contact point,
// baseline tilt and noise, and the real JPK text export of ../shared/data.
#include "io/JpkCurve.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "support/SharedData.h"

namespace tp {
namespace {

using ::testing::HasSubstr;

// Hertz-like contact F = K δ^{3/2} behind a cantilever of stiffness k: for each piezo height h
// the indentation solves δ = (h_c − h) − K δ^{3/2}/k (bisection).
struct Synthetic {
  std::vector<double> height, force;
  double hc = 33.0, K = 0.01, k = 0.061, offset = 0.011, slope = 2e-5, noise = 1e-4;
};

Synthetic makeApproach() {
  Synthetic s;
  std::uint32_t state = 12345;
  auto uniform = [&] {  // deterministic noise in [-1, 1]
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / double(1u << 24) * 2.0 - 1.0;
  };
  for (int i = 0; i <= 1000; ++i) {
    const double h = 40.0 - 0.01 * i;
    double F = 0;
    if (h < s.hc) {
      double lo = 0, hi = s.hc - h;
      for (int it = 0; it < 200; ++it) {
        const double d = 0.5 * (lo + hi);
        (d + s.K * std::pow(d, 1.5) / s.k > s.hc - h ? hi : lo) = d;
      }
      F = s.K * std::pow(0.5 * (lo + hi), 1.5);
    }
    s.height.push_back(h);
    s.force.push_back(F + s.offset + s.slope * h + s.noise * uniform());
  }
  return s;
}

TEST(RawCurve, SyntheticApproachGivesItsContactPointAndHertzCurve) {
  const Synthetic s = makeApproach();
  const RawCurveReading r = indentationFromApproach(s.height, s.force, s.k, "synthetic");
  EXPECT_NEAR(r.baselineSlope, s.slope, 5e-6);
  EXPECT_NEAR(r.baselineOffset, s.offset, 5e-4);
  EXPECT_NEAR(r.noise, s.noise / std::sqrt(3.0), 0.3e-4);  // uniform noise: σ = a/√3
  // The contact point within the height where the force reaches a few noise levels:
  // K δ^{3/2} = 5σ at δ ≈ 0.08 µm.
  EXPECT_NEAR(r.contactHeight, s.hc, 0.1);
  // Along the curve, the force is the Hertz force of the indentation (to the noise and the
  // contact point's error).
  ASSERT_GT(r.curve.depth.size(), 200u);
  const double d = r.curve.depth.back(), F = r.curve.force.back();
  EXPECT_NEAR(F, s.K * std::pow(d, 1.5), 0.02 * F);
  EXPECT_GT(d, 2.0);
  // A contact point given by the user is used as given.
  RawCurveOptions o;
  o.contactHeight = 33.0;
  const RawCurveReading u = indentationFromApproach(s.height, s.force, s.k, "synthetic", o);
  EXPECT_FALSE(u.contactEstimated);
  EXPECT_DOUBLE_EQ(u.contactHeight, 33.0);
  EXPECT_NEAR(u.curve.force.back(), s.K * std::pow(u.curve.depth.back(), 1.5),
              0.01 * u.curve.force.back());
  o.contactHeight = 50.0;
  EXPECT_THROW(indentationFromApproach(s.height, s.force, s.k, "s", o), std::runtime_error);
}

TEST(RawCurve, NoContactIsSaidPlainly) {
  Synthetic s = makeApproach();
  for (double& f : s.force) f = s.offset;  // the probe never touched
  s.force[3] += 1e-6;
  try {
    indentationFromApproach(s.height, s.force, s.k, "flat.txt");
    FAIL() << "a flat curve gave a contact point";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("flat.txt: the force at the end of the approach"));
    EXPECT_THAT(e.what(), HasSubstr("no contact found"));
  }
}

TEST(RawCurve, RealJpkTextExport) {
  const std::string path =
      test::sharedDataFile("afm_jpk_text_export/force-save-2021.06.30-12.04.16.071.txt");
  TP_SKIP_WITHOUT_DATA(path);
  const RawCurveReading r = readJpkForceCurve(path);
  // The header's spring constant (0.061 N/m), the extend segment's 3000 rows.
  EXPECT_NEAR(r.springConstant, 0.061, 1e-12);
  EXPECT_EQ(r.height.size(), 3000u);
  EXPECT_NEAR(r.height.front(), 47.403348, 1e-6);     // µm (measuredHeight)
  EXPECT_NEAR(r.force.front(), 1.12304654e-2, 1e-9);  // µN (11.2 nN of offset)
  // A soft tissue: the force rises by about 10 nN over the last part of a 30 µm approach.
  EXPECT_GT(r.contactHeight, 17.5);
  EXPECT_LT(r.contactHeight, 35.0);
  EXPECT_GT(r.curve.force.back(), 0.005);
  EXPECT_LT(r.curve.force.back(), 0.015);
  EXPECT_GT(r.curve.depth.back(), 1.0);
  // Below the baseline noise at the contact point, well above it at the end.
  EXPECT_LT(std::abs(r.curve.force.front()), 1e-12);
  EXPECT_GT(r.curve.force.back(), 20 * r.noise);
  EXPECT_TRUE(looksLikeJpkText("# TEXT EXPORT\n# index: 0\n"));
  EXPECT_FALSE(looksLikeJpkText("depth (nm),force (nN)\n1,2\n"));
}

TEST(RawCurve, MalformedJpkIsNamed) {
  auto error = [](const std::string& text) {
    try {
      parseJpkForceCurve(text, "c.txt");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_THAT(error("# TEXT EXPORT\n# springConstant: 0.06\n"), HasSubstr("no extend segment"));
  const std::string head =
      "# TEXT EXPORT\n# springConstant: 0.06\n# segment: extend\n# columns: height vDeflection\n"
      "# units: m N\n";
  EXPECT_THAT(error(head + "1e-5 2e-9\n1e-5 x\n"), HasSubstr("c.txt: line 7"));
  EXPECT_THAT(
      error("# TEXT EXPORT\n# segment: extend\n# columns: height force\n# units: m N\n1 2\n"),
      HasSubstr("no height and vDeflection columns"));
}

}  // namespace
}  // namespace tp
