#pragma once
// A session as JSON: the tissue file, the parameters, the loading schedule, the sites picked
// (the last one is re-prepared on load) and the curves with their names and points. Units: µm,
// MPa, µN. Example:
//   {"format": "tissueprobe-session", "version": 1, "tissue": "/path/meristem.ply",
//    "parameters": {...}, "schedule": {...}, "sites": [[0, 0, 45.8]], "current_site": 0,
//    "curves": [{"name": "...", "site": [x, y, z], "parameters": {...}, "live": false,
//                "points": [[depth, force, iterations, residual, converged, unloading], ...]}]}

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "Curves.h"
#include "Parameters.h"

namespace tp::gui {

struct SessionState {
  std::string tissuePath;  // empty: the shipped default tissue
  SimulationParams params;
  Schedule schedule;
  std::vector<Eigen::Vector3d> sites;  // µm, in the order they were picked
  int currentSite = -1;                // index into sites, −1 = the default site (the top)
  std::vector<NamedCurve> curves;
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
