#include "mechanics/Bending.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace tp {

// θ = atan2(y, x) with x = u·v, y = (u × v)·ŵ, u = e × a, v = b × e, w = e,
// e = x1 − x0, a = x2 − x0, b = x3 − x0 (u, v: unnormalised normals of A and B).
// Derivatives by the chain rule through q = (u, v, w): ∇θ = Jᵀ ∇_q θ and
// ∇²θ = Jᵀ ∇²_q θ J + Σ_k (∂θ/∂q_k) ∇² q_k, where u and v are bilinear in the edge vectors.
namespace {

// The angle (when `angle`), its gradient and Hessian (each when asked for).
double dihedral(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3, Vec12* grad,
                Mat12* hess, bool angle) {
  const Vec3 e = x1 - x0, a = x2 - x0, b = x3 - x0;
  const Vec3 u = e.cross(a), v = b.cross(e);
  const double wn = e.norm();
  const Vec3 wh = e / wn;
  const Vec3 c = u.cross(v);
  const double x = u.dot(v);
  const double y = c.dot(wh);
  const double theta = angle ? std::atan2(y, x) : 0.0;
  if (!grad && !hess) return theta;

  const double r2 = x * x + y * y;
  const double th_x = -y / r2, th_y = x / r2;
  Eigen::Matrix<double, 9, 1> gx, gy;
  const Mat3 P = Mat3::Identity() - wh * wh.transpose();
  gx << v, u, Vec3::Zero();
  gy << v.cross(wh), wh.cross(u), P * c / wn;
  const Eigen::Matrix<double, 9, 1> gq = th_x * gx + th_y * gy;

  if (grad) {  // Jᵀ g_q with J = ∂q/∂x written out: [c]ₓᵀ w = w × c
    const Vec3 gu = gq.segment<3>(0), gv = gq.segment<3>(3), ge = gq.segment<3>(6);
    grad->segment<3>(0) = gu.cross(a - e) + gv.cross(e - b) - ge;
    grad->segment<3>(3) = a.cross(gu) + gv.cross(b) + ge;
    grad->segment<3>(6) = gu.cross(e);
    grad->segment<3>(9) = e.cross(gv);
  }
  if (!hess) return theta;

  // ∇²_q θ = θ_x ∇²_q x + θ_y ∇²_q y + [∇_q x ∇_q y] S [∇_q x ∇_q y]ᵀ, S the 2 × 2 Hessian of
  // atan2; ∇²_q x couples u and v (the identity), ∇²_q y is written block by block.
  const double r4 = r2 * r2;
  const double th_xx = 2 * x * y / r4, th_yy = -2 * x * y / r4, th_xy = (y * y - x * x) / r4;
  Eigen::Matrix<double, 9, 2> Gxy, W;
  Gxy << gx, gy;
  W << th_xx * gx + th_xy * gy, th_xy * gx + th_yy * gy;
  Eigen::Matrix<double, 9, 9> Hq;
  Hq.noalias() = W.lazyProduct(Gxy.transpose());
  const Mat3 Cw = crossMatrix(wh), Cu = crossMatrix(u), Cv = crossMatrix(v);
  const Mat3 uv = th_x * Mat3::Identity() - th_y * Cw;  // the (u, v) block; (v, u) is its transpose
  Hq.block<3, 3>(0, 3) += uv;
  Hq.block<3, 3>(3, 0) += uv.transpose();
  const Mat3 uw = (th_y / wn) * Cv * P, vw = (-th_y / wn) * Cu * P;
  Hq.block<3, 3>(0, 6) += uw;
  Hq.block<3, 3>(6, 0) += uw.transpose();
  Hq.block<3, 3>(3, 6) += vw;
  Hq.block<3, 3>(6, 3) += vw.transpose();
  const double cw = c.dot(wh);
  Hq.block<3, 3>(6, 6) -=
      (th_y / (wn * wn)) * (c * wh.transpose() + wh * c.transpose() +
                            cw * (Mat3::Identity() - 3.0 * wh * wh.transpose()));

  // θ depends on the differences (e, a, b) alone: its Hessian R over them is Mᵀ ∇²_q θ M with
  // M = ∂q/∂(e, a, b) = [[−[a]ₓ, [e]ₓ, 0], [[b]ₓ, 0, −[e]ₓ], [I, 0, 0]] (block-sparse, written
  // out: about a third of the work of the product with the 9 × 12 ∂q/∂x), plus the second-order
  // terms of the bilinear u = e × a and v = b × e; then x0 = −(x1 + x2 + x3) in the differences
  // gives the 12 × 12 blocks.
  const Mat3 Ce = crossMatrix(e), Ca = crossMatrix(a), Cb = crossMatrix(b);
  const auto Qu = Hq.middleCols<3>(0), Qv = Hq.middleCols<3>(3), Qw = Hq.middleCols<3>(6);
  Eigen::Matrix<double, 9, 9> QM;  // ∇²_q θ M, columns by (e, a, b)
  QM.middleCols<3>(0).noalias() = Qv.lazyProduct(Cb);
  QM.middleCols<3>(0).noalias() -= Qu.lazyProduct(Ca);
  QM.middleCols<3>(0) += Qw;
  QM.middleCols<3>(3).noalias() = Qu.lazyProduct(Ce);
  QM.middleCols<3>(6).noalias() = -Qv.lazyProduct(Ce);
  Eigen::Matrix<double, 9, 9> R;  // Mᵀ (∇²_q θ M); [c]ₓᵀ = −[c]ₓ
  R.middleRows<3>(0).noalias() = Ca.lazyProduct(QM.middleRows<3>(0));
  R.middleRows<3>(0).noalias() -= Cb.lazyProduct(QM.middleRows<3>(3));
  R.middleRows<3>(0) += QM.middleRows<3>(6);
  R.middleRows<3>(3).noalias() = -Ce.lazyProduct(QM.middleRows<3>(0));
  R.middleRows<3>(6).noalias() = Ce.lazyProduct(QM.middleRows<3>(3));
  // gu·(e × a) and gv·(b × e): ∂²/∂e∂a = −[gu]ₓ, ∂²/∂e∂b = [gv]ₓ.
  const Mat3 Gu = crossMatrix(gq.segment<3>(0)), Gv = crossMatrix(gq.segment<3>(3));
  R.block<3, 3>(0, 3) -= Gu;
  R.block<3, 3>(3, 0) += Gu;
  R.block<3, 3>(0, 6) += Gv;
  R.block<3, 3>(6, 0) -= Gv;
  hess->block<9, 9>(3, 3) = R;
  Mat3 corner = Mat3::Zero();
  for (int j = 0; j < 3; ++j) {
    const Mat3 col = R.block<3, 3>(0, 3 * j) + R.block<3, 3>(3, 3 * j) + R.block<3, 3>(6, 3 * j);
    const Mat3 row = R.block<3, 3>(3 * j, 0) + R.block<3, 3>(3 * j, 3) + R.block<3, 3>(3 * j, 6);
    hess->block<3, 3>(0, 3 + 3 * j) = -col;
    hess->block<3, 3>(3 + 3 * j, 0) = -row;
    corner += col;
  }
  hess->block<3, 3>(0, 0) = corner;
  return theta;
}

}  // namespace

