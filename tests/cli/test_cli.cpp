// tissueprobe-cli as a user runs it: exit codes, printed curves, files written, error messages.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <csignal>
#include <sys/wait.h>
#include <unistd.h>

#include "io/CurveCsv.h"
#include "support/RunCommand.h"
#include "support/SharedData.h"

using testing::HasSubstr;
using testing::ContainsRegex;
using testing::Not;

namespace {

using CliRun = tp::test::CommandRun;

CliRun cli(const std::string& args) {
  return tp::test::runCommand(std::string(TP_CLI) + " " + args);
}

std::string tmp(const std::string& name) { return testing::TempDir() + "/cli_" + name; }

// A small meristem shared by the tests (built once with `build --generate`).
const std::string& smallTissue() {
  static const std::string path = [] {
    const std::string p = tmp("small.ply");
    const CliRun r = cli("build --generate --cells 60 --diameter 30 --cap-height 12 --stem-height 4 "
                      "--seed 3 --out " + p);
    EXPECT_EQ(r.status, 0) << r.output;
    return p;
  }();
  return path;
}


// Runs `command` (a shell command line, its output to a pipe) and sends SIGINT once its output
// contains `trigger`, however fast the build (the sanitizer build is ten times slower).
struct InterruptedRun {
  bool signalled = false;
  bool exited = false;
  int status = -1;      // exit status when exited
  std::string output;
};

InterruptedRun runAndInterrupt(const std::string& command, const std::string& trigger) {
  InterruptedRun r;
  const std::string cmd = "exec " + command + " 2>&1";
  int out[2];
  if (pipe(out) != 0) return r;
  const pid_t pid = fork();
  if (pid < 0) return r;
  if (pid == 0) {
    dup2(out[1], STDOUT_FILENO);
    close(out[0]);
    close(out[1]);
    execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  close(out[1]);
  std::array<char, 4096> buf{};
  for (ssize_t n; (n = read(out[0], buf.data(), buf.size())) > 0;) {
    r.output.append(buf.data(), static_cast<size_t>(n));
    if (!r.signalled && r.output.find(trigger) != std::string::npos) {
      r.signalled = true;
      kill(pid, SIGINT);
    }
  }
  close(out[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  r.exited = WIFEXITED(status);
  if (r.exited) r.status = WEXITSTATUS(status);
  return r;
}
}  // namespace

TEST(Cli, HelpNamesEveryOptionWithUnits) {
  const CliRun r = cli("indent --help");
  EXPECT_EQ(r.status, 0);
  for (const char* opt : {"--mesh", "--E", "--nu", "--thickness", "--pressure", "--bending",
                          "--probe-radius", "--site", "--axis", "--depth", "--force", "--steps",
                          "--unload", "--csv", "--vtu", "--refine", "--mesh-tolerance", "--solver"})
    EXPECT_THAT(r.output, HasSubstr(opt));
  for (const char* unit : {"MPa", "um", "uN"}) EXPECT_THAT(r.output, HasSubstr(unit));
}

TEST(Cli, DepthControlWritesCsvAndVtu) {
  const std::string csv = tmp("curve.csv"), vtu = tmp("final.vtu");
  const CliRun r = cli("indent --mesh " + smallTissue() + " --depth 0.2 --steps 4 --csv " + csv +
                    " --vtu " + vtu);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("depth_um"));
  const auto curve = tp::readCurveCsv(csv);
  ASSERT_EQ(curve.size(), 5u);
  for (size_t k = 1; k < curve.size(); ++k) {
    EXPECT_TRUE(curve[k].converged);
    EXPECT_GT(curve[k].force, curve[k - 1].force);
  }
  EXPECT_NEAR(curve.back().depth, 0.2, 1e-12);
  std::ifstream in(vtu);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_THAT(text.str(), HasSubstr("von_mises_MPa"));
  EXPECT_THAT(text.str(), HasSubstr("displacement_um"));
}

// The rest state's line: a tissue without turgor is in equilibrium as given, and says so with
// its residual (it printed a relative residual of 6e-03, against a load scale of nothing but the
// solver's floor, which read as a poor convergence); turgid on the tissue's own mesh it is the
// turgid state solved first; refined, the Newton iterations its solve took.
TEST(Cli, RestStateLineSaysWhatWasSolved) {
  const CliRun plasmolysed =
      cli("indent --mesh " + smallTissue() + " --pressure 0 --refine 0 --depth 0.05 --steps 1");
  ASSERT_EQ(plasmolysed.status, 0) << plasmolysed.output;
  EXPECT_THAT(plasmolysed.output, HasSubstr("# rest state: in equilibrium as given (residual "));
  EXPECT_THAT(plasmolysed.output, Not(HasSubstr("relative residual")));
  const CliRun own =
      cli("indent --mesh " + smallTissue() + " --pressure 0.8 --refine 0 --depth 0.05 --steps 1");
  ASSERT_EQ(own.status, 0) << own.output;
  EXPECT_THAT(own.output, HasSubstr("# rest state: the turgid state of the tissue's own mesh"));
  const CliRun refined =
      cli("indent --mesh " + smallTissue() + " --pressure 0.8 --refine 1 --depth 0.05 --steps 1");
  ASSERT_EQ(refined.status, 0) << refined.output;
  EXPECT_THAT(refined.output,
              ContainsRegex("# rest state: [1-9][0-9]* Newton iterations, relative residual"));
}

TEST(Cli, ForceControlAndUnloading) {
  const std::string csv = tmp("force.csv");
  const CliRun r = cli("indent --mesh " + smallTissue() + " --force 0.5 --steps 3 --unload --csv " + csv);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto curve = tp::readCurveCsv(csv);
  ASSERT_EQ(curve.size(), 7u);  // contact, 3 up, 3 down
  // Equilibrium to 1e-8 of the load scale (the turgor forces, ~100 µN): force within ~1e-5 µN.
  EXPECT_NEAR(curve[3].force, 0.5, 1e-5);
  EXPECT_NEAR(curve.back().force, 0.0, 1e-5);
  EXPECT_NEAR(curve.back().depth, 0.0, 1e-3);
}

TEST(Cli, DeepIndentationKeepsContact) {
  // Issue 9: to 5 µm (25 wall thicknesses, five probe radii) in 0.5 µm steps on the shipped
  // default meristem, where the unrefined mesh lost the contact past 4.5 µm and reported 0 µN as
  // converged. Every point must carry force, rising with depth.
  const std::string csv = tmp("deep.csv");
  const CliRun r = cli("indent --depth 5 --steps 10 --refine 3 --csv " + csv);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto curve = tp::readCurveCsv(csv);
  ASSERT_EQ(curve.size(), 11u);
  for (size_t k = 1; k < curve.size(); ++k) {
    EXPECT_TRUE(curve[k].converged) << "point " << k;
    EXPECT_GT(curve[k].force, 1.05 * curve[k - 1].force) << "point " << k;
  }
  EXPECT_NEAR(curve.back().depth, 5.0, 1e-9);
}

TEST(Cli, ReferenceSolverRefusesKoiterBendingUpFront) {
  // The implicit-Euler reference runs the published models; asked for the default Koiter bending
  // it says so before reading anything (exit 2), naming the options that work.
  const CliRun r = cli("indent --mesh " + smallTissue() +
                       " --refine 0 --depth 0.06 --steps 3 --solver implicit-euler-cg");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--bending linear"), std::string::npos) << r.output;
}

TEST(Cli, ReferenceSolverGivesTheSameCurve) {
  const std::string a = tmp("newton.csv"), b = tmp("euler.csv");
  // On the tissue as given (--refine 0), as the published method was.
  ASSERT_EQ(
      cli("indent --mesh " + smallTissue() + " --refine 0 --depth 0.06 --steps 3 --bending hinge "
          "--csv " + a)
          .status,
      0);
  // The published method as published: each step relaxed from the last equilibrium.
  const CliRun r = cli("indent --mesh " + smallTissue() +
                       " --refine 0 --depth 0.06 --steps 3 --solver implicit-euler-cg "
                       "--bending hinge --no-predictor --csv " + b);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto ca = tp::readCurveCsv(a), cb = tp::readCurveCsv(b);
  ASSERT_EQ(ca.size(), cb.size());
  for (size_t k = 1; k < ca.size(); ++k) EXPECT_NEAR(cb[k].force, ca[k].force, 1e-5 * ca.back().force);
}

TEST(Cli, RefinementAtTheSite) {
  // A fixed level: the mesh is refined around the site, the curve's end value carries an error
  // estimated against the next level, and the CSV says so in comment lines above the header.
  const std::string csv = tmp("refined.csv");
  const CliRun r = cli("indent --mesh " + smallTissue() +
                       " --depth 0.1 --steps 2 --refine 2 --csv " + csv);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("# mesh level 2 (fixed)"));
  EXPECT_THAT(r.output, HasSubstr("estimated discretisation error +-"));
  std::ifstream in(csv);
  std::string first;
  std::getline(in, first);
  EXPECT_THAT(first, HasSubstr("# mesh level 2"));
  const auto curve = tp::readCurveCsv(csv);  // comments skipped
  EXPECT_EQ(curve.size(), 3u);
  // Level 0 is the tissue as given.
  const CliRun raw = cli("indent --mesh " + smallTissue() + " --depth 0.1 --steps 2 --refine 0");
  EXPECT_EQ(raw.status, 0) << raw.output;
  EXPECT_THAT(raw.output, HasSubstr("# mesh level 0 (fixed)"));
  const CliRun bad = cli("indent --mesh " + smallTissue() + " --refine fine");
  EXPECT_EQ(bad.status, 2);
  EXPECT_THAT(bad.output, HasSubstr("--refine: expected auto or a level"));
}

// --junction-band refines a band along the junctions by the site besides the level's sizes:
// the same level has more vertices, says so in its header, and the force moves by less than the
// level's own estimated error (a finer mesh of the same tissue, not another model).
TEST(Cli, JunctionBandRefinesAlongTheJunctionsAndSaysSo) {
  const std::string base = "indent --mesh " + smallTissue() + " --depth 0.2 --steps 2 --refine 2";
  const CliRun plain = cli(base), band = cli(base + " --junction-band");
  ASSERT_EQ(plain.status, 0) << plain.output;
  ASSERT_EQ(band.status, 0) << band.output;
  EXPECT_THAT(band.output, HasSubstr("triangles, smallest angle"));
  EXPECT_THAT(band.output, HasSubstr("deg, junction band"));
  EXPECT_THAT(plain.output, Not(HasSubstr("junction band")));
  const auto vertices = [](const std::string& out) {
    const auto at = out.find("# mesh level 2 (fixed): ");
    return at == std::string::npos ? -1 : std::stoi(out.substr(at + 24));
  };
  const auto endForce = [](const std::string& out) {
    const auto at = out.find("\n   0.20000 ");
    return at == std::string::npos ? NAN : std::stod(out.substr(at + 12));
  };
  const auto error = [](const std::string& out) {
    const auto at = out.find("estimated discretisation error +-");
    return at == std::string::npos ? NAN : std::stod(out.substr(at + 33)) / 100;
  };
  EXPECT_GT(vertices(band.output), vertices(plain.output) * 11 / 10) << plain.output << band.output;
  const double fPlain = endForce(plain.output), fBand = endForce(band.output);
  ASSERT_TRUE(std::isfinite(fPlain) && std::isfinite(fBand)) << plain.output << band.output;
  EXPECT_NE(fPlain, fBand);
  EXPECT_LE(std::abs(fBand - fPlain), error(plain.output) * std::abs(fPlain));
}

TEST(Cli, BadInputIsNamed) {
  CliRun r = cli("indent --mesh " + smallTissue() + " --site 1,2");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("--site: expected three comma-separated numbers, got '1,2'"));
  r = cli("indent --mesh " + smallTissue() + " --E -5");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("Young's modulus must be positive"));
  r = cli("indent --mesh " + smallTissue() + " --bending stiff");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("stiff"));
  const std::string bad = tmp("bad.ply");
  std::ofstream(bad) << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n";
  r = cli("indent --mesh " + bad);
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("bad.ply"));
  // A cube whose top corner (6,6,6) sits on (6,0,6): two zero-area triangles, named at read
  // (issue 9: this was exit 3 "energy is not finite" in the middle of the solve).
  const std::string degen = tmp("degenerate.ply");
  std::ofstream(degen)
      << "ply\nformat ascii 1.0\nelement vertex 8\nproperty double x\nproperty double y\n"
         "property double z\nproperty uchar fixed\nelement face 12\n"
         "property list uchar int vertex_indices\nproperty int cell\nproperty int neighbor\n"
         "property int wall\nend_header\n"
         "0 0 0 1\n6 0 0 1\n0 6 0 1\n6 6 0 1\n0 0 6 0\n6 0 6 0\n0 6 6 0\n6 0 6 0\n"
         "3 4 6 0 1 -1 0\n3 6 2 0 1 -1 0\n3 1 3 5 1 -1 1\n3 3 7 5 1 -1 1\n3 0 1 4 1 -1 2\n"
         "3 1 5 4 1 -1 2\n3 6 7 2 1 -1 3\n3 7 3 2 1 -1 3\n3 2 3 0 1 -1 4\n3 3 1 0 1 -1 4\n"
         "3 4 5 6 1 -1 5\n3 5 7 6 1 -1 5\n";
  r = cli("indent --mesh " + degen + " --depth 0.1 --steps 1");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("degenerate.ply: not a valid tissue"));
  EXPECT_THAT(r.output,
              HasSubstr("triangle 3 (vertices 3, 7, 5): degenerate, area 0 µm² (its corners are "
                        "collinear or coincide)"));
  // Centroid tables: two cells at one point, and a column position past any int.
  const std::string same = tmp("same.csv");
  std::ofstream(same) << "label,x,y,z\n1,0,0,0\n2,5,0,0\n3,0,5,0\n4,0,0,5\n5,5,0,0\n";
  r = cli("build --centroids " + same + " --out " + tmp("never.ply"));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("same.csv:6: cell 5 has the same centroid as cell 2 (line 3)"));
  r = cli("build --centroids " + same + " --columns 99999999999,2,3,4 --out " + tmp("never.ply"));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("column 99999999999 for the label does not exist"));
  const std::string mgx =
      tp::test::sharedDataFile("mgx2r_meristem_morphographx/mesh_meristem_full_T0.ply");
  TP_SKIP_WITHOUT_DATA(mgx);
  r = cli("indent --mesh " + mgx);
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("376 error(s)"));
  EXPECT_THAT(r.output, HasSubstr("surface mesh"));
}

