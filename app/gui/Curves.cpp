#include "Curves.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "io/AtomicFile.h"
#include "io/CurveCsv.h"

namespace tp::gui {

namespace {

constexpr const char* kPointColumns = "depth_um,force_uN,iterations,residual,converged,unloading";
// Per curve, repeated on each of its rows so that a table program can filter and group by them
// (empty for a measured curve, an unknown level or an error not estimated).
constexpr const char* kCurveColumns =
    "site_x_um,site_y_um,site_z_um,E_MPa,nu,h_um,p_MPa,probe_radius_um,mesh_level,mesh_error";
constexpr int kCurveColumnCount = 10;

std::string curveColumns(const NamedCurve& c) {
  if (c.measured) return std::string(kCurveColumnCount - 1, ',');
  char b[512];
  std::snprintf(b, sizeof b, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,", c.site.x(),
                c.site.y(), c.site.z(), c.params.youngModulus, c.params.poissonRatio,
                c.params.thickness, c.params.pressure, c.params.probeRadius);
  std::string out = b;
  if (c.meshLevel >= 0) out += std::to_string(c.meshLevel);
  out += ',';
  if (c.meshError >= 0) {
    std::snprintf(b, sizeof b, "%.6g", c.meshError);
    out += b;
  }
  return out;
}

std::string quoted(const std::string& name) {
  std::string out = "\"";
  for (char c : name) {
    if (c == '\n' || c == '\r') c = ' ';
    if (c == '"') out += '"';
    out += c;
  }
  return out + '"';
}

}  // namespace

std::string curveName(int siteNumber, const Eigen::Vector3d& site, const SimulationParams& p,
                      bool live) {
  char where[96];
  std::snprintf(where, sizeof where, "site %d (%.1f, %.1f, %.1f) µm", siteNumber, site.x(),
                site.y(), site.z());
  return std::string(where) + " · " + describe(p) + (live ? " · drag" : "");
}

std::string forceText(double force) {
  if (!std::isfinite(force)) return "—";
  if (std::abs(force) < 1e-6) return "0";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", force);
  return buf;
}

std::string meshErrorText(const NamedCurve& c) {
  if (c.measured) return "measured";
  if (c.meshError < 0) return "error not estimated";
  char b[64];
  std::snprintf(b, sizeof b, "±%.*f %%", c.meshError < 0.001 ? 2 : 1, 100 * c.meshError);
  return b;
}

std::string curvesCsv(const std::vector<NamedCurve>& curves) {
  std::string out;
  for (const NamedCurve& c : curves) {
    std::string line = "# " + quoted(c.name) + ": ";
    if (c.measured) {
      out += line + "measured (read from an experiment's file)\n";
      continue;
    }
    line += c.meshLevel >= 0 ? "mesh level " + std::to_string(c.meshLevel) : "mesh level unknown";
    if (c.meshError >= 0) {
      char at[64];
      std::snprintf(at, sizeof at, " at %g %s", c.meshErrorAt, c.meshErrorForce ? "uN" : "um");
      line += ", estimated discretisation error " + meshErrorText(c) + " of the " +
              (c.meshErrorForce ? "depth" : "force") + at + " (" + c.meshErrorMethod + ")";
    } else {
      line += ", discretisation error not estimated";
    }
    for (char& ch : line)
      if (ch == '\n' || ch == '\r') ch = ' ';
    out += line + "\n";
  }
  out += std::string("curve,") + kCurveColumns + ',' + kPointColumns + "\n";
  for (const NamedCurve& c : curves) {
    // tp::curveCsv writes the five point columns exactly; add the name, the curve's columns and
    // `unloading`.
    const std::string body = curveCsv(c.points);
    const std::string head = quoted(c.name) + ',' + curveColumns(c) + ',';
    size_t start = body.find('\n') + 1;  // past the header
    for (const CurvePoint& p : c.points) {
      const size_t end = body.find('\n', start);
      out += head + body.substr(start, end - start) + (p.unloading ? ",1\n" : ",0\n");
      start = end + 1;
    }
  }
  return out;
}

void writeCurvesCsv(const std::string& path, const std::vector<NamedCurve>& curves) {
  writeFileAtomically(path, curvesCsv(curves));
}

std::vector<std::pair<std::string, std::vector<CurvePoint>>> parseCurvesCsv(
    std::string_view text, const std::string& nameForErrors) {
  std::vector<std::pair<std::string, std::string>> bodies;  // name → point rows with a header
  size_t pos = 0;
  int line = 0;
  bool header = true;
  int skip = 0;  // the curve columns after the name, when the file has them
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view row = text.substr(pos, end - pos);
    pos = end + 1;
    ++line;
    if (!row.empty() && row.back() == '\r') row.remove_suffix(1);
    if (row.empty() || row.front() == '#') continue;
    if (header) {
      // This version's header, or the one before the curve columns (files of earlier versions).
      const std::string now = std::string("curve,") + kCurveColumns + ',' + kPointColumns;
      if (row == now)
        skip = kCurveColumnCount;
      else if (row != std::string("curve,") + kPointColumns)
        throw std::runtime_error(nameForErrors + ": line " + std::to_string(line) +
                                 ": expected the header '" + now + "'");
      header = false;
      continue;
    }
    std::string name;
    size_t i = 0;
    if (row.empty() || row[0] != '"')
      throw std::runtime_error(nameForErrors + ": line " + std::to_string(line) +
                               ": the curve name must be quoted");
    for (i = 1; i < row.size(); ++i) {
      if (row[i] == '"') {
        if (i + 1 < row.size() && row[i + 1] == '"') {
          name += '"';
          ++i;
          continue;
        }
        break;
      }
      name += row[i];
    }
    if (i + 1 >= row.size() || row[i + 1] != ',')
      throw std::runtime_error(nameForErrors + ": line " + std::to_string(line) +
                               ": expected a comma after the curve name");
    auto it = bodies.begin();
    while (it != bodies.end() && it->first != name) ++it;
    if (it == bodies.end()) {
      bodies.emplace_back(name, std::string(kPointColumns) + "\n");
      it = bodies.end() - 1;
    }
    size_t from = i + 2;  // past the name and its comma
    for (int k = 0; k < skip; ++k) {
      const size_t comma = row.find(',', from);
      if (comma == std::string_view::npos)
        throw std::runtime_error(nameForErrors + ": line " + std::to_string(line) + ": expected " +
                                 std::to_string(kCurveColumnCount) +
                                 " curve columns after the name");
      from = comma + 1;
    }
    it->second.append(row.substr(from));
    it->second += '\n';
  }
  std::vector<std::pair<std::string, std::vector<CurvePoint>>> out;
  for (const auto& [name, body] : bodies)
    out.emplace_back(name, parseCurveCsv(body, nameForErrors + " (curve '" + name + "')"));
  return out;
}

AxisScale axisScale(bool nondimensional, double meanCellSize, double youngModulus) {
  if (!nondimensional || !(meanCellSize > 0) || !(youngModulus > 0)) return {};
  return {1.0 / meanCellSize, 1.0 / (youngModulus * meanCellSize * meanCellSize)};
}

}  // namespace tp::gui
