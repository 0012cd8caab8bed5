// PLY reading and writing: round trips, the ways faces become cells and walls, and malformed files.

#include "io/Ply.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>

#include "io/IoTestUtil.h"
#include "mesh/Quality.h"
#include "tissue/Shapes.h"

namespace tp {
namespace {

using test::messageOf;
using test::TempDir;
using ::testing::AllOf;
using ::testing::Contains;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

CellComplex readString(const std::string& text, PlyInfo* info = nullptr,
                       const std::string& name = "test.ply") {
  std::istringstream in(text);
  return readPly(in, name, info);
}

// Sorted copy, for comparing lists whose order does not matter (UnorderedElementsAre would need
// libgmock, which the test executables do not link).
std::vector<std::string> sorted(std::vector<std::string> v) {
  std::sort(v.begin(), v.end());
  return v;
}

std::string plyError(const std::string& text) {
  return messageOf<PlyError>([&] { readString(text, nullptr, "bad.ply"); });
}

std::string plyText(const CellComplex& cc, bool binary, const Points* x = nullptr) {
  std::ostringstream out;
  writePly(out, cc, x, binary);
  return out.str();
}

// Same vertices, flags, triangles, walls and labels (wall and cell indices compared directly:
// the shapes used here have ascending labels and walls in triangle order).
void expectSameComplex(const CellComplex& a, const CellComplex& b) {
  ASSERT_EQ(a.vertexCount(), b.vertexCount());
  for (int v = 0; v < a.vertexCount(); ++v)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(a.rest(k, v)),
                std::bit_cast<std::uint64_t>(b.rest(k, v)))
          << "vertex " << v << " coordinate " << k;
  EXPECT_EQ(a.fixed, b.fixed);
  ASSERT_EQ(a.triangleCount(), b.triangleCount());
  for (int t = 0; t < a.triangleCount(); ++t) EXPECT_EQ(a.triangles[t], b.triangles[t]);
  EXPECT_EQ(a.triangleWall, b.triangleWall);
  ASSERT_EQ(a.wallCount(), b.wallCount());
  for (int w = 0; w < a.wallCount(); ++w) {
    EXPECT_EQ(a.walls[w].cell, b.walls[w].cell) << "wall " << w;
    EXPECT_EQ(a.walls[w].neighbor, b.walls[w].neighbor) << "wall " << w;
  }
  EXPECT_EQ(a.cellLabels, b.cellLabels);
}

// Indices in range everywhere: what a reader must guarantee even for a strange file.
void expectStructurallySound(const CellComplex& cc) {
  ASSERT_EQ(static_cast<int>(cc.fixed.size()), cc.vertexCount());
  ASSERT_EQ(cc.triangleWall.size(), cc.triangles.size());
  for (int t = 0; t < cc.triangleCount(); ++t) {
    ASSERT_GE(cc.triangleWall[t], 0);
    ASSERT_LT(cc.triangleWall[t], cc.wallCount());
    for (int k = 0; k < 3; ++k) {
      ASSERT_GE(cc.triangles[t][k], 0);
      ASSERT_LT(cc.triangles[t][k], cc.vertexCount());
    }
  }
  for (const Wall& w : cc.walls) {
    ASSERT_GE(w.cell, -1);
    ASSERT_LT(w.cell, cc.cellCount());
    ASSERT_GE(w.neighbor, -1);
    ASSERT_LT(w.neighbor, cc.cellCount());
  }
}

std::string header(int vertices, int faces, const std::string& faceProperties) {
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
         std::to_string(faces) + "\nproperty list uchar int vertex_indices\n" + faceProperties +
         "end_header\n";
}

// The unit cube [0,1]^3: vertex i at its binary digits, faces wound outward.
const char* kCubeVertices = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n";
const char* kCubeQuads = "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 0 4 7 3\n4 1 2 6 5\n";

// ---------------------------------------------------------------------------------------------
// Round trips

TEST(PlyRoundTrip, BoxTissueAsciiAndBinary) {
  const CellComplex box = boxTissue(2, 2, 2, 1.0);
  ASSERT_TRUE(checkValidity(box).ok());
  TempDir dir;
  for (bool binary : {false, true}) {
    SCOPED_TRACE(binary ? "binary" : "ascii");
    const std::string path = dir.file(binary ? "box_bin.ply" : "box.ply");
    writePly(path, box, nullptr, binary);
    PlyInfo info;
    const CellComplex back = readPly(path, &info);
    EXPECT_EQ(info.format, binary ? "binary_little_endian" : "ascii");
    EXPECT_TRUE(info.hadCellLabels);
    EXPECT_TRUE(info.ignoredElements.empty());
    EXPECT_TRUE(info.ignoredProperties.empty());
    expectSameComplex(box, back);
    EXPECT_TRUE(checkValidity(back).ok()) << checkValidity(back).summary();
  }
}

TEST(PlyRoundTrip, SphereAtDeformedPositionsKeepsEveryBit) {
  const CellComplex sphere = octaSphere(3.0, 2);
  Points x = sphere.rest;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> noise(-0.1, 0.1);
  for (int v = 0; v < x.cols(); ++v)
    for (int k = 0; k < 3; ++k) x(k, v) = x(k, v) * (1.0 / 3.0) + noise(rng);
  x(1, 0) = -0.0;  // vertex 0 lies on the x axis
  x(2, 0) = 1e-300;
  x(0, 1) = 0.1 + 1e-16;
  CellComplex expected = sphere;
  expected.rest = x;
  for (bool binary : {false, true}) {
    SCOPED_TRACE(binary ? "binary" : "ascii");
    const CellComplex back = readString(plyText(sphere, binary, &x));
    expectSameComplex(expected, back);
    EXPECT_TRUE(checkValidity(back).ok()) << checkValidity(back).summary();
  }
}

TEST(PlyRoundTrip, SheetWithClampedRimStaysASheet) {
  const CellComplex disc = latticeDisc(2.0, 3);
  const CellComplex back = readString(plyText(disc, false));
  expectSameComplex(disc, back);
  EXPECT_EQ(back.cellCount(), 0);
  EXPECT_EQ(back.walls[0].cell, -1);
}

TEST(PlyWrite, RefusesInconsistentComplexBeforeTouchingTheFile) {
  TempDir dir;
  CellComplex box = boxTissue(1, 1, 1, 1.0);
  box.cellLabels = {-4};
  EXPECT_THAT(messageOf<std::invalid_argument>([&] { writePly(dir.file("a.ply"), box); }),
              HasSubstr("negative"));
  box = boxTissue(2, 1, 1, 1.0);
  box.cellLabels = {3, 3};
  EXPECT_THAT(messageOf<std::invalid_argument>([&] { writePly(dir.file("a.ply"), box); }),
              HasSubstr("used twice"));
  box = boxTissue(1, 1, 1, 1.0);
  Points x = box.rest;
  x(1, 2) = std::nan("");
  EXPECT_THAT(messageOf<std::invalid_argument>([&] { writePly(dir.file("a.ply"), box, &x); }),
              HasSubstr("vertex 2"));
  Points small(3, 2);
  small.setZero();
  EXPECT_THROW(writePly(dir.file("a.ply"), box, &small), std::invalid_argument);
  EXPECT_TRUE(dir.entries().empty());
}

// Binary files in both byte orders give the same tissue as the ASCII one.
template <class T>
void putBytes(std::string& buf, T v, bool bigEndian) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (bigEndian != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
  buf.append(b, sizeof(T));
}

std::string binaryTetra(bool bigEndian) {
  std::string s = std::string("ply\nformat ") +
                  (bigEndian ? "binary_big_endian" : "binary_little_endian") +
                  " 1.0\nelement vertex 4\nproperty float32 x\nproperty float32 y\n"
                  "property float32 z\nproperty int16 weight\nproperty uint8 fixed\n"
                  "element face 4\nproperty list uint8 uint32 vertex_indices\n"
                  "property int cell\nproperty list int16 double extra\nend_header\n";
  const float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int v = 0; v < 4; ++v) {
    for (float c : p[v]) putBytes(s, c, bigEndian);
    putBytes<std::int16_t>(s, static_cast<std::int16_t>(-v), bigEndian);
    putBytes<std::uint8_t>(s, v == 0 ? 1 : 0, bigEndian);
  }
  const std::uint32_t f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (int i = 0; i < 4; ++i) {
    putBytes<std::uint8_t>(s, 3, bigEndian);
    for (std::uint32_t v : f[i]) putBytes(s, v, bigEndian);
    putBytes<std::int32_t>(s, 42, bigEndian);
    putBytes<std::int16_t>(s, static_cast<std::int16_t>(i), bigEndian);  // i doubles to skip
    for (int k = 0; k < i; ++k) putBytes<double>(s, k * 0.5, bigEndian);
  }
  return s;
}

