#include "experiment/Map.h"

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <numeric>
#include <set>
#include <sstream>
#include <thread>

#include "experiment/Analysis.h"
#include "io/AtomicFile.h"
#include "io/TextFile.h"
#include "io/TissueFiles.h"
#include "io/Vtu.h"
#include "mechanics/Contact.h"
#include "solver/CholmodSolver.h"
#include "solver/OpenMpRegions.h"

namespace tp {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

bool clamped(const CellComplex& cc, int v) { return !cc.fixed.empty() && cc.fixed[v] != 0; }

bool fullyClampedTriangle(const CellComplex& cc, int t) {
  const auto& tri = cc.triangles[t];
  return clamped(cc, tri[0]) && clamped(cc, tri[1]) && clamped(cc, tri[2]);
}

double triangleArea(const CellComplex& cc, int t) {
  const auto& tri = cc.triangles[t];
  return 0.5 * (cc.rest.col(tri[1]) - cc.rest.col(tri[0]))
                   .cross(cc.rest.col(tri[2]) - cc.rest.col(tri[0]))
                   .norm();
}

Vec3 closestOnSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double l2 = ab.squaredNorm();
  const double s = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return a + s * ab;
}

std::string shortNumber(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// A table cell: %.6g, empty for NaN (not computed).
std::string cell(double v) { return std::isfinite(v) ? shortNumber(v) : std::string(); }

// A CSV field: quoted when it holds a comma, quote or line break.
std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

json finiteOrNull(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

double numberOrNaN(const json& j, const char* key, const std::string& file) {
  if (!j.contains(key)) throw std::runtime_error(file + ": no '" + key + "'");
  const json& v = j.at(key);
  if (v.is_null()) return std::numeric_limits<double>::quiet_NaN();
  if (!v.is_number()) throw std::runtime_error(file + ": '" + key + "' is not a number");
  return v.get<double>();
}

int intAt(const json& j, const char* key, const std::string& file) {
  if (!j.contains(key) || !j.at(key).is_number_integer())
    throw std::runtime_error(file + ": '" + key + "' must be an integer");
  const auto v = j.at(key).get<long long>();
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    throw std::runtime_error(file + ": '" + key + "' is out of range");
  return static_cast<int>(v);
}

std::string stringAt(const json& j, const char* key, const std::string& file) {
  if (!j.contains(key) || !j.at(key).is_string())
    throw std::runtime_error(file + ": '" + key + "' must be a string");
  return j.at(key).get<std::string>();
}

json vecJson(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

Vec3 vecAt(const json& j, const char* key, const std::string& file) {
  if (!j.contains(key) || !j.at(key).is_array() || j.at(key).size() != 3)
    throw std::runtime_error(file + ": '" + key + "' must be three numbers");
  Vec3 v;
  for (int k = 0; k < 3; ++k) {
    const json& c = j.at(key)[k];
    if (c.is_null()) {
      v[k] = std::numeric_limits<double>::quiet_NaN();
    } else {
      if (!c.is_number()) throw std::runtime_error(file + ": '" + key + "' must be three numbers");
      v[k] = c.get<double>();
    }
  }
  return v;
}

json settingsToJson(const ExperimentSettings& s) {
  const IndentationSettings& i = s.indentation;
  json j;
  j["E_MPa"] = s.material.youngModulus;
  j["nu"] = s.material.poissonRatio;
  j["h_um"] = s.material.thickness;
  j["bending"] = toString(s.material.bending);
  j["junctions"] = toString(s.material.junctions);
  j["p_MPa"] = s.pressure;
  j["probe_radius_um"] = i.probeRadius;
  j["axis"] = i.axis ? vecJson(*i.axis) : json(nullptr);
  j["control"] = i.control == Control::Force ? "force" : "depth";
  j["end"] = i.control == Control::Force ? i.maxForce : i.maxDepth;
  j["steps"] = i.steps;
  j["predictor"] = i.predictor;
  j["mesh"] = s.mesh.automatic ? json("auto") : json(s.mesh.level);
  j["mesh_tolerance"] = s.mesh.tolerance;
  if (s.mesh.junctionBand) j["junction_band"] = true;  // absent when off: older plans still match
  // Absent at the stress picture's panels, which every plan before this key had.
  if (s.mesh.panelCells != MeshSettings::kStressPanelCells)
    j["mesh_panel_cells"] = s.mesh.panelCells;
  j["newton_tolerance"] = s.solver.tolerance;
  return j;
}

std::string taskFileName(int task) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "task-%06d.json", task);
  return buf;
}

std::string valueHeader(const std::string& name) {
  if (name == "E") return "E_MPa";
  if (name == "nu") return "nu";
  if (name == "h") return "h_um";
  if (name == "p") return "p_MPa";
  return "probe_radius_um";
}

// One line of the run log, appended (a line is written whole by one write call).
void appendLog(const std::string& dir, const std::string& line) {
  std::ofstream out(fs::path(dir) / "run.log", std::ios::app);
  out << line << '\n';
}

std::string nowStamp() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

// Writes the table (and for a map the surface) into `dir`, all or nothing.
std::vector<std::string> writeOutputs(const std::string& dir, const CellComplex& cc,
                                      const MapPlan& plan, const std::vector<TaskResult>& results) {
  std::vector<std::pair<std::string, std::function<void(std::ostream&)>>> files;
  const std::string table = (fs::path(dir) / "map.csv").string();
  files.emplace_back(table, [&](std::ostream& o) { o << mapTable(plan, results); });
  std::vector<std::string> written{table};
  // The same as JSON, at full precision: the plan and every task's result in task order.
  const std::string all = (fs::path(dir) / "map.json").string();
  files.emplace_back(all, [&](std::ostream& o) {
    json j;
    j["plan"] = plan.toJson();
    json rows = json::array();
    for (const auto& r : results) rows.push_back(r.toJson());
    j["results"] = rows;
    o << j.dump(1) << "\n";
  });
  written.push_back(all);
  if (plan.vary.empty()) {
    const std::string surface = (fs::path(dir) / "map-surface.vtu").string();
    files.emplace_back(surface, [&](std::ostream& o) { o << mapSurfaceVtu(cc, plan, results); });
    written.push_back(surface);
  }
  writeFilesAtomically(files);
  return written;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Sites

std::string toString(SiteKind kind) {
  switch (kind) {
    case SiteKind::CellMiddle: return "cells";
    case SiteKind::Junction: return "junctions";
    case SiteKind::Grid: return "grid";
    case SiteKind::Listed: return "list";
  }
  return "list";
}

SiteKind parseSiteKind(const std::string& word) {
  for (SiteKind k : {SiteKind::CellMiddle, SiteKind::Junction, SiteKind::Grid, SiteKind::Listed})
    if (toString(k) == word) return k;
  throw std::invalid_argument("unknown kind of sites '" + word +
                              "' (choose cells, junctions, grid or list)");
}

std::vector<MapSite> cellMiddleSites(const CellComplex& cc) {
  // Each cell's outer wall: of its walls on the outer surface, the one with the most free area
  // (the periclinal wall of an L1 cell), ties (within 1e-9) to the highest centre.
  struct WallArea {
    std::vector<int> triangles;
    double area = 0;
    Vec3 centre = Vec3::Zero();  // area-weighted
  };
  std::vector<WallArea> walls(cc.wallCount());
  for (int t = 0; t < cc.triangleCount(); ++t) {
    const Wall& w = cc.walls[cc.triangleWall[t]];
    if (w.neighbor >= 0 || w.cell < 0 || fullyClampedTriangle(cc, t)) continue;
    const auto& tri = cc.triangles[t];
    const double a = triangleArea(cc, t);
    WallArea& wa = walls[cc.triangleWall[t]];
    wa.triangles.push_back(t);
    wa.area += a;
    wa.centre += a * (cc.rest.col(tri[0]) + cc.rest.col(tri[1]) + cc.rest.col(tri[2])) / 3.0;
  }
  std::vector<int> chosen(cc.cellCount(), -1);
  for (int w = 0; w < cc.wallCount(); ++w) {
    if (!(walls[w].area > 0)) continue;
    walls[w].centre /= walls[w].area;
    int& c = chosen[cc.walls[w].cell];
    if (c < 0) {
      c = w;
      continue;
    }
    const double tie = 1e-9 * std::max(walls[w].area, walls[c].area);
    if (walls[w].area > walls[c].area + tie ||
        (std::abs(walls[w].area - walls[c].area) <= tie && walls[w].centre.z() > walls[c].centre.z()))
      c = w;
  }
  std::vector<MapSite> sites;
  for (int c = 0; c < cc.cellCount(); ++c) {
    if (chosen[c] < 0) continue;
    const WallArea& wa = walls[chosen[c]];
    double best = std::numeric_limits<double>::infinity();
    Vec3 point = wa.centre;
    for (int t : wa.triangles) {
      const auto& tri = cc.triangles[t];
      Vec3 y;
      const double d2 = pointTriangleDistance2(wa.centre, cc.rest.col(tri[0]), cc.rest.col(tri[1]),
                                               cc.rest.col(tri[2]), nullptr, nullptr, nullptr, &y);
      if (d2 < best) {
        best = d2;
        point = y;
      }
    }
    sites.push_back({SiteKind::CellMiddle, "cell " + std::to_string(cc.cellLabels[c]), point});
  }
  return sites;
}

std::vector<MapSite> junctionSites(const CellComplex& cc) {
  // Undirected edges of free outer triangles → the cells whose outer walls hold them.
  std::map<std::pair<int, int>, std::set<int>> edgeCells;
  for (int t = 0; t < cc.triangleCount(); ++t) {
    const Wall& w = cc.walls[cc.triangleWall[t]];
    if (w.neighbor >= 0 || w.cell < 0) continue;
    const auto& tri = cc.triangles[t];
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      if (clamped(cc, a) && clamped(cc, b)) continue;
      edgeCells[{std::min(a, b), std::max(a, b)}].insert(w.cell);
    }
  }
  std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> junctions;  // cell pair → edges
  for (const auto& [edge, cells] : edgeCells) {
    if (cells.size() != 2) continue;  // inside one wall, or a point where three cells meet
    junctions[{*cells.begin(), *cells.rbegin()}].push_back(edge);
  }
  std::vector<MapSite> sites;
  for (const auto& [pair, edges] : junctions) {
    Vec3 centre = Vec3::Zero();
    double length = 0;
    for (const auto& [a, b] : edges) {
      const double l = (cc.rest.col(a) - cc.rest.col(b)).norm();
      centre += l * 0.5 * (cc.rest.col(a) + cc.rest.col(b));
      length += l;
    }
    if (!(length > 0)) continue;
    centre /= length;
    double best = std::numeric_limits<double>::infinity();
    Vec3 point = centre;
    for (const auto& [a, b] : edges) {
      const Vec3 y = closestOnSegment(centre, cc.rest.col(a), cc.rest.col(b));
      if ((y - centre).squaredNorm() < best) {
        best = (y - centre).squaredNorm();
        point = y;
      }
    }
    sites.push_back({SiteKind::Junction,
                     "cells " + std::to_string(cc.cellLabels[pair.first]) + "|" +
                         std::to_string(cc.cellLabels[pair.second]),
                     point});
  }
  return sites;
}

std::vector<MapSite> gridSites(const CellComplex& cc, double spacing) {
  if (!(spacing > 0) || !std::isfinite(spacing))
    throw std::invalid_argument("the grid spacing must be a positive number of um (got " +
                                shortNumber(spacing) + ")");
  std::vector<int> up;  // free outer triangles facing upwards
  Eigen::AlignedBox2d box;
  for (int t = 0; t < cc.triangleCount(); ++t) {
    if (!cc.isOuterTriangle(t) || fullyClampedTriangle(cc, t)) continue;
    const auto& tri = cc.triangles[t];
    Vec3 n = (cc.rest.col(tri[1]) - cc.rest.col(tri[0]))
                 .cross(cc.rest.col(tri[2]) - cc.rest.col(tri[0]));
    if (!(n.norm() > 0)) continue;
    n.normalize();
    if (cc.walls[cc.triangleWall[t]].cell < 0) n = n.cwiseAbs();  // an open sheet: either side
    if (n.z() < 0.1) continue;                                   // steeper than ~84°
    up.push_back(t);
    for (int k = 0; k < 3; ++k) box.extend(cc.rest.col(tri[k]).head<2>());
  }
  std::vector<MapSite> sites;
  if (up.empty()) return sites;
  const Eigen::Vector2d c = box.center();
  const int nx = static_cast<int>(std::floor(0.5 * box.sizes().x() / spacing));
  const int ny = static_cast<int>(std::floor(0.5 * box.sizes().y() / spacing));
  if (static_cast<double>(2 * nx + 1) * (2 * ny + 1) > 1e6)
    throw std::invalid_argument("a grid spacing of " + shortNumber(spacing) + " um gives over a million "
                                "grid points on this tissue: choose a larger spacing");
  for (int j = -ny; j <= ny; ++j)
    for (int i = -nx; i <= nx; ++i) {
      const Eigen::Vector2d q = c + spacing * Eigen::Vector2d(i, j);
      double top = -std::numeric_limits<double>::infinity();
      for (int t : up) {
        const auto& tri = cc.triangles[t];
        const Vec3 a = cc.rest.col(tri[0]), b = cc.rest.col(tri[1]), d = cc.rest.col(tri[2]);
        // Barycentric coordinates of q in the triangle's projection onto the xy plane.
        const double det = (b.x() - a.x()) * (d.y() - a.y()) - (d.x() - a.x()) * (b.y() - a.y());
        if (std::abs(det) < 1e-300) continue;
        const double u = ((q.x() - a.x()) * (d.y() - a.y()) - (d.x() - a.x()) * (q.y() - a.y())) / det;
        const double v = ((b.x() - a.x()) * (q.y() - a.y()) - (q.x() - a.x()) * (b.y() - a.y())) / det;
        if (u < -1e-12 || v < -1e-12 || u + v > 1 + 1e-12) continue;
        top = std::max(top, a.z() + u * (b.z() - a.z()) + v * (d.z() - a.z()));
      }
      if (std::isfinite(top))
        sites.push_back({SiteKind::Grid, "grid " + std::to_string(i) + "," + std::to_string(j),
                         Vec3(q.x(), q.y(), top)});
    }
  return sites;
}

std::vector<MapSite> readSiteList(const std::string& path) {
  const std::string text = readTextFile(path, "site list");
  std::istringstream in(text);
  std::string line;
  std::vector<MapSite> sites;
  int lineNo = 0;
  bool header = true;  // a first line that is not numbers is a header
  while (std::getline(in, line)) {
    ++lineNo;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    for (char& c : line)
      if (c == ',' || c == ';' || c == '\t') c = ' ';
    std::istringstream fields(line);
    std::vector<std::string> words;
    for (std::string w; fields >> w;) words.push_back(w);
    if (words.empty()) continue;
    const bool first = header;
    header = false;
    std::vector<double> v;
    bool numeric = true;
    for (const auto& w : words) {
      try {
        size_t used = 0;
        const double x = std::stod(w, &used);
        if (used != w.size()) throw std::invalid_argument(w);
        v.push_back(x);
      } catch (const std::exception&) {
        numeric = false;
        if (!first)
          throw std::runtime_error(path + ":" + std::to_string(lineNo) + ": '" + w +
                                   "' is not a number (expected x,y,z in um)");
      }
    }
    if (!numeric) continue;  // the header
    if (v.size() != 3)
      throw std::runtime_error(path + ":" + std::to_string(lineNo) + ": expected x,y,z, found " +
                               std::to_string(v.size()) + " number(s)");
    for (double x : v)
      if (!std::isfinite(x) || std::abs(x) > kMaxCoordinate)
        throw std::runtime_error(path + ":" + std::to_string(lineNo) + ": '" + shortNumber(x) +
                                 "' is not a coordinate (finite, at most 1e6 um)");
    sites.push_back({SiteKind::Listed, "line " + std::to_string(lineNo), Vec3(v[0], v[1], v[2])});
  }
  if (sites.empty()) throw std::runtime_error(path + ": no site (expected lines of x,y,z in um)");
  return sites;
}

void checkSitesNearSurface(const CellComplex& cc, const std::vector<MapSite>& sites,
                           const std::string& source) {
  const double cell = meanCellSize(cc);
  std::vector<int> outer;
  for (int t = 0; t < cc.triangleCount(); ++t)
    if (cc.isOuterTriangle(t) && !fullyClampedTriangle(cc, t)) outer.push_back(t);
  for (const auto& s : sites) {
    double best = std::numeric_limits<double>::infinity();
    for (int t : outer) {
      const auto& tri = cc.triangles[t];
      best = std::min(best, pointTriangleDistance2(s.point, cc.rest.col(tri[0]), cc.rest.col(tri[1]),
                                                   cc.rest.col(tri[2]), nullptr, nullptr, nullptr));
    }
    best = std::sqrt(best);
    if (!(best <= cell)) {
      std::ostringstream o;
      o << source << " " << s.label << ": the site (" << s.point.x() << ", " << s.point.y() << ", "
        << s.point.z() << ") um is " << shortNumber(best) << " um from the tissue's free outer surface, "
        << "more than a cell (" << shortNumber(cell) << " um)";
      throw std::invalid_argument(o.str());
    }
  }
}

std::vector<MapSite> mapSites(const CellComplex& cc, const std::vector<SiteKind>& kinds,
                              double gridSpacing, const std::string& siteList, double probeRadius,
                              std::vector<MapSite>* leftOut) {
  std::vector<MapSite> sites;
  for (SiteKind kind : kinds) {
    std::vector<MapSite> more;
    switch (kind) {
      case SiteKind::CellMiddle:
        more = cellMiddleSites(cc);
        break;
      case SiteKind::Junction:
        more = junctionSites(cc);
        break;
      case SiteKind::Grid:
        try {
          more = gridSites(cc, std::isnan(gridSpacing) ? meanCellSize(cc) : gridSpacing);
        } catch (const std::invalid_argument& e) {
          throw std::invalid_argument(std::string("--grid-spacing: ") + e.what());
        }
        break;
      case SiteKind::Listed:
        if (siteList.empty()) throw std::invalid_argument("--sites list needs --site-list FILE");
        more = readSiteList(siteList);
        checkSitesNearSurface(cc, more, siteList);
        break;
    }
    for (MapSite& site : more) {
      const bool onBase = kind != SiteKind::Listed && std::isfinite(probeRadius) &&
                          !clampedMaterialWithin(cc, site.point, probeRadius).empty();
      if (!onBase)
        sites.push_back(std::move(site));
      else if (leftOut)
        leftOut->push_back(std::move(site));
    }
  }
  return sites;
}

// ---------------------------------------------------------------------------------------------
// Sweeps

Variation parseVariation(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::invalid_argument("--vary '" + text + "': expected NAME=A:B:N or NAME=V1,V2,...");
  Variation v;
  v.name = text.substr(0, eq);
  ExperimentSettings probe;
  applyVariation(probe, v.name, 1.0);  // throws for an unknown name
  const std::string rest = text.substr(eq + 1);
  auto num = [&](const std::string& w) {
    try {
      size_t used = 0;
      const double x = std::stod(w, &used);
      if (used != w.size() || !std::isfinite(x)) throw std::invalid_argument(w);
      return x;
    } catch (const std::exception&) {
      throw std::invalid_argument("--vary '" + text + "': '" + w + "' is not a number");
    }
  };
  std::vector<std::string> parts;
  const char sep = rest.find(':') != std::string::npos ? ':' : ',';
  std::stringstream ss(rest);
  for (std::string w; std::getline(ss, w, sep);) parts.push_back(w);
  if (sep == ':') {
    if (parts.size() != 3)
      throw std::invalid_argument("--vary '" + text + "': a range is A:B:N (N values from A to B)");
    const double a = num(parts[0]), b = num(parts[1]);
    const double n = num(parts[2]);
    if (n < 1 || n > 1000 || n != std::floor(n))
      throw std::invalid_argument("--vary '" + text + "': N must be a whole number 1-1000");
    const int count = static_cast<int>(n);
    if (count == 1 && a != b)
      throw std::invalid_argument("--vary '" + text + "': one value cannot span " + parts[0] +
                                  " to " + parts[1]);
    for (int k = 0; k < count; ++k)
      v.values.push_back(count == 1 ? a : a + (b - a) * k / (count - 1));
  } else {
    for (const auto& w : parts) v.values.push_back(num(w));
  }
  if (v.values.empty()) throw std::invalid_argument("--vary '" + text + "': no value");
  for (double x : v.values) {  // each value must make valid settings
    ExperimentSettings s;
    applyVariation(s, v.name, x);
    try {
      s.validate();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("--vary '" + text + "': " + e.what());
    }
  }
  return v;
}

ExperimentSettings mapSettings(ExperimentSettings indentation) {
  indentation.mesh.panelCells = MeshSettings::kForcePanelCells;
  return indentation;
}

void applyVariation(ExperimentSettings& s, const std::string& name, double value) {
  if (name == "E") s.material.youngModulus = value;
  else if (name == "nu") s.material.poissonRatio = value;
  else if (name == "h") s.material.thickness = value;
  else if (name == "p") s.pressure = value;
  else if (name == "probe-radius") s.indentation.probeRadius = value;
  else
    throw std::invalid_argument("cannot vary '" + name +
                                "' (choose E, nu, h, p or probe-radius)");
}

// ---------------------------------------------------------------------------------------------
// The plan

void MapPlan::checkSize() const {
  double n = static_cast<double>(sites.size());
  for (const auto& v : vary) n *= static_cast<double>(v.values.size());
  if (n > kMaxTasks)
    throw std::invalid_argument("the plan has " + shortNumber(n) + " tasks (sites x parameter sets), " +
                                "more than " + shortNumber(kMaxTasks) + ": vary fewer values or sites");
}

double MapPlan::largestProbeRadius() const {
  double r = settings.indentation.probeRadius;
  for (const Variation& v : vary)
    if (v.name == "probe-radius")
      for (double x : v.values) r = std::max(r, x);
  return r;
}

int MapPlan::parameterSets() const {
  int n = 1;
  for (const auto& v : vary) n *= static_cast<int>(v.values.size());
  return n;
}

const MapSite& MapPlan::site(int task) const {
  return sites.at(static_cast<size_t>(task) % sites.size());
}

std::vector<double> MapPlan::values(int task) const {
  int set = task / static_cast<int>(sites.size());
  std::vector<double> out(vary.size());
  // The last variation varies fastest.
  for (int k = static_cast<int>(vary.size()) - 1; k >= 0; --k) {
    const int n = static_cast<int>(vary[k].values.size());
    out[k] = vary[k].values[set % n];
    set /= n;
  }
  return out;
}

ExperimentSettings MapPlan::taskSettings(int task) const {
  ExperimentSettings s = settings;
  const auto v = values(task);
  for (size_t k = 0; k < vary.size(); ++k) applyVariation(s, vary[k].name, v[k]);
  // Generated sites are material points of the rest surface (a cell's middle stays its middle
  // when turgor swells the tissue, a junction stays on the junction); listed ones are places, as
  // an AFM user measures them on the turgid tissue: the nearest turgid surface point is indented.
  if (site(task).kind == SiteKind::Listed) {
    s.indentation.site = site(task).point;
    s.indentation.restSite.reset();
  } else {
    s.indentation.restSite = site(task).point;
    s.indentation.site.reset();
  }
  return s;
}

json MapPlan::toJson() const {
  json j;
  j["format"] = "tissueprobe map plan";
  j["version"] = 1;
  j["tissue"] = tissue;
  j["tissue_digest"] = tissueDigest;
  j["settings"] = settingsJson.is_null() ? settingsToJson(settings) : settingsJson;
  json vj = json::array();
  for (const auto& v : vary) vj.push_back({{"name", v.name}, {"values", v.values}});
  j["vary"] = vj;
  json sj = json::array();
  for (const auto& s : sites)
    sj.push_back({{"kind", toString(s.kind)}, {"label", s.label}, {"point", vecJson(s.point)}});
  j["sites"] = sj;
  return j;
}

MapPlan MapPlan::fromJson(const json& j, const std::string& file) {
  if (!j.is_object() || j.value("format", "") != "tissueprobe map plan")
    throw std::runtime_error(file + ": not a TissueProbe map plan");
  if (intAt(j, "version", file) != 1)
    throw std::runtime_error(file + ": plan version " + j.at("version").dump() +
                             " is not known to this program (1)");
  MapPlan p;
  p.tissue = stringAt(j, "tissue", file);
  p.tissueDigest = stringAt(j, "tissue_digest", file);
  if (!j.contains("settings") || !j.at("settings").is_object())
    throw std::runtime_error(file + ": 'settings' must be an object");
  p.settingsJson = j.at("settings");
  if (!j.contains("vary") || !j.at("vary").is_array())
    throw std::runtime_error(file + ": 'vary' must be a list");
  for (const auto& v : j.at("vary")) {
    Variation var;
    var.name = stringAt(v, "name", file);
    ExperimentSettings probe;
    try {
      applyVariation(probe, var.name, 1.0);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(file + ": " + e.what());
    }
    if (!v.contains("values") || !v.at("values").is_array() || v.at("values").empty())
      throw std::runtime_error(file + ": 'values' of '" + var.name + "' must be a list of numbers");
    for (const auto& x : v.at("values")) {
      if (!x.is_number()) throw std::runtime_error(file + ": a value of '" + var.name + "' is not a number");
      var.values.push_back(x.get<double>());
    }
    p.vary.push_back(var);
  }
  if (!j.contains("sites") || !j.at("sites").is_array() || j.at("sites").empty())
    throw std::runtime_error(file + ": 'sites' must be a list of sites");
  for (const auto& s : j.at("sites")) {
    MapSite site;
    try {
      site.kind = parseSiteKind(stringAt(s, "kind", file));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(file + ": " + e.what());
    }
    site.label = stringAt(s, "label", file);
    site.point = vecAt(s, "point", file);
    p.sites.push_back(site);
  }
  try {
    p.checkSize();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(file + ": " + e.what());
  }
  return p;
}

std::string tissueDigest(const CellComplex& cc) {
  // FNV-1a over the rest coordinates' bytes, the triangles and the clamped flags.
  std::uint64_t h = 1469598103934665603ULL;
  auto mix = [&](const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ULL;
  };
  mix(cc.rest.data(), sizeof(double) * cc.rest.size());
  for (const auto& t : cc.triangles) mix(t.data(), sizeof(int) * 3);
  if (!cc.fixed.empty()) mix(cc.fixed.data(), cc.fixed.size());
  char buf[128];
  std::snprintf(buf, sizeof buf, "V %d, T %d, C %d, fnv1a %016" PRIx64, cc.vertexCount(),
                cc.triangleCount(), cc.cellCount(), h);
  return buf;
}

// ---------------------------------------------------------------------------------------------
// Results

json TaskResult::toJson() const {
  return {{"task", task},
          {"contact", {finiteOrNull(contact.x()), finiteOrNull(contact.y()), finiteOrNull(contact.z())}},
          {"depth", finiteOrNull(depth)},
          {"force", finiteOrNull(force)},
          {"secant", finiteOrNull(secant)},
          {"tangent", finiteOrNull(tangent)},
          {"hertz", finiteOrNull(hertz)},
          {"level", level},
          {"mesh_error", meshError},
          {"status", status},
          {"message", message},
          {"curve", curve}};
}

TaskResult TaskResult::fromJson(const json& j, const std::string& file) {
  if (!j.is_object()) throw std::runtime_error(file + ": not a task result");
  TaskResult r;
  r.task = intAt(j, "task", file);
  r.contact = vecAt(j, "contact", file);
  r.depth = numberOrNaN(j, "depth", file);
  r.force = numberOrNaN(j, "force", file);
  r.secant = numberOrNaN(j, "secant", file);
  r.tangent = numberOrNaN(j, "tangent", file);
  r.hertz = numberOrNaN(j, "hertz", file);
  r.level = intAt(j, "level", file);
  r.meshError = numberOrNaN(j, "mesh_error", file);
  r.status = stringAt(j, "status", file);
  r.message = stringAt(j, "message", file);
  if (j.contains("curve")) {  // results of earlier versions have none
    const json& c = j["curve"];
    bool ok = c.is_array();
    for (size_t k = 0; ok && k < c.size(); ++k) {
      ok = c[k].is_array() && c[k].size() == 2 && c[k][0].is_number() && c[k][1].is_number();
      if (ok) r.curve.push_back({c[k][0].get<double>(), c[k][1].get<double>()});
    }
    if (!ok) throw std::runtime_error(file + ": 'curve' is not a list of [depth, force] pairs");
  }
  if (r.status != "converged" && r.status != "mesh error above tolerance" && r.status != "failed")
    throw std::runtime_error(file + ": unknown status '" + r.status + "'");
  return r;
}

TaskResult taskResult(int task, const ExperimentSettings& settings, const ExperimentResult& r) {
  TaskResult out;
  out.task = task;
  out.message = r.message;
  const IndentationSettings& ind = settings.indentation;
  if (r.site) {
    out.level = r.site->level;
    out.contact = r.site->indentation->placement().site;
  }
  if (!r.complete) {
    out.status = "failed";
    if (out.message.empty()) out.message = "the curve did not reach its end";
    return out;
  }
  const CurvePoint& end = r.curve.at(ind.steps);
  const CurvePoint& before = r.curve.at(ind.steps - 1);
  out.depth = end.depth;
  out.force = end.force;
  out.secant = end.depth > 0 ? end.force / end.depth : std::numeric_limits<double>::quiet_NaN();
  out.tangent = end.depth > before.depth ? (end.force - before.force) / (end.depth - before.depth)
                                         : std::numeric_limits<double>::quiet_NaN();
  std::vector<CurvePoint> loading(r.curve.begin(), r.curve.begin() + ind.steps + 1);
  for (const CurvePoint& p : loading) out.curve.push_back({p.depth, p.force});
  out.hertz = hertzApparentModulus(loading, ind.probeRadius, settings.material.poissonRatio);
  out.meshError = r.error.estimated() ? r.error.relative : -1.0;
  const bool within = !settings.mesh.automatic || r.withinTolerance;
  out.status = within ? "converged" : "mesh error above tolerance";
  return out;
}

std::string mapTable(const MapPlan& plan, const std::vector<TaskResult>& results) {
  std::ostringstream o;
  o << "task,site,kind,label";
  for (const auto& v : plan.vary) o << "," << valueHeader(v.name);
  o << ",x_um,y_um,z_um,contact_x_um,contact_y_um,contact_z_um,depth_um,force_uN,"
       "secant_uN_per_um,tangent_uN_per_um,hertz_MPa,mesh_level,mesh_error,status,message\n";
  for (const auto& r : results) {
    if (r.task < 0) continue;
    const MapSite& s = plan.site(r.task);
    o << r.task << "," << r.task % plan.sites.size() << "," << toString(s.kind) << ","
      << csvField(s.label);
    for (double v : plan.values(r.task)) o << "," << shortNumber(v);
    o << "," << shortNumber(s.point.x()) << "," << shortNumber(s.point.y()) << "," << shortNumber(s.point.z())
      << "," << cell(r.contact.x()) << "," << cell(r.contact.y()) << "," << cell(r.contact.z())
      << "," << cell(r.depth) << "," << cell(r.force) << "," << cell(r.secant) << ","
      << cell(r.tangent) << "," << cell(r.hertz) << "," << (r.level >= 0 ? std::to_string(r.level) : "")
      << "," << (r.meshError >= 0 ? shortNumber(r.meshError) : "") << "," << r.status << ","
      << csvField(r.message) << "\n";
  }
  return o.str();
}

MapField::MapField(const MapPlan& plan, const std::vector<TaskResult>& results, double maxRadius)
    : radius_(maxRadius) {
  for (const auto& r : results) {
    if (r.task < 0 || !r.converged()) continue;
    const MapSite& site = plan.site(r.task);
    const bool place = site.kind == SiteKind::Listed && r.contact.allFinite();
    sites_.push_back({place ? r.contact : site.point, r.task, {r.secant, r.force, r.hertz}});
  }
  // The interpolation radius: twice the median nearest-neighbour distance between sites.
  std::vector<double> nearest;
  for (size_t a = 0; a < sites_.size(); ++a) {
    double d = std::numeric_limits<double>::infinity();
    for (size_t b = 0; b < sites_.size(); ++b)
      if (a != b) d = std::min(d, (sites_[a].x - sites_[b].x).norm());
    if (std::isfinite(d)) nearest.push_back(d);
  }
  if (!nearest.empty()) {
    std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
    radius_ = std::min(radius_, 2.0 * nearest[nearest.size() / 2]);
  }
}

int MapField::nearestSite(const Vec3& x, double* distance) const {
  int best = -1;
  double d2 = std::numeric_limits<double>::infinity();
  for (size_t a = 0; a < sites_.size(); ++a)
    if (const double e = (sites_[a].x - x).squaredNorm(); e < d2) d2 = e, best = static_cast<int>(a);
  if (distance) *distance = std::sqrt(d2);
  return best;
}

int MapField::nearestTask(const Vec3& x, double* distance) const {
  const int best = nearestSite(x, distance);
  return best < 0 ? -1 : sites_[best].task;
}

double MapField::nearest(const Vec3& x, Value v) const {
  const int best = nearestSite(x);
  return best < 0 ? std::numeric_limits<double>::quiet_NaN() : sites_[best].value[v];
}

double MapField::interpolated(const Vec3& x, Value v) const {
  double w = 0, sum = 0;
  for (const auto& s : sites_) {
    const double d = (s.x - x).norm();
    if (d > radius_) continue;
    if (d < 1e-9) return s.value[v];    // on a site: its value
    const double wi = 1.0 / (d * d);    // Shepard 1968, power 2
    w += wi, sum += wi * s.value[v];
  }
  return w > 0 ? sum / w : std::numeric_limits<double>::quiet_NaN();
}

std::string mapSurfaceVtu(const CellComplex& cc, const MapPlan& plan,
                          const std::vector<TaskResult>& results) {
  // The outer surface as a complex of its own (the same vertices; only outer triangles).
  CellComplex surface;
  surface.rest = cc.rest;
  surface.fixed = cc.fixed;
  surface.cellLabels = cc.cellLabels;
  surface.walls = cc.walls;
  std::vector<char> onSurface(cc.vertexCount(), 0);
  for (int t = 0; t < cc.triangleCount(); ++t)
    if (cc.isOuterTriangle(t)) {
      surface.triangles.push_back(cc.triangles[t]);
      surface.triangleWall.push_back(cc.triangleWall[t]);
      for (int i = 0; i < 3; ++i) onSurface[cc.triangles[t][i]] = 1;
    }
  const MapField field(plan, results);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const int V = cc.vertexCount(), T = surface.triangleCount();
  std::vector<std::vector<double>> site(MapField::kValueCount, std::vector<double>(T, nan));
  std::vector<std::vector<double>> interp(MapField::kValueCount, std::vector<double>(V, nan));
  for (int q = 0; q < MapField::kValueCount; ++q) {
    const auto value = MapField::Value(q);
    if (!field.empty())
      for (int k = 0; k < T; ++k) {
        const auto& tri = surface.triangles[k];
        const Vec3 c = (cc.rest.col(tri[0]) + cc.rest.col(tri[1]) + cc.rest.col(tri[2])) / 3.0;
        site[q][k] = field.nearest(c, value);
      }
    for (int v = 0; v < V; ++v)
      if (onSurface[v]) interp[q][v] = field.interpolated(cc.rest.col(v), value);
  }
  std::ostringstream o;
  writeVtu(o, surface, cc.rest,
           {{"interpolated_stiffness_uN_per_um", 1, interp[0]},
            {"interpolated_force_uN", 1, interp[1]},
            {"interpolated_hertz_MPa", 1, interp[2]}},
           {{"site_stiffness_uN_per_um", 1, site[0]},
            {"site_force_uN", 1, site[1]},
            {"site_hertz_MPa", 1, site[2]}});
  return o.str();
}

std::vector<TaskResult> readResults(const std::string& dir, const MapPlan& plan) {
  std::vector<TaskResult> out(plan.taskCount());
  const fs::path folder = fs::path(dir) / "results";
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return out;
  for (int t = 0; t < plan.taskCount(); ++t) {
    const fs::path f = folder / taskFileName(t);
    if (!fs::exists(f, ec)) continue;
    const std::string file = f.string();
    json j;
    try {
      j = json::parse(readTextFile(file, "task result"));
    } catch (const json::exception& e) {
      throw std::runtime_error(file + ": not JSON (" + e.what() + ")");
    }
    TaskResult r = TaskResult::fromJson(j, file);
    if (r.task != t)
      throw std::runtime_error(file + ": holds task " + std::to_string(r.task) + ", not " +
                               std::to_string(t));
    out[t] = r;
  }
  return out;
}

namespace {

// The plan in `dir`: written when absent, else checked to be the same. Returns its path.
void ensurePlan(const std::string& dir, const json& plan) {
  std::error_code ec;
  fs::create_directories(fs::path(dir) / "results", ec);
  if (ec) throw WriteError(dir + ": cannot create the folder (" + ec.message() + ")");
  const std::string path = (fs::path(dir) / "plan.json").string();
  if (fs::exists(path, ec)) {
    json old;
    try {
      old = json::parse(readTextFile(path, "map plan"));
    } catch (const json::exception& e) {
      throw std::runtime_error(path + ": not JSON (" + e.what() + ")");
    }
    if (old != plan) {
      std::string what = "the plan";
      for (const char* key : {"tissue", "tissue_digest", "settings", "vary", "sites"})
        if (old.value(key, json()) != plan.value(key, json())) {
          what = std::string("'") + key + "'";
          break;
        }
      throw std::runtime_error(dir + " holds results of another map or sweep (" + what +
                               " differs from this run's): choose another --out folder");
    }
    return;
  }
  writeFileAtomically(path, plan.dump(1) + "\n");
}

}  // namespace

MapRunSummary runMap(std::shared_ptr<const CellComplex> tissue, const MapPlan& plan,
                     const MapRunOptions& options) {
  if (options.shards < 1 || options.shard < 0 || options.shard >= options.shards)
    throw std::invalid_argument("shard " + std::to_string(options.shard) + "/" +
                                std::to_string(options.shards) + " does not exist (0 <= I < N)");
  if (plan.sites.empty()) throw std::invalid_argument("the map has no site");
  plan.checkSize();
  const json planJson = plan.toJson();
  ensurePlan(options.outDir, planJson);
  const auto done0 = readResults(options.outDir, plan);
  MapRunSummary summary;
  std::vector<int> todo;
  for (int t = options.shard; t < plan.taskCount(); t += options.shards) {
    ++summary.shardTasks;
    if (done0[t].task >= 0) ++summary.skipped;
    else todo.push_back(t);
  }
  const int jobs = std::clamp(options.jobs, 1, std::max(1, static_cast<int>(todo.size())));
  const auto started = std::chrono::steady_clock::now();
  auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  };
  appendLog(options.outDir, nowStamp() + " start shard " + std::to_string(options.shard) + "/" +
                                std::to_string(options.shards) + " on " + options.host + ": " +
                                std::to_string(todo.size()) + " task(s) to do, " +
                                std::to_string(summary.skipped) + " already done, " +
                                std::to_string(jobs) + " worker(s)");
  std::atomic<size_t> next{0};
  std::mutex mutex;  // the summary, the progress callback, the log and the first error
  std::exception_ptr error;
  auto worker = [&] {
    // One thread per worker, for the assembly's OpenMP regions and for BLAS: the workers are
    // the parallelism, and a task's bits then do not depend on how many workers, shards or
    // cores there are (parallel sums and BLAS kernels split their work by thread count). One
    // worker runs on the calling thread, whose team size comes back when it ends.
    const OmpThreadsScope oneThread(1);
    std::unique_ptr<Experiment> experiment;
    Monitor monitor;
    monitor.cancel = options.cancel;
    while (!monitor.cancelled()) {
      const size_t k = next.fetch_add(1);
      if (k >= todo.size()) break;
      {
        std::lock_guard lock(mutex);
        if (error) break;
      }
      const int task = todo[k];
      const auto t0 = std::chrono::steady_clock::now();
      try {
        const ExperimentSettings s = plan.taskSettings(task);
        if (!experiment)
          experiment = std::make_unique<Experiment>(tissue, s);
        else
          experiment->setSettings(s);
        TaskResult r;
        try {
          const ExperimentResult x = experiment->run(monitor);
          if (x.cancelled) break;  // not a result: the task is done again next time
          r = taskResult(task, s, x);
        } catch (const SolveFailure& e) {
          r.task = task;
          r.status = "failed";
          r.message = e.what();
        } catch (const std::invalid_argument& e) {  // this site cannot be indented
          r.task = task;
          r.status = "failed";
          r.message = e.what();
          experiment.reset();
        }
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        writeFileAtomically((fs::path(options.outDir) / "results" / taskFileName(task)).string(),
                            r.toJson().dump(1) + "\n");
        std::lock_guard lock(mutex);
        ++summary.done;
        if (!r.converged()) ++summary.failed;
        char line[256];
        std::snprintf(line, sizeof line, "task %d (%s) %s in %.2f s on %s", task,
                      plan.site(task).label.c_str(), r.status.c_str(), r.seconds,
                      options.host.c_str());
        appendLog(options.outDir, line);
        if (options.progress) {
          MapProgress p;
          p.done = summary.done;
          p.failed = summary.failed;
          p.todo = static_cast<int>(todo.size());
          p.skipped = summary.skipped;
          p.seconds = seconds();
          p.last = &r;
          options.progress(p);
        }
      } catch (const Cancelled&) {
        break;
      } catch (...) {
        std::lock_guard lock(mutex);
        if (!error) error = std::current_exception();
        break;
      }
    }
  };
  {
    const CholmodSolver::BlasThreadCap oneBlasThread(1);
    std::vector<std::thread> threads;
    for (int w = 1; w < jobs; ++w) threads.emplace_back(worker);
    worker();
    for (auto& t : threads) t.join();
  }
  if (error) std::rethrow_exception(error);
  summary.cancelled = options.cancel && options.cancel->load();
  char line[160];
  std::snprintf(line, sizeof line, " end shard %d/%d: %d done (%d not converged) in %.1f s%s",
                options.shard, options.shards, summary.done, summary.failed, seconds(),
                summary.cancelled ? ", interrupted" : "");
  appendLog(options.outDir, nowStamp() + line);
  const auto all = readResults(options.outDir, plan);
  summary.complete =
      std::all_of(all.begin(), all.end(), [](const TaskResult& r) { return r.task >= 0; });
  if (summary.complete) summary.written = writeOutputs(options.outDir, *tissue, plan, all);
  return summary;
}

