#pragma once
// The mesh-convergence argument of the closed-form checks (DESIGN.md §4), shared by the fast
// suite (tests/experiment/test_closed_form.cpp) and the slow one (tests/experiment/slow).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

namespace tp::test {

inline void report(const char* what, int level, double value, double expected) {
  std::printf("  %-34s mesh %d: %.6g (closed form %.6g), error %+.3f%%\n", what, level, value,
              expected, 100.0 * (value / expected - 1.0));
}

// The mesh-convergence argument. Meshes are refined by halving the spacing, and the finest mesh
// must be within tolFinest. When the last three errors converge monotonically, their observed
// order p gives the Richardson extrapolation e∞ = e₃ − (e₂ − e₃)/(2^p − 1), the estimated error of
// the converged discretisation, which must be within tolLimit. Otherwise the errors have reached
// the scatter of the meshes (lattice against circle), and the last two must both be within
// tolFinest.
inline void expectConverging(const std::vector<double>& e, double tolFinest, double tolLimit,
                      const char* what) {
  ASSERT_GE(e.size(), 3u);
  const size_t n = e.size();
  const double last = e[n - 1];
  EXPECT_LT(std::abs(last), tolFinest) << what << ": finest mesh error " << 100 * last << "%";
  const double d1 = e[n - 3] - e[n - 2], d2 = e[n - 2] - e[n - 1];
  if (d1 * d2 > 0 && std::abs(d1) > std::abs(d2)) {
    const double order = std::log2(d1 / d2);
    const double limit = last - d2 / (std::pow(2.0, order) - 1);
    std::printf("  %-34s observed order %.2f, extrapolated error %+.3f%%\n", what, order,
                100 * limit);
    EXPECT_LT(std::abs(limit), tolLimit) << what << ": extrapolated error " << 100 * limit << "%";
  } else {
    std::printf("  %-34s errors not monotone (converged to within their scatter)\n", what);
    EXPECT_LT(std::abs(e[n - 2]), tolFinest) << what;
  }
}


}  // namespace tp::test
