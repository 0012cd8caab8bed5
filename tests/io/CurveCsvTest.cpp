#include "io/CurveCsv.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "io/IoTestUtil.h"

namespace tp {
namespace {

using test::messageOf;
using test::TempDir;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::StartsWith;

std::vector<CurvePoint> sampleCurve() {
  const double inf = std::numeric_limits<double>::infinity();
  return {
      {0.0, 0.0, 0, 0.0, true, false},
      {0.1, 0.123456789012345678, 7, 1.5e-13, true, false},
      {1.0 / 3.0, -2.5e-310, 12, 3e-9, true, false},
      {0.5, std::nan(""), 250, inf, false, false},
      {0.25, 1e300, 3, -0.0, true, true},
  };
}

TEST(CurveCsv, HeaderAndFormat) {
  const std::string text = curveCsv(sampleCurve());
  EXPECT_THAT(text, StartsWith("depth_um,force_uN,iterations,residual,converged\n"));
  EXPECT_THAT(text, HasSubstr("\n0,0,0,0,1\n"));
  EXPECT_THAT(text, HasSubstr("\n0.5,nan,250,inf,0\n"));
  EXPECT_EQ(curveCsv({}), "depth_um,force_uN,iterations,residual,converged\n");
}

TEST(CurveCsv, RoundTripIsExactIncludingNaN) {
  TempDir dir;
  const std::string path = dir.file("curve.csv");
  const auto curve = sampleCurve();
  writeCurveCsv(path, curve);
  EXPECT_EQ(test::readText(path), curveCsv(curve));
  const auto back = readCurveCsv(path);
  ASSERT_EQ(back.size(), curve.size());
  for (std::size_t i = 0; i < curve.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(back[i].depth, curve[i].depth);
    if (std::isnan(curve[i].force))
      EXPECT_TRUE(std::isnan(back[i].force));
    else
      EXPECT_EQ(back[i].force, curve[i].force);
    EXPECT_EQ(back[i].iterations, curve[i].iterations);
    EXPECT_EQ(back[i].residual, curve[i].residual);
    EXPECT_EQ(back[i].converged, curve[i].converged);
    EXPECT_FALSE(back[i].unloading);  // not a column of the file
  }
}

TEST(CurveCsv, ColumnsByNameWithOptionalUnloading) {
  const auto c = parseCurveCsv(
      "converged, iterations,depth_um,force_uN,residual,unloading,comment\r\n"
      "1,4,0.5,2.25,1e-12,1,hello\r\n\r\n0,9,0.25,1,nan,1,\r\n",
      "x.csv");
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0].depth, 0.5);
  EXPECT_EQ(c[0].force, 2.25);
  EXPECT_EQ(c[0].iterations, 4);
  EXPECT_TRUE(c[0].converged);
  EXPECT_TRUE(c[0].unloading);
  EXPECT_FALSE(c[1].converged);
  EXPECT_TRUE(std::isnan(c[1].residual));
}

TEST(CurveCsv, ErrorsNameFileLineAndColumn) {
  const std::string head = "depth_um,force_uN,iterations,residual,converged\n";
  auto error = [](const std::string& text) {
    return messageOf<std::runtime_error>([&] { parseCurveCsv(text, "c.csv"); });
  };
  EXPECT_THAT(error(head + "0,0,1,0,1\n0.1,abc,2,0,1\n"),
              AllOf(HasSubstr("c.csv: line 3"), HasSubstr("column 2 (force_uN)"),
                    HasSubstr("'abc' is not a number")));
  EXPECT_THAT(
      error(head + "0,0,1.5,0,1\n"),
      AllOf(HasSubstr("line 2"), HasSubstr("column 3 (iterations)"), HasSubstr("not an integer")));
  EXPECT_THAT(error(head + "0,0,1,0,yes\n"),
              AllOf(HasSubstr("column 5 (converged)"), HasSubstr("not 0 or 1")));
  EXPECT_THAT(error(head + "0,0,1,0\n"), AllOf(HasSubstr("line 2"), HasSubstr("found 4")));
  EXPECT_THAT(error(head + "0,,1,0,1\n"), HasSubstr("column 2"));
  EXPECT_THAT(error("depth,force\n1,2\n"),
              AllOf(HasSubstr("line 1"), HasSubstr("no column 'depth_um'")));
  EXPECT_THAT(error(""), HasSubstr("empty file"));
  TempDir dir;
  EXPECT_THAT(messageOf<std::runtime_error>([&] { readCurveCsv(dir.file("none.csv")); }),
              AllOf(HasSubstr("none.csv"), HasSubstr("No such file")));
}

}  // namespace
}  // namespace tp
