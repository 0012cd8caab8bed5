#include "io/MeasuredCurve.h"

#include "io/TextFile.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>

namespace tp {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string trimmed(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = s.substr(1, s.size() - 2);
  return std::string(s);
}

// Splits a row at the table's delimiter (whitespace runs when it is ' ').
std::vector<std::string> split(const std::string& line, char delimiter) {
  std::vector<std::string> out;
  if (delimiter == ' ') {
    std::istringstream in(line);
    std::string w;
    while (in >> w) out.push_back(w);
    return out;
  }
  std::string field;
  for (char c : line) {
    if (c == delimiter) {
      out.push_back(trimmed(field));
      field.clear();
    } else {
      field += c;
    }
  }
  out.push_back(trimmed(field));
  return out;
}

bool parseNumber(const std::string& s, double& v) {
  std::string_view t = s;
  if (t.size() > 1 && t[0] == '+') t.remove_prefix(1);
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  return ec == std::errc() && end == t.data() + t.size();
}

// The unit in a header name: "depth (nm)", "force [uN]", "force_nN", "F/nN".
std::string unitOf(const std::string& header) {
  const auto open = header.find_first_of("([");
  if (open != std::string::npos) {
    const auto close = header.find_first_of(")]", open);
    if (close != std::string::npos) return trimmed(header.substr(open + 1, close - open - 1));
  }
  // After '_', '/' or a space only a known unit counts ("indentation depth" has none).
  const auto sep = header.find_last_of("_/ ");
  if (sep == std::string::npos) return {};
  const std::string u = trimmed(header.substr(sep + 1));
  return lengthUnitInMicrometres(u) > 0 || forceUnitInMicronewtons(u) > 0 ? u : std::string();
}

// The name without its unit decoration, lower case.
std::string bareName(const std::string& header) {
  std::string n = header.substr(0, header.find_first_of("(["));
  if (!unitOf(header).empty() && n.size() == header.size()) {
    const auto sep = header.find_last_of("_/ ");
    if (sep != std::string::npos) n = header.substr(0, sep);
  }
  return lower(trimmed(n));
}

}  // namespace

double lengthUnitInMicrometres(const std::string& unit) {
  const std::string u = unit;
  if (u == "m") return 1e6;
  if (u == "mm") return 1e3;
  if (u == "um" || u == "µm" || u == "μm" || u == "micron") return 1.0;
  if (u == "nm") return 1e-3;
  return 0;
}

double forceUnitInMicronewtons(const std::string& unit) {
  const std::string u = unit;
  if (u == "N") return 1e6;
  if (u == "mN") return 1e3;
  if (u == "uN" || u == "µN" || u == "μN") return 1.0;
  if (u == "nN") return 1e-3;
  if (u == "pN") return 1e-6;
  return 0;
}

MeasuredCurve parseMeasuredCurve(const std::string& text, const std::string& name,
                                 const MeasuredColumns& spec) {
  auto fail = [&](const std::string& msg) { throw std::runtime_error(name + ": " + msg); };
  // The rows, without comments and blank lines, with their line numbers.
  std::vector<std::pair<int, std::string>> rows;
  {
    std::istringstream in(text);
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const std::string t = trimmed(line);
      if (t.empty() || t[0] == '#') continue;
      rows.emplace_back(n, line);
    }
  }
  if (rows.empty()) fail("no rows (an empty table, or only comments)");
  // The delimiter: the first of tab, comma, semicolon in the first row, else whitespace.
  char delimiter = ' ';
  for (char d : {'\t', ',', ';'})
    if (rows[0].second.find(d) != std::string::npos) {
      delimiter = d;
      break;
    }
  std::vector<std::string> header = split(rows[0].second, delimiter);
  double probe = 0;
  const bool hasHeader = !header.empty() && !parseNumber(header[0], probe);
  const int columns = static_cast<int>(header.size());

  auto find = [&](const std::string& wanted, std::initializer_list<const char*> defaults,
                  int fallback, const char* what) {
    if (!wanted.empty()) {
      double pos = 0;
      if (parseNumber(wanted, pos)) {
        if (!(pos >= 1 && pos <= columns && pos == std::floor(pos)))
          fail(std::string(what) + " column " + wanted + " is not a column (the table has " +
               std::to_string(columns) + ")");
        return static_cast<int>(pos) - 1;
      }
      if (!hasHeader)
        fail(std::string(what) + " column '" + wanted + "' asked by name, but the table has no " +
             "header row: give its position (1, 2, ...)");
      for (int k = 0; k < columns; ++k)
        if (lower(header[k]) == lower(wanted) || bareName(header[k]) == lower(wanted)) return k;
      std::string names;
      for (const auto& h : header) names += (names.empty() ? "'" : ", '") + h + "'";
      fail(std::string("no ") + what + " column '" + wanted + "' (the columns are " + names + ")");
    }
    if (hasHeader)
      for (int k = 0; k < columns; ++k)
        for (const char* d : defaults)
          if (bareName(header[k]).rfind(d, 0) == 0) return k;
    if (fallback >= columns)
      fail(std::string("no ") + what + " column: the table has " + std::to_string(columns) +
           " column(s)");
    return fallback;
  };
  const int dc = find(spec.depth, {"depth", "indentation", "delta", "separation"}, 0, "depth");
  const int fc = find(spec.force, {"force", "f"}, dc == 1 ? 0 : 1, "force");
  if (dc == fc)
    fail("the depth and force columns are the same (column " + std::to_string(dc + 1) + ")");

  auto scale = [&](const std::string& given, int column, bool length) {
    const std::string unit = !given.empty() ? given : hasHeader ? unitOf(header[column]) : "";
    const char* what = length ? "depth" : "force";
    if (unit.empty())
      fail(std::string("the ") + what + " column's unit is not given: name it in the header " +
           "(e.g. '" + (length ? "depth (nm)" : "force (nN)") + "') or give --" + what + "-unit");
    const double f = length ? lengthUnitInMicrometres(unit) : forceUnitInMicronewtons(unit);
    if (!(f > 0))
      fail(std::string("unknown ") + what + " unit '" + unit + "' (" +
           (length ? "m, mm, um, µm, nm" : "N, mN, uN, µN, nN, pN") + ")");
    return f;
  };
  const double ds = scale(spec.depthUnit, dc, true), fs = scale(spec.forceUnit, fc, false);

  MeasuredCurve c;
  c.name = name;
  for (size_t r = hasHeader ? 1 : 0; r < rows.size(); ++r) {
    const auto& [line, row] = rows[r];
    const std::vector<std::string> f = split(row, delimiter);
    const std::string at = "line " + std::to_string(line) + ": ";
    if (static_cast<int>(f.size()) <= std::max(dc, fc))
      fail(at + std::to_string(f.size()) + " value(s), the columns need " +
           std::to_string(std::max(dc, fc) + 1));
    double d = 0, F = 0;
    if (!parseNumber(f[dc], d) || !std::isfinite(d))
      fail(at + "depth '" + f[dc] + "' is not a finite number");
    if (!parseNumber(f[fc], F) || !std::isfinite(F))
      fail(at + "force '" + f[fc] + "' is not a finite number");
    c.depth.push_back(d * ds);
    c.force.push_back(F * fs);
  }
  if (c.depth.size() < 2) fail("fewer than two data rows");
  return c;
}

MeasuredCurve readMeasuredCurve(const std::string& path, const MeasuredColumns& columns) {
  return parseMeasuredCurve(readTextFile(path, "curve"), path, columns);
}

}  // namespace tp
