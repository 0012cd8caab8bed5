// The generic PLY table reader on its own: tables that are not tissues, every scalar type in both
// byte orders, skipping, and the order in which elements must be read.
#include "io/PlyTable.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace tp::ply {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

// Reads every instance of element e, all properties wanted.
std::vector<Instance> readAll(TableReader& t, int e) {
  std::vector<Instance> out;
  const std::vector<char> all(t.elements()[e].properties.size(), 1);
  t.read(e, all, [&](std::uint64_t index, const Instance& in) {
    EXPECT_EQ(index, out.size());
    out.push_back(in);
  });
  return out;
}

std::string errorOf(const std::string& text, int skipFirst = 0) {
  try {
    TableReader t(text, "t.ply");
    for (int e = 0; e < static_cast<int>(t.elements().size()); ++e) {
      if (e < skipFirst)
        t.skip(e);
      else
        readAll(t, e);
    }
  } catch (const PlyError& err) {
    return err.what();
  }
  return "";
}

TEST(PlyTable, ReadsATableThatIsNotATissue) {
  // An edge graph with a list per edge and a comment; the header is kept as written.
  const std::string text =
      "ply\nformat ascii 1.0\ncomment a graph\nelement edge 2\nproperty int a\n"
      "property uchar b\nproperty list uchar float w\nelement note 1\nproperty double v\n"
      "end_header\n7 255 2 0.5 -1e3\n\n-3 0 0\n+2.5\n";
  TableReader t(text, "t.ply");
  EXPECT_EQ(t.format(), Format::Ascii);
  EXPECT_EQ(t.formatName(), "ascii");
  ASSERT_EQ(t.elements().size(), 2u);
  EXPECT_EQ(t.findElement("note"), 1);
  EXPECT_EQ(t.findElement("face"), -1);
  const Element& edge = t.elements()[0];
  EXPECT_EQ(edge.count, 2u);
  EXPECT_EQ(edge.line, 4);
  EXPECT_EQ(edge.find("w"), 2);
  EXPECT_TRUE(edge.properties[2].isList);
  EXPECT_EQ(edge.properties[2].type, Scalar::Float32);
  EXPECT_EQ(edge.properties[2].countType, Scalar::UInt8);
  const auto edges = readAll(t, 0);
  ASSERT_EQ(edges.size(), 2u);
  EXPECT_EQ(edges[0].values[0], 7);
  EXPECT_EQ(edges[0].values[1], 255);
  EXPECT_THAT(edges[0].lists[2], ElementsAre(0.5, -1000.0));
  EXPECT_EQ(edges[1].values[0], -3);
  EXPECT_TRUE(edges[1].lists[2].empty());
  const auto notes = readAll(t, 1);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].values[0], 2.5);
  EXPECT_EQ(t.trailingBytes(), 0u);
}

TEST(PlyTable, ElementsAreReadInFileOrder) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement a 1\nproperty int x\nelement b 1\nproperty int y\n"
      "end_header\n1\n2\n";
  TableReader t(text, "t.ply");
  EXPECT_THROW(readAll(t, 1), std::logic_error);
  TableReader u(text, "t.ply");
  u.skip(0);
  const auto b = readAll(u, 1);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].values[0], 2);
}

TEST(PlyTable, UnwantedAsciiValuesAreNotChecked) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement a 1\nproperty int x\nproperty int y\nend_header\nzz 4\n";
  TableReader t(text, "t.ply");
  std::vector<double> y;
  t.read(0, {0, 1}, [&](std::uint64_t, const Instance& in) { y.push_back(in.values[1]); });
  EXPECT_THAT(y, ElementsAre(4.0));
  EXPECT_THAT(errorOf(text), AllOf(HasSubstr("t.ply: line 7 (a 0)"),
                                   HasSubstr("'zz' is not an integer (property 'x'")));
}

