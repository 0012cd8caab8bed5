#include "mechanics/Contact.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace tp {

namespace {

// Region of the closest point (Ericson, Real-Time Collision Detection, §5.1.5).
ClosestFeature classify(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ClosestFeature::Vertex0;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return ClosestFeature::Vertex1;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return ClosestFeature::Edge01;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return ClosestFeature::Vertex2;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return ClosestFeature::Edge20;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return ClosestFeature::Edge12;
  return ClosestFeature::Face;
}

}  // namespace

namespace {

// Squared distance from p to the affine hull of feature f (m + 1 vertices of the triangle) and
// its exact derivatives with respect to (p, x0, x1, x2) by the envelope theorem.
double featureDistance2(const Vec3& p, const Vec3* const xs[3], const int f[3], int m,
                        Vec12* grad, Mat12* hess, Vec3* closest) {
  const Vec3& y0 = *xs[f[0]];
  Eigen::Matrix<double, 3, 2> Eb;
  for (int k = 0; k < m; ++k) Eb.col(k) = *xs[f[k + 1]] - y0;
  // β: least-squares coordinates of p's projection onto the feature's affine hull.
  Eigen::Vector2d beta = Eigen::Vector2d::Zero();
  Eigen::Matrix2d M = Eigen::Matrix2d::Identity();
  if (m == 1) {
    M(0, 0) = Eb.col(0).squaredNorm();
    beta(0) = Eb.col(0).dot(p - y0) / M(0, 0);
  } else if (m == 2) {
    M = Eb.transpose() * Eb;
    beta = M.ldlt().solve(Eb.transpose() * (p - y0));
  }
  Vec3 y = y0;
  for (int k = 0; k < m; ++k) y += beta(k) * Eb.col(k);
  if (closest) *closest = y;
  const Vec3 r = p - y;
  const double D = r.squaredNorm();
  if (!grad && !hess) return D;

  // A = ∂r/∂X as per-vertex coefficients times I: block 0 is p, blocks 1..3 are x0..x2.
  double coef[4] = {1, 0, 0, 0};
  double sumBeta = 0;
  for (int k = 0; k < m; ++k) {
    coef[1 + f[k + 1]] = -beta(k);
    sumBeta += beta(k);
  }
  coef[1 + f[0]] = -(1.0 - sumBeta);
  if (grad)
    for (int i = 0; i < 4; ++i) grad->segment<3>(3 * i) = 2.0 * coef[i] * r;
  if (hess) {
    hess->setZero();
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        hess->block<3, 3>(3 * i, 3 * j).diagonal().setConstant(2.0 * coef[i] * coef[j]);
    if (m > 0) {
      // f_βX, row k: 2 (∂A/∂β_k)ᵀ r − 2 Aᵀ e_k.
      Eigen::Matrix<double, 2, 12> C = Eigen::Matrix<double, 2, 12>::Zero();
      for (int k = 0; k < m; ++k) {
        const Vec3 ek = Eb.col(k);
        for (int i = 0; i < 4; ++i) C.block<1, 3>(k, 3 * i) = -2.0 * coef[i] * ek.transpose();
        C.block<1, 3>(k, 3 * (1 + f[0])) += 2.0 * r.transpose();
        C.block<1, 3>(k, 3 * (1 + f[k + 1])) -= 2.0 * r.transpose();
      }
      if (m == 1) {
        *hess -= C.row(0).transpose() * C.row(0) / (2.0 * M(0, 0));
      } else {
        *hess -= C.topRows<2>().transpose() * (2.0 * M).inverse() * C.topRows<2>();
      }
    }
  }
  return D;
}

}  // namespace

