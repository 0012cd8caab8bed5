// Stiffness maps and sweeps (core/experiment/Map.h): sites placed where they belong on a block
// of cubic cells and on a meristem, site lists and --vary values read or refused by name, the
// task numbering, results that survive their files, a map whose tasks are the indentations they
// say, and the same table from one process, two workers, two shards merged, and a resumed run.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>

#include "experiment/Experiment.h"
#include "experiment/Map.h"
#include "io/Centroids.h"
#include "io/TextFile.h"
#include "solver/CholmodSolver.h"
#include "solver/OpenMpRegions.h"
#include "support/SharedData.h"
#include "support/SmallMeristem.h"
#include "tissue/Meristem.h"
#include "tissue/RealTissue.h"
#include "tissue/Shapes.h"

using namespace tp;
namespace fs = std::filesystem;

namespace {

using test::smallMeristem;

std::string freshDir(const std::string& name) {
  const std::string d = testing::TempDir() + "/map_" + name;
  fs::remove_all(d);
  return d;
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

// Distance from p to the nearest free outer triangle of the rest tissue.
double distanceToOuterSurface(const CellComplex& cc, const Vec3& p) {
  double best = 1e300;
  for (int t = 0; t < cc.triangleCount(); ++t) {
    if (!cc.isOuterTriangle(t)) continue;
    const auto& tri = cc.triangles[t];
    const Vec3 a = cc.rest.col(tri[0]), b = cc.rest.col(tri[1]), c = cc.rest.col(tri[2]);
    // Sample-free exact distance: project onto the plane, clamp by barycentric search.
    const Vec3 n = (b - a).cross(c - a).normalized();
    const Vec3 q = p - n.dot(p - a) * n;
    const double area = (b - a).cross(c - a).dot(n);
    const double u = (c - b).cross(q - b).dot(n) / area, v = (a - c).cross(q - c).dot(n) / area;
    if (u >= -1e-9 && v >= -1e-9 && u + v <= 1 + 1e-9) best = std::min(best, (p - q).norm());
  }
  return best;
}

}  // namespace

TEST(MapSites, CellMiddlesOfABlockAreTheTopCentres) {
  const CellComplex box = boxTissue(3, 3, 1, 10.0);
  const auto sites = cellMiddleSites(box);
  ASSERT_EQ(sites.size(), 9u);  // every cell's largest outer wall is its top (ties: the highest)
  std::vector<Vec3> expected;
  for (const auto& s : sites) {
    EXPECT_NEAR(s.point.z(), 10.0, 1e-12) << s.label;
    const double fx = std::fmod(s.point.x(), 10.0), fy = std::fmod(s.point.y(), 10.0);
    EXPECT_NEAR(fx, 5.0, 1e-9) << s.label;
    EXPECT_NEAR(fy, 5.0, 1e-9) << s.label;
    EXPECT_EQ(s.kind, SiteKind::CellMiddle);
  }
}

TEST(MapSites, JunctionsOfABlockAreOnTheWallsBetweenCells) {
  const CellComplex box = boxTissue(3, 3, 1, 10.0);
  const auto sites = junctionSites(box);
  // 12 pairs of neighbouring cells, each meeting on the top (and, at the rim, down the side).
  ASSERT_EQ(sites.size(), 12u);
  int middles = 0;
  for (const auto& s : sites) {
    const double fx = std::fmod(s.point.x() + 1e-9, 10.0), fy = std::fmod(s.point.y() + 1e-9, 10.0);
    // on a junction line: x or y on a multiple of 10 (the walls between cells)
    EXPECT_TRUE(std::abs(fx) < 1e-6 || std::abs(fy) < 1e-6) << s.label << " " << s.point.transpose();
    // the four pairs with the centre cell meet only on the top: the middle of their edge
    if (std::abs(s.point.z() - 10) < 1e-9 && (std::abs(fx - 5) < 1e-6 || std::abs(fy - 5) < 1e-6) &&
        std::abs(s.point.x() - 15) < 5.1 && std::abs(s.point.y() - 15) < 5.1)
      ++middles;
  }
  EXPECT_EQ(middles, 4);
}

TEST(MapSites, AGridIsDroppedOntoTheTopSurface) {
  const CellComplex box = boxTissue(3, 3, 1, 10.0);
  const auto nine = gridSites(box, 10.0);
  ASSERT_EQ(nine.size(), 9u);
  for (const auto& s : nine) EXPECT_NEAR(s.point.z(), 10.0, 1e-12);
  EXPECT_NEAR(nine.front().point.x(), 5.0, 1e-12);
  EXPECT_NEAR(nine.front().point.y(), 5.0, 1e-12);
  EXPECT_NEAR(nine.back().point.x(), 25.0, 1e-12);
  EXPECT_EQ(gridSites(box, 7.0).size(), 25u);  // x, y in {1, 8, 15, 22, 29}
  EXPECT_THROW(gridSites(box, 0.0), std::invalid_argument);
  EXPECT_THROW(gridSites(box, std::nan("")), std::invalid_argument);
  EXPECT_THROW(gridSites(box, 1e-4), std::invalid_argument);  // over a million points
}

TEST(MapSites, OnAMeristemEverySiteIsOnTheOuterSurface) {
  const auto cc = smallMeristem();
  const auto cells = cellMiddleSites(*cc);
  const auto junctions = junctionSites(*cc);
  const auto grid = gridSites(*cc, 3.0);
  // One middle per cell with a free outer wall (the epidermis), fewer than all cells.
  int outerCells = 0;
  {
    std::vector<char> outer(cc->cellCount(), 0);
    for (int t = 0; t < cc->triangleCount(); ++t) {
      const Wall& w = cc->walls[cc->triangleWall[t]];
      const auto& tri = cc->triangles[t];
      const bool allFixed = cc->fixed[tri[0]] && cc->fixed[tri[1]] && cc->fixed[tri[2]];
      if (w.neighbor < 0 && w.cell >= 0 && !allFixed) outer[w.cell] = 1;
    }
    for (char o : outer) outerCells += o;
  }
  EXPECT_EQ(static_cast<int>(cells.size()), outerCells);
  EXPECT_LT(outerCells, cc->cellCount());
  EXPECT_GT(junctions.size(), cells.size());  // a polygonal tiling has more edges than faces
  EXPECT_GT(grid.size(), 30u);
  for (const auto* list : {&cells, &junctions, &grid})
    for (const auto& s : *list) EXPECT_LT(distanceToOuterSurface(*cc, s.point), 1e-9) << s.label;
}

// The sites the program chooses leave out those where the probe would reach the clamped base,
// which the experiment refuses: on the real flower (../shared/data) a map of its cell middles
// ended with such a site failed (cell 66, clamped vertex 295 within the 1 µm probe radius).
// Listed sites are the user's: kept, to fail saying why.
TEST(MapSites, SitesWhereTheProbeWouldReachTheClampedBaseAreLeftOut) {
  const CellComplex flower =
      tissueFromCentroids(readCentroids(test::sharedDataFile("refahi2021_flower_stage4/cells.csv")),
                          RealTissueOptions{});
  const std::vector<MapSite> all = cellMiddleSites(flower);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(mapSites(flower, {SiteKind::CellMiddle}, nan, "").size(), all.size());
  for (const double radius : {1.0, 3.0}) {
    std::vector<MapSite> out;
    const std::vector<MapSite> kept =
        mapSites(flower, {SiteKind::CellMiddle}, nan, "", radius, &out);
    EXPECT_EQ(kept.size() + out.size(), all.size()) << radius;
    EXPECT_GE(out.size(), 1u) << radius;
    EXPECT_LT(out.size(), all.size() / 5) << radius;  // the rim, not the flower
    for (const MapSite& site : out)
      EXPECT_FALSE(clampedMaterialWithin(flower, site.point, radius).empty()) << site.label;
    for (const MapSite& site : kept)
      EXPECT_TRUE(clampedMaterialWithin(flower, site.point, radius).empty()) << site.label;
    // In the order of all the sites, each either kept or left out.
    size_t k = 0, o = 0;
    for (const MapSite& site : all) {
      if (k < kept.size() && kept[k].label == site.label)
        ++k;
      else if (o < out.size() && out[o].label == site.label)
        ++o;
    }
    EXPECT_EQ(k, kept.size());
    EXPECT_EQ(o, out.size());
    if (radius == 1.0) {
      bool cell66 = false;
      for (const MapSite& site : out) cell66 |= site.label == "cell 66";
      EXPECT_TRUE(cell66);
      // A list naming such a site keeps it.
      const std::string list = testing::TempDir() + "/map_base_site.txt";
      std::ostringstream line;
      line.precision(17);
      line << out[0].point.x() << "," << out[0].point.y() << "," << out[0].point.z() << "\n";
      writeText(list, line.str());
      std::vector<MapSite> none;
      EXPECT_EQ(mapSites(flower, {SiteKind::Listed}, nan, list, radius, &none).size(), 1u);
      EXPECT_TRUE(none.empty());
    }
  }
  // The experiment refuses a left-out site for the same reason (the small meristem: its base
  // rest state is quick to solve).
  const auto cc = smallMeristem();
  std::vector<MapSite> out;
  double radius = 1.0;  // the smallest whole radius that leaves out a site (its stem is 4 µm)
  for (; out.empty() && radius <= 8; radius += 1)
    mapSites(*cc, {SiteKind::CellMiddle, SiteKind::Junction}, nan, "", radius, &out);
  radius -= 1;
  ASSERT_FALSE(out.empty());
  ExperimentSettings s;
  s.indentation.probeRadius = radius;
  s.indentation.restSite = out.front().point;
  Experiment e(cc, s);
  try {
    e.prepareBase();
    FAIL() << "a site on the clamped base was accepted";
  } catch (const std::invalid_argument& err) {
    EXPECT_NE(std::string(err.what())
                  .find("is on the clamped base of the tissue (" +
                        clampedMaterialWithin(*cc, out.front().point, radius)),
              std::string::npos)
        << err.what();
  }
}

TEST(MapSites, AListIsReadWithItsHeaderAndRefusedByLine) {
  const std::string dir = freshDir("list");
  fs::create_directories(dir);
  writeText(dir + "/ok.csv", "x,y,z\n# a comment\n1,2,3\n\n4\t5\t6  # tab separated\n7 8 9\r\n");
  const auto sites = readSiteList(dir + "/ok.csv");
  ASSERT_EQ(sites.size(), 3u);
  EXPECT_EQ(sites[1].point, Vec3(4, 5, 6));
  EXPECT_EQ(sites[2].label, "line 6");
  auto message = [](const std::string& path) {
    try {
      readSiteList(path);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  writeText(dir + "/word.csv", "1,2,3\n4,5,6\n1,2,x\n");
  EXPECT_NE(message(dir + "/word.csv").find("word.csv:3: 'x' is not a number"), std::string::npos)
      << message(dir + "/word.csv");
  writeText(dir + "/two.csv", "1,2\n");
  EXPECT_NE(message(dir + "/two.csv").find("two.csv:1: expected x,y,z, found 2"), std::string::npos);
  writeText(dir + "/inf.csv", "1,2,inf\n");
  EXPECT_NE(message(dir + "/inf.csv").find("inf.csv:1: 'inf' is not a coordinate"), std::string::npos);
  writeText(dir + "/empty.csv", "x,y,z\n");
  EXPECT_NE(message(dir + "/empty.csv").find("no site"), std::string::npos);
  EXPECT_NE(message(dir + "/missing.csv").find("missing.csv"), std::string::npos);
}

TEST(MapSweep, VariationsAreReadOrRefusedByName) {
  const Variation e = parseVariation("E=50:200:4");
  EXPECT_EQ(e.name, "E");
  EXPECT_EQ(e.values, (std::vector<double>{50, 100, 150, 200}));
  EXPECT_EQ(parseVariation("p=0,0.4,0.8").values, (std::vector<double>{0, 0.4, 0.8}));
  EXPECT_EQ(parseVariation("probe-radius=2:2:1").values, (std::vector<double>{2}));
  auto message = [](const std::string& text) {
    try {
      parseVariation(text);
    } catch (const std::invalid_argument& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("E").find("expected NAME=A:B:N"), std::string::npos);
  EXPECT_NE(message("Q=1,2").find("cannot vary 'Q'"), std::string::npos);
  EXPECT_NE(message("E=1:2").find("A:B:N"), std::string::npos);
  EXPECT_NE(message("E=1:2:0").find("whole number"), std::string::npos);
  EXPECT_NE(message("E=1:2:2.5").find("whole number"), std::string::npos);
  EXPECT_NE(message("E=1,x").find("'x' is not a number"), std::string::npos);
  EXPECT_NE(message("nu=0.3,0.7").find("Poisson"), std::string::npos) << message("nu=0.3,0.7");
  EXPECT_NE(message("E=-5,10").find("E="), std::string::npos);
}

TEST(MapPlan, AMapRunsAnIndentationOnAMeshMadeForForces) {
  // A map reports forces and draws no stress: its settings are the indentation's with the
  // refined zone's walls in the coarser panels made for forces, and its plan says so (the
  // stress picture's panels, absent from the plan as in every plan before the key).
  ExperimentSettings indentation;
  indentation.pressure = 0.3;
  indentation.mesh.tolerance = 0.02;
  indentation.indentation.steps = 7;
  const ExperimentSettings map = mapSettings(indentation);
  EXPECT_EQ(map.mesh.panelCells, MeshSettings::kForcePanelCells);
  EXPECT_EQ(indentation.mesh.panelCells, MeshSettings::kStressPanelCells);
  EXPECT_EQ(map.pressure, 0.3);
  EXPECT_EQ(map.mesh.tolerance, 0.02);
  EXPECT_EQ(map.indentation.steps, 7);
  MapPlan plan;
  plan.settings = map;
  EXPECT_EQ(plan.toJson()["settings"]["mesh_panel_cells"], MeshSettings::kForcePanelCells);
  plan.settings = indentation;
  EXPECT_FALSE(plan.toJson()["settings"].contains("mesh_panel_cells"));
}

TEST(MapPlan, TasksRunSiteFastestThenTheLastVariation) {
  MapPlan plan;
  plan.sites = {{SiteKind::Listed, "a", Vec3(1, 0, 0)}, {SiteKind::Listed, "b", Vec3(2, 0, 0)}};
  plan.vary = {parseVariation("E=10,20,30"), parseVariation("p=0,0.5")};
  ASSERT_EQ(plan.parameterSets(), 6);
  ASSERT_EQ(plan.taskCount(), 12);
  // task 7 = set 3 (E = 20, p = 0.5), site b
  EXPECT_EQ(plan.values(7), (std::vector<double>{20, 0.5}));
  EXPECT_EQ(plan.site(7).label, "b");
  const ExperimentSettings s = plan.taskSettings(7);
  EXPECT_EQ(s.material.youngModulus, 20);
  EXPECT_EQ(s.pressure, 0.5);
  EXPECT_EQ(*s.indentation.site, Vec3(2, 0, 0));  // a listed site: a place
  EXPECT_FALSE(s.indentation.restSite);
  plan.sites[1].kind = SiteKind::CellMiddle;  // a generated site: a material point
  EXPECT_EQ(*plan.taskSettings(7).indentation.restSite, Vec3(2, 0, 0));
  EXPECT_FALSE(plan.taskSettings(7).indentation.site);
  plan.sites[1].kind = SiteKind::Listed;
  EXPECT_EQ(plan.values(4), (std::vector<double>{20, 0}));
  EXPECT_EQ(plan.values(11), (std::vector<double>{30, 0.5}));
  // Round trip of what the table needs.
  plan.tissue = "/t.ply";
  plan.tissueDigest = "V 1";
  const MapPlan back = MapPlan::fromJson(plan.toJson(), "plan.json");
  EXPECT_EQ(back.toJson()["sites"], plan.toJson()["sites"]);
  EXPECT_EQ(back.vary[1].values, plan.vary[1].values);
  EXPECT_EQ(back.settingsJson, plan.toJson()["settings"]);
  // Too many tasks: refused by count, before any product can overflow an int.
  MapPlan huge = plan;
  for (int k = 0; k < 5; ++k) huge.vary.push_back(parseVariation("h=0.1:0.3:1000"));
  EXPECT_THROW(huge.checkSize(), std::invalid_argument);
  try {
    MapPlan::fromJson(huge.toJson(), "huge.json");
    ADD_FAILURE() << "accepted 1.2e16 tasks";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("huge.json: the plan has 1.2e+16 tasks"), std::string::npos)
        << e.what();
  }
  nlohmann::json bad = plan.toJson();
  bad["sites"][1]["kind"] = "middles";
  try {
    MapPlan::fromJson(bad, "p.json");
    ADD_FAILURE() << "accepted an unknown kind of site";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("p.json: unknown kind of sites 'middles'"), std::string::npos)
        << e.what();
  }
}

TEST(MapResults, ATaskResultSurvivesItsFileWithNaNs) {
  TaskResult r;
  r.task = 17;
  r.contact = Vec3(1.25, -3.5, 1e-17);
  r.force = 0.123456789012345678;
  r.secant = 2.5;
  r.level = 3;
  r.meshError = 0.0123;
  r.status = "failed";
  r.message = "a, \"quoted\" message";
  r.curve = {{0.0, 0.0}, {0.1, 0.0123456789012345678}, {0.2, 0.05}};
  const TaskResult back = TaskResult::fromJson(nlohmann::json::parse(r.toJson().dump()), "f");
  EXPECT_EQ(back.task, 17);
  EXPECT_EQ(back.contact, r.contact);
  EXPECT_EQ(back.force, r.force);  // bit for bit
  EXPECT_TRUE(std::isnan(back.depth));
  EXPECT_TRUE(std::isnan(back.hertz));
  EXPECT_EQ(back.level, 3);
  EXPECT_EQ(back.message, r.message);
  EXPECT_EQ(back.curve, r.curve);  // bit for bit
  nlohmann::json bad = r.toJson();
  bad.erase("curve");  // results of earlier versions have no curve
  EXPECT_TRUE(TaskResult::fromJson(bad, "f").curve.empty());
  bad["curve"] = nlohmann::json::array({nlohmann::json::array({0.1})});
  EXPECT_THROW(TaskResult::fromJson(bad, "f"), std::runtime_error);
  bad = r.toJson();
  bad["status"] = "fine";
  EXPECT_THROW(TaskResult::fromJson(bad, "f"), std::runtime_error);
  bad = r.toJson();
  bad["level"] = 3.5;
  EXPECT_THROW(TaskResult::fromJson(bad, "f"), std::runtime_error);
}

TEST(MapResults, AMapFieldIsTheSiteValueAtASiteAndShepardBetween) {
  // Three converged sites on a line 0, 2, 10 µm and a failed one: nearest distances 2, 2, 8, so
  // the radius is twice the median, 4 µm.
  MapPlan plan;
  for (double x : {0.0, 2.0, 10.0, 1.0}) {
    MapSite s;
    s.kind = SiteKind::CellMiddle;
    s.point = Vec3(x, 0, 5);
    plan.sites.push_back(s);
  }
  std::vector<TaskResult> results(4);
  const double stiffness[] = {1.0, 4.0, 9.0, 100.0};
  for (int t = 0; t < 4; ++t) {
    results[t].task = t;
    results[t].status = t == 3 ? "failed" : "converged";
    results[t].secant = stiffness[t];
    results[t].force = 0.5 * stiffness[t];
    results[t].hertz = 10 * stiffness[t];
    results[t].contact = Vec3(100, 100, 100);  // a generated site is where its point is
  }
  const MapField f(plan, results);
  EXPECT_EQ(f.siteCount(), 3);
  EXPECT_DOUBLE_EQ(f.radius(), 4.0);
  EXPECT_EQ(f.interpolated(Vec3(2, 0, 5), MapField::Stiffness), 4.0);
  EXPECT_EQ(f.interpolated(Vec3(10, 0, 5), MapField::Hertz), 90.0);
  // at x = 0.5: weights 1/0.25 and 1/2.25 (the site at 10 µm is beyond the radius)
  const double w0 = 4.0, w1 = 1.0 / 2.25;
  EXPECT_NEAR(f.interpolated(Vec3(0.5, 0, 5), MapField::Stiffness), (w0 * 1 + w1 * 4) / (w0 + w1),
              1e-14);
  EXPECT_NEAR(f.interpolated(Vec3(0.5, 0, 5), MapField::Force), 0.5 * (w0 * 1 + w1 * 4) / (w0 + w1),
              1e-14);
  EXPECT_TRUE(std::isnan(f.interpolated(Vec3(15, 0, 5), MapField::Stiffness)));  // no site near
  EXPECT_EQ(f.nearest(Vec3(6.5, 0, 5), MapField::Stiffness), 9.0);
  double d = 0;
  EXPECT_EQ(f.nearestTask(Vec3(1.2, 0, 5), &d), 1);  // not the failed site at 1 µm
  EXPECT_NEAR(d, 0.8, 1e-14);
  // a cap on the radius: at 0.5 µm only the site at 0 µm is within 1 µm
  EXPECT_EQ(MapField(plan, results, 1.0).interpolated(Vec3(0.5, 0, 5), MapField::Stiffness), 1.0);
  EXPECT_DOUBLE_EQ(MapField(plan, results, 1.0).radius(), 1.0);
  EXPECT_TRUE(MapField(plan, {}).empty());
  EXPECT_EQ(MapField(plan, {}).nearestTask(Vec3::Zero()), -1);
}

namespace {

MapPlan smallPlan(const CellComplex& cc) {
  MapPlan plan;
  plan.tissue = "small meristem";
  plan.tissueDigest = tissueDigest(cc);
  ExperimentSettings& s = plan.settings;
  s.mesh.automatic = false;
  s.mesh.level = 0;
  s.mesh.estimateError = false;
  s.indentation.maxDepth = 0.2;
  s.indentation.steps = 3;
  const auto middles = cellMiddleSites(cc);
  for (int k : {0, 5, 9, 14}) plan.sites.push_back(middles.at(k));
  return plan;
}

std::string table(const std::string& dir) { return readTextFile(dir + "/map.csv", "table"); }

}  // namespace

TEST(MapRun, EachTaskIsTheIndentationOfItsSite) {
  const auto cc = smallMeristem();
  const MapPlan plan = smallPlan(*cc);
  MapRunOptions o;
  o.outDir = freshDir("one");
  o.jobs = 1;
  // The map caps BLAS at one thread while it runs and leaves a cap held elsewhere (the
  // application's worker holds one during a drag) in force.
  std::optional<CholmodSolver::BlasThreadCap> elsewhere(std::in_place, 3);
  std::vector<int> capDuring;
  o.progress = [&](const MapProgress&) { capDuring.push_back(CholmodSolver::blasThreadCap()); };
  const MapRunSummary r = runMap(cc, plan, o);
  EXPECT_EQ(capDuring, std::vector<int>(4, 1));
  EXPECT_EQ(CholmodSolver::blasThreadCap(), 3);
  elsewhere.reset();
  EXPECT_EQ(CholmodSolver::blasThreadCap(), 0);
  EXPECT_TRUE(r.complete);
  EXPECT_EQ(r.done, 4);
  EXPECT_EQ(r.failed, 0);
  ASSERT_EQ(r.written.size(), 3u);  // the table, its JSON and the surface
  const auto results = readResults(o.outDir, plan);
  // The same computation as the map's worker, which runs on one thread, in its OpenMP regions and
  // in BLAS: on two the sums come in another order, and a solve may take another path to an
  // equilibrium within its tolerance (forces 5e-7 apart; 2e-6 with BLAS on two threads).
  const OmpThreadsScope oneThread(1);  // for the rest of this test
  const CholmodSolver::BlasThreadCap oneBlasThread(1);
  for (int t : {0, 3}) {
    Experiment e(cc, plan.taskSettings(t));
    const ExperimentResult x = e.run();
    ASSERT_TRUE(x.complete);
    const TaskResult& m = results[t];
    EXPECT_EQ(m.status, "converged");
    EXPECT_NEAR(m.force, x.curve[3].force, 1e-9 * std::abs(x.curve[3].force));
    EXPECT_NEAR(m.depth, 0.2, 1e-12);
    EXPECT_NEAR(m.secant, m.force / 0.2, 1e-9 * m.secant);
    EXPECT_NEAR(m.tangent, (x.curve[3].force - x.curve[2].force) / (x.curve[3].depth - x.curve[2].depth),
                1e-9 * std::abs(m.tangent));
    EXPECT_LT((m.contact - x.site->indentation->placement().site).norm(), 1e-9);
    // its loading curve, point for point (what the application draws for a map site)
    ASSERT_EQ(m.curve.size(), 4u);
    for (int k = 0; k <= 3; ++k) {
      EXPECT_NEAR(m.curve[k][0], x.curve[k].depth, 1e-12);
      EXPECT_NEAR(m.curve[k][1], x.curve[k].force, 1e-9 * std::abs(x.curve[3].force));
    }
    // a cell middle is a material point: the one indented is the site itself at rest
    EXPECT_LT((e.restSite() - plan.site(t).point).norm(), 1e-9);
  }
  // The sites differ: so do their forces (the map maps something). (Two neighbouring cell
  // middles can come within 0.1 % of each other; the four span 8 % here.)
  double lo = results[0].force, hi = lo;
  for (int t = 1; t < 4; ++t) {
    lo = std::min(lo, results[t].force);
    hi = std::max(hi, results[t].force);
  }
  EXPECT_GT(hi - lo, 1e-2 * hi);
  // The table: a header and a row per task, in task order, with the site's kind and label.
  std::istringstream rows(table(o.outDir));
  std::string line;
  std::getline(rows, line);
  EXPECT_EQ(line.rfind("task,site,kind,label,x_um", 0), 0u) << line;
  int n = 0;
  while (std::getline(rows, line)) {
    EXPECT_EQ(line.rfind(std::to_string(n) + "," + std::to_string(n) + ",cells," +
                             plan.sites[n].label + ",", 0),
              0u)
        << line;
    ++n;
  }
  EXPECT_EQ(n, 4);
  const std::string vtu = readTextFile(o.outDir + "/map-surface.vtu", "surface");
  for (const char* field : {"interpolated_stiffness_uN_per_um", "site_stiffness_uN_per_um",
                            "interpolated_hertz_MPa", "site_force_uN"})
    EXPECT_NE(vtu.find(field), std::string::npos) << field;
}

TEST(MapRun, WorkersShardsMergeAndResumeGiveTheSameTable) {
  const auto cc = smallMeristem();
  const MapPlan plan = smallPlan(*cc);
  MapRunOptions one;
  one.outDir = freshDir("single");
  runMap(cc, plan, one);
  const std::string reference = table(one.outDir);
  const std::string surface = readTextFile(one.outDir + "/map-surface.vtu", "surface");

  MapRunOptions two = one;
  two.outDir = freshDir("two-workers");
  two.jobs = 2;
  EXPECT_TRUE(runMap(cc, plan, two).complete);
  EXPECT_EQ(table(two.outDir), reference);

  std::vector<std::string> shards;
  for (int i = 0; i < 3; ++i) {
    MapRunOptions s = one;
    s.outDir = freshDir("shard" + std::to_string(i));
    s.shard = i;
    s.shards = 3;
    const MapRunSummary r = runMap(cc, plan, s);
    EXPECT_EQ(r.shardTasks, i == 0 ? 2 : 1);  // tasks 0, 3 | 1 | 2
    EXPECT_FALSE(r.complete);
    EXPECT_FALSE(fs::exists(s.outDir + "/map.csv"));
    shards.push_back(s.outDir);
  }
  // Two of three shards: the third's task is named missing, no table.
  const std::string merged = freshDir("merged");
  const MergeSummary partial = mergeMaps({shards[0], shards[1]}, merged, cc);
  EXPECT_EQ(partial.missing, std::vector<int>{2});
  EXPECT_FALSE(fs::exists(merged + "/map.csv"));
  // All three: the single run's table and surface, byte for byte.
  const MergeSummary full = mergeMaps(shards, merged, cc);
  EXPECT_TRUE(full.missing.empty());
  EXPECT_EQ(full.found, 4);
  EXPECT_EQ(table(merged), reference);
  EXPECT_EQ(readTextFile(merged + "/map-surface.vtu", "surface"), surface);
  EXPECT_EQ(readTextFile(merged + "/map.json", "json"), readTextFile(one.outDir + "/map.json", "json"));
  // The JSON holds the results at full precision.
  const auto j = nlohmann::json::parse(readTextFile(merged + "/map.json", "json"));
  const auto results = readResults(one.outDir, plan);
  ASSERT_EQ(j["results"].size(), 4u);
  EXPECT_EQ(j["results"][2]["force"].get<double>(), results[2].force);
  EXPECT_EQ(j["plan"], plan.toJson());

  // Resumed: a folder with task 1 done runs only the other three.
  MapRunOptions resumed = one;
  resumed.outDir = freshDir("resumed");
  fs::create_directories(resumed.outDir + "/results");
  fs::copy_file(one.outDir + "/results/task-000001.json", resumed.outDir + "/results/task-000001.json");
  fs::copy_file(one.outDir + "/plan.json", resumed.outDir + "/plan.json");
  const MapRunSummary r = runMap(cc, plan, resumed);
  EXPECT_EQ(r.skipped, 1);
  EXPECT_EQ(r.done, 3);
  EXPECT_EQ(table(resumed.outDir), reference);
  // Run again: nothing to do.
  EXPECT_EQ(runMap(cc, plan, resumed).done, 0);
}

TEST(MapRun, AnotherPlanInTheFolderIsRefusedAndACancelKeepsWhatIsDone) {
  const auto cc = smallMeristem();
  MapPlan plan = smallPlan(*cc);
  MapRunOptions o;
  o.outDir = freshDir("refused");
  std::atomic<bool> cancel{true};  // cancelled before the first task
  o.cancel = &cancel;
  const MapRunSummary r = runMap(cc, plan, o);
  EXPECT_TRUE(r.cancelled);
  EXPECT_EQ(r.done, 0);
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(fs::exists(o.outDir + "/plan.json"));
  // A cancel after the first finished task: that task is kept, the rest are not written.
  cancel = false;
  o.progress = [&](const MapProgress& p) {
    if (p.done == 1) cancel = true;
  };
  const MapRunSummary part = runMap(cc, plan, o);
  EXPECT_EQ(part.done, 1);
  EXPECT_TRUE(part.cancelled);
  int files = 0;
  for (const auto& f : fs::directory_iterator(o.outDir + "/results")) files += f.is_regular_file();
  EXPECT_EQ(files, 1);
  // The same folder for different settings: refused, naming what differs.
  plan.settings.material.youngModulus = 50;
  o.cancel = nullptr;
  try {
    runMap(cc, plan, o);
    ADD_FAILURE() << "ran another plan into the folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'settings' differs"), std::string::npos) << e.what();
  }
  MapRunOptions bad = o;
  bad.shard = 3;
  bad.shards = 3;
  EXPECT_THROW(runMap(cc, plan, bad), std::invalid_argument);
}

TEST(MapRun, ASweepRunsEveryParameterSetAndItsForceGrowsWithE) {
  const auto cc = smallMeristem();
  MapPlan plan = smallPlan(*cc);
  plan.sites.resize(1);
  plan.settings.pressure = 0;  // plasmolysed: the force is proportional to E
  plan.vary = {parseVariation("E=50,100")};
  MapRunOptions o;
  o.outDir = freshDir("sweep");
  const MapRunSummary r = runMap(cc, plan, o);
  ASSERT_TRUE(r.complete);
  ASSERT_EQ(r.written.size(), 2u);  // the table and its JSON; no surface for a sweep
  const auto results = readResults(o.outDir, plan);
  // Without turgor every energy term is linear in E: twice E, twice the force.
  EXPECT_NEAR(results[1].force / results[0].force, 2.0, 1e-6);
  const std::string t = table(o.outDir);
  EXPECT_NE(t.find("task,site,kind,label,E_MPa,x_um"), std::string::npos) << t;
  EXPECT_NE(t.find("\n1,0,cells," + plan.sites[0].label + ",100,"), std::string::npos) << t;
}