TEST(Cli, OptionsAreCheckedUpFrontWithTheirRange) {
  // Issue 9: each of these ran (for minutes, or to a wrong answer with exit 0); now each is
  // refused at once with exit 2 and a message naming the value and what is allowed.
  const std::string mesh = " --mesh " + smallTissue();
  const std::string out = " --out " + tmp("never.ply");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"indent" + mesh + " --probe-radius 1e-9", "the probe radius must be between 0.001 and 1000 µm (got 1e-09)"},
      {"indent" + mesh + " --probe-radius 1e6", "the probe radius must be between 0.001 and 1000 µm (got 1e+06)"},
      {"indent" + mesh + " --tolerance 1e10", "the solver tolerance must be between 1e-14 and 1e-3 (got 1e+10)"},
      {"indent" + mesh + " --tolerance nan", "the solver tolerance must be between 1e-14 and 1e-3 (got nan)"},
      {"indent" + mesh + " --steps 10000000", "the number of steps must be between 1 and 100000"},
      {"indent" + mesh + " --pressure -0.8", "the turgor pressure must be between 0 and 100 MPa (got -0.8)"},
      {"indent" + mesh + " --pressure 1e6", "the turgor pressure must be between 0 and 100 MPa"},
      {"indent" + mesh + " --force 1e9", "the force must be positive and at most 1e7 µN (got 1e+09)"},
      {"indent" + mesh + " --refine 60", "the refinement level must be between 0 and 6 (got 60)"},
      {"indent" + mesh + " --mesh-panels 0", "the zone's panel size must be between 0.05 and 10 cell sizes (got 0)"},
      {"indent" + mesh + " --depth 1e3", "the depth 1000 µm is more than half the size of the tissue"},
      {"indent" + mesh + " --site 0,0,-1000", "µm from the tissue surface, more than a cell"},
      {"indent" + mesh + " --site 1,2,3,4", "--site: expected three comma-separated numbers, got '1,2,3,4'"},
      {"indent" + mesh + " --axis 0,0,1", "the probe axis (0, 0, 1) does not point into the tissue at the site"},
      {"indent" + mesh + " --depth abc", "--depth"},
      {"build --generate --cells 10000000" + out, "a meristem has between 10 and 20000 cells (asked for 10000000)"},
      {"build --box 1000,1000,1000" + out, "--box: 1000,1000,1000 is more than 20000 cells"},
      {"build --box 4294967298,2,1" + out, "--box: 4294967298,2,1 is more than 20000 cells"},
      {"build --box 2,2" + out, "--box: expected three positive cell counts NX,NY,NZ, got '2,2'"},
  };
  for (const auto& [args, message] : cases) {
    const CliRun r = cli(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.output;
    EXPECT_THAT(r.output, HasSubstr(message)) << args;
  }
  EXPECT_FALSE(std::filesystem::exists(tmp("never.ply")));
  // On the clamped base of the shipped meristem (z = 0).
  const CliRun r = cli("indent --site 40,0,0");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("is on the clamped base of the tissue"));
}

