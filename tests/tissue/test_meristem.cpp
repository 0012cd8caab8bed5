// The floral-meristem generator: valid closed cell complexes for many seeds, volumes, layers,
// reproducibility, sizes.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <set>

#include "io/Ply.h"
#include "mesh/Quality.h"
#include "mesh/Topology.h"
#include "tissue/Meristem.h"

using namespace tp;
using Mat3 = Eigen::Matrix3d;

namespace {

// Volume enclosed by the outer surface alone (outer triangles are wound outward).
double enclosedVolume(const CellComplex& cc) {
  double v = 0;
  for (int t = 0; t < cc.triangleCount(); ++t) {
    if (!cc.isOuterTriangle(t)) continue;
    const auto& tri = cc.triangles[t];
    v += cc.rest.col(tri[0]).dot(cc.rest.col(tri[1]).cross(cc.rest.col(tri[2]))) / 6.0;
  }
  return v;
}

void expectValidTissue(const CellComplex& cc, const std::string& what) {
  const ValidityReport r = checkValidity(cc);
  EXPECT_TRUE(r.ok()) << what << ": " << r.summary();
  EXPECT_EQ(r.openCells, 0) << what;
  EXPECT_EQ(r.misorientedCells, 0) << what;
  EXPECT_EQ(r.nonManifoldEdges, 0) << what;
  // Every inner wall lies between two distinct cells; no pair of cells has two walls.
  std::set<std::pair<int, int>> pairs;
  for (const Wall& w : cc.walls) {
    ASSERT_GE(w.cell, 0) << what;
    if (w.neighbor < 0) continue;
    EXPECT_NE(w.cell, w.neighbor) << what;
    EXPECT_TRUE(pairs.insert(std::minmax(w.cell, w.neighbor)).second)
        << what << ": two walls between cells " << w.cell << " and " << w.neighbor;
  }
  // Each inner-wall triangle bounds exactly its two cells: over all cells every such triangle is
  // counted twice, every outer one once.
  std::vector<int> uses(cc.triangleCount(), 0);
  for (int t = 0; t < cc.triangleCount(); ++t) {
    const Wall& w = cc.walls[cc.triangleWall[t]];
    uses[t] = (w.cell >= 0) + (w.neighbor >= 0);
    EXPECT_EQ(uses[t], cc.isOuterTriangle(t) ? 1 : 2);
  }
  // Volumes: positive, and they add up to the volume the outer surface encloses.
  const auto vol = cellVolumes(cc, cc.rest);
  double sum = 0;
  for (double v : vol) {
    EXPECT_GT(v, 0) << what;
    sum += v;
  }
  EXPECT_NEAR(sum / enclosedVolume(cc), 1.0, 1e-10) << what;
  // The clamped vertices are exactly those of the base plane z = 0.
  for (int v = 0; v < cc.vertexCount(); ++v)
    EXPECT_EQ(cc.fixed[v] != 0, cc.rest(2, v) == 0.0) << what << ": vertex " << v;
}

}  // namespace

TEST(Meristem, DefaultParametersGiveTheStudysTissue) {
  MeristemParams p;
  MeristemReport rep;
  const CellComplex cc = generateMeristem(p, &rep);
  expectValidTissue(cc, "default meristem");
  const MeshQuality q = measureQuality(cc);
  std::printf("  default meristem: %d cells (L1 %d, L2 %d, inner %d), %d vertices, %d triangles, "
              "min angle %.2f deg, %d walls, generated in %.2f s\n",
              q.cells, rep.l1Cells, rep.l2Cells, rep.innerCells, q.vertices, q.triangles,
              q.minAngleDeg, q.walls, rep.seconds);
  EXPECT_NEAR(q.cells, 500, 15);
  EXPECT_GT(q.vertices, 2000);
  EXPECT_LT(q.vertices, 3500);
  EXPECT_GT(q.triangles, 8000);
  EXPECT_LT(q.triangles, 13000);
  EXPECT_GT(q.minAngleDeg, 1.0);
  // 80 µm across; the enclosed volume is the dome's up to the flat facets of the outer walls.
  EXPECT_NEAR(q.bboxMax.x() - q.bboxMin.x(), 80.0, 0.5);
  EXPECT_NEAR(q.volume / p.shape.volume(), 1.0, 0.03);
  // Cells 5–10 µm: the median equivalent diameter.
  std::vector<double> d;
  for (double v : cellVolumes(cc, cc.rest)) d.push_back(std::cbrt(6 * v / std::numbers::pi));
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  EXPECT_GT(d[d.size() / 2], 5.0);
  EXPECT_LT(d[d.size() / 2], 10.0);
}

TEST(Meristem, ValidForManySeeds) {
  for (std::uint32_t seed = 1; seed <= 16; ++seed) {
    MeristemParams p;
    p.seed = seed;
    p.cells = 150 + 25 * (seed % 5);
    p.shape.radius = 25 + seed % 3 * 5;
    p.shape.capHeight = 20 + seed % 4 * 3;
    MeristemReport rep;
    const CellComplex cc = generateMeristem(p, &rep);
    expectValidTissue(cc, "seed " + std::to_string(seed));
    EXPECT_NEAR(cc.cellCount(), p.cells, 0.05 * p.cells) << "seed " << seed;
  }
}

