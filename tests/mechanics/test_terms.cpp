// Every registered energy term (mechanics/terms/Registry.cpp), alone, against finite
// differences of its energy and gradient, through the model's assembly (its slots and its own
// unknowns), over the configurations where element formulas are delicate — as the IPC Toolkit
// tests its distance and barrier terms: walls nearly flat (hinges at their rest angle), the
// probe's closest feature a face, an edge or a vertex with tiny offsets from the boundaries of
// those regions, a nearly collinear (sliver) triangle, and the whole problem scaled over six
// decades of length. A new term registered is checked here without a line of test.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "mechanics/Model.h"
#include "support/ModelDerivatives.h"
#include "tissue/Shapes.h"

using namespace tp;

namespace {

struct Config {
  std::string name;
  Points x;
  std::optional<Probe> probe;
};


// The configurations on a box tissue of cells of edge s (its top at z = s). The probe (radius
// 0.3 s) presses 0.05 s into the top.
std::vector<Config> configurations(const CellComplex& cc, double s, bool degenerate) {
  const double r = 0.3 * s, press = 0.05 * s;
  std::vector<Config> out;
  out.push_back({"generic", test::perturbedRest(cc, 0.05 * s, 7), Probe{Vec3(0.9 * s, 0.45 * s, s + r - press), r}});
  if (!degenerate) return out;
  out.push_back({"nearly flat", test::perturbedRest(cc, 1e-4 * s, 8), std::nullopt});
  // A top triangle, one of its edges inside the top face (shared with another top triangle), and
  // one of its free vertices.
  int top = -1;
  for (int t = 0; t < cc.triangleCount() && top < 0; ++t) {
    const auto& tri = cc.triangles[t];
    bool allTop = true;
    for (int k = 0; k < 3; ++k) allTop &= std::abs(cc.rest(2, tri[k]) - s) < 1e-9 * s;
    if (allTop) top = t;
  }
  EXPECT_GE(top, 0);
  const auto& tri = cc.triangles[top];
  const Vec3 a = cc.rest.col(tri[0]), b = cc.rest.col(tri[1]), c = cc.rest.col(tri[2]);
  const Vec3 up(0, 0, 1);
  const Points flat = test::perturbedRest(cc, 1e-5 * s, 9);
  // The edge of the triangle that is a diagonal of the square face (the longest).
  Vec3 e0 = a, e1 = b, opp = c;
  if ((c - b).norm() > (e1 - e0).norm()) e0 = b, e1 = c, opp = a;
  if ((a - c).norm() > (e1 - e0).norm()) e0 = c, e1 = a, opp = b;
  const Vec3 mid = 0.5 * (e0 + e1);
  const Vec3 inward = (opp - mid - (opp - mid).dot((e1 - e0).normalized()) * (e1 - e0).normalized()).normalized();
  const double tiny = 1e-3 * s;
  out.push_back({"probe over a face", flat, Probe{(a + b + c) / 3 + (r - press) * up, r}});
  out.push_back({"probe just inside an edge", flat, Probe{mid + tiny * inward + (r - press) * up, r}});
  out.push_back({"probe just outside an edge", flat, Probe{mid - tiny * inward + (r - press) * up, r}});
  out.push_back({"probe just off a vertex", flat,
                 Probe{opp + tiny * (opp - mid).normalized() + (r - press) * up, r}});
  // A sliver: a free top vertex moved to within 1e-3 s of the line of the opposite edge of one
  // of its triangles.
  Points sliver = test::perturbedRest(cc, 0.02 * s, 10);
  int v = -1, w0 = -1, w1 = -1;
  for (int t = 0; t < cc.triangleCount() && v < 0; ++t)
    for (int k = 0; k < 3 && v < 0; ++k)
      if (!cc.fixed[cc.triangles[t][k]] && cc.rest(2, cc.triangles[t][k]) > 0.5 * s) {
        v = cc.triangles[t][k];
        w0 = cc.triangles[t][(k + 1) % 3];
        w1 = cc.triangles[t][(k + 2) % 3];
      }
  EXPECT_GE(v, 0);
  const Vec3 foot = 0.5 * (sliver.col(w0) + sliver.col(w1));
  sliver.col(v) = foot + 1e-3 * s * (sliver.col(v) - foot).normalized();
  out.push_back({"a sliver triangle", sliver, Probe{Vec3(0.9 * s, 0.45 * s, s + r - press), r}});
  return out;
}

void checkEveryTerm(BendingModel bending, JunctionRule junctions) {
  std::map<std::string, int> activeChecks;
  int terms = 0;
  for (double s : {1e-3, 1e-2, 1e-1, 1.0, 1e1, 1e2, 1e3}) {
    auto cc = std::make_shared<CellComplex>(boxTissue(2, 1, 1, s));
    Material mat;
    mat.youngModulus = 10;
    mat.thickness = 0.1 * s;
    mat.bending = bending;
    mat.junctions = junctions;
    Model m(cc, mat);
    terms = static_cast<int>(m.terms().size());
    m.setCellPressures({0.5, 0.3});
    m.setPointForces({{5, Vec3(0.1, -0.2, 0.3) * s * s}});
    for (const Config& c : configurations(*cc, s, s == 1.0)) {
      if (c.probe)
        m.setProbe(*c.probe);
      else
        m.clearProbe();
      for (int k = 0; k < terms; ++k) {
        const EnergyTerm& term = *m.terms()[k];
        const std::string what = toString(bending) + "/" + toString(junctions) + ", " +
                                 term.name() + ", " + c.name + ", length scale " + std::to_string(s);
        Evaluation ev;
        m.evaluate(c.x, ev, EvalOptions{.onlyTerm = k});
        if (ev.gradient.cwiseAbs().maxCoeff() == 0.0) continue;  // not acting here (no probe)
        const test::DerivativeErrors e = test::modelDerivativeErrors(m, c.x, 1e-7 * m.meanEdgeLength(), k);
        EXPECT_LT(e.energy, 1e-12) << what;
        EXPECT_LT(e.gradient, 1e-6) << what;
        EXPECT_LT(e.hessian, 1e-5) << what;
        ++activeChecks[term.name()];
      }
    }
  }
  // Membrane, bending, pressure, contact, point forces: each checked in every configuration it
  // acts in (contact: all but the probe-free one, 6 at unit scale and 6 others).
  EXPECT_EQ(terms, bending == BendingModel::None ? 4 : 5);
  EXPECT_EQ(static_cast<int>(activeChecks.size()), terms);
  for (const auto& [name, n] : activeChecks) EXPECT_GE(n, 12) << name;
}

}  // namespace