// The version is the project's (CMakeLists.txt), as the application reports it: it printed a
// hand-written "0.1" against the project's 0.1.0.
TEST(Cli, VersionIsTheProjectVersion) {
  const CliRun r = cli("--version");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.output, std::string("tissueprobe-cli ") + TP_PROJECT_VERSION + "\n");
}

// The exit statuses the README documents, for every subcommand: 0 success, 2 bad input (a parse
// error, an unknown subcommand or option value, a missing or unreadable file), 4 an output that
// cannot be written. (130, interrupted: Cli.CtrlCStopsTheRunAndKeepsThePointsDone. 3, a solve
// that did not converge, is reached by the CLI only after a minute or more of iterations, e.g.
// p = 100 MPa on a 40-cell meristem in 94 s; the failure itself is tested in core.)
TEST(Cli, ExitStatusOfEverySubcommand) {
  EXPECT_EQ(cli("").status, 2);
  EXPECT_EQ(cli("frobnicate").status, 2);
  EXPECT_EQ(cli("--help").status, 0);
  EXPECT_EQ(cli("info " + smallTissue()).status, 0);
  EXPECT_EQ(cli("info " + tmp("missing.ply")).status, 2);
  EXPECT_EQ(cli("info").status, 2);
  CliRun r = cli("build --box 2,2,1 --out " + tmp("no-such-folder") + "/box.ply");
  EXPECT_EQ(r.status, 4) << r.output;
  EXPECT_THAT(r.output, HasSubstr("does not exist"));
  EXPECT_EQ(cli("build --box 2,2 --out " + tmp("box.ply")).status, 2);
  EXPECT_EQ(cli("build --box 2,2,1 --out " + tmp("box.ply")).status, 0);
  r = cli("indent --mesh " + smallTissue() + " --depth 0.05 --steps 1 --refine 0 --csv " +
          tmp("no-such-folder") + "/curve.csv");
  EXPECT_EQ(r.status, 4) << r.output;
  EXPECT_EQ(cli("indent --mesh " + smallTissue() + " --steps two").status, 2);
}

