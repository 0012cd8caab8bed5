#pragma once
// Bending of the walls, per hinge (two triangles sharing an edge, see mesh/Topology.h).
//
// Hinge model (default): W = k (θ − θ̄)², θ the signed dihedral angle between the triangles'
// normals, θ̄ its rest value, k = D ‖ē‖² / (2 (Ā_A + Ā_B)) with D = E h³/(12(1−ν²)).
// The constant makes the hinges reproduce the plate energy D/2 ∫ (tr κ)² on an equilateral mesh:
// for the piecewise-linear interpolant of z = ½ xᵀKx on a lattice of edge ℓ, the angle across an
// edge with unit normal m and tangent t is θ = ℓ (3 K_mm − K_tt) / (2√3); summing k θ² over the
// three edge directions (2√3/ℓ² edges per area) gives D (2H² − (4/3) K_G) per area, i.e. the mean
// curvature part exactly (the Gaussian part only changes boundary terms). Checked by tests on a
// cylinder and against the clamped-plate solutions δ = F a²/(16πD) and δ = q a⁴/(64D).
//
// Linear model (Volino & Magnenat-Thalmann 2006, "Simple linear bending stiffness in particle
// systems"): bending vector R = Σ αᵢ xᵢ (α from the rest geometry: the gap between the two
// diagonals of the hinge quad), W = λ/2 ‖R − R̄‖², λ = (2/3)(h_A + h_B)/(h_A² h_B²) ‖ē‖ D, with
// h_A, h_B the rest heights of the wing vertices over the edge and R̄ the rest bending vector.
// Quadratic and not rotation invariant, as published.
// Units: positions µm, D in µN·µm, energies in pJ.

#include <Eigen/Core>
#include <array>

#include "mechanics/Math.h"

namespace tp {

using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

/// Signed dihedral angle (rad) of the hinge x0–x1 with wings x2 (triangle x0,x1,x2) and x3
/// (triangle x1,x0,x3): θ = atan2((n_A × n_B)·ê, n_A·n_B), 0 when flat. Optional exact
/// gradient and Hessian with respect to (x0, x1, x2, x3).
double dihedralAngle(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3, Vec12* grad,
                     Mat12* hess);
/// The same angle and its gradient in closed form (cheaper than the chain rule above, for
/// callers that need no Hessian): ∇_{x2}θ = −|e| n_A/|n_A|², ∇_{x3}θ = −|e| n_B/|n_B|² (n the
/// unnormalised normals, e = x1 − x0), and the edge's ends share the wings' gradients by where
/// the wings project onto the edge (Bridson et al., "Simulation of clothing with folds and
/// wrinkles", SCA 2003; Tamstorf and Grinspun, "Discrete bending forces and their Jacobians",
/// 2013).
double dihedralAngleGradient(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                             Vec12& grad);
/// The angle's Hessian alone (as dihedralAngle's), without the angle or its gradient.
void dihedralAngleHessian(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                          Mat12& hess);

struct HingeRest {
  double stiffness = 0;   // k (µN·µm)
  double restAngle = 0;   // θ̄ (rad)
};

/// D the bending rigidity (µN·µm); X the rest positions in hinge order.
HingeRest hingeRest(const Vec3& X0, const Vec3& X1, const Vec3& X2, const Vec3& X3, double D);

double hingeEnergy(const HingeRest& rest, const Vec3& x0, const Vec3& x1, const Vec3& x2,
                   const Vec3& x3, Vec12* grad, Mat12* hess);

struct LinearBendingRest {
  std::array<double, 4> alpha{};  // weights of x0..x3 in R (sum zero)
  double lambda = 0;              // µN/µm
  Vec3 restVector = Vec3::Zero(); // R̄ (µm)
};

LinearBendingRest linearBendingRest(const Vec3& X0, const Vec3& X1, const Vec3& X2,
                                    const Vec3& X3, double D);

double linearBendingEnergy(const LinearBendingRest& rest, const Vec3& x0, const Vec3& x1,
                           const Vec3& x2, const Vec3& x3, Vec12* grad, Mat12* hess);

}  // namespace tp
