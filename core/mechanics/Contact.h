#pragma once
// Rigid sphere probe against triangles (DESIGN.md §1): each outer-surface triangle within reach
// of the sphere adds W_t = φ(r − d_t), d_t the distance from the sphere's centre to the triangle
// (not only its vertices, so a probe smaller than a triangle is still caught by its face).
// φ is a C² penalty: κ g³/(6 g₀) for 0 < g < g₀, κ(g²/2 − g g₀/2 + g₀²/6) beyond, 0 when g ≤ 0.
// Units: µm, κ in µN/µm, energy in pJ.
//
// d_t² is differentiated exactly: with the closest feature (vertex, edge or face) found as in
// Ericson's "Real-Time Collision Detection" §5.1.5 and β its affine coordinates, D(X) =
// min_β ‖p − y(β)‖², so by the envelope theorem ∇D = ∂f/∂X and ∇²D = f_XX − f_Xβ f_ββ⁻¹ f_βX
// (f = ‖p − y(β)‖² is quadratic in X at fixed β and in β at fixed X).

#include <Eigen/Core>

#include "mechanics/Math.h"

namespace tp {

using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

enum class ClosestFeature { Face, Edge01, Edge12, Edge20, Vertex0, Vertex1, Vertex2 };

/// Squared distance from p to the triangle (x0, x1, x2) and the closest feature; optionally the
/// exact gradient and Hessian with respect to (p, x0, x1, x2) within that feature's region.
double pointTriangleDistance2(const Vec3& p, const Vec3& x0, const Vec3& x1, const Vec3& x2,
                              ClosestFeature* feature, Vec12* grad, Mat12* hess,
                              Vec3* closest = nullptr);

struct ContactLaw {
  double stiffness = 1e3;   // κ (µN/µm)
  double smoothing = 1e-3;  // g₀ (µm)
  double phi(double g) const;
  double dphi(double g) const;
  double d2phi(double g) const;
};

/// The positive part of a contact element's Hessian (its negative eigenvalues set to zero): the
/// sphere's curvature makes the exact one indefinite (−φ'/(2d) ∇²D), and contact codes keep the
/// positive part, as for barrier terms, so that it never spoils the tangent.
Mat12 positivePart(const Mat12& hessian);

/// Contact energy between a sphere (centre p, radius r) and one triangle; derivatives with respect
/// to (p, x0, x1, x2). Returns 0 (and zero derivatives) when the sphere does not reach the triangle.
double sphereTriangleEnergy(const ContactLaw& law, const Vec3& p, double radius, const Vec3& x0,
                            const Vec3& x1, const Vec3& x2, Vec12* grad, Mat12* hess);

}  // namespace tp
