// The assembled model: total gradient and sparse Hessian against finite differences (so the slot
// tables and the scatter are checked, not only the elements), and the invariants of DESIGN.md §4.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "mechanics/Model.h"
#include "support/FiniteDifference.h"
#include "support/ModelDerivatives.h"
#include "tissue/Shapes.h"

using namespace tp;

namespace {

void checkModelDerivatives(Model& m, const Points& x0, const std::string& what) {
  const test::DerivativeErrors e = test::modelDerivativeErrors(m, x0, 1e-6 * m.meanEdgeLength());
  EXPECT_LT(e.energy, 1e-12) << what;
  EXPECT_LT(e.gradient, 1e-6) << what;
  EXPECT_LT(e.hessian, 1e-5) << what;
}

Points perturbed(const Points& x, double amp, unsigned seed, const std::vector<std::uint8_t>& fixed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amp, amp);
  Points y = x;
  for (int v = 0; v < y.cols(); ++v)
    if (!fixed[v])
      for (int k = 0; k < 3; ++k) y(k, v) += u(rng);
  return y;
}

}  // namespace

TEST(ModelAssembly, GradientAndSparseHessianOfAllTermsTogether) {
  // Two box cells, turgor, bending, a probe pressing the top: every term active at once.
  auto cc = std::make_shared<CellComplex>(boxTissue(2, 1, 1, 1.0));
  // Koiter: the box's edges where three walls meet exercise the hinged edges' own unknowns or the
  // rigid junctions' shared ones, the outer sheet's, and the clamped base's built-in edges.
  const std::vector<std::pair<BendingModel, JunctionRule>> models{
      {BendingModel::Koiter, JunctionRule::Hinged}, {BendingModel::Koiter, JunctionRule::Rigid},
      {BendingModel::Hinge, JunctionRule::Hinged}, {BendingModel::Linear, JunctionRule::Hinged}};
  for (const auto& [bm, rule] : models) {
    Material mat;
    mat.youngModulus = 10;
    mat.thickness = 0.1;
    mat.bending = bm;
    mat.junctions = rule;
    Model m(cc, mat);
    m.setCellPressures({0.5, 0.3});
    m.setPointForces({{5, Vec3(0.1, -0.2, 0.3)}});
    const Points x = perturbed(cc->rest, 0.05, 11, cc->fixed);
    m.setProbe({Vec3(0.9, 0.5, 1.0 + 0.3 - 0.05), 0.3});
    Evaluation ev;
    m.evaluate(x, ev, false);
    ASSERT_GT(ev.contactTriangles, 0);
    ASSERT_LT(ev.energy.pressure, 0.0);
    ASSERT_GT(ev.energy.bending, 0.0);
    checkModelDerivatives(m, x, toString(bm) + " " + toString(rule));
  }
}

TEST(ModelAssembly, PerDofClampsArePatternedOut) {
  auto cc = std::make_shared<CellComplex>(octaSphere(1.0, 1));
  Model m(cc, Material{});
  std::vector<std::uint8_t> fixed(3 * cc->vertexCount(), 0);
  fixed[0] = fixed[1] = fixed[5] = 1;  // two components of vertex 0, one of vertex 1
  m.setFixedDofs(fixed);
  m.setUniformPressure(0.2);
  EXPECT_EQ(m.dofs().freeCount(), 3 * cc->vertexCount() - 3);
  const Points x = perturbed(cc->rest, 0.05, 3, cc->fixed);
  checkModelDerivatives(m, x, "per-dof clamps");
}

