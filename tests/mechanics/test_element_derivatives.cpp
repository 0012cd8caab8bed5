// Finite-difference checks of the gradient and Hessian of every energy term, one element at a
// time, over random and degenerate placements (PolyFEM's test_form_derivatives idea: one check
// applied to every form).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <random>

#include "mechanics/Bending.h"
#include "mechanics/Contact.h"
#include "mechanics/Membrane.h"
#include "mechanics/Pressure.h"
#include "support/FiniteDifference.h"

using namespace tp;
using tp::test::fdGradient;
using tp::test::fdJacobian;
using tp::test::relError;

namespace {

using Fn = std::function<double(const Eigen::VectorXd&, Eigen::VectorXd*, Eigen::MatrixXd*)>;

// Checks g = ∇f and H = ∇g against central differences at x. Errors are relative to the
// largest entry, or to `scale` (a typical Hessian entry) when the derivatives vanish.
void checkDerivatives(const Fn& f, const Eigen::VectorXd& x, double h, double tolG, double tolH,
                      const std::string& what, double scale = 0) {
  Eigen::VectorXd g;
  Eigen::MatrixXd H;
  f(x, &g, &H);
  const double hScale = std::max(scale, H.cwiseAbs().maxCoeff());
  const auto value = [&](const Eigen::VectorXd& y) { return f(y, nullptr, nullptr); };
  const auto grad = [&](const Eigen::VectorXd& y) {
    Eigen::VectorXd gy;
    f(y, &gy, nullptr);
    return gy;
  };
  const Eigen::VectorXd gfd = fdGradient(value, x, h);
  const Eigen::MatrixXd Hfd = fdJacobian(grad, x, h);
  EXPECT_LT(relError(g, gfd, 1e-2 * hScale), tolG)
      << what << "\n analytic " << g.transpose() << "\n fd       " << gfd.transpose();
  EXPECT_LT(relError(H, Hfd, 1e-2 * hScale), tolH) << what << "\n" << H << "\n fd\n" << Hfd;
  EXPECT_LT(relError(H, Eigen::MatrixXd(H.transpose())), 1e-12) << what << ": Hessian not symmetric";
}

Vec3 randomVec(std::mt19937& rng, double s = 1.0) {
  std::uniform_real_distribution<double> u(-s, s);
  return Vec3(u(rng), u(rng), u(rng));
}

Eigen::Matrix3d randomRotation(std::mt19937& rng) {
  return Eigen::Quaterniond(Eigen::Vector4d(randomVec(rng).homogeneous()).normalized())
      .toRotationMatrix();
}

}  // namespace

TEST(MembraneDerivatives, RandomConfigurations) {
  std::mt19937 rng(1);
  const double mu = 3.0, lam = 7.0, h = 0.3;
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 X0 = randomVec(rng), X1 = randomVec(rng), X2 = randomVec(rng);
    const MembraneRest rest = membraneRest(X0, X1, X2);
    Eigen::VectorXd x(9);
    x << X0 + 0.3 * randomVec(rng), X1 + 0.3 * randomVec(rng), X2 + 0.3 * randomVec(rng);
    const Fn f = [&](const Eigen::VectorXd& y, Eigen::VectorXd* g, Eigen::MatrixXd* H) {
      Vec9 g9;
      Mat9 H9;
      const double e = membraneEnergy(rest, y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), mu,
                                      lam, h, g ? &g9 : nullptr, H ? &H9 : nullptr);
      if (g) *g = g9;
      if (H) *H = H9;
      return e;
    };
    checkDerivatives(f, x, 1e-6, 1e-6, 1e-5, "membrane trial " + std::to_string(trial));
  }
}

