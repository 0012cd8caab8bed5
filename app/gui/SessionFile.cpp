#include "SessionFile.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "ColorMap.h"
#include "MapValues.h"
#include "experiment/Quantities.h"
#include "io/AtomicFile.h"

namespace tp::gui {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kFormat = "tissueprobe-session";

json vec(const Eigen::Vector3d& v) {
  return json::array({v.x(), v.y(), v.z()});
}

Eigen::Vector3d vecFrom(const json& j, const std::string& what) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
    throw std::runtime_error(what + " must be an array of three numbers");
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

// NaN (the force of a point that did not converge) is not JSON: store it as null.
json real(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}
double realFrom(const json& j, const std::string& what) {
  if (j.is_null()) return std::numeric_limits<double>::quiet_NaN();
  if (!j.is_number()) throw std::runtime_error(what + " must be a number or null");
  return j.get<double>();
}

json pointsToJson(const std::vector<CurvePoint>& pts) {
  json a = json::array();
  for (const CurvePoint& p : pts)
    a.push_back(
        {real(p.depth), real(p.force), p.iterations, real(p.residual), p.converged, p.unloading});
  return a;
}

std::vector<CurvePoint> pointsFromJson(const json& a, const std::string& what) {
  if (!a.is_array()) throw std::runtime_error(what + " must be an array");
  std::vector<CurvePoint> out;
  for (size_t i = 0; i < a.size(); ++i) {
    const std::string w = what + "[" + std::to_string(i) + "]";
    const json& r = a[i];
    if (!r.is_array() || r.size() != 6 || !r[2].is_number_integer() || !r[4].is_boolean() ||
        !r[5].is_boolean())
      throw std::runtime_error(w +
                               " must be [depth, force, iterations, residual, converged, "
                               "unloading]");
    CurvePoint p;
    p.depth = realFrom(r[0], w + " depth");
    p.force = realFrom(r[1], w + " force");
    p.iterations = intFromJson(r[2], w + " iterations");
    p.residual = realFrom(r[3], w + " residual");
    p.converged = r[4].get<bool>();
    p.unloading = r[5].get<bool>();
    out.push_back(p);
  }
  return out;
}

}  // namespace

