#include "Parameters.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace tp::gui {

namespace {

double number(const nlohmann::json& j, const char* key, double fallback) {
  if (!j.contains(key)) return fallback;
  const auto& v = j.at(key);
  if (!v.is_number()) throw std::runtime_error(std::string("'") + key + "' must be a number");
  const double x = v.get<double>();
  if (!std::isfinite(x)) throw std::runtime_error(std::string("'") + key + "' must be finite");
  return x;
}

int integer(const nlohmann::json& j, const char* key, int fallback) {
  if (!j.contains(key)) return fallback;
  return intFromJson(j.at(key), std::string("'") + key + "'");
}

bool boolean(const nlohmann::json& j, const char* key, bool fallback) {
  if (!j.contains(key)) return fallback;
  const auto& v = j.at(key);
  if (!v.is_boolean()) throw std::runtime_error(std::string("'") + key + "' must be true or false");
  return v.get<bool>();
}

// A value given by name (an enum's string), parsed by `parse`; the fallback when absent.
template <class T, class Parse>
T named(const nlohmann::json& j, const char* key, T fallback, Parse parse) {
  if (!j.contains(key)) return fallback;
  const auto& v = j.at(key);
  if (!v.is_string()) throw std::runtime_error(std::string("'") + key + "' must be a string");
  try {
    return parse(v.get<std::string>());
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("'") + key + "': " + e.what());
  }
}

}  // namespace

Material SimulationParams::material() const {
  Material m;
  m.youngModulus = youngModulus;
  m.poissonRatio = poissonRatio;
  m.thickness = thickness;
  m.bending = bending;
  m.junctions = junctions;
  return m;
}

ExperimentSettings SimulationParams::experimentSettings() const {
  ExperimentSettings s;
  s.material = material();
  s.pressure = pressure;
  s.indentation.probeRadius = probeRadius;
  s.mesh.automatic = autoMesh;
  if (!autoMesh) s.mesh.level = meshLevel;
  s.mesh.tolerance = meshTolerance;
  s.mesh.junctionBand = junctionBand;
  return s;
}

SimulationParams turgidPreset(SimulationParams p) {
  p.pressure = ExperimentSettings{}.pressure;  // the default turgor is the turgid state
  return p;
}

SimulationParams plasmolysedPreset(SimulationParams p) {
  p.pressure = 0.0;
  return p;
}

std::string describe(const SimulationParams& p) {
  std::ostringstream s;
  s << "E " << p.youngModulus << " MPa, p " << p.pressure << " MPa, r " << p.probeRadius << " µm";
  const SimulationParams d;  // only what differs from the defaults is named
  if (p.thickness != d.thickness) s << ", h " << p.thickness << " µm";
  if (p.poissonRatio != d.poissonRatio) s << ", ν " << p.poissonRatio;
  if (p.bending != d.bending) s << ", " << toString(p.bending) << " bending";
  else if (p.junctions != d.junctions) s << ", " << toString(p.junctions) << " junctions";
  if (!p.autoMesh) s << ", mesh level " << p.meshLevel;
  if (junctionBandApplies(p.experimentSettings())) s << ", junction band";
  return s.str();
}

nlohmann::json toJson(const SimulationParams& p) {
  return {{"E_MPa", p.youngModulus},
          {"nu", p.poissonRatio},
          {"thickness_um", p.thickness},
          {"pressure_MPa", p.pressure},
          {"bending", toString(p.bending)},
          {"junctions", toString(p.junctions)},
          {"probe_radius_um", p.probeRadius},
          {"mesh", p.autoMesh ? nlohmann::json("auto") : nlohmann::json(p.meshLevel)},
          {"mesh_tolerance", p.meshTolerance},
          {"junction_band", p.junctionBand}};
}

nlohmann::json toJson(const Schedule& s) {
  return {{"control", s.control == Control::Force ? "force" : "depth"},
          {"max_depth_um", s.maxDepth},
          {"max_force_uN", s.maxForce},
          {"steps", s.steps},
          {"unload", s.unload}};
}

int intFromJson(const nlohmann::json& v, const std::string& what) {
  const bool fits =
      (v.is_number_unsigned() &&
       v.get<std::uint64_t>() <= static_cast<std::uint64_t>(std::numeric_limits<int>::max())) ||
      (v.is_number_integer() && !v.is_number_unsigned() &&
       v.get<std::int64_t>() >= std::numeric_limits<int>::min() &&
       v.get<std::int64_t>() <= std::numeric_limits<int>::max());
  if (!fits) throw std::runtime_error(what + " must be an integer, not " + v.dump());
  return static_cast<int>(v.get<std::int64_t>());
}

SimulationParams paramsFromJson(const nlohmann::json& j) {
  if (!j.is_object()) throw std::runtime_error("parameters must be a JSON object");
  SimulationParams p;
  p.youngModulus = number(j, "E_MPa", p.youngModulus);
  p.poissonRatio = number(j, "nu", p.poissonRatio);
  p.thickness = number(j, "thickness_um", p.thickness);
  p.pressure = number(j, "pressure_MPa", p.pressure);
  p.bending = named(j, "bending", p.bending, parseBendingModel);
  p.junctions = named(j, "junctions", p.junctions, parseJunctionRule);
  p.probeRadius = number(j, "probe_radius_um", p.probeRadius);
  if (j.contains("mesh")) {
    const auto& m = j.at("mesh");
    if (m.is_string() && m == "auto") {
      p.autoMesh = true;
    } else if (m.is_number_integer()) {
      p.autoMesh = false;
      p.meshLevel = intFromJson(m, "'mesh'");
    } else {
      throw std::runtime_error("'mesh' must be \"auto\" or a level (an integer)");
    }
  } else if (j.contains("refine_level")) {  // sessions of version 1: a fixed level
    p.autoMesh = false;
    p.meshLevel = integer(j, "refine_level", 0);
  }
  p.meshTolerance = number(j, "mesh_tolerance", p.meshTolerance);
  p.junctionBand = boolean(j, "junction_band", p.junctionBand);
  try {
    p.experimentSettings().validate();  // the same ranges as the command line
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
  return p;
}

Schedule scheduleFromJson(const nlohmann::json& j) {
  if (!j.is_object()) throw std::runtime_error("the schedule must be a JSON object");
  Schedule s;
  if (j.contains("control")) {
    const auto& c = j.at("control");
    if (!c.is_string() || (c != "force" && c != "depth"))
      throw std::runtime_error("'control' must be \"depth\" or \"force\"");
    s.control = c == "force" ? Control::Force : Control::Depth;
  }
  s.maxDepth = number(j, "max_depth_um", s.maxDepth);
  s.maxForce = number(j, "max_force_uN", s.maxForce);
  s.steps = integer(j, "steps", s.steps);
  s.unload = boolean(j, "unload", s.unload);
  if (s.steps < 1) throw std::runtime_error("'steps' must be at least 1");
  return s;
}

}  // namespace tp::gui
