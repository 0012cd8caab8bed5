#include "mechanics/Membrane.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace tp {

MembraneRest membraneRest(const Vec3& X0, const Vec3& X1, const Vec3& X2) {
  const Vec3 d1 = X1 - X0, d2 = X2 - X0;
  const Vec3 n = d1.cross(d2);
  MembraneRest r;
  r.area = 0.5 * n.norm();
  const Vec3 e1 = d1.normalized();
  const Vec3 e2 = n.normalized().cross(e1);
  Eigen::Matrix2d Dm;  // rest edge vectors in the triangle's own orthonormal frame
  Dm << d1.dot(e1), d2.dot(e1), d1.dot(e2), d2.dot(e2);
  const Eigen::Matrix2d B = Dm.inverse();  // F = Ds B, Ds = [x1 − x0, x2 − x0]
  r.G.row(1) = B.row(0);
  r.G.row(2) = B.row(1);
  r.G.row(0) = -(B.row(0) + B.row(1));
  return r;
}

namespace {

struct PsiDerivs {
  double psi;
  Eigen::Matrix<double, 6, 1> g;  // ∂Ψ/∂(f1, f2)
  Eigen::Matrix<double, 6, 6> H;  // ∂²Ψ/∂(f1, f2)²
};

// Ψ(f1, f2) and derivatives with respect to the two columns of F.
PsiDerivs psiDerivatives(const Vec3& f1, const Vec3& f2, double mu, double lambda, bool wantHess) {
  PsiDerivs d;
  const double I1 = f1.squaredNorm() + f2.squaredNorm();
  const Vec3 n = f1.cross(f2);
  const double J = n.norm();
  const double s = std::sqrt(I1 + 2.0 * J);  // tr S
  d.psi = mu * (I1 - 2.0 * s + 2.0) + 0.5 * lambda * (s - 2.0) * (s - 2.0);

  const double psi_s = -2.0 * mu + lambda * (s - 2.0);
  const double s_I = 0.5 / s, s_J = 1.0 / s;
  const double psi_I = mu + psi_s * s_I;
  const double psi_J = psi_s * s_J;

  Eigen::Matrix<double, 6, 1> gI;  // ∇I₁
  gI << 2.0 * f1, 2.0 * f2;
  Eigen::Matrix<double, 6, 1> gJ = Eigen::Matrix<double, 6, 1>::Zero();  // ∇J
  Vec3 nh = Vec3::Zero();
  const double Jsafe = std::max(J, 1e-300);
  if (J > 0) {
    nh = n / J;
    gJ << f2.cross(nh), nh.cross(f1);
  }
  d.g = psi_I * gI + psi_J * gJ;
  if (!wantHess) return d;

  const double psi_ss = lambda;
  const double s3 = s * s * s;
  const double s_II = -0.25 / s3, s_IJ = -0.5 / s3, s_JJ = -1.0 / s3;
  const double psi_II = psi_ss * s_I * s_I + psi_s * s_II;
  const double psi_IJ = psi_ss * s_I * s_J + psi_s * s_IJ;
  const double psi_JJ = psi_ss * s_J * s_J + psi_s * s_JJ;

  // ∇²J = Nᵀ (I − n̂n̂ᵀ)/J N + bilinear part, N = ∂n/∂(f1, f2) = [−[f2]×, [f1]×].
  Eigen::Matrix<double, 3, 6> N;
  N << -crossMatrix(f2), crossMatrix(f1);
  Eigen::Matrix<double, 6, 6> HJ = N.transpose() * (Mat3::Identity() - nh * nh.transpose()) * N / Jsafe;
  HJ.block<3, 3>(0, 3) -= crossMatrix(nh);
  HJ.block<3, 3>(3, 0) += crossMatrix(nh);

  d.H = psi_II * gI * gI.transpose() + psi_IJ * (gI * gJ.transpose() + gJ * gI.transpose()) +
        psi_JJ * gJ * gJ.transpose() + psi_J * HJ;
  d.H.diagonal().array() += 2.0 * psi_I;
  return d;
}

}  // namespace

double membraneEnergy(const MembraneRest& rest, const Vec3& x0, const Vec3& x1, const Vec3& x2,
                      double mu, double lambda, double h, Vec9* grad, Mat9* hess) {
  const auto& G = rest.G;
  const Vec3 f1 = x0 * G(0, 0) + x1 * G(1, 0) + x2 * G(2, 0);
  const Vec3 f2 = x0 * G(0, 1) + x1 * G(1, 1) + x2 * G(2, 1);
  const PsiDerivs d = psiDerivatives(f1, f2, mu, lambda, hess != nullptr);
  const double w = h * rest.area;
  if (grad) {
    for (int a = 0; a < 3; ++a)
      grad->segment<3>(3 * a) = w * (G(a, 0) * d.g.head<3>() + G(a, 1) * d.g.tail<3>());
  }
  if (hess) {
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        Mat3 blk = Mat3::Zero();
        for (int j = 0; j < 2; ++j)
          for (int k = 0; k < 2; ++k) blk += G(a, j) * G(b, k) * d.H.block<3, 3>(3 * j, 3 * k);
        hess->block<3, 3>(3 * a, 3 * b) = w * blk;
      }
  }
  return w * d.psi;
}

MembraneStress membraneStress(const MembraneRest& rest, const Vec3& x0, const Vec3& x1,
                              const Vec3& x2, double mu, double lambda) {
  const auto& G = rest.G;
  const Vec3 f1 = x0 * G(0, 0) + x1 * G(1, 0) + x2 * G(2, 0);
  const Vec3 f2 = x0 * G(0, 1) + x1 * G(1, 1) + x2 * G(2, 1);
  const PsiDerivs d = psiDerivatives(f1, f2, mu, lambda, false);
  MembraneStress s;
  s.energyDensity = d.psi;
  const Vec3 n = f1.cross(f2);
  const double J = n.norm();
  if (!(J > 0)) return s;
  Eigen::Matrix<double, 3, 2> F, P;
  F << f1, f2;
  P << d.g.head<3>(), d.g.tail<3>();
  s.cauchy = P * F.transpose() / J;
  s.cauchy = 0.5 * (s.cauchy + s.cauchy.transpose()).eval();
  const InPlanePrincipal p = inPlanePrincipal(s.cauchy, n / J);  // the deformed tangent plane
  s.principalMax = p.max;
  s.principalMin = p.min;
  s.vonMises = p.vonMises;
  return s;
}

InPlanePrincipal inPlanePrincipal(const Mat3& sigma, const Vec3& n) {
  const Vec3 t1 = n.unitOrthogonal(), t2 = n.cross(t1);
  Eigen::Matrix<double, 3, 2> T;
  T << t1, t2;
  const Eigen::Matrix2d s = T.transpose() * sigma * T;
  const double mean = 0.5 * (s(0, 0) + s(1, 1));
  const double rad = std::hypot(0.5 * (s(0, 0) - s(1, 1)), s(0, 1));
  InPlanePrincipal p;
  p.max = mean + rad;
  p.min = mean - rad;
  p.vonMises = std::sqrt(p.max * p.max - p.max * p.min + p.min * p.min);
  return p;
}

}  // namespace tp