namespace {

json displayToJson(const DisplaySettings& d) {
  json j = {{"quantity", d.quantity},
            {"colour_map", d.colourMap},
            {"auto_range", d.autoRange},
            {"range", {d.lo, d.hi}},
            {"outlines", d.outlines},
            {"mesh", d.mesh},
            {"principal_directions", d.glyphs},
            {"deformation_scale", d.deformationScale},
            {"section",
             {{"on", d.section},
              {"axis", std::string(1, "xyz"[std::clamp(d.sectionAxis, 0, 2)])},
              {"position", d.sectionPosition},
              {"keep_other_side", d.keepOtherSide}}}};
  if (d.camera)
    j["camera"] = {{"target", vec(d.camera->target)},
                   {"orientation",
                    {d.camera->orientation[0], d.camera->orientation[1], d.camera->orientation[2],
                     d.camera->orientation[3]}},
                   {"distance", d.camera->distance}};
  return j;
}

// Every key is optional (defaults as in DisplaySettings); a key present must hold a valid value.
DisplaySettings displayFromJson(const json& j) {
  if (!j.is_object()) throw std::runtime_error("'display' must be an object");
  DisplaySettings d;
  auto boolean = [&](const json& o, const char* key, bool& out, const std::string& where) {
    if (!o.contains(key)) return;
    if (!o.at(key).is_boolean()) throw std::runtime_error(where + key + " must be true or false");
    out = o.at(key).get<bool>();
  };
  auto number = [&](const json& o, const char* key, double lo, double hi, double& out,
                    const std::string& where) {
    if (!o.contains(key)) return;
    const json& v = o.at(key);
    if (!v.is_number() || !(v.get<double>() >= lo && v.get<double>() <= hi))
      throw std::runtime_error(where + key + " must be a number in [" + std::to_string(lo) +
                               ", " + std::to_string(hi) + "], not " + v.dump());
    out = v.get<double>();
  };
  if (j.contains("quantity")) {
    const json& q = j.at("quantity");
    if (!q.is_string() ||
        (quantityIndex(q.get<std::string>()) < 0 && mapValueIndex(q.get<std::string>()) < 0))
      throw std::runtime_error("display.quantity " + q.dump() + " is not a known quantity");
    d.quantity = q.get<std::string>();
  }
  if (j.contains("colour_map")) {
    const json& m = j.at("colour_map");
    bool known = false;
    for (int k = 0; k < ColorMap::kKindCount && m.is_string(); ++k)
      known |= m.get<std::string>() == ColorMap::key(ColorMap::Kind(k));
    if (!known) throw std::runtime_error("display.colour_map " + m.dump() + " is not a colour map");
    d.colourMap = m.get<std::string>();
  }
  boolean(j, "auto_range", d.autoRange, "display.");
  if (j.contains("range")) {
    const json& r = j.at("range");
    if (!r.is_array() || r.size() != 2 || !r[0].is_number() || !r[1].is_number() ||
        !std::isfinite(r[0].get<double>()) || !std::isfinite(r[1].get<double>()))
      throw std::runtime_error("display.range must be two finite numbers [low, high]");
    d.lo = r[0].get<double>();
    d.hi = r[1].get<double>();
  }
  boolean(j, "outlines", d.outlines, "display.");
  boolean(j, "mesh", d.mesh, "display.");
  boolean(j, "principal_directions", d.glyphs, "display.");
  number(j, "deformation_scale", 1.0, 50.0, d.deformationScale, "display.");
  if (j.contains("section")) {
    const json& sec = j.at("section");
    if (!sec.is_object()) throw std::runtime_error("display.section must be an object");
    boolean(sec, "on", d.section, "display.section.");
    if (sec.contains("axis")) {
      const json& a = sec.at("axis");
      const std::string axis = a.is_string() ? a.get<std::string>() : "";
      if (axis != "x" && axis != "y" && axis != "z")
        throw std::runtime_error("display.section.axis must be \"x\", \"y\" or \"z\", not " +
                                 a.dump());
      d.sectionAxis = axis[0] - 'x';
    }
    number(sec, "position", 0.0, 1.0, d.sectionPosition, "display.section.");
    boolean(sec, "keep_other_side", d.keepOtherSide, "display.section.");
  }
  if (j.contains("camera")) {
    const json& c = j.at("camera");
    if (!c.is_object()) throw std::runtime_error("display.camera must be an object");
    DisplaySettings::Camera cam;
    cam.target = vecFrom(c.value("target", json()), "display.camera.target");
    const json& o = c.value("orientation", json());
    bool ok = o.is_array() && o.size() == 4;
    for (int i = 0; ok && i < 4; ++i) {
      ok = o[i].is_number() && std::isfinite(o[i].get<double>());
      if (ok) cam.orientation[i] = o[i].get<double>();
    }
    if (!ok || !(cam.orientation.norm() > 1e-6))
      throw std::runtime_error("display.camera.orientation must be a quaternion [w, x, y, z]");
    // Normalised once: a unit quaternion read again is kept bit for bit (normalising twice can
    // move the last bit, and a session saved and opened again must not change).
    const double norm = cam.orientation.norm();
    if (std::abs(norm - 1.0) > 1e-12) cam.orientation /= norm;
    number(c, "distance", 1e-9, 1e9, cam.distance, "display.camera.");
    if (!c.contains("distance")) throw std::runtime_error("display.camera.distance is missing");
    d.camera = cam;
  }
  return d;
}

}  // namespace

json mapToJson(const SessionMap& m) {
  json rows = json::array();
  for (const TaskResult& r : m.results)
    if (r.task >= 0) rows.push_back(r.toJson());
  return {{"plan", m.plan.toJson()}, {"parameters", toJson(m.params)}, {"results", rows}};
}

