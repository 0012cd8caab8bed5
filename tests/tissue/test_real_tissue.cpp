// A tissue from the centroids of a real stage-4 floral meristem (Refahi et al. 2021 atlas,
// ../shared/data/refahi2021_flower_stage4): closed cells, measured volumes, Delaunay adjacency,
// an indentation curve; and the centroid reader's errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "experiment/Indentation.h"
#include "io/Centroids.h"
#include "support/SharedData.h"
#include "tissue/RealTissue.h"

using namespace tp;
using testing::HasSubstr;

namespace {

std::string refahi() { return test::sharedDataFile("refahi2021_flower_stage4/cells.csv"); }

struct Built {
  CentroidTable table;
  RealTissueReport report;
  CellComplex cc;
};

const Built& refahiTissue() {
  static const Built b = [] {
    Built out;
    out.table = readCentroids(refahi(), CentroidColumns::parse("label,x,y,z,volume_um3"));
    out.cc = tissueFromCentroids(out.table, RealTissueOptions{}, &out.report);
    return out;
  }();
  return b;
}

std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST(RealTissue, EveryCellClosedAndLabelsKept) {
  TP_SKIP_WITHOUT_DATA(refahi());
  const Built& b = refahiTissue();
  ASSERT_EQ(b.table.points.size(), 1331u);
  const ValidityReport& v = b.report.validity;
  EXPECT_TRUE(v.ok()) << v.summary();
  EXPECT_EQ(v.openCells, 0);
  EXPECT_EQ(b.cc.cellCount(), 1331 - b.report.droppedBelowBase);
  EXPECT_LT(b.report.droppedBelowBase, 60);
  for (int c = 0; c < b.cc.cellCount(); ++c)
    EXPECT_EQ(b.cc.cellLabels[c], b.table.labels[b.report.keptRows[c]]);
  for (double vol : cellVolumes(b.cc, b.cc.rest)) EXPECT_GT(vol, 0);
  int clamped = 0;
  for (int i = 0; i < b.cc.vertexCount(); ++i) {
    if (b.cc.fixed[i]) {
      ++clamped;
      EXPECT_EQ(b.cc.rest(2, i), b.report.baseZ);
    }
  }
  EXPECT_GT(clamped, 20);
}

TEST(RealTissue, VolumesCorrelateWithTheMeasuredOnes) {
  TP_SKIP_WITHOUT_DATA(refahi());
  const Built& b = refahiTissue();
  const auto vol = cellVolumes(b.cc, b.cc.rest);
  std::vector<double> built, measured;
  for (int c = 0; c < b.cc.cellCount(); ++c) {
    built.push_back(vol[c]);
    measured.push_back(b.table.volumes[b.report.keptRows[c]]);
  }
  const double r = correlation(built, measured);
  double sb = 0, sm = 0;
  for (size_t i = 0; i < built.size(); ++i) sb += built[i], sm += measured[i];
  std::printf("  %d cells, %d vertices, %d triangles; volumes: built %.0f um^3 in all, measured "
              "%.0f um^3; correlation r = %.3f\n",
              b.cc.cellCount(), b.cc.vertexCount(), b.cc.triangleCount(), sb, sm, r);
  EXPECT_GT(r, 0.6);
  EXPECT_NEAR(sb / sm, 1.0, 0.35);
}

TEST(RealTissue, WallsJoinOnlyDelaunayNeighbours) {
  // The dual of the Voronoi tessellation: two cells sharing a wall of non-negligible area must be
  // neighbours in the Delaunay triangulation of the centroids.
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Vb = CGAL::Triangulation_vertex_base_with_info_3<int, K>;
  using Dt = CGAL::Delaunay_triangulation_3<K, CGAL::Triangulation_data_structure_3<Vb>>;
  TP_SKIP_WITHOUT_DATA(refahi());
  const Built& b = refahiTissue();
  std::vector<std::pair<K::Point_3, int>> pts;
  for (int c = 0; c < b.cc.cellCount(); ++c) {
    const Vec3& p = b.table.points[b.report.keptRows[c]];
    pts.emplace_back(K::Point_3(p.x(), p.y(), p.z()), c);
  }
  const Dt dt(pts.begin(), pts.end());
  std::set<std::pair<int, int>> delaunay;
  for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e)
    delaunay.insert(std::minmax(e->first->vertex(e->second)->info(),
                                e->first->vertex(e->third)->info()));
  const auto pairs = wallAdjacency(b.cc, 0.01);
  ASSERT_GT(pairs.size(), 3u * b.cc.cellCount());
  int missing = 0;
  for (const auto& pr : pairs) missing += delaunay.count(pr) ? 0 : 1;
  EXPECT_EQ(missing, 0) << missing << " of " << pairs.size() << " wall pairs";
}

