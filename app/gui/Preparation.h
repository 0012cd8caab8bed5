#pragma once
// Preparing an indentation for the window's parameters and site (the worker calls this, never
// the GUI thread): the model, its turgid state and the probe placed at the site, on the tissue
// as loaded or refined around the site as tissueprobe-cli --refine does. No Qt. Units: µm, MPa.

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "Parameters.h"
#include "experiment/Indentation.h"

namespace tp::gui {

struct PreparationRequest {
  SimulationParams params;
  std::optional<Vec3> site;       // µm, near the outer surface; none: the top of the tissue
  std::optional<Vec3> restPoint;  // the material point (rest state, µm) the probe should stay on
};

struct PreparedIndentation {
  std::shared_ptr<const CellComplex> complex;  // the tissue as loaded, or refined
  std::unique_ptr<Model> model;
  std::unique_ptr<Indentation> indentation;  // prepared; destroyed before the model
};

/// Builds and prepares. `cellSize` (µm) sets the default refinement radius. Throws
/// std::runtime_error with the solver's message when the turgid state is not found, and
/// std::invalid_argument for impossible parameters. `progress` hears what is being done.
PreparedIndentation prepareIndentation(
    std::shared_ptr<const CellComplex> base, double cellSize, const PreparationRequest& request,
    const std::function<void(const std::string&)>& progress = {});

/// The point with the barycentric coordinates of `p` in triangle t of positions `from`, in
/// positions `to` (e.g. from the rest state to a turgid state).
Vec3 transferPoint(const CellComplex& cc, int t, const Points& from, const Points& to,
                   const Vec3& p);

}  // namespace tp::gui