SessionMap mapFromJson(const json& j, const std::string& where) {
  if (!j.is_object() || !j.contains("plan") || !j.contains("results") || !j.at("results").is_array())
    throw std::runtime_error(where + " must be an object with 'plan' and 'results'");
  SessionMap m;
  m.plan = MapPlan::fromJson(j.at("plan"), where + ".plan");
  if (m.plan.sites.empty()) throw std::runtime_error(where + ".plan has no sites");
  // The application shows maps, not sweeps (and a task count bounded by the sites listed).
  if (!m.plan.vary.empty()) throw std::runtime_error(where + ".plan varies parameters: a sweep, not a map");
  if (j.contains("parameters")) m.params = paramsFromJson(j.at("parameters"));
  m.results.assign(m.plan.taskCount(), TaskResult{});
  const json& rows = j.at("results");
  for (size_t i = 0; i < rows.size(); ++i) {
    const std::string w = where + ".results[" + std::to_string(i) + "]";
    TaskResult r = TaskResult::fromJson(rows[i], w);
    if (r.task < 0 || r.task >= m.plan.taskCount())
      throw std::runtime_error(w + ": task " + std::to_string(r.task) + " is not a task of the plan");
    m.results[r.task] = std::move(r);
  }
  return m;
}

json sessionToJson(const SessionState& s) {
  json j;
  j["format"] = kFormat;
  j["version"] = 1;
  j["tissue"] = s.tissuePath;
  j["parameters"] = toJson(s.params);
  j["schedule"] = toJson(s.schedule);
  j["sites"] = json::array();
  for (const auto& site : s.sites) j["sites"].push_back(vec(site));
  j["current_site"] = s.currentSite;
  j["curves"] = json::array();
  for (const NamedCurve& c : s.curves) {
    json curve = {{"name", c.name},
                  {"site", vec(c.site)},
                  {"parameters", toJson(c.params)},
                  {"live", c.live},
                  {"measured", c.measured},
                  {"points", pointsToJson(c.points)}};
    if (!c.residuals.empty()) {
      curve["residuals_uN"] = json::array();
      for (double r : c.residuals) curve["residuals_uN"].push_back(real(r));
    }
    if (c.meshLevel >= 0) curve["mesh_level"] = c.meshLevel;
    if (c.meshError >= 0)
      curve["mesh_error"] = {{"relative", c.meshError},
                             {c.meshErrorForce ? "at_force_uN" : "at_depth_um", c.meshErrorAt},
                             {"method", c.meshErrorMethod}};
    j["curves"].push_back(std::move(curve));
  }
  if (s.display) j["display"] = displayToJson(*s.display);
  if (s.map) j["map"] = mapToJson(*s.map);
  return j;
}

