#include "io/Vtu.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <regex>
#include <sstream>

#include "io/IoTestUtil.h"
#include "tissue/Shapes.h"

namespace tp {
namespace {

using test::messageOf;
using test::TempDir;
using ::testing::AllOf;
using ::testing::HasSubstr;

int countOf(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

// The text between <DataArray ... Name="name" ...> and </DataArray>.
std::string arrayBody(const std::string& xml, const std::string& name) {
  const std::size_t at = xml.find("Name=\"" + name + "\"");
  if (at == std::string::npos) return "";
  const std::size_t open = xml.find('>', at) + 1;
  return xml.substr(open, xml.find("</DataArray>", open) - open);
}

std::string decodeBase64(const std::string& text) {
  std::string out;
  std::uint32_t acc = 0;
  int bits = 0;
  for (char c : text) {
    int v;
    if (c >= 'A' && c <= 'Z')
      v = c - 'A';
    else if (c >= 'a' && c <= 'z')
      v = c - 'a' + 26;
    else if (c >= '0' && c <= '9')
      v = c - '0' + 52;
    else if (c == '+')
      v = 62;
    else if (c == '/')
      v = 63;
    else
      continue;  // whitespace and padding
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((acc >> bits) & 0xff);
    }
  }
  return out;
}

struct Sample {
  CellComplex cc = boxTissue(2, 1, 1, 1.0);
  Points x;
  std::vector<VtuField> pointFields, cellFields;
  Sample() {
    x = cc.rest * 1.5;
    VtuField disp{"displacement", 3, {}};
    for (int v = 0; v < cc.vertexCount(); ++v)
      for (int k = 0; k < 3; ++k) disp.values.push_back(x(k, v) - cc.rest(k, v));
    VtuField stress{"von Mises <MPa>", 1, std::vector<double>(cc.triangleCount(), 0.25)};
    stress.values[1] = std::nan("");
    pointFields = {disp};
    cellFields = {stress};
  }
};

TEST(Vtu, AsciiFileIsWellFormedAndComplete) {
  Sample s;
  TempDir dir;
  const std::string path = dir.file("tissue.vtu");
  writeVtu(path, s.cc, s.x, s.pointFields, s.cellFields, VtuEncoding::Ascii);
  const std::string xml = test::readText(path);
  EXPECT_THAT(xml, HasSubstr("NumberOfPoints=\"" + std::to_string(s.cc.vertexCount()) + "\""));
  EXPECT_THAT(xml, HasSubstr("NumberOfCells=\"" + std::to_string(s.cc.triangleCount()) + "\""));
  // fixed, displacement | wall, cell, outer, stress | Points | connectivity, offsets, types
  EXPECT_EQ(countOf(xml, "<DataArray"), 10);
  EXPECT_EQ(countOf(xml, "</DataArray>"), 10);
  for (const char* tag :
       {"VTKFile", "UnstructuredGrid", "Piece", "PointData", "CellData", "Points", "Cells"})
    EXPECT_EQ(
        countOf(xml, std::string("<") + tag + ">") + countOf(xml, std::string("<") + tag + " "),
        countOf(xml, std::string("</") + tag + ">"))
        << tag;
  EXPECT_THAT(xml, HasSubstr("Name=\"von Mises &lt;MPa&gt;\""));  // escaped
  EXPECT_THAT(arrayBody(xml, "von Mises &lt;MPa&gt;"), HasSubstr("0.25 nan 0.25"));

  // Types all 5, offsets 3, 6, ..., connectivity = the triangles.
  std::istringstream types(arrayBody(xml, "types")), offsets(arrayBody(xml, "offsets")),
      conn(arrayBody(xml, "connectivity")), fixed(arrayBody(xml, "fixed"));
  for (int t = 0; t < s.cc.triangleCount(); ++t) {
    int type = 0, offset = 0;
    types >> type;
    offsets >> offset;
    EXPECT_EQ(type, 5);
    EXPECT_EQ(offset, 3 * (t + 1));
    for (int k = 0; k < 3; ++k) {
      int v = -1;
      conn >> v;
      EXPECT_EQ(v, s.cc.triangles[t][k]);
    }
  }
  for (int v = 0; v < s.cc.vertexCount(); ++v) {
    int f = -1;
    fixed >> f;
    EXPECT_EQ(f, s.cc.fixed[v]);
  }
  std::istringstream cells(arrayBody(xml, "cell")), outer(arrayBody(xml, "outer"));
  for (int t = 0; t < s.cc.triangleCount(); ++t) {
    int c = -2, o = -1;
    cells >> c;
    outer >> o;
    EXPECT_EQ(c, s.cc.cellLabels[s.cc.walls[s.cc.triangleWall[t]].cell]);
    EXPECT_EQ(o, s.cc.isOuterTriangle(t) ? 1 : 0);
  }
}

TEST(Vtu, Base64ArraysDecodeToTheExactData) {
  Sample s;
  std::ostringstream out;
  writeVtu(out, s.cc, s.x, s.pointFields, s.cellFields);
  const std::string xml = out.str();
  EXPECT_THAT(xml, HasSubstr("header_type=\"UInt64\""));
  EXPECT_EQ(countOf(xml, "format=\"binary\""), 10);
  const std::string bytes = decodeBase64(arrayBody(xml, "Points"));
  const std::size_t n = 3 * static_cast<std::size_t>(s.cc.vertexCount());
  ASSERT_EQ(bytes.size(), 8 + 8 * n);
  std::uint64_t size = 0;
  std::memcpy(&size, bytes.data(), 8);
  EXPECT_EQ(size, 8 * n);
  EXPECT_EQ(std::memcmp(bytes.data() + 8, s.x.data(), 8 * n), 0);
  const std::string stress = decodeBase64(arrayBody(xml, "von Mises &lt;MPa&gt;"));
  double second = 0;
  std::memcpy(&second, stress.data() + 8 + 8, 8);
  EXPECT_TRUE(std::isnan(second));
}

TEST(Vtu, FieldsAreValidatedBeforeWriting) {
  Sample s;
  TempDir dir;
  const std::string path = dir.file("bad.vtu");
  auto error = [&](std::vector<VtuField> pf, std::vector<VtuField> cf) {
    return messageOf<std::invalid_argument>([&] { writeVtu(path, s.cc, s.x, pf, cf); });
  };
  const int V = s.cc.vertexCount();
  EXPECT_THAT(
      error({{"speed", 3, std::vector<double>(3 * V - 1)}}, {}),
      AllOf(HasSubstr("point field 'speed'"), HasSubstr("expected 3 x " + std::to_string(V))));
  EXPECT_THAT(error({}, {{"energy", 1, {1.0, 2.0}}}), HasSubstr("cell field 'energy'"));
  EXPECT_THAT(error({{"fixed", 1, std::vector<double>(V)}}, {}), HasSubstr("already used"));
  EXPECT_THAT(error({}, {{"a", 1, std::vector<double>(s.cc.triangleCount())},
                         {"a", 1, std::vector<double>(s.cc.triangleCount())}}),
              HasSubstr("'a': name already used"));
  EXPECT_THAT(error({{"zero", 0, {}}}, {}), HasSubstr("components"));
  EXPECT_THAT(error({{"", 1, std::vector<double>(V)}}, {}), HasSubstr("empty name"));
  EXPECT_THAT(
      messageOf<std::invalid_argument>([&] { writeVtu(path, s.cc, Points::Zero(3, 2), {}, {}); }),
      HasSubstr("positions"));
  EXPECT_TRUE(dir.entries().empty());
}

}  // namespace
}  // namespace tp