TEST(Cli, OutputsNeverReplaceInputsOrReadOnlyFiles) {
  // Issue 9: --csv could name the input mesh and overwrite it, a read-only result was replaced;
  // now both are refused before any work (exit 2 for an output that is an input, 4 for one that
  // cannot be written), and nothing is touched.
  const std::string mesh = smallTissue();
  const auto before = std::filesystem::file_size(mesh);
  CliRun r = cli("indent --mesh " + mesh + " --csv " + mesh);
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("the output '" + mesh + "' is the input file"));
  EXPECT_EQ(std::filesystem::file_size(mesh), before);
  const std::string same = tmp("same.out");
  r = cli("indent --mesh " + mesh + " --csv " + same + " --vtu " + same);
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("two outputs are the same file"));
  const std::string locked = tmp("locked.csv");
  std::ofstream(locked) << "kept\n";
  std::filesystem::permissions(locked, std::filesystem::perms::owner_read);
  r = cli("indent --mesh " + mesh + " --depth 0.05 --steps 1 --refine 0 --csv " + locked);
  EXPECT_EQ(r.status, 4);
  EXPECT_THAT(r.output, HasSubstr("the file is read-only"));
  std::ifstream in(locked);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "kept");
  const std::string table = tmp("centroids.csv");
  std::ofstream(table) << "label,x,y,z\n1,0,0,0\n";
  r = cli("build --centroids " + table + " --out " + table);
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("is the input file"));
}