TEST(PlyRead, BinaryBothByteOrdersAndAscii) {
  const std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar fixed\nelement face 4\n"
      "property list uchar int vertex_indices\nproperty int cell\nend_header\n"
      "0 0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n"
      "3 0 2 1 42\n3 0 1 3 42\n3 0 3 2 42\n3 1 2 3 42\n";
  const CellComplex ref = readString(ascii);
  EXPECT_EQ(ref.cellLabels, std::vector<int>{42});
  EXPECT_NEAR(cellVolumes(ref, ref.rest)[0], 1.0 / 6.0, 1e-15);
  for (bool big : {false, true}) {
    SCOPED_TRACE(big ? "big endian" : "little endian");
    PlyInfo info;
    const CellComplex cc = readString(binaryTetra(big), &info);
    EXPECT_EQ(info.format, big ? "binary_big_endian" : "binary_little_endian");
    EXPECT_THAT(sorted(info.ignoredProperties), ElementsAre("face.extra", "vertex.weight"));
    expectSameComplex(ref, cc);
    EXPECT_TRUE(checkValidity(cc).ok());
  }
}

// ---------------------------------------------------------------------------------------------
// Faces to cells and walls

TEST(PlyRead, CubeOfQuadsWithoutLabelsIsOneClosedCell) {
  PlyInfo info;
  const CellComplex cc = readString(header(8, 6, "") + kCubeVertices + kCubeQuads, &info);
  EXPECT_FALSE(info.hadCellLabels);
  EXPECT_EQ(cc.cellLabels, std::vector<int>{0});
  EXPECT_EQ(cc.wallCount(), 6);  // one wall per polygon
  EXPECT_EQ(cc.triangleCount(), 12);
  for (const Wall& w : cc.walls) {
    EXPECT_EQ(w.polygon.size(), 4u);
    EXPECT_EQ(w.cell, 0);
    EXPECT_EQ(w.neighbor, -1);
  }
  EXPECT_NEAR(cellVolumes(cc, cc.rest)[0], 1.0, 1e-14);
  EXPECT_TRUE(checkValidity(cc).ok()) << checkValidity(cc).summary();
}