TEST(MembraneDerivatives, CompressedAndRotated) {
  // Strong in-plane compression (tr S < 2, compressive stress) and a large rotation.
  std::mt19937 rng(2);
  const Vec3 X0(0, 0, 0), X1(1, 0, 0), X2(0.3, 0.9, 0);
  const MembraneRest rest = membraneRest(X0, X1, X2);
  const Eigen::Matrix3d R = randomRotation(rng);
  Eigen::VectorXd x(9);
  x << R * (0.6 * X0), R * (0.6 * X1), R * (0.7 * X2);
  const Fn f = [&](const Eigen::VectorXd& y, Eigen::VectorXd* g, Eigen::MatrixXd* H) {
    Vec9 g9;
    Mat9 H9;
    const double e = membraneEnergy(rest, y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), 2.0,
                                    5.0, 0.2, g ? &g9 : nullptr, H ? &H9 : nullptr);
    if (g) *g = g9;
    if (H) *H = H9;
    return e;
  };
  checkDerivatives(f, x, 1e-6, 1e-6, 1e-5, "compressed membrane");
}

TEST(MembraneInvariants, RigidMotionHasNoEnergyOrForce) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 10; ++trial) {
    const Vec3 X0 = randomVec(rng), X1 = randomVec(rng), X2 = randomVec(rng);
    const MembraneRest rest = membraneRest(X0, X1, X2);
    const Eigen::Matrix3d R = randomRotation(rng);
    const Vec3 t = randomVec(rng, 10.0);
    Vec9 g;
    const double e = membraneEnergy(rest, R * X0 + t, R * X1 + t, R * X2 + t, 3.0, 7.0, 0.3, &g,
                                    nullptr);
    EXPECT_NEAR(e, 0.0, 1e-12);
    EXPECT_LT(g.norm(), 1e-10);
  }
}

TEST(MembraneStress, UniaxialStretchMatchesPlaneStressHooke) {
  // Small uniaxial stretch ε along x with free lateral contraction ε_y = −ν ε (plane stress):
  // σ_xx = E ε, σ_yy = 0 to first order.
  const double E = 10.0, nu = 0.3, eps = 1e-4;
  const double mu = E / (2 * (1 + nu)), lam = E * nu / (1 - nu * nu);
  const Vec3 X0(0, 0, 0), X1(1, 0, 0), X2(0.2, 1, 0);
  const MembraneRest rest = membraneRest(X0, X1, X2);
  auto def = [&](const Vec3& X) { return Vec3((1 + eps) * X.x(), (1 - nu * eps) * X.y(), 0); };
  const MembraneStress s = membraneStress(rest, def(X0), def(X1), def(X2), mu, lam);
  EXPECT_NEAR(s.principalMax / (E * eps), 1.0, 1e-3);
  EXPECT_NEAR(s.principalMin / (E * eps), 0.0, 1e-3);
  EXPECT_NEAR(s.vonMises / (E * eps), 1.0, 1e-3);
  EXPECT_NEAR(s.energyDensity / (0.5 * E * eps * eps), 1.0, 1e-3);
}

TEST(DihedralAngle, ValuesAndSign) {
  const Vec3 x0(0, 0, 0), x1(1, 0, 0), x2(0.5, 1, 0);
  EXPECT_NEAR(dihedralAngle(x0, x1, x2, Vec3(0.5, -1, 0), nullptr, nullptr), 0.0, 1e-15);
  // Wing B folded up by 60 degrees about the edge.
  const double a = std::numbers::pi / 3;
  const Vec3 x3(0.5, -std::cos(a), std::sin(a));
  EXPECT_NEAR(std::abs(dihedralAngle(x0, x1, x2, x3, nullptr, nullptr)), a, 1e-12);
  // Opposite fold has opposite sign.
  const Vec3 x3m(0.5, -std::cos(a), -std::sin(a));
  EXPECT_NEAR(dihedralAngle(x0, x1, x2, x3, nullptr, nullptr),
              -dihedralAngle(x0, x1, x2, x3m, nullptr, nullptr), 1e-12);
}

