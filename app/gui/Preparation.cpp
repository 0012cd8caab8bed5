#include "Preparation.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "tissue/Refine.h"

namespace tp::gui {

namespace {

void say(const std::function<void(const std::string&)>& progress, const std::string& what) {
  if (progress) progress(what);
}

std::unique_ptr<Indentation> prepared(Model& model, const IndentationSettings& settings) {
  auto ind = std::make_unique<Indentation>(model, settings);
  ind->prepare();
  if (!ind->prepared()) throw std::runtime_error(ind->lastMessage());
  return ind;
}

}  // namespace

Vec3 transferPoint(const CellComplex& cc, int t, const Points& from, const Points& to,
                   const Vec3& p) {
  const auto& tri = cc.triangles[t];
  const Vec3 a = from.col(tri[0]), b = from.col(tri[1]), c = from.col(tri[2]);
  const Vec3 n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (!(n2 > 0)) return to.col(tri[0]);
  const double wa = (c - b).cross(p - b).dot(n) / n2;
  const double wb = (a - c).cross(p - c).dot(n) / n2;
  return wa * to.col(tri[0]) + wb * to.col(tri[1]) + (1.0 - wa - wb) * to.col(tri[2]);
}

PreparedIndentation prepareIndentation(std::shared_ptr<const CellComplex> base, double cellSize,
                                       const PreparationRequest& r,
                                       const std::function<void(const std::string&)>& progress) {
  const SimulationParams& params = r.params;
  const Material mat = params.material();
  mat.validate();
  IndentationSettings settings;
  settings.probeRadius = params.probeRadius;
  settings.site = r.site;
  PreparedIndentation out;
  out.complex = base;
  if (params.refineLevel > 0) {
    // Find the site on the turgid unrefined tissue, refine the rest mesh around that material
    // point, and indent the refined tissue at the same place.
    say(progress, "Solving the turgid state to find the site…");
    Model coarse(base, mat);
    coarse.setUniformPressure(params.pressure);
    const auto probe = prepared(coarse, settings);
    const ProbePlacement& pl = probe->placement();
    const Vec3 at = restPositionOf(coarse, probe->turgidState(), pl.site, pl.triangle);
    // Default radius: the larger of three probe radii and one cell, so the walls under the
    // probe are refined whole.
    const double radius = params.refineRadius > 0 ? params.refineRadius
                                                  : std::max(3.0 * params.probeRadius, cellSize);
    std::ostringstream what;
    what << "Refining " << params.refineLevel << "× within " << radius << " µm of the site…";
    say(progress, what.str());
    out.complex =
        std::make_shared<const CellComplex>(refineNear(*base, at, radius, params.refineLevel));
    settings.site = pl.site;
  }
  std::ostringstream what;
  what << "Solving the turgid state (p = " << params.pressure << " MPa)…";
  say(progress, what.str());
  out.model = std::make_unique<Model>(out.complex, mat);
  out.model->setUniformPressure(params.pressure);
  out.indentation = prepared(*out.model, settings);
  if (r.restPoint) {
    // Where the material point went in the new turgid state. The probe was placed at the point
    // of the new surface nearest to the old site, which on a deflated (or stiffer) tissue is
    // another material point: place it again if it is off by more than a twentieth of a radius.
    const CellComplex& cc = *out.complex;
    int t = -1;
    const Vec3 onRest = nearestSurfacePoint(*out.model, cc.rest, *r.restPoint, &t);
    const Vec3 target = transferPoint(cc, t, cc.rest, out.indentation->turgidState(), onRest);
    if ((target - out.indentation->placement().site).norm() > 0.05 * params.probeRadius) {
      say(progress, "Placing the probe on the same material point…");
      settings.site = target;
      out.indentation.reset();
      out.indentation = prepared(*out.model, settings);
    }
  }
  return out;
}

}  // namespace tp::gui
