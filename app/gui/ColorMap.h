#pragma once
// Colour maps for per-wall quantities: value → RGB over a range, and "nice" tick values for the
// colour bar. Viridis (perceptually uniform, luminance rising) for magnitudes; a cool–warm
// diverging map for signed quantities (blue below the middle, red above). No Qt, no GL.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace tp::gui {

class ColorMap {
 public:
  enum class Kind { Viridis, CoolWarm };
  static constexpr int kKindCount = 2;

  explicit ColorMap(Kind kind = Kind::Viridis);

  Kind kind() const { return kind_; }
  void setKind(Kind kind) { kind_ = kind; }
  static const char* name(Kind kind);  // "viridis", "cool–warm (diverging)"
  static const char* key(Kind kind);   // "viridis", "coolwarm"
  bool diverging() const { return kind_ == Kind::CoolWarm; }

  /// The values mapped to the two ends. An empty range (hi ≤ lo) is widened upwards by 10 % of
  /// |lo| (1 if lo = 0) so that every value still gets a colour.
  void setRange(double lo, double hi);
  double lo() const { return lo_; }
  double hi() const { return hi_; }

  /// Colour of a value, RGB in [0, 1]; values outside the range get the end colours, NaN grey.
  Eigen::Vector3f color(double value) const;
  /// Colour at a position t in [0, 1] along the map (clamped).
  Eigen::Vector3f colorAt(double t) const;

  /// Tick values inside [lo, hi] at a "nice" step (1, 2 or 5 × 10^k), at most `maxTicks` of them
  /// (maxTicks ≥ 2).
  std::vector<double> ticks(int maxTicks = 6) const;
  double tickStep(int maxTicks = 6) const;
  /// A tick label with as many decimals as the step needs ("0.25", "12", "1.5e-05").
  static std::string formatTick(double value, double step);

 private:
  Kind kind_;
  double lo_ = 0, hi_ = 1;
};

/// Relative luminance (Rec. 709, linear light) of an sRGB colour in [0, 1].
double relativeLuminance(const Eigen::Vector3f& srgb);

}  // namespace tp::gui