TEST(HingeDerivatives, RandomAndFlatConfigurations) {
  std::mt19937 rng(4);
  const double D = 0.7;
  for (int trial = 0; trial < 30; ++trial) {
    Vec3 X[4] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.4, 0.8, 0), Vec3(0.6, -0.9, 0)};
    if (trial % 3 == 1) X[3].z() = 0.5;  // non-flat rest (rest angle)
    for (auto& v : X) v += 0.1 * randomVec(rng);
    const HingeRest rest = hingeRest(X[0], X[1], X[2], X[3], D);
    Eigen::VectorXd x(12);
    const double amp = trial % 3 == 2 ? 0.0 : 0.3;  // trial%3==2: exactly at rest (θ = θ̄)
    for (int i = 0; i < 4; ++i) x.segment<3>(3 * i) = X[i] + amp * randomVec(rng);
    const Fn f = [&](const Eigen::VectorXd& y, Eigen::VectorXd* g, Eigen::MatrixXd* H) {
      Vec12 g12;
      Mat12 H12;
      const double e = hingeEnergy(rest, y.segment<3>(0), y.segment<3>(3), y.segment<3>(6),
                                   y.segment<3>(9), g ? &g12 : nullptr, H ? &H12 : nullptr);
      if (g) *g = g12;
      if (H) *H = H12;
      return e;
    };
    checkDerivatives(f, x, 1e-6, 1e-6, 2e-5, "hinge trial " + std::to_string(trial));
  }
}

TEST(HingeDerivatives, DihedralAngleItself) {
  // The angle's own Hessian (not only through the energy), including a strongly folded hinge.
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd x(12);
    x << 0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.5, -0.3, (trial % 2 ? 0.95 : -0.95);
    x += 0.2 * Eigen::VectorXd::Random(12);
    const Fn f = [&](const Eigen::VectorXd& y, Eigen::VectorXd* g, Eigen::MatrixXd* H) {
      Vec12 g12;
      Mat12 H12;
      const double th = dihedralAngle(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6),
                                      y.segment<3>(9), g ? &g12 : nullptr, H ? &H12 : nullptr);
      if (g) *g = g12;
      if (H) *H = H12;
      return th;
    };
    checkDerivatives(f, x, 1e-6, 1e-6, 2e-5, "dihedral trial " + std::to_string(trial));
  }
}

TEST(HingeDerivatives, ClosedFormGradientAndHessianAloneAgreeWithTheChainRule) {
  // dihedralAngleGradient (closed form) and dihedralAngleHessian against dihedralAngle, whose
  // derivatives the finite differences above check: flat, folded, nearly folded shut, and wings
  // whose feet fall outside the edge.
  std::mt19937 rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    Vec3 X[4] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0), Vec3(0.5, -1, 0)};
    const double fold = 3.0 * (trial % 7) / 6.0;  // 0 … 3 rad
    X[3] = Vec3(trial % 5 == 4 ? 1.8 : 0.5, -std::cos(fold), std::sin(fold));
    if (trial % 5 == 3) X[2].x() = -0.7;
    const Eigen::Matrix3d R = randomRotation(rng);
    const Vec3 shift = randomVec(rng, 3.0);
    for (auto& p : X) p = R * (p + 0.05 * randomVec(rng)) + shift;
    Vec12 g, gClosed;
    Mat12 H, HAlone;
    const double theta = dihedralAngle(X[0], X[1], X[2], X[3], &g, &H);
    EXPECT_NEAR(dihedralAngleGradient(X[0], X[1], X[2], X[3], gClosed), theta, 1e-14) << trial;
    EXPECT_LT((gClosed - g).norm(), 1e-12 * g.norm()) << trial;
    dihedralAngleHessian(X[0], X[1], X[2], X[3], HAlone);
    EXPECT_EQ((HAlone - H).norm(), 0.0) << trial;
  }
}

TEST(HingeInvariants, RigidMotionHasNoEnergyOrForce) {
  std::mt19937 rng(6);
  const Vec3 X[4] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.4, 0.8, 0.1), Vec3(0.6, -0.9, 0.4)};
  const HingeRest rest = hingeRest(X[0], X[1], X[2], X[3], 1.0);
  const LinearBendingRest lin = linearBendingRest(X[0], X[1], X[2], X[3], 1.0);
  const Eigen::Matrix3d R = randomRotation(rng);
  const Vec3 t = randomVec(rng, 5.0);
  Vec12 g;
  EXPECT_NEAR(hingeEnergy(rest, R * X[0] + t, R * X[1] + t, R * X[2] + t, R * X[3] + t, &g, nullptr),
              0.0, 1e-20);
  EXPECT_LT(g.norm(), 1e-10);
  // The linear model is invariant to translations only (as published).
  EXPECT_NEAR(linearBendingEnergy(lin, X[0] + t, X[1] + t, X[2] + t, X[3] + t, &g, nullptr), 0.0,
              1e-20);
  EXPECT_LT(g.norm(), 1e-10);
}