TEST(Cli, InfoAndBuildFromCentroids) {
  CliRun r = cli("info " + smallTissue());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("yes, every cell"));
  const std::string out = tmp("real.ply");
  const std::string centroids = tp::test::sharedDataFile("refahi2021_flower_stage4/cells.csv");
  TP_SKIP_WITHOUT_DATA(centroids);
  r = cli("build --centroids " + centroids + " " +
          "--columns label,x,y,z,volume_um3 --out " + out);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("correlation"));
  EXPECT_TRUE(std::filesystem::exists(out));
}

// The closed-form shapes: a cap and a plate are written with their clamped rims; bad shapes are
// refused by name (their use is in tests/experiment/slow/test_cli_closed_form.cpp).
TEST(Cli, BuildsTheShapesOfTheClosedForms) {
  CliRun r = cli("build --cap 10,6 --rings 4 --out " + tmp("cap.ply"));
  ASSERT_EQ(r.status, 0) << r.output;
  r = cli("info " + tmp("cap.ply"));
  EXPECT_THAT(r.output, testing::ContainsRegex("vertices +[0-9]+ \\([1-9][0-9]* clamped\\)"));
  EXPECT_THAT(r.output, HasSubstr(", 10] um"));  // the apex on the sphere of radius 10
  EXPECT_THAT(r.output, HasSubstr("open cells clamped at the rim"));
  r = cli("build --plate 10 --rings 4 --out " + tmp("plate.ply"));
  ASSERT_EQ(r.status, 0) << r.output;
  for (const std::string bad : {"--cap 6,10", "--cap 10", "--cap 10,nan", "--plate -1",
                                "--plate 10 --rings 1", "--cap 10,6 --rings 5000"}) {
    r = cli("build " + bad + " --out " + tmp("bad.ply"));
    EXPECT_EQ(r.status, 2) << bad << ": " << r.output;
    EXPECT_THAT(r.output, HasSubstr(bad.find("rings") != std::string::npos
                                        ? "--rings"
                                        : bad.substr(0, bad.find(' '))))
        << bad;
  }
}

