// Reading the real PLY files of /work/shared/data (facts from each folder's NOTES.md).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "io/IoTestUtil.h"
#include "io/Ply.h"

namespace tp {
namespace {

using test::messageOf;
using ::testing::AllOf;
using ::testing::Contains;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

std::string dataFile(const std::string& relative) { return test::sharedDataFile(relative); }

void expectBox(const CellComplex& cc, const Vec3& lo, const Vec3& hi, double tol) {
  const Vec3 mn = cc.rest.rowwise().minCoeff(), mx = cc.rest.rowwise().maxCoeff();
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(mn[k], lo[k], tol) << "axis " << k;
    EXPECT_NEAR(mx[k], hi[k], tol) << "axis " << k;
  }
}

double totalArea(const CellComplex& cc) {
  double a = 0;
  for (double t : triangleAreas(cc, cc.rest)) a += t;
  return a;
}

TEST(PlyData, MorphoGraphXMeshFaceLabelsAreCells) {
  const std::string path = dataFile("mgx2r_meristem_morphographx/mesh_meristem_full_T0.ply");
  TP_SKIP_WITHOUT_DATA(path);
  PlyInfo info;
  const CellComplex cc = readPly(path, &info);
  EXPECT_EQ(info.format, "ascii");
  EXPECT_EQ(cc.vertexCount(), 4158);
  EXPECT_EQ(cc.triangleCount(), 7763);
  EXPECT_EQ(info.cellProperty, "label");
  EXPECT_EQ(cc.cellCount(), 376);
  EXPECT_EQ(cc.wallCount(), 376);  // each cell's patch of the surface is one wall
  for (const Wall& w : cc.walls) EXPECT_EQ(w.neighbor, -1);
  EXPECT_THAT(info.ignoredProperties, Contains("vertex.signal"));
  EXPECT_THAT(info.ignoredProperties, Contains("vertex.cellNr"));
  expectBox(cc, Vec3(-58.6, -45.5, -17.4), Vec3(57.9, 56.3, 13.4), 0.06);
  // A surface only: every cell is an open patch, which the checker reports.
  const ValidityReport report = checkValidity(cc);
  EXPECT_FALSE(report.ok());
  EXPECT_EQ(report.openCells, 376);
  EXPECT_EQ(report.misorientedCells, 0);
}

TEST(PlyData, MorphoGraphXCellGraphHasNoFaces) {
  const std::string path = dataFile("mgx2r_meristem_morphographx/cellGraph_meristem_full_T0.ply");
  TP_SKIP_WITHOUT_DATA(path);
  EXPECT_THAT(messageOf<PlyError>([&] { readPly(path); }),
              AllOf(HasSubstr(path), HasSubstr("no faces"), HasSubstr("vertex, edge")));
}

TEST(PlyData, OpenAleaTopomeshSurfaces) {
  struct Case {
    const char* file;
    const char* table;
    int vertices, triangles, cells;
    Vec3 lo, hi;
    double area;
  };
  const Case cases[] = {
      {"cellcomplex_p194_L1_surface/p194-t4_L1_topomesh.ply",
       "cellcomplex_p194_L1_surface/p194-t4_L1_topomesh_cell_surface_centroids.csv", 2148, 4162,
       491, Vec3(8.4, 5.1, 5.9), Vec3(109.7, 111.2, 69.4), 16994},
      {"cellcomplex_p194_L1_surface/p194-t5_imgSeg_SegExp_CellShapeCorr_L1_topomesh.ply",
       "cellcomplex_p194_L1_surface/"
       "p194-t5_imgSeg_SegExp_CellShapeCorr_L1_topomesh_cell_surface_centroids.csv",
       3451, 6708, 728, Vec3(6.5, 5.5, 5.4), Vec3(135.9, 134.1, 87.8), 26705},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    const std::string path = dataFile(c.file);
    TP_SKIP_WITHOUT_DATA(path);
    PlyInfo info;
    const CellComplex cc = readPly(path, &info);
    EXPECT_EQ(cc.vertexCount(), c.vertices);
    EXPECT_EQ(cc.triangleCount(), c.triangles);
    EXPECT_THAT(info.ignoredElements, ElementsAre("edge"));
    EXPECT_THAT(info.ignoredProperties, Contains("face.epidermis"));
    // The cells come from the `volume` element: 25 of them list no face (NOTES.md).
    EXPECT_TRUE(info.hadCellLabels);
    EXPECT_EQ(info.cellProperty, "volume.label");
    EXPECT_THAT(info.notes, Contains(HasSubstr("25 volume(s) with no faces")));
    EXPECT_EQ(cc.cellCount(), c.cells);
    expectBox(cc, c.lo, c.hi, 0.06);
    EXPECT_NEAR(totalArea(cc), c.area, 1.0);
    // Each label has the triangles the derived table counts (from the same file, by another
    // reader): label,x,y,z,outer_area_um2,n_triangles.
    std::map<int, int> triangles;
    for (int t = 0; t < cc.triangleCount(); ++t) {
      const Wall& w = cc.walls[cc.triangleWall[t]];
      EXPECT_EQ(w.neighbor, -1);  // the L1 surface only: no wall between two cells
      ++triangles[cc.cellLabels[w.cell]];
    }
    std::ifstream table(dataFile(c.table));
    ASSERT_TRUE(table.good()) << c.table;
    std::string line;
    const auto next = [&] {  // the table has CRLF line ends
      if (!std::getline(table, line)) return false;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      return true;
    };
    ASSERT_TRUE(next());
    ASSERT_EQ(line, "label,x,y,z,outer_area_um2,n_triangles");
    int rows = 0;
    while (next()) {
      std::vector<std::string> v;
      std::stringstream fields(line);
      for (std::string f; std::getline(fields, f, ',');) v.push_back(f);
      ASSERT_EQ(v.size(), 6u) << line;
      EXPECT_EQ(triangles[std::stoi(v[0])], std::stoi(v[5])) << "label " << v[0];
      ++rows;
    }
    EXPECT_EQ(rows, c.cells);
    // An open surface: every cell is an open patch, which the checker reports.
    EXPECT_EQ(checkValidity(cc).openCells, c.cells);
  }
}

}  // namespace
}  // namespace tp