TEST(LinearBendingDerivatives, Random) {
  std::mt19937 rng(7);
  const Vec3 X[4] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.4, 0.8, 0), Vec3(0.6, -0.9, 0.2)};
  const LinearBendingRest rest = linearBendingRest(X[0], X[1], X[2], X[3], 0.5);
  double asum = 0;
  for (double a : rest.alpha) asum += a;
  EXPECT_NEAR(asum, 0.0, 1e-14);
  Eigen::VectorXd x(12);
  for (int i = 0; i < 4; ++i) x.segment<3>(3 * i) = X[i] + 0.2 * randomVec(rng);
  const Fn f = [&](const Eigen::VectorXd& y, Eigen::VectorXd* g, Eigen::MatrixXd* H) {
    Vec12 g12;
    Mat12 H12;
    const double e = linearBendingEnergy(rest, y.segment<3>(0), y.segment<3>(3), y.segment<3>(6),
                                         y.segment<3>(9), g ? &g12 : nullptr, H ? &H12 : nullptr);
    if (g) *g = g12;
    if (H) *H = H12;
    return e;
  };
  checkDerivatives(f, x, 1e-5, 1e-7, 1e-6, "linear bending");
}

TEST(PressureDerivatives, Random) {
  std::mt19937 rng(8);
  for (int trial = 0; trial < 10; ++trial) {
    Eigen::VectorXd x(9);
    x << randomVec(rng, 2.0), randomVec(rng, 2.0), randomVec(rng, 2.0);
    const Fn f = [&](const Eigen::VectorXd& y, Eigen::VectorXd* g, Eigen::MatrixXd* H) {
      Vec9 g9;
      Mat9 H9;
      const double e = pressureEnergy(0.8, y.segment<3>(0), y.segment<3>(3), y.segment<3>(6),
                                      g ? &g9 : nullptr, H ? &H9 : nullptr);
      if (g) *g = g9;
      if (H) *H = H9;
      return e;
    };
    checkDerivatives(f, x, 1e-6, 1e-8, 1e-8, "pressure");
  }
}

namespace {

Fn contactFn(const ContactLaw& law, double radius) {
  return [law, radius](const Eigen::VectorXd& y, Eigen::VectorXd* g, Eigen::MatrixXd* H) {
    Vec12 g12;
    Mat12 H12;
    const double e = sphereTriangleEnergy(law, y.segment<3>(0), radius, y.segment<3>(3),
                                          y.segment<3>(6), y.segment<3>(9), g ? &g12 : nullptr,
                                          H ? &H12 : nullptr);
    if (g) *g = g12;
    if (H) *H = H12;
    return e;
  };
}

Fn distanceFn() {
  return [](const Eigen::VectorXd& y, Eigen::VectorXd* g, Eigen::MatrixXd* H) {
    Vec12 g12;
    Mat12 H12;
    const double d = pointTriangleDistance2(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6),
                                            y.segment<3>(9), nullptr, g ? &g12 : nullptr,
                                            H ? &H12 : nullptr);
    if (g) *g = g12;
    if (H) *H = H12;
    return d;
  };
}

}  // namespace