TEST(PlyRead, InwardWoundClosedSurfaceIsTurnedOutward) {
  const std::string inward = "4 1 2 3 0\n4 7 6 5 4\n4 4 5 1 0\n4 6 7 3 2\n4 3 7 4 0\n4 5 6 2 1\n";
  PlyInfo info;
  const CellComplex cc = readString(header(8, 6, "") + kCubeVertices + inward, &info);
  EXPECT_NEAR(cellVolumes(cc, cc.rest)[0], 1.0, 1e-14);
  EXPECT_TRUE(checkValidity(cc).ok());
  EXPECT_THAT(info.notes, Contains(HasSubstr("reversed")));
}

TEST(PlyRead, OpenQuadSheetHasNoCell) {
  const std::string text =
      header(6, 2, "") + "0 0 0\n1 0 0\n2 0 0\n0 1 0\n1 1 0\n2 1 0\n" + "4 0 1 4 3\n4 1 2 5 4\n";
  const CellComplex cc = readString(text);
  EXPECT_EQ(cc.cellCount(), 0);
  EXPECT_EQ(cc.triangleCount(), 4);
  for (const Wall& w : cc.walls) EXPECT_EQ(w.cell, -1);
  EXPECT_TRUE(checkValidity(cc).ok());
  EXPECT_NEAR(triangleAreas(cc, cc.rest)[0] + triangleAreas(cc, cc.rest)[1], 1.0, 1e-14);
  // `info` never calls a sheet closed (issue 9).
  EXPECT_THAT(formatQuality(measureQuality(cc)), HasSubstr("closed           no: a sheet (no cells)"));
}

// Two unit cubes side by side, x in [0,1] (label 10) and [1,2] (label 20); vertices 8..11 at x=2.
const char* kTwoCubeVertices =
    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n2 0 0\n2 1 0\n2 0 1\n2 1 1\n";

