// Closed forms through tissueprobe-cli as a user runs them (issue 8): coarse meshes made by
// `build --cap` and `build --plate`, indented with the default automatic refinement, which must
// land within 3 % of the closed form and say that its own estimated error is within tolerance.
// The closed forms are those of test_shell_closed_form.cpp and test_closed_form.cpp, where they
// are checked on sequences of uniform meshes; here the mesh is the program's choice. The cap and
// the plate are faceted and polygonal as given (12 rings), so the difference also holds the
// geometry of the input, which no refinement at the site changes. Units: µm, MPa, µN.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <regex>
#include <string>

#include "support/RunCommand.h"

using std::numbers::pi;

namespace {

using CliRun = tp::test::CommandRun;

CliRun cli(const std::string& args) {
  return tp::test::runCommand(std::string(TP_CLI) + " " + args);
}

std::string tmp(const std::string& name) {
  return testing::TempDir() + "/cf_" + name;
}

struct Indented {
  double stiffness = NAN;  // the secant stiffness the CLI prints, µN/µm
  double estimated = NAN;  // its estimated discretisation error, relative
  int level = -1;          // the mesh level it chose
};

// `indent` with the default (automatic) mesh; the secant stiffness F/δ at the end point.
Indented indent(const std::string& mesh, const std::string& args) {
  const CliRun r = cli("indent --mesh " + mesh + " --steps 2 " + args);
  Indented out;
  EXPECT_EQ(r.status, 0) << r.output;
  std::smatch m;
  if (std::regex_search(r.output, m, std::regex(R"(# secant stiffness ([-+0-9.eE]+) uN/um)")))
    out.stiffness = std::stod(m[1]);
  if (std::regex_search(r.output, m,
                        std::regex(R"(estimated discretisation error \+-([0-9.eE]+) %)")))
    out.estimated = std::stod(m[1]) / 100;
  if (std::regex_search(r.output, m, std::regex(R"(# mesh level (\d+) \(auto)")))
    out.level = std::stoi(m[1]);
  EXPECT_TRUE(std::isfinite(out.stiffness) && std::isfinite(out.estimated)) << r.output;
  return out;
}

void expectClose(const Indented& got, double closedForm, const std::string& what) {
  const double error = got.stiffness / closedForm - 1;
  std::printf(
      "  %s: F/delta %.6g, closed form %.6g, error %+.2f %%, level %d, estimated +-%.2f %%\n",
      what.c_str(), got.stiffness, closedForm, 100 * error, got.level, 100 * got.estimated);
  EXPECT_LT(std::abs(error), 0.03) << what;
  EXPECT_LE(got.estimated, 0.03) << what << ": the program did not reach its tolerance";
  EXPECT_GE(got.level, 3) << what << ": the probe is far finer than the input mesh";
}

}  // namespace

// A thin sphere's cap (R = 10 µm, h = 0.1 µm, clamped 6 √(Rh) from the pole, 12 rings: 0.5 µm
// facets) under a probe of 0.1 µm, δ = h/100: Reissner's F/δ = 4 E h² / (R √(3(1 − ν²))) without
// pressure, and Vella et al. 2012 (the formula of test_shell_closed_form.cpp) inflated to
// τ = pR²/(4√(BY)) = 1.5 and 3.
TEST(ClosedFormThroughCli, ThinSphereReissnerAndVella) {
  const double R0 = 10, E = 100, h = 0.1, nu = 0.3;
  const std::string cap = tmp("cap.ply");
  const CliRun b = cli("build --cap 10,6 --rings 12 --out " + cap);
  ASSERT_EQ(b.status, 0) << b.output;
  char material[160];
  std::snprintf(material, sizeof material, "--E %g --nu %g --thickness %g --depth 0.001 ", E, nu,
                h);
  const double reissner = 4 * E * h * h / (R0 * std::sqrt(3 * (1 - nu * nu)));
  expectClose(indent(cap, std::string(material) + "--pressure 0 --probe-radius 0.1"), reissner,
              "Reissner");
  const double B = E * h * h * h / (12 * (1 - nu * nu)), Y = E * h;
  for (double tau : {1.5, 3.0}) {
    const double p = 4 * tau * std::sqrt(B * Y) / (R0 * R0);
    const double R = R0 * (1 + p * R0 * (1 - nu) / (2 * E * h));  // inflated (small strain)
    const double t = p * R * R / (4 * std::sqrt(B * Y));
    const double vella = 4 * pi * std::sqrt(B * Y) / R * std::sqrt(t * t - 1) / std::acosh(t);
    char pressure[64];
    std::snprintf(pressure, sizeof pressure, "%.9g", p);
    expectClose(indent(cap, std::string(material) + "--pressure " + pressure + " --probe-radius 0.05"),
                vella, "Vella, tau " + std::to_string(tau));
  }
}

// A clamped circular plate (a = 10 µm, built-in edge, 12 rings: 0.83 µm triangles), a probe of
// 0.1 µm at the centre, δ = h/20: F/δ = 16 π D / a² (Timoshenko), for ν = 0, 0.3 and 0.49. The
// whole plate bends, so the refinement must reach beyond the site (siteRefinement's panel cap).
TEST(ClosedFormThroughCli, ClampedPlate) {
  const double a = 10, E = 1000, h = 0.2;
  const std::string plate = tmp("plate.ply");
  const CliRun b = cli("build --plate 10 --rings 12 --out " + plate);
  ASSERT_EQ(b.status, 0) << b.output;
  for (double nu : {0.0, 0.3, 0.49}) {
    const double D = E * h * h * h / (12 * (1 - nu * nu));
    char args[200];
    std::snprintf(args, sizeof args,
                  "--E %g --nu %g --thickness %g --pressure 0 --probe-radius 0.1 --depth 0.01", E,
                  nu, h);
    expectClose(indent(plate, args), 16 * pi * D / (a * a),
                "clamped plate, nu " + std::to_string(nu));
  }
}