double dihedralAngle(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3, Vec12* grad,
                     Mat12* hess) {
  return dihedral(x0, x1, x2, x3, grad, hess, true);
}

void dihedralAngleHessian(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                          Mat12& hess) {
  dihedral(x0, x1, x2, x3, nullptr, &hess, false);
}

// θ grows as n_B turns positively about ê relative to n_A, so ∂θ/∂n_A = −(ê × n_A)/|n_A|² and
// ∂θ/∂n_B = (ê × n_B)/|n_B|²; through n_A = e × (x2 − x0) and n_B = (x3 − x0) × e these give the
// wings' gradients below. Translating all four points or moving x0 and x1 with the wings' feet on
// the edge leaves θ unchanged, which fixes the ends' shares:
//   ∇_{x1}θ = −(α_A ∇_{x2}θ + α_B ∇_{x3}θ),   ∇_{x0}θ = −(∇_{x1}θ + ∇_{x2}θ + ∇_{x3}θ),
// α the wings' projections on the edge as fractions of it from x0.
double dihedralAngleGradient(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                             Vec12& grad) {
  const Vec3 e = x1 - x0, a = x2 - x0, b = x3 - x0;
  const Vec3 u = e.cross(a), v = b.cross(e);
  const double ee = e.squaredNorm(), wn = std::sqrt(ee);
  const double theta = std::atan2(u.cross(v).dot(e) / wn, u.dot(v));
  const Vec3 g2 = (-wn / u.squaredNorm()) * u, g3 = (-wn / v.squaredNorm()) * v;
  const double alphaA = a.dot(e) / ee, alphaB = b.dot(e) / ee;
  const Vec3 g1 = -(alphaA * g2 + alphaB * g3);
  grad.segment<3>(0) = -(g1 + g2 + g3);
  grad.segment<3>(3) = g1;
  grad.segment<3>(6) = g2;
  grad.segment<3>(9) = g3;
  return theta;
}