TEST(PlyRead, SharedWallGivenFromBothSidesIsOneWall) {
  // Each cube lists its six faces wound outward; without `neighbor` the twins supply it.
  const std::string text = header(12, 12, "property int cell\n") + kTwoCubeVertices +
                           "4 0 3 2 1 10\n4 4 5 6 7 10\n4 0 1 5 4 10\n4 2 3 7 6 10\n"
                           "4 0 4 7 3 10\n4 1 2 6 5 10\n"
                           "4 1 2 9 8 20\n4 5 10 11 6 20\n4 1 8 10 5 20\n4 9 2 6 11 20\n"
                           "4 1 5 6 2 20\n4 8 9 11 10 20\n";
  PlyInfo info;
  const CellComplex cc = readString(text, &info);
  EXPECT_EQ(cc.cellLabels, (std::vector<int>{10, 20}));
  EXPECT_EQ(cc.wallCount(), 11);
  int shared = 0;
  for (const Wall& w : cc.walls)
    if (w.neighbor >= 0) {
      ++shared;
      EXPECT_EQ(w.cell, 0);
      EXPECT_EQ(w.neighbor, 1);
    }
  EXPECT_EQ(shared, 1);
  const auto vol = cellVolumes(cc, cc.rest);
  EXPECT_NEAR(vol[0], 1.0, 1e-14);
  EXPECT_NEAR(vol[1], 1.0, 1e-14);
  EXPECT_TRUE(checkValidity(cc).ok()) << checkValidity(cc).summary();
  EXPECT_THAT(info.notes, Contains(HasSubstr("merged")));
}

TEST(PlyRead, SharedWallTwiceWithNeighborMustAgree) {
  const std::string faces =
      "4 0 3 2 1 10 -1\n4 4 5 6 7 10 -1\n4 0 1 5 4 10 -1\n4 2 3 7 6 10 -1\n"
      "4 0 4 7 3 10 -1\n4 1 2 6 5 10 20\n"
      "4 1 2 9 8 20 -1\n4 5 10 11 6 20 -1\n4 1 8 10 5 20 -1\n4 9 2 6 11 20 -1\n"
      "4 1 5 6 2 20 10\n4 8 9 11 10 20 -1\n";
  const std::string head = header(12, 12, "property int cell\nproperty int neighbor\n");
  const CellComplex cc = readString(head + kTwoCubeVertices + faces);
  EXPECT_EQ(cc.wallCount(), 11);
  EXPECT_TRUE(checkValidity(cc).ok()) << checkValidity(cc).summary();

  std::string wrong = faces;
  wrong.replace(wrong.find("4 1 5 6 2 20 10"), 15, "4 1 5 6 2 20 -1");
  const std::string msg = plyError(head + kTwoCubeVertices + wrong);
  EXPECT_THAT(msg, AllOf(HasSubstr("bad.ply"), HasSubstr("face 10 (line 34)"),
                         HasSubstr("face 5 (line 29)"), HasSubstr("disagree")));
}

TEST(PlyRead, CellKnownOnlyAsNeighborBecomesACell) {
  // A tetrahedron described from outside: normals point into cell 3, which no face names as
  // `cell`. The faces are turned round so that cell 3 owns them.
  const std::string text = header(4, 4, "property int cell\nproperty int neighbor\n") +
                           "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                           "3 0 1 2 -1 3\n3 0 3 1 -1 3\n3 0 2 3 -1 3\n3 1 3 2 -1 3\n";
  const CellComplex cc = readString(text);
  EXPECT_EQ(cc.cellLabels, std::vector<int>{3});
  ASSERT_EQ(cc.wallCount(), 1);  // triangles with the same cells form one wall
  EXPECT_EQ(cc.walls[0].cell, 0);
  EXPECT_EQ(cc.walls[0].neighbor, -1);
  EXPECT_NEAR(cellVolumes(cc, cc.rest)[0], 1.0 / 6.0, 1e-15);
  EXPECT_TRUE(checkValidity(cc).ok()) << checkValidity(cc).summary();
}

