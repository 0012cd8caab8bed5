#pragma once
// The parameters a user sets in the window: material, turgor, probe and refinement (what a
// preparation depends on) and the loading schedule of a "Run curve". Units: µm, MPa, µN.

#include <nlohmann/json.hpp>
#include <string>

#include "experiment/Experiment.h"
#include "experiment/Indentation.h"
#include "mechanics/Material.h"

namespace tp::gui {

// Every default is core's (Material, ExperimentSettings, IndentationSettings, MeshSettings), so
// the window, the command line and the benchmarks start from the same values.
struct SimulationParams {
  double youngModulus = Material{}.youngModulus;    // E, MPa
  double poissonRatio = Material{}.poissonRatio;    // ν
  double thickness = Material{}.thickness;          // h, µm
  double pressure = ExperimentSettings{}.pressure;  // turgor p of every cell, MPa
  BendingModel bending = Material{}.bending;
  JunctionRule junctions = Material{}.junctions;  // how walls share rotation at a junction (Koiter)
  double probeRadius = IndentationSettings{}.probeRadius;  // µm
  // The mesh at the site (core/experiment/Experiment.h): automatic (refined level by level
  // until the estimated discretisation error is within meshTolerance) or a fixed level.
  bool autoMesh = MeshSettings{}.automatic;
  int meshLevel = MeshSettings{}.level;            // the fixed level (0 = the tissue as loaded)
  double meshTolerance = MeshSettings{}.tolerance;  // relative
  // A band along the junctions of the probed cell at the width of the walls' bending layer
  // (MeshSettings::junctionBand): to check a result's sensitivity to it.
  bool junctionBand = MeshSettings{}.junctionBand;

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
  Control control = IndentationSettings{}.control;
  double maxDepth = IndentationSettings{}.maxDepth;  // µm (depth control)
  double maxForce = IndentationSettings{}.maxForce;  // µN (force control)
  int steps = IndentationSettings{}.steps;
  bool unload = IndentationSettings{}.unload;
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
