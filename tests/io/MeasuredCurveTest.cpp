// Reading measured force–indentation curves from tables: delimiters, header units, columns by
// name and position, and the errors a user meets.
#include "io/MeasuredCurve.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace tp {
namespace {

using ::testing::DoubleNear;
using ::testing::HasSubstr;
using ::testing::Pointwise;

std::string errorOf(const std::string& text, const MeasuredColumns& c = {}) {
  try {
    parseMeasuredCurve(text, "m.csv", c);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(MeasuredCurve, HeaderUnitsAreConvertedToMicrometresAndMicronewtons) {
  const MeasuredCurve c = parseMeasuredCurve(
      "# an AFM curve\ntime_s,depth (nm),force [nN]\n0,0,0\n1,250,12.5\n"
      "2,500,40\n",
      "m.csv");
  EXPECT_EQ(c.name, "m.csv");
  EXPECT_THAT(c.depth, Pointwise(DoubleNear(1e-15), std::vector<double>{0.0, 0.25, 0.5}));
  EXPECT_THAT(c.force, Pointwise(DoubleNear(1e-15), std::vector<double>{0.0, 0.0125, 0.04}));
  // Tabs, unit suffixes after '_', µ spelled both ways.
  const MeasuredCurve t = parseMeasuredCurve("Indentation_um\tF_uN\n0.1\t1\n0.2\t3\n", "t.tsv");
  EXPECT_THAT(t.depth, Pointwise(DoubleNear(1e-15), std::vector<double>{0.1, 0.2}));
  EXPECT_THAT(t.force, Pointwise(DoubleNear(1e-15), std::vector<double>{1.0, 3.0}));
  const MeasuredCurve m = parseMeasuredCurve("depth (µm);force (pN)\n1;2000\n2;5000\n", "m.csv");
  EXPECT_THAT(m.force, Pointwise(DoubleNear(1e-15), std::vector<double>{0.002, 0.005}));
}

TEST(MeasuredCurve, ColumnsByNameOrPositionAndUnitsGiven) {
  const std::string text = "z (m), F (N), depth (m)\n1, 2e-9, 1e-7\n2, 5e-9, 3e-7\n";
  MeasuredColumns c;
  c.depth = "depth";
  c.force = "F";
  const MeasuredCurve named = parseMeasuredCurve(text, "w.txt", c);
  EXPECT_THAT(named.depth,
              Pointwise(DoubleNear(1e-15), std::vector<double>{0.1, 0.3}));  // 1e-7 m = 0.1 µm
  EXPECT_DOUBLE_EQ(named.force[1], 5e-3);                                    // 5e-9 N = 5e-3 µN
  c.depth = "3";
  c.force = "2";
  EXPECT_THAT(parseMeasuredCurve(text, "w.txt", c).depth,
              Pointwise(DoubleNear(1e-15), std::vector<double>{0.1, 0.3}));
  // No header: positions and units from the caller.
  MeasuredColumns bare;
  bare.depthUnit = "nm";
  bare.forceUnit = "nN";
  const MeasuredCurve b = parseMeasuredCurve("100, 1\n200, 4\n+300, 9\n", "b.csv", bare);
  EXPECT_THAT(b.depth, Pointwise(DoubleNear(1e-15), std::vector<double>{0.1, 0.2, 0.3}));
  EXPECT_THAT(b.force, Pointwise(DoubleNear(1e-15), std::vector<double>{0.001, 0.004, 0.009}));
}

TEST(MeasuredCurve, ErrorsNameTheFileLineAndValue) {
  EXPECT_THAT(errorOf("depth (nm),force (nN)\n1,2\n3,abc\n"),
              HasSubstr("m.csv: line 3: force 'abc' is not a finite number"));
  EXPECT_THAT(errorOf("depth (nm),force (nN)\n1,2\n3,nan\n"), HasSubstr("line 3"));
  EXPECT_THAT(errorOf("depth,force (nN)\n1,2\n3,4\n"),
              HasSubstr("the depth column's unit is not given"));
  EXPECT_THAT(errorOf("depth (furlong),force (nN)\n1,2\n3,4\n"),
              HasSubstr("unknown depth unit 'furlong'"));
  MeasuredColumns c;
  c.force = "stiffness";
  EXPECT_THAT(
      errorOf("depth (nm),force (nN)\n1,2\n3,4\n", c),
      HasSubstr("no force column 'stiffness' (the columns are 'depth (nm)', 'force (nN)')"));
  c.force = "7";
  EXPECT_THAT(errorOf("depth (nm),force (nN)\n1,2\n3,4\n", c),
              HasSubstr("column 7 is not a column"));
  EXPECT_THAT(errorOf("depth (nm),force (nN)\n1,2\n"), HasSubstr("fewer than two data rows"));
  EXPECT_THAT(errorOf("# nothing\n\n"), HasSubstr("no rows"));
  EXPECT_THAT(errorOf("depth (nm),force (nN)\n1,2\n3\n"), HasSubstr("line 3: 1 value(s)"));
  EXPECT_THROW(readMeasuredCurve("/nonexistent/curve.csv"), std::runtime_error);
}

TEST(MeasuredCurve, UnitNames) {
  EXPECT_DOUBLE_EQ(lengthUnitInMicrometres("nm"), 1e-3);
  EXPECT_DOUBLE_EQ(lengthUnitInMicrometres("m"), 1e6);
  EXPECT_DOUBLE_EQ(forceUnitInMicronewtons("nN"), 1e-3);
  EXPECT_DOUBLE_EQ(forceUnitInMicronewtons("N"), 1e6);
  EXPECT_EQ(lengthUnitInMicrometres("nN"), 0.0);
  EXPECT_EQ(forceUnitInMicronewtons("um"), 0.0);
}

}  // namespace
}  // namespace tp