TEST(PlyRead, WallIdsGroupFacesAndMustAgreeOnCells) {
  // The cube as 12 triangles, two per side, grouped by `wall`.
  const std::string tris =
      "3 0 3 2 5 0\n3 0 2 1 5 0\n3 4 5 6 5 1\n3 4 6 7 5 1\n3 0 1 5 5 2\n3 0 5 4 5 2\n"
      "3 2 3 7 5 3\n3 2 7 6 5 3\n3 0 4 7 5 4\n3 0 7 3 5 4\n3 1 2 6 5 5\n3 1 6 5 5 5\n";
  const std::string head = header(8, 12, "property int cell\nproperty int wall\n");
  const CellComplex cc = readString(head + kCubeVertices + tris);
  EXPECT_EQ(cc.wallCount(), 6);
  EXPECT_EQ(cc.triangleWall, (std::vector<int>{0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5}));
  EXPECT_TRUE(checkValidity(cc).ok());

  std::string wrong = tris;
  wrong.replace(wrong.find("3 4 6 7 5 1"), 11, "3 4 6 7 6 1");
  EXPECT_THAT(
      plyError(head + kCubeVertices + wrong),
      AllOf(HasSubstr("face 3 (line 23) is in wall 1 with face 2 (line 22)"), HasSubstr("cell 6")));
}

TEST(PlyRead, MorphoGraphXStyleLabelsAndNames) {
  const std::string text =
      "ply\nformat ascii 1.0\ncomment Exported from MorphoGraphX 2.0\n"
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "property int label\nproperty list uchar float /Cell Axis curv10microns\n"
      "element face 2\nproperty list uchar int vertex_index\nproperty int label\nend_header\n"
      "0 0 0 -1 2 0.5 0.25\n1 0 0 -1 0\n1 1 0 -1 1 7\n0 1 0 -1 0\n"
      "3 0 1 2 7\n3 0 2 3 9\n";
  PlyInfo info;
  const CellComplex cc = readString(text, &info);
  EXPECT_TRUE(info.hadCellLabels);
  EXPECT_EQ(info.cellProperty, "label");
  EXPECT_THAT(sorted(info.ignoredProperties),
              ElementsAre("vertex./Cell Axis curv10microns", "vertex.label"));
  EXPECT_EQ(cc.cellLabels, (std::vector<int>{7, 9}));
  ASSERT_EQ(cc.wallCount(), 2);
  EXPECT_EQ(cc.walls[1].cell, 1);
}

// openalea's PropertyTopomesh PLY: faces without labels, one `volume` per cell listing its faces.
const std::string kTopomesh =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
    "property float z\nelement face 3\nproperty list uchar int vertex_indices\n"
    "property int epidermis\nelement volume 3\nproperty list int int face_index\n"
    "property int label\nend_header\n"
    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
    "3 0 1 2 1\n3 0 1 3 1\n3 0 2 3 0\n"
    "2 0 2 5\n0 11\n2 1 2 8\n";  // lines 21-23: face 2 bounds cells 5 and 8; 11 is empty

TEST(PlyRead, OpenAleaVolumesGiveTheCells) {
  PlyInfo info;
  const CellComplex cc = readString(kTopomesh, &info);
  EXPECT_TRUE(info.hadCellLabels);
  EXPECT_EQ(info.cellProperty, "volume.label");
  EXPECT_TRUE(info.ignoredElements.empty());
  EXPECT_THAT(info.notes, Contains(HasSubstr("1 volume(s) with no faces")));
  EXPECT_EQ(cc.cellLabels, (std::vector<int>{5, 8}));
  ASSERT_EQ(cc.triangleCount(), 3);
  const auto cellsOf = [&](int t) {
    const Wall& w = cc.walls[cc.triangleWall[t]];
    return std::pair(w.cell, w.neighbor);
  };
  EXPECT_EQ(cellsOf(0), std::pair(0, -1));
  EXPECT_EQ(cellsOf(1), std::pair(1, -1));
  EXPECT_EQ(cellsOf(2), std::pair(0, 1));  // listed by both: a wall between them
}

TEST(PlyRead, ExtraElementsListsAndUnknownTypesAreReadPast) {
  const std::string text =
      "ply\nformat ascii 1.0\nobj_info made by hand\nelement vertex 3\nproperty float32 x\n"
      "property float32 y\nproperty float32 z\nelement face 1\n"
      "property list uchar int32 vertex_indices\nproperty uchar red\nproperty float32 area\n"
      "property tensor strain\n"  // not a PLY type, but after everything we need
      "element edge 3\nproperty int source\nproperty int target\nproperty list int int face_index\n"
      "element volume 1\nproperty list int int face_index\nproperty tensor stress\n"
      "property int label\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n"
      "3 0 1 2 255 0.5 1 2 3 4 5 6\n"
      "0 1 1 0\n\n1 2 1 0\n2 0 1 0\n"  // a blank line is harmless
      "1 0 (1,2;3,4) 2\n";
  PlyInfo info;
  const CellComplex cc = readString(text, &info);
  EXPECT_EQ(cc.triangleCount(), 1);
  EXPECT_THAT(info.ignoredElements, ElementsAre("edge", "volume"));
  EXPECT_THAT(sorted(info.ignoredProperties), ElementsAre("face.area", "face.red", "face.strain"));
  EXPECT_FALSE(info.hadCellLabels);
}

