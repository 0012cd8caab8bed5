// Stiffness maps (issue 14) show what the published study found on the meristem (and what AFM
// maps report, Milani et al. 2011): with turgor the walls are stiffer next to anticlinal walls
// than in the middle of a cell, and the sites differ far less from one another than without
// turgor, where the cell middles are soft plates and the junctions carry the load. Here: a map of
// the shipped default meristem at the three cells at its top (their middles and the three
// junctions between them), turgid (0.8 MPa) and plasmolysed (0), at mesh level 2 with the error
// of each site estimated from level 3 (up to ~30 % at a turgid junction, a few % elsewhere);
// every comparison takes each value at the end of its error bar that works against it.
// Slow (about a minute and a half on two cores): ctest label "slow".
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>

#include "experiment/Map.h"
#include "io/Paths.h"
#include "io/Ply.h"

using namespace tp;

namespace {

// The cell numbers of a site's label: "cell 105" → {105}; "cells 59|105" → {59, 105}.
std::set<int> cellsOf(const std::string& label) {
  std::set<int> cells;
  std::string digits;
  for (char c : label + " ") {
    if (std::isdigit(static_cast<unsigned char>(c))) {
      digits += c;
    } else if (!digits.empty()) {
      cells.insert(std::stoi(digits));
      digits.clear();
    }
  }
  return cells;
}

struct Population {
  std::vector<double> stiffness, error;  // secant µN/µm and its relative mesh error
  // The mean with every value at the low (−1) or high (+1) end of its error bar.
  double mean(int end = 0) const {
    double sum = 0;
    for (size_t k = 0; k < stiffness.size(); ++k) sum += stiffness[k] * (1 + end * error[k]);
    return sum / stiffness.size();
  }
  double lowest(int end = 0) const {
    double m = 1e300;
    for (size_t k = 0; k < stiffness.size(); ++k) m = std::min(m, stiffness[k] * (1 + end * error[k]));
    return m;
  }
  double highest(int end = 0) const {
    double m = -1e300;
    for (size_t k = 0; k < stiffness.size(); ++k) m = std::max(m, stiffness[k] * (1 + end * error[k]));
    return m;
  }
};

// The spread between the sites of both populations, highest over lowest stiffness: at most
// (widest = +1: the highest value at its upper end, the lowest at its lower end) or at least.
double spread(const Population& a, const Population& b, int widest) {
  return std::max(a.highest(widest), b.highest(widest)) /
         std::min(a.lowest(-widest), b.lowest(-widest));
}

}  // namespace

TEST(MapPopulations, TurgorStiffensNextToAnticlinalWallsAndNarrowsTheSpread) {
  const auto cc = std::make_shared<const CellComplex>(readPly(defaultTissuePath()));
  // The three cells whose wall middles are highest, and the junctions between them.
  std::vector<MapSite> middles = cellMiddleSites(*cc);
  std::sort(middles.begin(), middles.end(),
            [](const MapSite& a, const MapSite& b) { return a.point.z() > b.point.z(); });
  middles.resize(3);
  std::set<int> top;
  for (const auto& m : middles) top.insert(*cellsOf(m.label).begin());
  std::vector<MapSite> junctions;
  for (const auto& j : junctionSites(*cc)) {
    const std::set<int> pair = cellsOf(j.label);
    if (std::includes(top.begin(), top.end(), pair.begin(), pair.end())) junctions.push_back(j);
  }
  ASSERT_EQ(junctions.size(), 3u) << "the three top cells meet pairwise";

  MapPlan plan;
  plan.settings = mapSettings(plan.settings);  // a map's mesh, made for forces
  plan.tissue = defaultTissuePath();
  plan.tissueDigest = tissueDigest(*cc);
  plan.settings.mesh.automatic = false;
  plan.settings.mesh.level = 2;
  plan.settings.mesh.estimateError = true;
  plan.settings.indentation.maxDepth = 0.5;
  plan.settings.indentation.steps = 5;
  plan.sites = middles;
  plan.sites.insert(plan.sites.end(), junctions.begin(), junctions.end());
  plan.vary.push_back({"p", {0.8, 0.0}});  // turgid, then plasmolysed

  MapRunOptions options;
  options.outDir = testing::TempDir() + "/map_populations";
  std::filesystem::remove_all(options.outDir);
  options.jobs = 2;
  const MapRunSummary run = runMap(cc, plan, options);
  ASSERT_TRUE(run.complete);
  const std::vector<TaskResult> results = readResults(options.outDir, plan);

  Population middle[2], junction[2];  // [0] turgid, [1] plasmolysed
  for (const TaskResult& r : results) {
    ASSERT_TRUE(r.converged()) << plan.site(r.task).label << ": " << r.message;
    ASSERT_GE(r.meshError, 0.0) << "the mesh error is estimated";
    const int state = r.task / static_cast<int>(plan.sites.size());
    Population& p = plan.site(r.task).kind == SiteKind::Junction ? junction[state] : middle[state];
    p.stiffness.push_back(r.secant);
    p.error.push_back(r.meshError);
  }
  for (int s = 0; s < 2; ++s) {
    std::printf("%s: middles", s ? "plasmolysed" : "turgid");
    for (size_t k = 0; k < 3; ++k)
      std::printf(" %.3f±%.0f%%", middle[s].stiffness[k], 100 * middle[s].error[k]);
    std::printf(" | junctions");
    for (size_t k = 0; k < 3; ++k)
      std::printf(" %.3f±%.0f%%", junction[s].stiffness[k], 100 * junction[s].error[k]);
    std::printf(" µN/µm; highest/lowest %.2f (%.2f to %.2f)\n", spread(middle[s], junction[s], 0),
                spread(middle[s], junction[s], -1), spread(middle[s], junction[s], 1));
  }
  // With turgor, every junction is stiffer than every cell middle, beyond their mesh errors.
  for (size_t j = 0; j < 3; ++j)
    for (size_t m = 0; m < 3; ++m)
      EXPECT_GT(junction[0].stiffness[j] * (1 - junction[0].error[j]),
                middle[0].stiffness[m] * (1 + middle[0].error[m]))
          << "junction " << j << " against middle " << m;
  EXPECT_GT(junction[0].mean(-1) / middle[0].mean(+1), 1.2);
  // Without turgor the junctions hold the probe and the middles give way: the two populations
  // are far apart, and turgor narrows the spread between sites (at its widest with turgor, at
  // its narrowest without, still less than half).
  EXPECT_GT(junction[1].mean(-1) / middle[1].mean(+1), 2.0 * junction[0].mean(+1) / middle[0].mean(-1));
  EXPECT_LT(spread(middle[0], junction[0], +1), 0.5 * spread(middle[1], junction[1], -1));
  // And turgor stiffens every site (the pressurised walls are pre-stressed).
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_GT(middle[0].stiffness[k] * (1 - middle[0].error[k]),
              5 * middle[1].stiffness[k] * (1 + middle[1].error[k]));
    EXPECT_GT(junction[0].stiffness[k] * (1 - junction[0].error[k]),
              2 * junction[1].stiffness[k] * (1 + junction[1].error[k]));
  }
}
