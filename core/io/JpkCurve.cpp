#include "io/JpkCurve.h"

#include "io/TextFile.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace tp {

namespace {

bool parseNumber(std::string_view t, double& v) {
  if (t.size() > 1 && t[0] == '+') t.remove_prefix(1);
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  return ec == std::errc() && end == t.data() + t.size();
}

std::vector<std::string> words(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

}  // namespace

RawCurveReading indentationFromApproach(const std::vector<double>& height,
                                        const std::vector<double>& force, double k,
                                        const std::string& name, const RawCurveOptions& o) {
  auto fail = [&](const std::string& m) { throw std::runtime_error(name + ": " + m); };
  const size_t n = height.size();
  if (n != force.size() || n < 10) fail("an approach needs at least 10 points of height and force");
  if (!(k > 0) || !std::isfinite(k)) fail("the spring constant must be positive");
  RawCurveReading r;
  r.height = height;
  r.force = force;
  r.springConstant = k;
  // Baseline: least-squares line F = a + b h over the far part of the approach.
  const size_t nb = std::max<size_t>(5, static_cast<size_t>(o.baselineFraction * n));
  double sh = 0, sf = 0, shh = 0, shf = 0;
  for (size_t i = 0; i < nb; ++i) {
    sh += height[i];
    sf += force[i];
    shh += height[i] * height[i];
    shf += height[i] * force[i];
  }
  const double den = nb * shh - sh * sh;
  r.baselineSlope = den != 0 ? (nb * shf - sh * sf) / den : 0.0;
  r.baselineOffset = (sf - r.baselineSlope * sh) / nb;
  std::vector<double> f(n);
  for (size_t i = 0; i < n; ++i) f[i] = force[i] - (r.baselineOffset + r.baselineSlope * height[i]);
  double ss = 0;
  for (size_t i = 0; i < nb; ++i) ss += f[i] * f[i];
  r.noise = std::sqrt(ss / std::max<size_t>(1, nb - 2));

  size_t contact = 0;
  if (o.contactHeight) {
    r.contactEstimated = false;
    r.contactHeight = *o.contactHeight;
    const auto [lo, hi] = std::minmax_element(height.begin(), height.end());
    if (!(r.contactHeight >= *lo && r.contactHeight <= *hi))
      fail("the contact height " + std::to_string(r.contactHeight) + " um is outside the heights " +
           "of the approach (" + std::to_string(*lo) + " to " + std::to_string(*hi) + " um)");
    while (contact + 1 < n && height[contact] > r.contactHeight) ++contact;
  } else {
    // The deepest point must stand out of the noise; then back to where the force last sat at
    // or below the baseline.
    const double threshold = o.thresholdSigma * r.noise;
    if (!(f[n - 1] > threshold))
      fail("the force at the end of the approach (" + std::to_string(f[n - 1]) + " uN above the " +
           "baseline) does not rise above " + std::to_string(o.thresholdSigma) +
           " times the baseline noise (" + std::to_string(r.noise) + " uN): no contact found");
    size_t i = n - 1;
    while (i > 0 && f[i] > threshold) --i;  // the last point within the noise band
    while (i > 0 && f[i] > 0) --i;          // back to the baseline itself
    contact = i;
    r.contactHeight = height[contact];
  }
  r.curve.name = name;
  const double fc = f[contact];
  for (size_t i = contact; i < n; ++i) {
    const double F = f[i] - fc;
    const double delta = (r.contactHeight - height[i]) - F / k;
    r.curve.depth.push_back(delta);
    r.curve.force.push_back(F);
  }
  if (r.curve.depth.size() < 2) fail("fewer than two points after the contact point");
  return r;
}

bool looksLikeJpkText(const std::string& text) {
  return text.rfind("# TEXT EXPORT", 0) == 0 || (text.find("# segment:") != std::string::npos &&
                                                 text.find("# columns:") != std::string::npos);
}

RawCurveReading parseJpkForceCurve(const std::string& text, const std::string& name,
                                   const RawCurveOptions& options) {
  auto fail = [&](const std::string& m) { throw std::runtime_error(name + ": " + m); };
  std::istringstream in(text);
  std::string line, segment;
  std::map<std::string, std::string> header;  // the latest value of each key (segments repeat)
  std::vector<std::string> columns, units;
  std::vector<double> height, force;
  int hCol = -1, fCol = -1, lineNo = 0;
  double fScale = 0;
  bool inExtend = false, sawExtend = false;
  while (std::getline(in, line)) {
    ++lineNo;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (line[0] == '#') {
      const auto colon = line.find(':');
      if (colon == std::string::npos) continue;
      std::string key = line.substr(1, colon - 1);
      key.erase(0, key.find_first_not_of(' '));
      std::string value = line.substr(colon + 1);
      value.erase(0, value.find_first_not_of(' '));
      header[key] = value;
      if (key == "segment") {
        if (inExtend) break;  // the approach is over
        inExtend = value == "extend";
        sawExtend = sawExtend || inExtend;
        columns.clear();
        units.clear();
      } else if (key == "columns") {
        columns = words(value);
      } else if (key == "units") {
        units = words(value);
      }
      continue;
    }
    if (!inExtend) continue;
    if (hCol < 0) {  // the first data row of the extend segment: choose the columns
      auto find = [&](const char* c) {
        const auto it = std::find(columns.begin(), columns.end(), c);
        return it == columns.end() ? -1 : static_cast<int>(it - columns.begin());
      };
      hCol = find("measuredHeight");
      if (hCol < 0) hCol = find("height");
      fCol = find("vDeflection");
      if (hCol < 0 || fCol < 0)
        fail("line " + std::to_string(lineNo) + ": the extend segment has no height and " +
             "vDeflection columns (its columns: '" + header["columns"] + "')");
      if (units.size() != columns.size())
        fail("line " + std::to_string(lineNo) + ": the extend segment's units do not match its " +
             "columns");
      if (units[hCol] != "m") fail("the height is in '" + units[hCol] + "', expected m");
      double sensitivity = 0, spring = 0;
      parseNumber(header["sensitivity"], sensitivity);
      parseNumber(header["springConstant"], spring);
      const std::string& fu = units[fCol];
      if (fu == "N")
        fScale = 1e6;  // µN
      else if (fu == "m")
        fScale = spring * 1e6;  // deflection (m) × k (N/m) → N → µN
      else if (fu == "V")
        fScale = sensitivity * spring * 1e6;
      else
        fail("the deflection is in '" + fu + "', expected N, m or V");
      if (!(fScale > 0)) fail("the header has no usable sensitivity or springConstant");
    }
    const auto w = words(line);
    if (static_cast<int>(w.size()) <= std::max(hCol, fCol))
      fail("line " + std::to_string(lineNo) + ": " + std::to_string(w.size()) +
           " value(s), the columns need " + std::to_string(std::max(hCol, fCol) + 1));
    double h = 0, F = 0;
    if (!parseNumber(w[hCol], h) || !parseNumber(w[fCol], F) || !std::isfinite(h) ||
        !std::isfinite(F))
      fail("line " + std::to_string(lineNo) + ": '" + w[hCol] + "' or '" + w[fCol] +
           "' is not a finite number");
    height.push_back(h * 1e6);
    force.push_back(F * fScale);
  }
  if (!sawExtend) fail("no extend segment (not a JPK force-curve text export?)");
  double spring = 0;
  if (!parseNumber(header["springConstant"], spring) || !(spring > 0))
    fail("the header has no springConstant");
  return indentationFromApproach(height, force, spring, name, options);
}

RawCurveReading readJpkForceCurve(const std::string& path, const RawCurveOptions& options) {
  return parseJpkForceCurve(readTextFile(path, "curve"), path, options);
}

}  // namespace tp