TEST(PlyRead, BinaryElementOfUnknownTypeAfterFacesIsSkipped) {
  const CellComplex tet = readString(binaryTetra(false));
  std::string bin = plyText(tet, true);
  bin.insert(bin.find("end_header"), "element blob 2\nproperty tensor t\n");
  bin += "some bytes we cannot interpret";
  PlyInfo info;
  const CellComplex cc = readString(bin, &info);
  expectSameComplex(tet, cc);
  EXPECT_THAT(info.notes, Contains(HasSubstr("blob")));

  std::string before = plyText(tet, true);
  before.insert(before.find("element vertex"), "element blob 2\nproperty tensor t\n");
  EXPECT_THAT(plyError(before), AllOf(HasSubstr("bad.ply"), HasSubstr("'blob'")));
}

// ---------------------------------------------------------------------------------------------
// Malformed files: clear messages, no crash, no hang, no huge allocation

const std::string kTriangle = header(3, 1, "") + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";  // lines 10-13

std::string replaceLine(const std::string& text, int line, const std::string& by) {
  std::istringstream in(text);
  std::string out, l;
  for (int i = 1; std::getline(in, l); ++i) out += (i == line ? by : l) + "\n";
  return out;
}

TEST(PlyErrors, TheValidTriangleReads) {
  const CellComplex cc = readString(kTriangle);
  EXPECT_EQ(cc.triangleCount(), 1);
  EXPECT_EQ(cc.cellCount(), 0);
}

TEST(PlyErrors, OpenAleaVolumesAreChecked) {
  EXPECT_THAT(plyError(replaceLine(kTopomesh, 23, "2 1 7 8")),
              AllOf(HasSubstr("bad.ply: line 23"), HasSubstr("face index 7 out of range")));
  EXPECT_THAT(plyError(replaceLine(kTopomesh, 22, "1 2 11")),
              AllOf(HasSubstr("bad.ply: line 23"),
                    HasSubstr("face 2 is already a wall of cells 5 and 11"),
                    HasSubstr("cannot also bound cell 8")));
  EXPECT_THAT(plyError(replaceLine(kTopomesh, 21, "2 0 2 -5")),
              AllOf(HasSubstr("line 21"), HasSubstr("cell label -5 is negative")));
}

TEST(PlyErrors, MissingCoordinate) {
  std::string t = kTriangle;
  t.replace(t.find("property float z\n"), 17, "");
  EXPECT_THAT(plyError(t), AllOf(HasSubstr("bad.ply"), HasSubstr("no property 'z'")));
}

TEST(PlyErrors, VertexIndexOutOfRange) {
  EXPECT_THAT(plyError(replaceLine(kTriangle, 13, "3 0 1 7")),
              AllOf(HasSubstr("bad.ply: line 13 (face 0)"), HasSubstr("vertex index 7"),
                    HasSubstr("out of range")));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 13, "3 0 -1 2")), HasSubstr("vertex index -1"));
}

TEST(PlyErrors, FaceWithTooFewOrRepeatedVertices) {
  EXPECT_THAT(plyError(replaceLine(kTriangle, 13, "2 0 1")),
              AllOf(HasSubstr("line 13"), HasSubstr("at least 3")));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 13, "3 0 1 1")),
              AllOf(HasSubstr("line 13"), HasSubstr("repeats vertex 1")));
  // A list length far beyond the vertex count fails before anything is read or allocated.
  EXPECT_THAT(plyError(replaceLine(kTriangle, 13, "200 0 1 2")),
              AllOf(HasSubstr("line 13"), HasSubstr("declares 200 items")));
}

TEST(PlyErrors, TruncatedAscii) {
  const std::string t = kTriangle.substr(0, kTriangle.find("3 0 1 2"));
  EXPECT_THAT(plyError(t), HasSubstr("premature end of file in element 'face' at index 0"));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 13, "3 0 1")),
              AllOf(HasSubstr("line 13"), HasSubstr("declares 3 items but the line has only 2")));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 12, "0 1")),
              AllOf(HasSubstr("line 12"), HasSubstr("too few values: property 'z'")));
}