TEST(Meristem, SameSeedSameTissueOtherSeedOtherTissue) {
  MeristemParams p;
  p.cells = 120;
  p.shape.radius = 20;
  p.shape.capHeight = 18;
  const CellComplex a = generateMeristem(p);
  const CellComplex b = generateMeristem(p);
  ASSERT_EQ(a.vertexCount(), b.vertexCount());
  ASSERT_EQ(a.triangleCount(), b.triangleCount());
  EXPECT_EQ((a.rest - b.rest).cwiseAbs().maxCoeff(), 0.0);
  for (int t = 0; t < a.triangleCount(); ++t) EXPECT_EQ(a.triangles[t], b.triangles[t]);
  p.seed = 2;
  const CellComplex c = generateMeristem(p);
  EXPECT_TRUE(c.vertexCount() != a.vertexCount() ||
              (c.rest - a.rest).cwiseAbs().maxCoeff() > 1e-3);
}

TEST(Meristem, EpidermalCellsAreFlatterAndLieAlongTheSurface) {
  MeristemParams p;
  const CellComplex cc = generateMeristem(p);
  // Surface cells: those with an outer wall on the dome (not only on the base).
  std::vector<char> surface(cc.cellCount(), 0);
  std::vector<Vec3> outward(cc.cellCount(), Vec3::Zero());
  for (int t = 0; t < cc.triangleCount(); ++t) {
    const Wall& w = cc.walls[cc.triangleWall[t]];
    if (w.neighbor >= 0) continue;
    const auto& tri = cc.triangles[t];
    const Vec3 n = (cc.rest.col(tri[1]) - cc.rest.col(tri[0])).cross(cc.rest.col(tri[2]) - cc.rest.col(tri[0]));
    if (n.normalized().z() < -0.99) continue;  // base
    surface[w.cell] = 1;
    outward[w.cell] += n;
  }
  // Shape of each cell from the covariance of its vertices.
  std::vector<std::set<int>> verts(cc.cellCount());
  for (int t = 0; t < cc.triangleCount(); ++t) {
    const Wall& w = cc.walls[cc.triangleWall[t]];
    for (int c : {w.cell, w.neighbor})
      if (c >= 0)
        for (int k = 0; k < 3; ++k) verts[c].insert(cc.triangles[t][k]);
  }
  double aspectSurface = 0, aspectInner = 0, align = 0;
  int nSurface = 0, nInner = 0;
  bool anyBase = false;
  for (int c = 0; c < cc.cellCount(); ++c) {
    Vec3 mean = Vec3::Zero();
    for (int v : verts[c]) mean += cc.rest.col(v);
    mean /= static_cast<double>(verts[c].size());
    Mat3 cov = Mat3::Zero();
    for (int v : verts[c]) cov += (cc.rest.col(v) - mean) * (cc.rest.col(v) - mean).transpose();
    Eigen::SelfAdjointEigenSolver<Mat3> es(cov);
    const double aspect = std::sqrt(es.eigenvalues()(2) / es.eigenvalues()(0));
    for (int v : verts[c]) anyBase = anyBase || cc.fixed[v];
    if (surface[c]) {
      aspectSurface += aspect;
      align += std::abs(es.eigenvectors().col(0).dot(outward[c].normalized()));
      ++nSurface;
    } else {
      aspectInner += aspect;
      ++nInner;
    }
  }
  aspectSurface /= nSurface;
  aspectInner /= nInner;
  align /= nSurface;
  std::printf("  L1 cells: %d, mean aspect %.2f, thin axis along the surface normal |cos| = %.2f; "
              "inner cells: %d, mean aspect %.2f\n",
              nSurface, aspectSurface, align, nInner, aspectInner);
  EXPECT_GT(aspectSurface, 1.25 * aspectInner);  // flatter
  EXPECT_GT(align, 0.8);                         // flattened across the surface
  EXPECT_TRUE(anyBase);
}

TEST(Meristem, SurvivesAPlyRoundTrip) {
  MeristemParams p;
  p.cells = 100;
  p.shape.radius = 20;
  const CellComplex cc = generateMeristem(p);
  const std::string path = testing::TempDir() + "/meristem_roundtrip.ply";
  writePly(path, cc, nullptr, true);
  const CellComplex back = readPly(path);
  expectValidTissue(back, "read back");
  EXPECT_EQ(back.cellLabels, cc.cellLabels);
  EXPECT_EQ(back.wallCount(), cc.wallCount());
  EXPECT_EQ(back.triangleCount(), cc.triangleCount());
}

TEST(Meristem, RejectsImpossibleParameters) {
  MeristemParams p;
  p.cells = 3;
  EXPECT_THROW(generateMeristem(p), std::invalid_argument);
  p = MeristemParams{};
  p.shape.radius = 5;
  p.shape.capHeight = 5;
  EXPECT_THROW(generateMeristem(p), std::invalid_argument);  // L1 + L2 thicker than the dome
}
