#pragma once
// A session as JSON: the tissue file, the parameters, the loading schedule, the sites picked
// (the last one is re-prepared on load) and the curves with their names and points. Units: µm,
// MPa, µN. Example:
//   {"format": "tissueprobe-session", "version": 1, "tissue": "/path/meristem.ply",
//    "parameters": {...}, "schedule": {...}, "sites": [[0, 0, 45.8]], "current_site": 0,
//    "curves": [{"name": "...", "site": [x, y, z], "parameters": {...}, "live": false,
//                "points": [[depth, force, iterations, residual, converged, unloading], ...]}],
//    "display": {"quantity": "von_mises", "colour_map": "viridis", "auto_range": true,
//                "range": [0, 20], "outlines": true, "mesh": false, "principal_directions": false,
//                "deformation_scale": 1,
//                "section": {"on": false, "axis": "y", "position": 0.5, "keep_other_side": false},
//                "camera": {"target": [x, y, z], "orientation": [w, x, y, z], "distance": d}},
//    "map": {"plan": {...}, "parameters": {...}, "results": [...]}}   (see SessionMap)

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "Curves.h"
#include "Parameters.h"
#include "experiment/Map.h"

namespace tp::gui {

/// How the tissue was shown (the Colour and section dock and the camera). Keys as in the JSON.
struct DisplaySettings {
  std::string quantity = "von_mises";  // a key of core/experiment/Quantities
  std::string colourMap = "viridis";   // ColorMap::key
  bool autoRange = true;
  double lo = 0, hi = 1;  // the manual range, in the quantity's unit
  bool outlines = true, mesh = false;
  bool glyphs = false;  // principal-stress directions drawn
  double deformationScale = 1;  // 1..50
  bool section = false;
  int sectionAxis = 1;            // 0 x, 1 y, 2 z
  double sectionPosition = 0.5;   // 0..1 across the tissue's extent
  bool keepOtherSide = false;
  struct Camera {
    Eigen::Vector3d target = Eigen::Vector3d::Zero();  // µm
    Eigen::Vector4d orientation{1, 0, 0, 0};           // unit quaternion w, x, y, z
    double distance = 1;                               // µm, eye to target
  };
  std::optional<Camera> camera;  // none: the initial view
};

/// A stiffness map shown in the application: what was mapped, with which parameters, and the
/// sites done (task order; a task not done has task = −1). In JSON as map.json has it, plus the
/// parameters: {"plan": {...}, "parameters": {...}, "results": [...]}.
struct SessionMap {
  MapPlan plan;
  SimulationParams params;
  std::vector<TaskResult> results;
};
nlohmann::json mapToJson(const SessionMap& m);
/// Throws std::runtime_error naming `where` and the key.
SessionMap mapFromJson(const nlohmann::json& j, const std::string& where);

struct SessionState {
  std::string tissuePath;  // empty: the shipped default tissue
  SimulationParams params;
  Schedule schedule;
  std::vector<Eigen::Vector3d> sites;  // µm, in the order they were picked
  int currentSite = -1;                // index into sites, −1 = the default site (the top)
  std::vector<NamedCurve> curves;
  std::optional<DisplaySettings> display;  // none in sessions of earlier versions
  std::optional<SessionMap> map;           // a stiffness map, if one was made
};

nlohmann::json sessionToJson(const SessionState& s);
/// Throws std::runtime_error naming `nameForErrors` and the offending key.
SessionState sessionFromJson(const nlohmann::json& j, const std::string& nameForErrors);
/// Parses the text of a session file; not JSON (or a number JSON cannot hold) throws
/// std::runtime_error too.
SessionState sessionFromText(const std::string& text, const std::string& nameForErrors);

/// Writes the session atomically. A tissue path inside the session's folder is stored relative
/// to it, so a folder of session + tissue can be moved. Throws std::runtime_error.
void saveSession(const std::string& path, const SessionState& s);
/// Reads a session; a relative tissue path is resolved against the session's folder. Throws
/// std::runtime_error naming the file and the problem.
SessionState loadSession(const std::string& path);

}  // namespace tp::gui