TEST(Cli, CtrlCStopsTheRunAndKeepsThePointsDone) {
  // Issue 9: a long run stopped with Ctrl-C (SIGINT) ends cleanly: exit 130, the converged points
  // printed and written to the CSV with a comment saying so, no temporary file left behind.
  namespace fs = std::filesystem;
  const fs::path dir = tmp("interrupt");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string csv = (dir / "curve.csv").string();
  // Stopped once the third point is reported (--progress prints a line per point).
  const InterruptedRun run = runAndInterrupt(
      std::string(TP_CLI) + " indent --mesh " + smallTissue() +
          " --depth 0.5 --steps 2000 --refine 2 --progress --csv " + csv,
      "point 3/2000");
  const std::string& output = run.output;
  ASSERT_TRUE(run.signalled) << output;
  ASSERT_TRUE(run.exited) << output;
  EXPECT_EQ(run.status, 130) << output;
  EXPECT_THAT(output, HasSubstr("interrupted: cancelled; the "));
  const auto curve = tp::readCurveCsv(csv);
  ASSERT_GE(curve.size(), 3u);
  EXPECT_LT(curve.size(), 2001u);
  for (const auto& p : curve) EXPECT_TRUE(p.converged);
  std::ifstream in(csv);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_THAT(text, HasSubstr("# interrupted by the user after " +
                              std::to_string(curve.size()) + " point(s)"));
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string(), "curve.csv") << "left behind: " << e.path();
}

TEST(Cli, FitReadsBackTheModulusAndTurgorOfCurvesItSimulated) {
  // Two curves simulated by `indent` at E = 60 MPa, p = 0.3 MPa (one turgid, one plasmolysed),
  // read back by `fit` from its defaults (E = 100, p = 0.8) on the same tissue, site and axis.
  const std::string box = tmp("fit_box.ply"), turgid = tmp("fit_turgid.csv"),
                    plasm = tmp("fit_plasm.csv"), report = tmp("fit.json"), out = tmp("fit.csv");
  ASSERT_EQ(cli("build --box 3,3,2 --cell-size 5 --out " + box).status, 0);
  const std::string where =
      " --mesh " + box + " --nu 0.3 --site 7.9,7.3,10.2 --axis 0,0,-1 --refine 0";
  ASSERT_EQ(cli("indent" + where + " --E 60 --pressure 0.3 --depth 0.4 --steps 8 --tolerance 1e-11 "
                "--quiet --csv " + turgid).status, 0);
  ASSERT_EQ(cli("indent" + where + " --E 60 --pressure 0 --depth 0.4 --steps 8 --tolerance 1e-11 "
                "--quiet --csv " + plasm).status, 0);
  const CliRun r = cli("fit" + where + " --curve " + turgid + " --plasmolysed-curve " + plasm +
                       " --fit E,p --report " + report + " --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("# correlation E-p"));
  EXPECT_THAT(r.output, HasSubstr("Hertz apparent modulus"));
  std::ifstream in(report);
  std::stringstream text;
  text << in.rdbuf();
  const std::string json = text.str();
  // The values under their option names, with intervals (checked by value in the core's tests;
  // here that the report carries them, parsed by a plain search).
  auto number = [&](const std::string& key, const std::string& field) {
    const auto k = json.find("\"" + key + "\": {");
    EXPECT_NE(k, std::string::npos) << key;
    const auto f = json.find("\"" + field + "\": ", k);
    return std::stod(json.substr(f + field.size() + 4));
  };
  EXPECT_NEAR(number("E", "value"), 60.0, 1e-6);
  EXPECT_NEAR(number("p", "value"), 0.3, 1e-7);
  EXPECT_NEAR(number("h", "value"), 0.2, 0);
  EXPECT_LT(number("E", "stderr"), 1e-6);
  EXPECT_THAT(json, HasSubstr("\"ci95\""));
  EXPECT_THAT(json, HasSubstr("\"identifiable\": true"));
  EXPECT_THAT(json, HasSubstr("\"pressure_held_MPa\": 0.0"));
  EXPECT_THAT(json, HasSubstr("\"depths_simulated\": 8"));  // 8 at positive depth, ≤ 10: each
  std::ifstream csv(out);
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header, "curve,depth_um,measured_uN,simulated_uN,residual_uN");
  int rows = 0;
  for (std::string line; std::getline(csv, line);) ++rows;
  EXPECT_EQ(rows, 18);

  // Bad input: exit 2 with the problem named.
  CliRun bad = cli("fit" + where + " --curve " + turgid + " --fit E,q");
  EXPECT_EQ(bad.status, 2);
  EXPECT_THAT(bad.output, HasSubstr("--fit: 'q' is not one of E, p, h, offset"));
  bad = cli("fit" + where + " --curve " + turgid + " --simulated-depths 1");
  EXPECT_EQ(bad.status, 2);
  EXPECT_THAT(bad.output, HasSubstr("--simulated-depths: 0 (every point) or at least 2, got 1"));
  bad = cli("fit" + where + " --curve " + tmp("no_such_curve.csv"));
  EXPECT_EQ(bad.status, 2);
  EXPECT_THAT(bad.output, HasSubstr("no file"));
  const std::string broken = tmp("fit_broken.csv");
  std::ofstream(broken) << "depth (nm),force (nN)\n0,0\n100,abc\n";
  bad = cli("fit" + where + " --curve " + broken);
  EXPECT_EQ(bad.status, 2);
  EXPECT_THAT(bad.output, HasSubstr("fit_broken.csv: line 3: force 'abc' is not a finite number"));
  bad = cli("fit" + where + " --curve " + turgid + " --report " + turgid);
  EXPECT_EQ(bad.status, 2);
  EXPECT_THAT(bad.output, HasSubstr("is the input file"));
  bad = cli("fit" + where);
  EXPECT_EQ(bad.status, 2);
  EXPECT_THAT(bad.output, HasSubstr("give at least one --curve"));
}

