#include "SessionFile.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

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
    p.iterations = r[2].get<int>();
    p.residual = realFrom(r[3], w + " residual");
    p.converged = r[4].get<bool>();
    p.unloading = r[5].get<bool>();
    out.push_back(p);
  }
  return out;
}

}  // namespace

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
                  {"points", pointsToJson(c.points)}};
    if (c.meshLevel >= 0) curve["mesh_level"] = c.meshLevel;
    if (c.meshError >= 0)
      curve["mesh_error"] = {{"relative", c.meshError},
                             {c.meshErrorForce ? "at_force_uN" : "at_depth_um", c.meshErrorAt},
                             {"method", c.meshErrorMethod}};
    j["curves"].push_back(std::move(curve));
  }
  return j;
}

SessionState sessionFromJson(const json& j, const std::string& nameForErrors) {
  try {
    if (!j.is_object() || j.value("format", "") != kFormat)
      throw std::runtime_error(std::string("not a TissueProbe session (no \"format\": \"") +
                               kFormat + "\")");
    if (j.value("version", 0) != 1)
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
    s.currentSite = j.value("current_site", -1);
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
        nc.points = pointsFromJson(c.value("points", json::array()), w + ".points");
        nc.meshLevel = c.value("mesh_level", -1);
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