TEST(RealTissue, IndentationCurveComputed) {
  TP_SKIP_WITHOUT_DATA(refahi());
  const Built& b = refahiTissue();
  auto cc = std::make_shared<CellComplex>(b.cc);
  Material mat;
  Model model(cc, mat);
  model.setUniformPressure(0.5);
  IndentationSettings s;
  s.maxDepth = 0.3;
  s.steps = 3;
  Indentation ind(model, s);
  ASSERT_TRUE(ind.prepare().converged) << ind.lastMessage();
  const auto curve = ind.run();
  ASSERT_EQ(curve.size(), 4u);
  for (size_t k = 1; k < curve.size(); ++k) {
    EXPECT_TRUE(curve[k].converged);
    EXPECT_GT(curve[k].force, curve[k - 1].force);
  }
  std::printf("  real tissue, site (%.1f, %.1f, %.1f): force %.3f uN at %.2f um\n",
              ind.placement().site.x(), ind.placement().site.y(), ind.placement().site.z(),
              curve.back().force, curve.back().depth);
}

TEST(Centroids, ColumnsByNameOrPositionAndTabs) {
  const auto csv = writeTemp("c1.csv", "\"id\",\"x\",\"y\",\"z\"\n7,1,2,3\n8,4,5,6\n9,7,8,9\n10,1,1,1\n");
  CentroidTable t = readCentroids(csv, CentroidColumns::parse("id,x,y,z"));
  EXPECT_EQ(t.labels, (std::vector<int>{7, 8, 9, 10}));
  EXPECT_EQ(t.points[1], Vec3(4, 5, 6));
  const auto tsv = writeTemp("c2.tsv", "a\tb\tc\td\n1\t0\t0\t5\n2\t1\t0\t6\n3\t0\t1\t7\n4\t1\t1\t8\n");
  t = readCentroids(tsv, CentroidColumns::parse("1,4,3,2"));
  EXPECT_EQ(t.points[0], Vec3(5, 0, 0));
  EXPECT_TRUE(t.volumes.empty());
}

TEST(Centroids, ErrorsNameFileLineAndColumn) {
  auto message = [](const std::string& path, const std::string& spec) {
    try {
      readCentroids(path, CentroidColumns::parse(spec));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const auto bad = writeTemp("bad.csv", "label,x,y,z\n1,0,0,0\n2,abc,0,0\n3,0,0,0\n4,1,1,1\n");
  EXPECT_THAT(message(bad, "label,x,y,z"), HasSubstr("bad.csv:3: x 'abc' (column 2) is not a finite number"));
  EXPECT_THAT(message(bad, "label,x,y,w"), HasSubstr("no column named 'w'"));
  EXPECT_THAT(message(bad, "label,x,y,9"), HasSubstr("column 9 for z does not exist"));
  const auto dup = writeTemp("dup.csv", "label,x,y,z\n1,0,0,0\n1,1,0,0\n3,0,0,0\n4,1,1,1\n");
  EXPECT_THAT(message(dup, "label,x,y,z"), HasSubstr("dup.csv:3: label 1 appears twice"));
  const auto same = writeTemp("same.csv", "label,x,y,z\n1,0,0,0\n2,5,0,0\n\n7,0,5,0\n9,5,0,0\n");
  EXPECT_THAT(message(same, "label,x,y,z"),
              HasSubstr("same.csv:6: cell 9 has the same centroid as cell 2 (line 3)"));
  EXPECT_THAT(message(bad, "label,x,y,99999999999"),
              HasSubstr("column 99999999999 for z does not exist (the header has 4 columns)"));
  const auto few = writeTemp("few.csv", "label,x,y,z\n1,0,0,0\n");
  EXPECT_THAT(message(few, "label,x,y,z"), HasSubstr("needs at least 4 centroids"));
  const auto nan = writeTemp("nan.csv", "label,x,y,z\n1,0,0,nan\n");
  EXPECT_THAT(message(nan, "label,x,y,z"), HasSubstr("is not a finite number"));
  // Found by fuzz_centroids: CGAL's alpha shape asserted on a centroid at 1e74 µm.
  const auto far = writeTemp("far.csv", "label,x,y,z\n1,0,0,0\n2,5,0,0\n3,0,5,0\n4,0,0,1e74\n");
  EXPECT_THAT(message(far, "label,x,y,z"),
              HasSubstr("far.csv:5: z '1e74' (column 4) is beyond ±1e6 µm"));
  EXPECT_THAT(message(testing::TempDir() + "/none.csv", "label,x,y,z"), HasSubstr("cannot open"));
  EXPECT_THROW(CentroidColumns::parse("x,y"), std::invalid_argument);
  // Found by fuzz_centroids: an empty coordinate column read the field before the row (f[-1]).
  EXPECT_THAT(message(bad, ",2,,4"),
              HasSubstr("column spec ',2,,4': y needs a column (a header name or a 1-based "
                        "position)"));
  CentroidColumns noY;
  noY.y.clear();
  try {
    readCentroids(bad, noY);
    ADD_FAILURE() << "an empty y column was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("bad.csv: no column given for y"));
  }
}

TEST(RealTissue, CoplanarCentroidsAreRefusedByName) {
  // Issue 9: CGAL's optimal-alpha search ran on a flat triangulation (undefined behaviour).
  CentroidTable t;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      t.labels.push_back(6 * i + j);
      t.points.emplace_back(5.0 * i + 0.3 * j, 5.0 * j, 0.0);
    }
  try {
    tissueFromCentroids(t, RealTissueOptions{});
    FAIL() << "coplanar centroids were accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("the centroids lie in a plane"));
  }
}