TEST(ContactDerivatives, DistanceInEveryRegion) {
  // p above the face, beside each edge, beyond each vertex: each feature's formula is exact.
  const Vec3 a(0, 0, 0), b(2, 0, 0), c(0.5, 1.8, 0);
  const Vec3 probes[] = {Vec3(0.8, 0.5, 0.7),  Vec3(1.0, -0.8, 0.5), Vec3(1.6, 1.3, -0.4),
                         Vec3(-0.7, 0.9, 0.3), Vec3(-0.6, -0.5, 0.6), Vec3(2.7, -0.3, 0.2),
                         Vec3(0.4, 2.6, 0.5)};
  const ClosestFeature expected[] = {ClosestFeature::Face,    ClosestFeature::Edge01,
                                     ClosestFeature::Edge12,  ClosestFeature::Edge20,
                                     ClosestFeature::Vertex0, ClosestFeature::Vertex1,
                                     ClosestFeature::Vertex2};
  for (int i = 0; i < 7; ++i) {
    ClosestFeature f;
    pointTriangleDistance2(probes[i], a, b, c, &f, nullptr, nullptr);
    EXPECT_EQ(static_cast<int>(f), static_cast<int>(expected[i])) << "probe " << i;
    Eigen::VectorXd x(12);
    x << probes[i], a, b, c;
    checkDerivatives(distanceFn(), x, 1e-6, 1e-7, 1e-6, "distance region " + std::to_string(i));
  }
}

TEST(ContactDerivatives, PenaltyRandom) {
  std::mt19937 rng(9);
  const ContactLaw law{50.0, 0.01};
  int touching = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Vec3 a = randomVec(rng), b = randomVec(rng), c = randomVec(rng);
    const Vec3 centroid = (a + b + c) / 3;
    const Vec3 n = (b - a).cross(c - a).normalized();
    const Vec3 p = centroid + 0.4 * randomVec(rng) + 0.5 * n;
    Eigen::VectorXd x(12);
    x << p, a, b, c;
    if (sphereTriangleEnergy(law, p, 0.7, a, b, c, nullptr, nullptr) > 0) ++touching;
    checkDerivatives(contactFn(law, 0.7), x, 1e-7, 1e-5, 1e-4, "contact trial " + std::to_string(trial));
  }
  EXPECT_GT(touching, 10);  // most trials are in contact, so the check is not vacuous
}

TEST(ContactDerivatives, WithinSmoothingZone) {
  // Penetration smaller than g0: the cubic part of the penalty.
  const ContactLaw law{100.0, 0.05};
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  Eigen::VectorXd x(12);
  x << Vec3(0.3, 0.3, 0.5 - 0.02), a, b, c;
  EXPECT_GT(sphereTriangleEnergy(law, x.head<3>(), 0.5, a, b, c, nullptr, nullptr), 0.0);
  checkDerivatives(contactFn(law, 0.5), x, 1e-7, 1e-5, 1e-4, "smoothing zone");
}

TEST(ContactDegenerate, ProbeTangentToFace) {
  // Exactly tangent: zero energy, zero force, and a Hessian that is continuous (C² penalty), so
  // finite differences across the contact onset agree with the analytic zero.
  const ContactLaw law{100.0, 0.05};
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  Eigen::VectorXd x(12);
  x << Vec3(0.3, 0.3, 0.5), a, b, c;
  Vec12 g;
  Mat12 H;
  EXPECT_EQ(sphereTriangleEnergy(law, x.head<3>(), 0.5, a, b, c, &g, &H), 0.0);
  EXPECT_EQ(g.norm(), 0.0);
  checkDerivatives(contactFn(law, 0.5), x, 1e-6, 1e-6, 1e-3, "tangent", law.stiffness);
}

TEST(ContactDegenerate, ProbeOnEdgeOfFlatPair) {
  // Sphere centre exactly above the shared edge of two coplanar triangles: each triangle switches
  // between its face and edge formulas there, but the pair's total energy is smooth; its gradient
  // and Hessian must match finite differences.
  const ContactLaw law{100.0, 0.01};
  const Vec3 v0(0, 0, 0), v1(1, 0, 0), v2(0.5, 0.9, 0), v3(0.5, -0.9, 0);
  const double r = 0.3;
  const Fn pair = [&](const Eigen::VectorXd& y, Eigen::VectorXd* g, Eigen::MatrixXd* H) {
    Vec12 gA, gB;
    Mat12 HA, HB;
    const Vec3 p = y.segment<3>(0);
    const double e = sphereTriangleEnergy(law, p, r, v0, v1, v2, &gA, &HA) +
                     sphereTriangleEnergy(law, p, r, v1, v0, v3, &gB, &HB);
    if (g) *g = gA.head<3>() + gB.head<3>();
    if (H) *H = HA.topLeftCorner<3, 3>() + HB.topLeftCorner<3, 3>();
    return e;
  };
  Eigen::VectorXd x(3);
  x << 0.5, 0.0, r - 0.05;
  Eigen::VectorXd g;
  pair(x, &g, nullptr);
  EXPECT_LT(g.z(), 0.0);  // lowering the probe costs energy: ∂W/∂p_z < 0
  checkDerivatives(pair, x, 1e-6, 1e-6, 1e-5, "edge of flat pair");
}