TEST(Cli, FitReadsJpkForceCurvesAndNamesTheirContactPoint) {
  const std::string jpk =
      tp::test::sharedDataFile("afm_jpk_text_export/force-save-2021.06.30-12.04.16.071.txt");
  TP_SKIP_WITHOUT_DATA(jpk);
  const std::string box = tmp("jpk_box.ply");
  ASSERT_EQ(cli("build --box 3,3,2 --cell-size 5 --out " + box).status, 0);
  // The curve is read and its contact point shown; this brain-tissue curve goes 13.9 um deep,
  // more than this small tissue allows, which is refused by name (exit 2), not attempted.
  CliRun r = cli("fit --mesh " + box + " --refine 0 --curve " + jpk + " --fit E");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("JPK approach of 3000 points, k = 0.061 N/m; contact at height "
                                  "31.46"));
  EXPECT_THAT(r.output, HasSubstr("is more than half the size of the tissue"));
  r = cli("fit --mesh " + box + " --refine 0 --curve " + jpk + " --contact-height 100");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("the contact height 100.000000 um is outside the heights"));
}

TEST(Cli, MapShardsMergeAndRefuseBadValuesByName) {
  // Issue 14: `map` over listed sites in two shards, merged, gives the single run's table; bad
  // values are refused before any work, naming the option and value.
  namespace fs = std::filesystem;
  const fs::path dir = tmp("map");
  fs::remove_all(dir);
  fs::create_directories(dir);
  {
    std::ofstream list(dir / "sites.csv");
    list << "x,y,z\n0,0,16.5\n4,0,16\n0,-4,16\n";
    std::ofstream far(dir / "far.csv");
    far << "0,0,16.5\n0,0,40\n";
  }
  const std::string common = "map --mesh " + smallTissue() + " --refine 0 --depth 0.2 --steps 2 " +
                             "--sites list --site-list " + (dir / "sites.csv").string();
  const CliRun single = cli(common + " --jobs 2 --out " + (dir / "single").string());
  ASSERT_EQ(single.status, 0) << single.output;
  EXPECT_THAT(single.output, HasSubstr("3 site(s) x 1 parameter set(s) = 3 task(s)"));
  for (int i = 0; i < 2; ++i) {
    const CliRun s = cli(common + " --shard " + std::to_string(i) + "/2 --out " +
                         (dir / ("shard" + std::to_string(i))).string());
    ASSERT_EQ(s.status, 0) << s.output;
    EXPECT_THAT(s.output, HasSubstr("tissueprobe-cli merge"));
  }
  const CliRun half = cli("merge " + (dir / "shard0").string() + " --out " + (dir / "half").string());
  EXPECT_EQ(half.status, 3) << half.output;
  EXPECT_THAT(half.output, HasSubstr("1 of 3 task(s) are in none of the folders (1)"));
  const CliRun merged = cli("merge " + (dir / "shard0").string() + " " + (dir / "shard1").string() +
                            " --out " + (dir / "merged").string());
  ASSERT_EQ(merged.status, 0) << merged.output;
  auto read = [](const fs::path& p) {
    std::ifstream in(p);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  const std::string table = read(dir / "single" / "map.csv");
  EXPECT_EQ(read(dir / "merged" / "map.csv"), table);
  EXPECT_THAT(table, HasSubstr("\n2,2,list,line 4,0,-4,16,"));
  EXPECT_THAT(table, HasSubstr(",converged,"));
  // Run again: everything is done already.
  const CliRun again = cli(common + " --out " + (dir / "single").string());
  EXPECT_EQ(again.status, 0) << again.output;
  EXPECT_THAT(again.output, HasSubstr("0 done now (0 not converged), 3 done before"));
  // Another E into the same folder: refused, naming what differs.
  const CliRun other = cli(common + " --E 50 --out " + (dir / "single").string());
  EXPECT_EQ(other.status, 2) << other.output;
  EXPECT_THAT(other.output, HasSubstr("'settings' differs from this run's"));
  // A map reports forces only: its plan says it ran on the coarser panels made for forces, and
  // the same map on the stress picture's panels (indent's) is another plan.
  EXPECT_THAT(read(dir / "single" / "plan.json"), HasSubstr("\"mesh_panel_cells\""));
  const CliRun stressPanels =
      cli(common + " --mesh-panels 0.35 --out " + (dir / "single").string());
  EXPECT_EQ(stressPanels.status, 2) << stressPanels.output;
  EXPECT_THAT(stressPanels.output, HasSubstr("'settings' differs from this run's"));
  for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
           {" --shard 2/2", "--shard: expected I/N with 0 <= I < N, got '2/2'"},
           {" --shard x", "--shard: expected I/N"},
       }) {
    const CliRun r = cli(common + args + " --out " + (dir / "bad").string());
    EXPECT_EQ(r.status, 2) << args << ": " << r.output;
    EXPECT_THAT(r.output, HasSubstr(says)) << args;
  }
  const CliRun middles = cli("map --mesh " + smallTissue() + " --sites cells,middles --out " +
                             (dir / "bad").string());
  EXPECT_EQ(middles.status, 2);
  EXPECT_THAT(middles.output, HasSubstr("--sites: unknown kind of sites 'middles'"));
  const CliRun far = cli("map --mesh " + smallTissue() + " --sites list --site-list " +
                         (dir / "far.csv").string() + " --out " + (dir / "bad").string());
  EXPECT_EQ(far.status, 2);
  EXPECT_THAT(far.output, HasSubstr("far.csv line 2: the site (0, 0, 40) um is "));
  const CliRun noList = cli("map --mesh " + smallTissue() + " --sites list --out " + (dir / "bad").string());
  EXPECT_EQ(noList.status, 2);
  EXPECT_THAT(noList.output, HasSubstr("--sites list needs --site-list FILE"));
  const CliRun sweep = cli("sweep --mesh " + smallTissue() + " --vary nu=0.3,0.6 --out " +
                           (dir / "bad").string());
  EXPECT_EQ(sweep.status, 2);
  EXPECT_THAT(sweep.output, HasSubstr("--vary 'nu=0.3,0.6'"));
  EXPECT_FALSE(fs::exists(dir / "bad" / "plan.json"));
}