// Every scalar type, big and little endian: the values read back exactly.
template <class T>
void put(std::string& out, T v, bool big) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &v, sizeof(T));
  if (big == (std::endian::native == std::endian::little)) std::reverse(bytes, bytes + sizeof(T));
  out.append(bytes, sizeof(T));
}

TEST(PlyTable, BinaryOfEitherByteOrderDecodesEveryType) {
  for (const bool big : {false, true}) {
    std::string text = std::string("ply\nformat ") +
                       (big ? "binary_big_endian" : "binary_little_endian") +
                       " 1.0\nelement v 1\nproperty char a\nproperty uchar b\nproperty short c\n"
                       "property ushort d\nproperty int e\nproperty uint f\nproperty float g\n"
                       "property double h\nproperty list ushort int i\nend_header\n";
    put<std::int8_t>(text, -5, big);
    put<std::uint8_t>(text, 250, big);
    put<std::int16_t>(text, -30000, big);
    put<std::uint16_t>(text, 60000, big);
    put<std::int32_t>(text, -2000000000, big);
    put<std::uint32_t>(text, 4000000000u, big);
    put<float>(text, 0.1f, big);
    put<double>(text, -1.0 / 3.0, big);
    put<std::uint16_t>(text, 2, big);
    put<std::int32_t>(text, 17, big);
    put<std::int32_t>(text, -9, big);
    text += "xy";  // two bytes more than the table
    TableReader t(text, "t.ply");
    const auto v = readAll(t, 0);
    ASSERT_EQ(v.size(), 1u);
    EXPECT_THAT(std::vector<double>(v[0].values.begin(), v[0].values.end() - 1),
                ElementsAre(-5, 250, -30000, 60000, -2000000000.0, 4000000000.0,
                            static_cast<double>(0.1f), -1.0 / 3.0));
    EXPECT_THAT(v[0].lists[8], ElementsAre(17, -9));
    EXPECT_EQ(t.trailingBytes(), 2u);
  }
}

TEST(PlyTable, ABinaryListLongerThanTheFileFailsBeforeReading) {
  std::string text =
      "ply\nformat binary_little_endian 1.0\nelement v 1\nproperty list uint int i\nend_header\n";
  put<std::uint32_t>(text, 1u << 30, false);
  put<std::int32_t>(text, 1, false);
  EXPECT_THAT(errorOf(text), HasSubstr("premature end of file in element 'v' at index 0 of 1"));
  EXPECT_THAT(errorOf(text, 1), HasSubstr("premature end of file in element 'v' at index 0"));
}

TEST(PlyTable, UnknownTypes) {
  const std::string ascii =
      "ply\nformat ascii 1.0\nelement a 1\nproperty int x\nproperty tensor t\nproperty int y\n"
      "end_header\n1 (a b) 2\n";
  TableReader t(ascii, "t.ply");
  EXPECT_TRUE(t.skippable(0));
  EXPECT_NO_THROW(t.checkReadable(0, {1, 0, 0}));
  EXPECT_THAT(
      [&] {
        try {
          t.checkReadable(0, {0, 0, 1});
        } catch (const PlyError& e) {
          return std::string(e.what());
        }
        return std::string();
      }(),
      HasSubstr("property 'y' of element 'a' cannot be read: it follows property 't' "
                "of unknown type 'tensor'"));
  std::vector<double> x;
  t.read(0, {1, 0, 0}, [&](std::uint64_t, const Instance& in) { x.push_back(in.values[0]); });
  EXPECT_THAT(x, ElementsAre(1.0));  // the rest of the line is not read

  const std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement a 1\nproperty tensor t\nend_header\n";
  TableReader b(binary, "t.ply");
  EXPECT_FALSE(b.skippable(0));
  EXPECT_THAT(errorOf(binary, 1), HasSubstr("a binary file cannot be read past it"));
  EXPECT_THAT(errorOf(binary), HasSubstr("which is not a PLY type; a binary file cannot be read"));
}

}  // namespace
}  // namespace tp::ply