TEST(EveryTerm, KoiterHingedAgainstFiniteDifferences) {
  checkEveryTerm(BendingModel::Koiter, JunctionRule::Hinged);
}
TEST(EveryTerm, KoiterRigidAgainstFiniteDifferences) {
  checkEveryTerm(BendingModel::Koiter, JunctionRule::Rigid);
}
TEST(EveryTerm, HingeAgainstFiniteDifferences) {
  checkEveryTerm(BendingModel::Hinge, JunctionRule::Hinged);
}
TEST(EveryTerm, LinearAgainstFiniteDifferences) {
  checkEveryTerm(BendingModel::Linear, JunctionRule::Hinged);
}
TEST(EveryTerm, RegistryHoldsEachTermOnce) {
  std::map<std::string, int> names;
  for (const auto& r : registeredTerms()) ++names[r.name];
  EXPECT_EQ(names.size(), registeredTerms().size());
  // One bending model at a time: a material builds exactly one of the three bending terms.
  auto cc = std::make_shared<CellComplex>(boxTissue(1, 1, 1, 1.0));
  for (BendingModel b : {BendingModel::Koiter, BendingModel::Hinge, BendingModel::Linear}) {
    Material mat;
    mat.bending = b;
    const Model m(cc, mat);
    int bendingTerms = 0;
    for (const auto& t : m.terms()) bendingTerms += t->part() == EnergyPart::Bending;
    EXPECT_EQ(bendingTerms, 1) << toString(b);
  }
}
