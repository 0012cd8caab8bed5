#pragma once
// The parameters a user sets in the window: material, turgor, probe and refinement (what a
// preparation depends on) and the loading schedule of a "Run curve". Units: µm, MPa, µN.

#include <nlohmann/json.hpp>
#include <string>

#include "experiment/Experiment.h"
#include "experiment/Indentation.h"
#include "mechanics/Material.h"

namespace tp::gui {

struct SimulationParams {
  double youngModulus = 100.0;  // E, MPa
  double poissonRatio = 0.49;   // ν
  double thickness = 0.2;       // h, µm
  double pressure = 0.8;        // turgor p of every cell, MPa
  BendingModel bending = BendingModel::Koiter;
  JunctionRule junctions = JunctionRule::Hinged;  // how walls share rotation at a junction (Koiter)
  double probeRadius = 1.0;  // µm
  // The mesh at the site (core/experiment/Experiment.h): automatic (refined level by level
  // until the estimated discretisation error is within meshTolerance) or a fixed level.
  bool autoMesh = true;
  int meshLevel = 3;            // the fixed level (0 = the tissue as loaded)
  double meshTolerance = 0.03;  // relative

  Material material() const;
  /// The core's settings for these parameters (probe, material, turgor, mesh).
  ExperimentSettings experimentSettings() const;
  bool operator==(const SimulationParams&) const = default;
};

/// "Turgid": p = 0.8 MPa (the meristem's turgor); "Plasmolysed": p = 0. Other values are kept.
SimulationParams turgidPreset(SimulationParams p);
SimulationParams plasmolysedPreset(SimulationParams p);

/// A short description for curve names and legends, e.g. "E 100 MPa, p 0.8 MPa, r 1 µm".
std::string describe(const SimulationParams& p);

struct Schedule {
  Control control = Control::Depth;
  double maxDepth = 0.5;  // µm (depth control)
  double maxForce = 20;   // µN (force control)
  int steps = 10;
  bool unload = false;
  bool operator==(const Schedule&) const = default;
};

nlohmann::json toJson(const SimulationParams& p);
nlohmann::json toJson(const Schedule& s);
/// Missing keys keep their defaults; a key of the wrong type or an invalid value throws
/// std::runtime_error naming it.
SimulationParams paramsFromJson(const nlohmann::json& j);
/// A JSON integer that fits an int; else throws std::runtime_error "<what> must be an integer"
/// (a float such as 3e11, or 2^40, is refused rather than converted: out of range, converting
/// it to int is undefined behaviour, found by fuzz_session).
int intFromJson(const nlohmann::json& v, const std::string& what);
Schedule scheduleFromJson(const nlohmann::json& j);

}  // namespace tp::gui