TEST(Cli, CtrlCStopsAMapAndTheSameCommandGoesOn) {
  // Issue 14: Ctrl-C during a map stops the workers, keeps every finished site (exit 130), and
  // the same command again does only the rest; the table is then that of an uninterrupted run.
  namespace fs = std::filesystem;
  const fs::path dir = tmp("map-interrupt");
  fs::remove_all(dir);
  const std::string args = "map --mesh " + smallTissue() +
                           " --refine 0 --depth 0.2 --steps 3 --sites grid --grid-spacing 8 --jobs 1 --progress";
  const InterruptedRun run =
      runAndInterrupt(std::string(TP_CLI) + " " + args + " --out " + (dir / "map").string(),
                      "] 3/");  // the third site done
  const std::string& output = run.output;
  ASSERT_TRUE(run.signalled) << output;
  ASSERT_TRUE(run.exited) << output;
  EXPECT_EQ(run.status, 130) << output;
  EXPECT_THAT(output, HasSubstr("run the same command again to go on"));
  int kept = 0;
  for (const auto& e : fs::directory_iterator(dir / "map" / "results")) {
    EXPECT_EQ(e.path().extension(), ".json") << "left behind: " << e.path();
    ++kept;
  }
  EXPECT_GE(kept, 3);
  EXPECT_FALSE(fs::exists(dir / "map" / "map.csv"));
  const CliRun rest = cli(args + " --out " + (dir / "map").string());
  ASSERT_EQ(rest.status, 0) << rest.output;
  EXPECT_THAT(rest.output, HasSubstr("done before"));
  EXPECT_THAT(rest.output, HasSubstr(", " + std::to_string(kept) + " done before"));
  const CliRun whole = cli(args + " --out " + (dir / "whole").string());
  ASSERT_EQ(whole.status, 0) << whole.output;
  auto read = [](const fs::path& p) {
    std::ifstream in(p);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  EXPECT_EQ(read(dir / "map" / "map.csv"), read(dir / "whole" / "map.csv"));
}
