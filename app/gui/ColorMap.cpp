#include "ColorMap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace tp::gui {

namespace {

using Stop = std::array<unsigned char, 3>;

// Viridis (van der Walt & Smith, matplotlib) sampled at t = 0, 1/8, …, 1.
constexpr std::array<Stop, 9> kViridis = {{{68, 1, 84},
                                           {71, 45, 123},
                                           {59, 82, 139},
                                           {44, 114, 142},
                                           {33, 145, 140},
                                           {40, 174, 128},
                                           {94, 201, 98},
                                           {173, 220, 48},
                                           {253, 231, 37}}};
// Moreland's cool–warm diverging map sampled at t = 0, 1/4, 1/2, 3/4, 1.
constexpr std::array<Stop, 5> kCoolWarm = {
    {{59, 76, 192}, {141, 176, 254}, {221, 221, 221}, {244, 154, 123}, {180, 4, 38}}};

template <size_t N>
Eigen::Vector3f sample(const std::array<Stop, N>& stops, double t) {
  const double x = std::clamp(t, 0.0, 1.0) * (N - 1);
  const size_t i = std::min(static_cast<size_t>(x), N - 2);
  const float f = static_cast<float>(x - i);
  const Eigen::Vector3f a(stops[i][0], stops[i][1], stops[i][2]);
  const Eigen::Vector3f b(stops[i + 1][0], stops[i + 1][1], stops[i + 1][2]);
  return ((1 - f) * a + f * b) / 255.0f;
}

double linear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

}  // namespace

ColorMap::ColorMap(Kind kind) : kind_(kind) {}

const char* ColorMap::name(Kind kind) {
  return kind == Kind::Viridis ? "viridis" : "cool–warm (diverging)";
}

const char* ColorMap::key(Kind kind) {
  return kind == Kind::Viridis ? "viridis" : "coolwarm";
}

void ColorMap::setRange(double lo, double hi) {
  if (!std::isfinite(lo)) lo = 0;
  if (!std::isfinite(hi)) hi = lo;
  if (!(hi > lo)) hi = lo + (lo != 0 ? 0.1 * std::abs(lo) : 1.0);
  lo_ = lo;
  hi_ = hi;
}

Eigen::Vector3f ColorMap::colorAt(double t) const {
  return kind_ == Kind::Viridis ? sample(kViridis, t) : sample(kCoolWarm, t);
}

Eigen::Vector3f ColorMap::color(double value) const {
  if (std::isnan(value)) return Eigen::Vector3f::Constant(0.5f);
  return colorAt((value - lo_) / (hi_ - lo_));
}

double ColorMap::tickStep(int maxTicks) const {
  // The smallest step of the 1–2–5 series that puts at most maxTicks ticks in the range,
  // starting from range/maxTicks (range/(maxTicks − 1) would often leave only two or three).
  maxTicks = std::max(2, maxTicks);
  const double range = hi_ - lo_;
  const double rough = range / maxTicks;
  double mag = std::pow(10.0, std::floor(std::log10(rough)));
  auto count = [&](double s) { return std::floor(hi_ / s + 1e-9) - std::ceil(lo_ / s - 1e-9) + 1; };
  for (int i = 0; i < 40; ++i, mag *= 10)
    for (double m : {1.0, 2.0, 5.0}) {
      const double step = m * mag;
      if (step >= rough * (1 - 1e-9) && count(step) <= maxTicks) return step;
    }
  return range;
}

std::vector<double> ColorMap::ticks(int maxTicks) const {
  const double step = tickStep(maxTicks);
  std::vector<double> out;
  const double first = std::ceil(lo_ / step - 1e-9);
  const double last = std::floor(hi_ / step + 1e-9);
  for (double k = first; k <= last && out.size() < 64; k += 1) {
    const double v = k * step;
    out.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
  }
  return out;
}

std::string ColorMap::formatTick(double value, double step) {
  char buf[64];
  const double a = std::max(std::abs(value), step);
  if (a >= 1e5 || a < 1e-3) {
    std::snprintf(buf, sizeof buf, "%.3g", value);
  } else {
    // Enough decimals to tell neighbouring ticks apart: 0.25 needs two, 0.2 one.
    int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
    const double scaled = step * std::pow(10.0, decimals);
    if (std::abs(scaled - std::round(scaled)) > 1e-6) ++decimals;
    std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  }
  return buf;
}

double relativeLuminance(const Eigen::Vector3f& srgb) {
  return 0.2126 * linear(srgb.x()) + 0.7152 * linear(srgb.y()) + 0.0722 * linear(srgb.z());
}

}  // namespace tp::gui
