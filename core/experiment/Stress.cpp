#include "experiment/Stress.h"

#include <Eigen/Geometry>
#include <cmath>

#include "experiment/Quantities.h"

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

StateFields stateFields(const Model& model, const Points& x, const Points& turgid) {
  const CellComplex& cc = model.complex();
  if (x.cols() != cc.vertexCount() || turgid.cols() != cc.vertexCount())
    throw std::invalid_argument("stateFields: positions do not match the tissue");
  const StressField st = computeStress(model, x);
  const StressField turgidSt = computeStress(model, turgid);
  StateFields out;
  VtuField sigma{"cauchy_stress_MPa", 9, {}}, s2{"principal_min_MPa", 1, {}};
  for (const auto& ts : st.triangles) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) sigma.values.push_back(ts.cauchy(i, j));
    s2.values.push_back(ts.principalMin);
  }
  out.triangles = {sigma, s2};
  // Every colour quantity of the application (experiment/Quantities.h) but the displacement,
  // which the points carry as a vector.
  const QuantityInputs in{&st, &turgidSt, &cc, &x, &turgid};
  const auto values = triangleQuantities(in);
  for (int q = 0; q < kQuantityCount; ++q) {
    if (Quantity(q) == Quantity::Displacement) continue;
    const QuantityInfo& info = quantityInfo(Quantity(q));
    out.triangles.push_back(
        VtuField{std::string(info.key) + "_" + info.unit, 1, values[q]});
  }
  VtuField disp{"displacement_um", 3, {}}, dispRest{"displacement_from_rest_um", 3, {}};
  for (int v = 0; v < cc.vertexCount(); ++v)
    for (int k = 0; k < 3; ++k) {
      disp.values.push_back(x(k, v) - turgid(k, v));
      dispRest.values.push_back(x(k, v) - cc.rest(k, v));
    }
  out.points = {disp, dispRest};
  return out;
}

}  // namespace tp
