// Reading the real PLY files of /work/shared/data (facts from each folder's NOTES.md).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "io/IoTestUtil.h"
#include "io/Ply.h"

namespace tp {
namespace {

using test::messageOf;
using ::testing::AllOf;
using ::testing::Contains;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

std::string dataFile(const std::string& relative) {
  return (test::sharedDataDir() / relative).string();
}

#define SKIP_IF_MISSING(path) \
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "data file not found: " << (path)

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
  SKIP_IF_MISSING(path);
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
  SKIP_IF_MISSING(path);
  EXPECT_THAT(messageOf<PlyError>([&] { readPly(path); }),
              AllOf(HasSubstr(path), HasSubstr("no faces"), HasSubstr("vertex, edge")));
}

TEST(PlyData, OpenAleaTopomeshSurfaces) {
  struct Case {
    const char* file;
    int vertices, triangles;
    Vec3 lo, hi;
    double area;
  };
  const Case cases[] = {
      {"cellcomplex_p194_L1_surface/p194-t4_L1_topomesh.ply", 2148, 4162, Vec3(8.4, 5.1, 5.9),
       Vec3(109.7, 111.2, 69.4), 16994},
      {"cellcomplex_p194_L1_surface/p194-t5_imgSeg_SegExp_CellShapeCorr_L1_topomesh.ply", 3451,
       6708, Vec3(6.5, 5.5, 5.4), Vec3(135.9, 134.1, 87.8), 26705},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    const std::string path = dataFile(c.file);
    SKIP_IF_MISSING(path);
    PlyInfo info;
    const CellComplex cc = readPly(path, &info);
    EXPECT_EQ(cc.vertexCount(), c.vertices);
    EXPECT_EQ(cc.triangleCount(), c.triangles);
    EXPECT_THAT(info.ignoredElements, ElementsAre("edge", "volume"));
    EXPECT_THAT(info.ignoredProperties, Contains("face.epidermis"));
    EXPECT_FALSE(info.hadCellLabels);
    EXPECT_EQ(cc.cellCount(), 0);  // an open surface without labels: a sheet
    ASSERT_EQ(cc.wallCount(), 1);
    EXPECT_EQ(cc.walls[0].cell, -1);
    expectBox(cc, c.lo, c.hi, 0.06);
    EXPECT_NEAR(totalArea(cc), c.area, 1.0);
  }
}

}  // namespace
}  // namespace tp