SessionState sessionFromJson(const json& j, const std::string& nameForErrors) {
  try {
    if (!j.is_object() || j.value("format", "") != kFormat)
      throw std::runtime_error(std::string("not a TissueProbe session (no \"format\": \"") +
                               kFormat + "\")");
    if (!j.contains("version") || !j.at("version").is_number_integer() ||
        intFromJson(j.at("version"), "'version'") != 1)
      throw std::runtime_error("unsupported session version " + j.value("version", json()).dump());
    SessionState s;
    if (j.contains("tissue")) {
      if (!j.at("tissue").is_string()) throw std::runtime_error("'tissue' must be a string");
      s.tissuePath = j.at("tissue").get<std::string>();
    }
    if (j.contains("parameters")) s.params = paramsFromJson(j.at("parameters"));
    if (j.contains("schedule")) s.schedule = scheduleFromJson(j.at("schedule"));
    if (j.contains("sites")) {
      if (!j.at("sites").is_array()) throw std::runtime_error("'sites' must be an array");
      for (size_t i = 0; i < j.at("sites").size(); ++i)
        s.sites.push_back(vecFrom(j.at("sites")[i], "sites[" + std::to_string(i) + "]"));
    }
    s.currentSite = j.contains("current_site")
                        ? intFromJson(j.at("current_site"), "'current_site'")
                        : -1;
    if (s.currentSite < -1 || s.currentSite >= static_cast<int>(s.sites.size()))
      throw std::runtime_error("'current_site' is not an index into 'sites'");
    if (j.contains("curves")) {
      if (!j.at("curves").is_array()) throw std::runtime_error("'curves' must be an array");
      for (size_t i = 0; i < j.at("curves").size(); ++i) {
        const json& c = j.at("curves")[i];
        const std::string w = "curves[" + std::to_string(i) + "]";
        if (!c.is_object()) throw std::runtime_error(w + " must be an object");
        NamedCurve nc;
        nc.name = c.value("name", "curve " + std::to_string(i + 1));
        if (c.contains("site")) nc.site = vecFrom(c.at("site"), w + ".site");
        if (c.contains("parameters")) nc.params = paramsFromJson(c.at("parameters"));
        nc.live = c.value("live", false);
        nc.measured = c.value("measured", false);
        nc.points = pointsFromJson(c.value("points", json::array()), w + ".points");
        if (c.contains("residuals_uN")) {
          const json& res = c.at("residuals_uN");
          if (!res.is_array() || res.size() != nc.points.size())
            throw std::runtime_error(w + ".residuals_uN must be an array of one number per point");
          for (size_t k = 0; k < res.size(); ++k)
            nc.residuals.push_back(
                realFrom(res[k], w + ".residuals_uN[" + std::to_string(k) + "]"));
        }
        nc.meshLevel = c.contains("mesh_level") ? intFromJson(c.at("mesh_level"), w + ".mesh_level")
                                                : -1;
        if (c.contains("mesh_error")) {
          const json& e = c.at("mesh_error");
          if (!e.is_object() || !e.value("relative", json()).is_number())
            throw std::runtime_error(w + ".mesh_error must hold a number 'relative'");
          nc.meshError = e.at("relative").get<double>();
          nc.meshErrorForce = e.contains("at_force_uN");
          nc.meshErrorAt = e.value(nc.meshErrorForce ? "at_force_uN" : "at_depth_um", 0.0);
          nc.meshErrorMethod = e.value("method", "");
        }
        s.curves.push_back(std::move(nc));
      }
    }
    if (j.contains("display")) s.display = displayFromJson(j.at("display"));
    if (j.contains("map")) s.map = mapFromJson(j.at("map"), "map");
    return s;
  } catch (const json::exception& e) {
    throw std::runtime_error(nameForErrors + ": " + e.what());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(nameForErrors + ": " + e.what());
  }
}

void saveSession(const std::string& path, const SessionState& s) {
  SessionState copy = s;
  if (!copy.tissuePath.empty()) {
    std::error_code ec;
    const fs::path dir = fs::absolute(path, ec).parent_path();
    const fs::path tissue = fs::absolute(copy.tissuePath, ec);
    const fs::path rel = tissue.lexically_relative(dir);
    if (!rel.empty() && *rel.begin() != "..") copy.tissuePath = rel.generic_string();
  }
  writeFileAtomically(path, sessionToJson(copy).dump(2) + "\n");
}

SessionState sessionFromText(const std::string& text, const std::string& nameForErrors) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {  // a syntax error, or a number out of range (fuzzing)
    throw std::runtime_error(nameForErrors + ": not valid JSON: " + e.what());
  }
  return sessionFromJson(j, nameForErrors);
}

SessionState loadSession(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open the session file");
  std::stringstream ss;
  ss << in.rdbuf();
  SessionState s = sessionFromText(ss.str(), path);
  if (!s.tissuePath.empty() && fs::path(s.tissuePath).is_relative()) {
    std::error_code ec;
    s.tissuePath =
        (fs::absolute(path, ec).parent_path() / s.tissuePath).lexically_normal().string();
  }
  return s;
}

}  // namespace tp::gui