TEST(PlyErrors, TruncatedBinary) {
  const CellComplex box = boxTissue(2, 2, 2, 1.0);
  const std::string bin = plyText(box, true);
  const std::size_t data = bin.find("end_header\n") + 11;
  const std::size_t vertexBytes = 3 * 8 + 1, faceBytes = 1 + 3 * 4 + 3 * 4;
  const std::string cut =
      bin.substr(0, data + box.vertexCount() * vertexBytes + 12 * faceBytes + 5);
  EXPECT_THAT(plyError(cut),
              AllOf(HasSubstr("bad.ply"), HasSubstr("premature end of file in element 'face' at "
                                                    "index 12")));
}

TEST(PlyErrors, NotANumberNotAnIntegerNotFinite) {
  EXPECT_THAT(plyError(replaceLine(kTriangle, 11, "1 abc 0")),
              AllOf(HasSubstr("bad.ply: line 11"), HasSubstr("'abc' is not a number")));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 13, "3 0 1.5 2")),
              AllOf(HasSubstr("line 13"), HasSubstr("'1.5' is not an integer")));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 10, "nan 0 0")),
              AllOf(HasSubstr("line 10"), HasSubstr("not finite")));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 12, "0 -inf 0")),
              AllOf(HasSubstr("line 12"), HasSubstr("coordinate y")));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 10, "0 0 0 0")),
              AllOf(HasSubstr("line 10"), HasSubstr("more than element 'vertex' declares")));
}

TEST(PlyErrors, AbsurdCoordinatesAreRefused) {
  // Issue 9: coordinates near 1e308 gave volume -nan and "closed yes".
  EXPECT_THAT(plyError(replaceLine(kTriangle, 11, "1e308 0 0")),
              AllOf(HasSubstr("line 11"), HasSubstr("coordinate x is 1e+308 µm (at most 1e+06 µm")));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 12, "0 0 -2e6")),
              AllOf(HasSubstr("line 12"), HasSubstr("coordinate z")));
}

TEST(PlyErrors, ClosedSurfaceWithAFlippedFaceNamesTheFaces) {
  // Issue 9: one face of the cube wound the other way made the file a 0-cell "sheet".
  ASSERT_NO_THROW(readString(header(8, 6, "") + kCubeVertices + kCubeQuads));
  // The cube's quads with the first one ("4 0 3 2 1") reversed.
  const std::string quads = std::string(kCubeQuads).replace(0, 9, "4 1 2 3 0");
  const std::string text = header(8, 6, "") + kCubeVertices + quads;
  const std::string message = plyError(text);
  EXPECT_THAT(message, HasSubstr("the surface is closed but its faces are not wound consistently"));
  EXPECT_THAT(message, HasSubstr("4 edge(s) run the same way in both of their faces (faces 0 and"));
}

TEST(PlyErrors, ValueOutOfItsTypesRange) {
  std::string t = kTriangle;
  t.replace(t.find("element face"), 0, "property uchar fixed\n");
  t = replaceLine(replaceLine(replaceLine(t, 11, "0 0 0 1"), 12, "1 0 0 300"), 13, "0 1 0 0");
  EXPECT_THAT(plyError(t), AllOf(HasSubstr("line 12"), HasSubstr("300"), HasSubstr("fixed")));
}

TEST(PlyErrors, HeaderProblems) {
  EXPECT_THAT(plyError(""), HasSubstr("empty file"));
  EXPECT_THAT(plyError("plx\nformat ascii 1.0\n"),
              AllOf(HasSubstr("bad.ply"), HasSubstr("not a PLY file")));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 2, "format binary_middle_endian 1.0")),
              AllOf(HasSubstr("line 2"), HasSubstr("unsupported format")));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 9, "end_hedaer")), HasSubstr("line 9"));
  EXPECT_THAT(plyError("ply\nformat ascii 1.0\nelement vertex 3\n"), HasSubstr("end_header"));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 3, "element vertex -3")), HasSubstr("line 3"));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 4, "property list uchar float x")),
              AllOf(HasSubstr("line 4"), HasSubstr("'x'"), HasSubstr("not a list")));
  EXPECT_THAT(plyError("ply\nformat ascii 1.0\nproperty float x\nend_header\n"),
              HasSubstr("before any 'element'"));
}