TEST(ContactDegenerate, ProbeOnVertexOneSided) {
  // Above a vertex the distance changes formula (vertex/edge/face regions meet), so only value and
  // gradient are continuous there. Check the gradient at the vertex, and the Hessian on each side
  // with a step far smaller than the offset into that side.
  const ContactLaw law{100.0, 0.01};
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const double r = 0.3;
  Eigen::VectorXd x(12);
  x << Vec3(0, 0, r - 0.05), a, b, c;
  Eigen::VectorXd g;
  contactFn(law, r)(x, &g, nullptr);
  const auto value = [&](const Eigen::VectorXd& y) { return contactFn(law, r)(y, nullptr, nullptr); };
  EXPECT_LT(relError(g, tp::test::fdGradient(value, x, 1e-7)), 1e-5);
  for (const Vec3& side : {Vec3(1e-4, 1e-4, 0), Vec3(-1e-4, 1e-4, 0), Vec3(-1e-4, -1e-4, 0)}) {
    Eigen::VectorXd xs = x;
    xs.head<3>() += side;
    checkDerivatives(contactFn(law, r), xs, 1e-8, 1e-4, 1e-3, "vertex side");
  }
}

TEST(ContactGeometry, SmallProbeCaughtByTriangleFace) {
  // A probe 1/20 of the triangle's size pressed into the middle of a face, far from all vertices:
  // the face (not a vertex) must push back.
  const ContactLaw law{100.0, 1e-4};
  const Vec3 a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
  const double r = 0.05;
  const Vec3 p(0.6, 0.6, r - 0.01);
  Vec12 g;
  const double e = sphereTriangleEnergy(law, p, r, a, b, c, &g, nullptr);
  EXPECT_GT(e, 0.0);
  EXPECT_LT(g.z(), 0.0);      // lowering the probe costs energy: ∂W/∂p_z < 0
  EXPECT_NEAR(g.segment<3>(3).z() + g.segment<3>(6).z() + g.segment<3>(9).z(), -g.z(), 1e-12);
}

TEST(ContactProjection, PositivePartKeepsTheEigenvectorsAndDropsNegativeEigenvalues) {
  // A symmetric matrix with known eigenpairs (a random rotation Q, eigenvalues from −3 to 8):
  // its positive part is Q max(Λ, 0) Qᵀ, positive semi-definite, equal to it on the positive
  // eigenvectors and zero on the negative ones.
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  Mat12 A;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) A(i, j) = n(rng);
  const Eigen::HouseholderQR<Mat12> qr(A);
  const Mat12 Q = qr.householderQ();
  Eigen::Matrix<double, 12, 1> lambda;
  for (int i = 0; i < 12; ++i) lambda[i] = -3.0 + i;
  const Mat12 H = Q * lambda.asDiagonal() * Q.transpose();
  const Mat12 P = positivePart(H);
  const Mat12 expected = Q * lambda.cwiseMax(0.0).asDiagonal() * Q.transpose();
  EXPECT_LE((P - expected).norm(), 1e-12 * expected.norm());
  for (int i = 0; i < 12; ++i) {
    const Eigen::Matrix<double, 12, 1> q = Q.col(i);
    EXPECT_NEAR((P * q - std::max(lambda[i], 0.0) * q).norm(), 0.0, 1e-12) << "eigenvector " << i;
  }
  // A positive semi-definite matrix is its own positive part.
  EXPECT_LE((positivePart(expected) - expected).norm(), 1e-12 * expected.norm());
}