double pointTriangleDistance2(const Vec3& p, const Vec3& x0, const Vec3& x1, const Vec3& x2,
                              ClosestFeature* featureOut, Vec12* grad, Mat12* hess,
                              Vec3* closest) {
  const ClosestFeature feature = classify(p, x0, x1, x2);
  if (featureOut) *featureOut = feature;
  // The feature as a base vertex f[0] and up to two more; local indices into (x0, x1, x2).
  int f[3] = {0, 1, 2}, m = 0, opposite = -1;
  switch (feature) {
    case ClosestFeature::Vertex0: f[0] = 0; break;
    case ClosestFeature::Vertex1: f[0] = 1; break;
    case ClosestFeature::Vertex2: f[0] = 2; break;
    case ClosestFeature::Edge01: f[0] = 0; f[1] = 1; m = 1; opposite = 2; break;
    case ClosestFeature::Edge12: f[0] = 1; f[1] = 2; m = 1; opposite = 0; break;
    case ClosestFeature::Edge20: f[0] = 2; f[1] = 0; m = 1; opposite = 1; break;
    case ClosestFeature::Face: m = 2; break;
  }
  const Vec3* const xs[3] = {&x0, &x1, &x2};
  const double D = featureDistance2(p, xs, f, m, grad, hess, closest);
  if (!hess || m == 0) return D;

  // On the boundary between the face region and an edge region, D is C¹ but its Hessian jumps;
  // use the mean of the two one-sided Hessians, the symmetric limit (exact for the sum over two
  // coplanar triangles, whose total is smooth there).
  const Vec3 n = (x1 - x0).cross(x2 - x0);
  const double n2 = n.squaredNorm();
  if (!(n2 > 0)) return D;
  auto bary = [&](int k) {  // barycentric coordinate of p's plane projection, opposite vertex k
    const Vec3& a = *xs[(k + 1) % 3];
    const Vec3& b = *xs[(k + 2) % 3];
    return (b - a).cross(p - a).dot(n) / n2;
  };
  int edgeOpp = opposite;
  if (m == 2) {
    for (int k = 0; k < 3; ++k)
      if (std::abs(bary(k)) < 1e-12) edgeOpp = k;
    if (edgeOpp < 0) return D;
  } else if (std::abs(bary(opposite)) >= 1e-12) {
    return D;
  }
  Mat12 other;
  if (m == 2) {
    const int fe[3] = {(edgeOpp + 1) % 3, (edgeOpp + 2) % 3, 0};
    featureDistance2(p, xs, fe, 1, nullptr, &other, nullptr);
  } else {
    const int ff[3] = {0, 1, 2};
    featureDistance2(p, xs, ff, 2, nullptr, &other, nullptr);
  }
  *hess = 0.5 * (*hess + other);
  return D;
}

double ContactLaw::phi(double g) const {
  if (g <= 0) return 0;
  if (g < smoothing) return stiffness * g * g * g / (6.0 * smoothing);
  return stiffness * (0.5 * g * g - 0.5 * g * smoothing + smoothing * smoothing / 6.0);
}

double ContactLaw::dphi(double g) const {
  if (g <= 0) return 0;
  if (g < smoothing) return stiffness * g * g / (2.0 * smoothing);
  return stiffness * (g - 0.5 * smoothing);
}

double ContactLaw::d2phi(double g) const {
  if (g <= 0) return 0;
  if (g < smoothing) return stiffness * g / smoothing;
  return stiffness;
}

Mat12 positivePart(const Mat12& hessian) {
  Eigen::SelfAdjointEigenSolver<Mat12> es(hessian);
  return es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() *
         es.eigenvectors().transpose();
}

double sphereTriangleEnergy(const ContactLaw& law, const Vec3& p, double radius, const Vec3& x0,
                            const Vec3& x1, const Vec3& x2, Vec12* grad, Mat12* hess) {
  Vec12 gD;
  Mat12 HD;
  const double D = pointTriangleDistance2(p, x0, x1, x2, nullptr, nullptr, nullptr);
  const double d = std::sqrt(D);
  const double g = radius - d;
  if (g <= 0 || d <= 0) {
    if (grad) grad->setZero();
    if (hess) hess->setZero();
    return 0;
  }
  if (grad || hess) pointTriangleDistance2(p, x0, x1, x2, nullptr, &gD, hess ? &HD : nullptr);
  // W(D) = φ(r − √D): W_D = −φ'/(2d), W_DD = φ''/(4d²) + φ'/(4d³).
  const double dp = law.dphi(g), d2p = law.d2phi(g);
  const double WD = -dp / (2.0 * d);
  if (grad) *grad = WD * gD;
  if (hess) {
    const double WDD = d2p / (4.0 * D) + dp / (4.0 * D * d);
    *hess = WDD * gD * gD.transpose() + WD * HD;
  }
  return law.phi(g);
}

}  // namespace tp