TEST(PlyErrors, HugeCountsFailWithoutAllocating) {
  EXPECT_THAT(plyError(replaceLine(kTriangle, 3, "element vertex 1000000000000")),
              AllOf(HasSubstr("bad.ply"), HasSubstr("1000000000000")));
  EXPECT_THAT(plyError(replaceLine(kTriangle, 7, "element face 1000000000")),
              HasSubstr("premature end of file in element 'face' at index 1 of 1000000000"));
  std::string bin = plyText(boxTissue(1, 1, 1, 1.0), true);
  bin.replace(bin.find("element face 12"), 15, "element face 2000000000");
  EXPECT_THAT(plyError(bin), HasSubstr("in element 'face' at index 12 of 2000000000"));
  // A huge list inside an ignored binary element.
  bin = plyText(boxTissue(1, 1, 1, 1.0), true);
  bin.insert(bin.find("element vertex"), "element blob 1\nproperty list uint int items\n");
  bin.insert(bin.find("end_header\n") + 11, std::string("\xff\xff\xff\x7f", 4));
  EXPECT_THAT(plyError(bin), HasSubstr("premature end of file in element 'blob' at index 0"));
}

TEST(PlyErrors, UnknownTypeWhereAValueIsNeeded) {
  std::string t = kTriangle;
  t.replace(t.find("end_header"), 0, "property tensor t\nproperty int cell\n");
  t = replaceLine(t, 15, "3 0 1 2 x 5");
  EXPECT_THAT(plyError(t), AllOf(HasSubstr("'cell'"), HasSubstr("'tensor'")));
  std::string bin = plyText(readString(kTriangle), true);
  bin.replace(bin.find("property int wall"), 17, "property tensor wall");
  EXPECT_THAT(plyError(bin), AllOf(HasSubstr("'wall'"), HasSubstr("binary")));
}

TEST(PlyErrors, CellAndNeighborTheSame) {
  const std::string t = header(3, 1, "property int cell\nproperty int neighbor\n") +
                        "0 0 0\n1 0 0\n0 1 0\n3 0 1 2 4 4\n";
  EXPECT_THAT(plyError(t), AllOf(HasSubstr("face 0 (line 15)"), HasSubstr("both 4")));
}

TEST(PlyErrors, NoFacesOrNoVertices) {
  EXPECT_THAT(plyError("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                       "property float y\nproperty float z\nend_header\n0 0 0\n"),
              AllOf(HasSubstr("bad.ply"), HasSubstr("no faces")));
  EXPECT_THAT(plyError("ply\nformat ascii 1.0\nelement face 0\n"
                       "property list uchar int vertex_indices\nend_header\n"),
              HasSubstr("no 'vertex' element"));
}

TEST(PlyErrors, MissingFileNamesThePath) {
  TempDir dir;
  const std::string path = dir.file("absent.ply");
  EXPECT_THAT(messageOf<PlyError>([&] { readPly(path); }),
              AllOf(HasSubstr(path), HasSubstr("No such file")));
}

// Every prefix of a valid file, and many random corruptions of it, either read or throw
// PlyError, and whatever is read has every index in range.
TEST(PlyErrors, TruncationsAndCorruptionsNeverCrash) {
  const CellComplex box = boxTissue(1, 1, 2, 1.0);
  std::mt19937 rng(2024);
  for (bool binary : {false, true}) {
    SCOPED_TRACE(binary ? "binary" : "ascii");
    const std::string good = plyText(box, binary);
    auto tryRead = [&](const std::string& text) {
      try {
        expectStructurallySound(readString(text));
      } catch (const PlyError&) {
      }
    };
    for (std::size_t n = 0; n < good.size(); ++n) tryRead(good.substr(0, n));
    std::uniform_int_distribution<std::size_t> at(0, good.size() - 1);
    std::uniform_int_distribution<int> byte(0, 255), howMany(1, 4);
    const std::string alphabet = "0123456789 -.e\n";
    for (int trial = 0; trial < 3000; ++trial) {
      std::string bad = good;
      for (int k = howMany(rng); k > 0; --k)
        bad[at(rng)] = binary || trial % 2 ? static_cast<char>(byte(rng))
                                           : alphabet[byte(rng) % alphabet.size()];
      tryRead(bad);
    }
  }
}

}  // namespace
}  // namespace tp