TEST(ModelInvariants, RigidMotionOfRestStateHasNoElasticEnergyOrForce) {
  auto cc = std::make_shared<CellComplex>(boxTissue(2, 2, 1, 1.5));
  for (const auto& [bm, rule] : {std::pair{BendingModel::Hinge, JunctionRule::Hinged},
                                 std::pair{BendingModel::Koiter, JunctionRule::Hinged},
                                 std::pair{BendingModel::Koiter, JunctionRule::Rigid}}) {
    Material mat;
    mat.bending = bm;
    mat.junctions = rule;
    Model m(cc, mat);
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    const Points x = (R * cc->rest).colwise() + Vec3(3, -1, 2);
    Evaluation ev;
    m.evaluate(x, ev, false);
    EXPECT_NEAR(ev.energy.total(), 0.0, 1e-12) << toString(bm) << " " << toString(rule);
    EXPECT_LT(ev.gradient.cwiseAbs().maxCoeff(), 1e-10) << toString(bm) << " " << toString(rule);
  }
}

TEST(ModelInvariants, ClosedCellForcesSumToZeroAndHaveNoTorque) {
  // A free, deformed, pressurised closed cell: internal forces are self-equilibrated.
  auto cc = std::make_shared<CellComplex>(octaSphere(2.0, 2));
  Model m(cc, Material{});
  m.setUniformPressure(0.8);
  const Points x = perturbed(cc->rest, 0.2, 5, cc->fixed);
  Evaluation ev;
  m.evaluate(x, ev, false);
  Vec3 force = Vec3::Zero(), torque = Vec3::Zero();
  for (int v = 0; v < cc->vertexCount(); ++v) {
    const Vec3 f = ev.gradient.segment<3>(3 * v);
    force += f;
    torque += x.col(v).cross(f);
  }
  const double scale = ev.gradient.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 1e-3);
  EXPECT_LT(force.norm(), 1e-11 * scale * cc->vertexCount());
  EXPECT_LT(torque.norm(), 1e-11 * scale * cc->vertexCount());
}

TEST(ModelInvariants, PressureForceIsPressureTimesVolumeGradient) {
  // −∂W_p/∂x = p ∂V/∂x, with ∂V/∂x by finite differences of the cell volume.
  auto cc = std::make_shared<CellComplex>(octaSphere(1.5, 2));
  Material mat;
  Model m(cc, mat);
  const double p = 0.37;
  m.setUniformPressure(p);
  const Points x = perturbed(cc->rest, 0.1, 9, cc->fixed);
  Evaluation ev;
  m.evaluate(x, ev, false);
  const auto volume = [&](const Eigen::VectorXd& u) {
    const Points y = Eigen::Map<const Points>(u.data(), 3, x.cols());
    return cellVolumes(*cc, y)[0];
  };
  const Eigen::VectorXd dV =
      test::fdGradient(volume, Eigen::Map<const Eigen::VectorXd>(x.data(), x.size()), 1e-6);
  EXPECT_LT(test::relError(-ev.loadGradient, p * dV), 1e-8);
}

TEST(ModelInvariants, EqualPressuresCancelOnSharedWalls) {
  // With the same pressure in both cells the shared wall carries no load: the load equals that of
  // the pressure on the outer surface alone.
  auto cc = std::make_shared<CellComplex>(boxTissue(2, 1, 1, 1.0));
  Model m(cc, Material{});
  const double p = 0.5;
  m.setUniformPressure(p);
  const Points x = perturbed(cc->rest, 0.05, 2, cc->fixed);
  Evaluation ev;
  m.evaluate(x, ev, false);
  Eigen::VectorXd expected = Eigen::VectorXd::Zero(x.size());
  int shared = 0;
  for (int t = 0; t < cc->triangleCount(); ++t) {
    const Wall& w = cc->walls[cc->triangleWall[t]];
    if (w.neighbor >= 0) {
      ++shared;
      continue;
    }
    const auto& tri = cc->triangles[t];
    for (int k = 0; k < 3; ++k)
      expected.segment<3>(3 * tri[k]) -=
          p / 6.0 * x.col(tri[(k + 1) % 3]).cross(x.col(tri[(k + 2) % 3]));
  }
  EXPECT_GT(shared, 0);
  EXPECT_LT(test::relError(ev.loadGradient, expected), 1e-12);
}
