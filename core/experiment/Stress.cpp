#include "experiment/Stress.h"

#include <Eigen/Geometry>
#include <cmath>

namespace tp {

StressField computeStress(const Model& model, const Points& x) {
  const CellComplex& cc = model.complex();
  StressField f;
  f.triangles = model.triangleStresses(x);
  const auto bend = model.triangleBendingEnergy(x);
  const auto restArea = triangleAreas(cc, cc.rest);
  const double h = model.material().thickness;
  f.bendingEnergyDensity.resize(cc.triangleCount());
  for (int t = 0; t < cc.triangleCount(); ++t)
    f.bendingEnergyDensity[t] = restArea[t] > 0 ? bend[t] / (h * restArea[t]) : 0.0;

  f.walls.assign(cc.wallCount(), WallStress{});
  std::vector<Vec3> normal(cc.wallCount(), Vec3::Zero());
  for (int t = 0; t < cc.triangleCount(); ++t) {
    const auto& tri = cc.triangles[t];
    const Vec3 n = 0.5 * (x.col(tri[1]) - x.col(tri[0])).cross(x.col(tri[2]) - x.col(tri[0]));
    const double a = n.norm();
    WallStress& w = f.walls[cc.triangleWall[t]];
    w.area += a;
    w.meanCauchy += a * f.triangles[t].cauchy;
    w.energyDensity += a * f.triangles[t].energyDensity;
    normal[cc.triangleWall[t]] += n;
  }
  for (int i = 0; i < cc.wallCount(); ++i) {
    WallStress& w = f.walls[i];
    if (!(w.area > 0)) continue;
    w.meanCauchy /= w.area;
    w.energyDensity /= w.area;
    const Vec3 n = normal[i].norm() > 0 ? Vec3(normal[i].normalized()) : Vec3::UnitZ();
    const InPlanePrincipal p = inPlanePrincipal(w.meanCauchy, n);
    w.principalMax = p.max;
    w.principalMin = p.min;
    w.vonMises = p.vonMises;
  }
  return f;
}

}  // namespace tp
