#include "io/Centroids.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <tuple>
#include <stdexcept>

namespace tp {

namespace {

std::vector<std::string> splitRow(const std::string& line, char delim) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') {
      quoted = !quoted;
      continue;
    }
    if (c == delim && !quoted) {
      out.push_back(cur);
      cur.clear();
      continue;
    }
    if (c != '\r') cur += c;
  }
  out.push_back(cur);
  for (auto& s : out) {  // trim spaces
    const auto b = s.find_first_not_of(" \t");
    const auto e = s.find_last_not_of(" \t");
    s = b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
  }
  return out;
}

bool isPosition(const std::string& s) {
  return !s.empty() && s.find_first_not_of("0123456789") == std::string::npos;
}

}  // namespace

CentroidColumns CentroidColumns::parse(const std::string& spec) {
  const auto parts = splitRow(spec, ',');
  if (parts.size() != 4 && parts.size() != 5)
    throw std::invalid_argument("column spec '" + spec +
                                "': expected label,x,y,z or label,x,y,z,volume");
  for (int k = 1; k <= 3; ++k)
    if (parts[k].empty())
      throw std::invalid_argument("column spec '" + spec + "': " + "xyz"[k - 1] +
                                  " needs a column (a header name or a 1-based position); only "
                                  "the label and the volume may be left empty");
  CentroidColumns c;
  c.label = parts[0];
  c.x = parts[1];
  c.y = parts[2];
  c.z = parts[3];
  if (parts.size() == 5) c.volume = parts[4];
  return c;
}

CentroidTable readCentroids(const std::string& path, const CentroidColumns& cols) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the file");
  return readCentroids(in, path, cols);
}

CentroidTable readCentroids(std::istream& in, const std::string& name, const CentroidColumns& cols) {
  std::string header;
  int lineNo = 0;
  while (std::getline(in, header)) {
    ++lineNo;
    if (header.find_first_not_of(" \t\r") != std::string::npos) break;
  }
  if (header.empty()) throw std::runtime_error(name + ": empty file");
  const char delim = header.find('\t') != std::string::npos   ? '\t'
                     : header.find(';') != std::string::npos && header.find(',') == std::string::npos
                         ? ';'
                         : ',';
  const auto names = splitRow(header, delim);
  auto column = [&](const std::string& want, const char* role, bool optional = true) -> int {
    if (want.empty()) {
      if (optional) return -1;
      throw std::runtime_error(name + ": no column given for " + role);
    }
    if (isPosition(want)) {
      // Positions are digits only; a long one overflows int, so compare as text first.
      const int pos = want.size() > 6 ? 0 : std::stoi(want);
      if (pos < 1 || pos > static_cast<int>(names.size()))
        throw std::runtime_error(name + ": column " + want + " for " + role + " does not exist (the header has " +
                                 std::to_string(names.size()) + " columns)");
      return pos - 1;
    }
    for (size_t i = 0; i < names.size(); ++i)
      if (names[i] == want) return static_cast<int>(i);
    std::string have;
    for (const auto& n : names) have += (have.empty() ? "" : ", ") + n;
    throw std::runtime_error(name + ": no column named '" + want + "' for " + role +
                             " (columns: " + have + ")");
  };
  const int cl = column(cols.label, "the label"), cx = column(cols.x, "x", false),
            cy = column(cols.y, "y", false), cz = column(cols.z, "z", false),
            cv = column(cols.volume, "the volume");
  CentroidTable t;
  std::set<int> seen;
  std::vector<int> rowLine;  // file line of each row, for messages
  std::string line;
  while (std::getline(in, line)) {
    ++lineNo;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const auto f = splitRow(line, delim);
    auto number = [&](int c, const char* role) {
      if (c >= static_cast<int>(f.size()))
        throw std::runtime_error(name + ":" + std::to_string(lineNo) + ": missing " + role +
                                 " (column " + std::to_string(c + 1) + ")");
      double v = 0;
      const std::string& s = f[c];
      const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
      if (r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(v))
        throw std::runtime_error(name + ":" + std::to_string(lineNo) + ": " + role + " '" + s +
                                 "' (column " + std::to_string(c + 1) + ") is not a finite number");
      return v;
    };
    int label = static_cast<int>(t.points.size()) + 1;
    if (cl >= 0) {
      const double v = number(cl, "label");
      if (v != std::floor(v) || std::abs(v) > 2e9)
        throw std::runtime_error(name + ":" + std::to_string(lineNo) + ": label '" + f[cl] +
                                 "' is not an integer");
      label = static_cast<int>(v);
    }
    if (!seen.insert(label).second)
      throw std::runtime_error(name + ":" + std::to_string(lineNo) + ": label " +
                               std::to_string(label) + " appears twice");
    t.labels.push_back(label);
    rowLine.push_back(lineNo);
    auto coordinate = [&](int c, const char* role) {
      const double v = number(c, role);
      if (std::abs(v) > kMaxCoordinate)  // found by fuzz_centroids: CGAL asserted on 1e74
        throw std::runtime_error(name + ":" + std::to_string(lineNo) + ": " + role + " '" + f[c] +
                                 "' (column " + std::to_string(c + 1) + ") is beyond ±1e6 µm");
      return v;
    };
    t.points.emplace_back(coordinate(cx, "x"), coordinate(cy, "y"), coordinate(cz, "z"));
    if (cv >= 0) t.volumes.push_back(number(cv, "volume"));
  }
  if (t.points.size() < 4)
    throw std::runtime_error(name + ": needs at least 4 centroids (found " +
                             std::to_string(t.points.size()) + ")");
  // Two cells at one point have no Voronoi wall between them: name both rows.
  std::vector<int> order(t.points.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  auto lexLess = [&](int a, int b) {
    const Vec3 &p = t.points[a], &q = t.points[b];
    return std::tie(p.x(), p.y(), p.z()) < std::tie(q.x(), q.y(), q.z());
  };
  std::sort(order.begin(), order.end(), lexLess);
  for (size_t k = 1; k < order.size(); ++k) {
    const int a = order[k - 1], b = order[k];
    if (t.points[a] == t.points[b]) {
      const int first = std::min(a, b), second = std::max(a, b);
      throw std::runtime_error(name + ":" + std::to_string(rowLine[second]) + ": cell " +
                               std::to_string(t.labels[second]) + " has the same centroid as cell " +
                               std::to_string(t.labels[first]) + " (line " +
                               std::to_string(rowLine[first]) + "): two cells cannot share a centroid");
    }
  }
  return t;
}

}  // namespace tp