MergeSummary mergeMaps(const std::vector<std::string>& dirs, const std::string& outDir,
                       std::shared_ptr<const CellComplex> tissue) {
  if (dirs.empty()) throw std::invalid_argument("merge: no folder given");
  json planJson;
  std::string planFrom;
  for (const auto& d : dirs) {
    const std::string path = (fs::path(d) / "plan.json").string();
    json j;
    try {
      j = json::parse(readTextFile(path, "map plan"));
    } catch (const json::exception& e) {
      throw std::runtime_error(path + ": not JSON (" + e.what() + ")");
    }
    if (planFrom.empty()) {
      planJson = j;
      planFrom = d;
    } else if (j != planJson) {
      throw std::runtime_error(d + " holds another map or sweep than " + planFrom +
                               " (their plan.json differ)");
    }
  }
  const MapPlan plan = MapPlan::fromJson(planJson, (fs::path(planFrom) / "plan.json").string());
  MergeSummary summary;
  summary.tasks = plan.taskCount();
  std::vector<TaskResult> all(plan.taskCount());
  for (const auto& d : dirs) {
    const auto found = readResults(d, plan);
    for (int t = 0; t < plan.taskCount(); ++t)
      if (all[t].task < 0 && found[t].task >= 0) all[t] = found[t];
  }
  ensurePlan(outDir, planJson);
  for (int t = 0; t < plan.taskCount(); ++t) {
    if (all[t].task < 0) {
      summary.missing.push_back(t);
      continue;
    }
    ++summary.found;
    const std::string target = (fs::path(outDir) / "results" / taskFileName(t)).string();
    std::error_code ec;
    if (!fs::exists(target, ec)) writeFileAtomically(target, all[t].toJson().dump(1) + "\n");
  }
  appendLog(outDir, nowStamp() + " merge of " + std::to_string(dirs.size()) + " folder(s): " +
                        std::to_string(summary.found) + " of " + std::to_string(summary.tasks) +
                        " task(s) found");
  if (!summary.missing.empty()) return summary;
  if (!tissue) {
    std::error_code ec;
    if (!fs::exists(plan.tissue, ec))
      throw std::runtime_error("the plan's tissue '" + plan.tissue +
                               "' is not here: give it with --mesh");
    tissue = std::make_shared<const CellComplex>(readTissue(plan.tissue));
  }
  if (tissueDigest(*tissue) != plan.tissueDigest)
    throw std::runtime_error("the tissue (" + tissueDigest(*tissue) + ") is not the plan's (" +
                             plan.tissueDigest + ")");
  summary.written = writeOutputs(outDir, *tissue, plan, all);
  return summary;
}

}  // namespace tp