HingeRest hingeRest(const Vec3& X0, const Vec3& X1, const Vec3& X2, const Vec3& X3, double D) {
  HingeRest r;
  const Vec3 e = X1 - X0;
  const double areaA = 0.5 * e.cross(X2 - X0).norm();
  const double areaB = 0.5 * (X3 - X0).cross(e).norm();
  r.stiffness = D * e.squaredNorm() / std::max(2.0 * (areaA + areaB), 1e-300);
  r.restAngle = dihedralAngle(X0, X1, X2, X3, nullptr, nullptr);
  return r;
}

double hingeEnergy(const HingeRest& rest, const Vec3& x0, const Vec3& x1, const Vec3& x2,
                   const Vec3& x3, Vec12* grad, Mat12* hess) {
  Vec12 g;
  Mat12 H;
  const double theta = dihedralAngle(x0, x1, x2, x3, (grad || hess) ? &g : nullptr,
                                     hess ? &H : nullptr);
  double d = theta - rest.restAngle;  // wrapped into (−π, π]
  if (d > std::numbers::pi) d -= 2 * std::numbers::pi;
  if (d <= -std::numbers::pi) d += 2 * std::numbers::pi;
  const double k = rest.stiffness;
  if (grad) *grad = 2.0 * k * d * g;
  if (hess) *hess = 2.0 * k * (g * g.transpose() + d * H);
  return k * d * d;
}

LinearBendingRest linearBendingRest(const Vec3& X0, const Vec3& X1, const Vec3& X2,
                                    const Vec3& X3, double D) {
  // Volino's naming: edge C = X0, D = X1; wings A = X2, B = X3.
  const double NA = (X2 - X0).cross(X2 - X1).norm();  // 2 × area of the wing triangle A
  const double NB = (X3 - X1).cross(X3 - X0).norm();
  const double NC = (X0 - X3).cross(X0 - X2).norm();  // 2 × area of (C, A, B)
  const double ND = (X1 - X2).cross(X1 - X3).norm();
  LinearBendingRest r;
  const double sAB = std::max(NA + NB, 1e-300), sCD = std::max(NC + ND, 1e-300);
  r.alpha = {-ND / sCD, -NC / sCD, NB / sAB, NA / sAB};
  const double len = (X1 - X0).norm();
  const double hA = NA / len, hB = NB / len;
  r.lambda = (2.0 / 3.0) * (hA + hB) / (hA * hA * hB * hB) * len * D;
  r.restVector = r.alpha[0] * X0 + r.alpha[1] * X1 + r.alpha[2] * X2 + r.alpha[3] * X3;
  return r;
}

double linearBendingEnergy(const LinearBendingRest& rest, const Vec3& x0, const Vec3& x1,
                           const Vec3& x2, const Vec3& x3, Vec12* grad, Mat12* hess) {
  const auto& al = rest.alpha;
  const Vec3 R = al[0] * x0 + al[1] * x1 + al[2] * x2 + al[3] * x3 - rest.restVector;
  if (grad)
    for (int i = 0; i < 4; ++i) grad->segment<3>(3 * i) = rest.lambda * al[i] * R;
  if (hess) {
    hess->setZero();
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        hess->block<3, 3>(3 * i, 3 * j).diagonal().setConstant(rest.lambda * al[i] * al[j]);
  }
  return 0.5 * rest.lambda * R.squaredNorm();
}

}  // namespace tp
