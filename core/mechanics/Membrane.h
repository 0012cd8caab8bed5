#pragma once
// Corotational linear membrane triangle (constant strain), plane stress.
// Energy per triangle: W = h·A₀·Ψ(F), Ψ = μ‖S − I‖² + λ*/2·tr(S − I)², where F (3×2) is the
// deformation gradient in the rest triangle's own 2D frame and F = R S its polar decomposition
// (DESIGN.md §1). Units: positions µm, moduli MPa, W in pJ (µN·µm).
//
// With I₁ = ‖F‖² and J = ‖f₁ × f₂‖ (= σ₁σ₂), tr S = σ₁ + σ₂ = √(I₁ + 2J), so
// Ψ = μ(I₁ − 2 tr S + 2) + λ*/2 (tr S − 2)²: closed form with exact first and second derivatives.

#include <Eigen/Core>

#include "mechanics/Math.h"

namespace tp {

using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;

/// Rest data of one triangle (SOFA's "TriangleInfo" idea: rest quantities kept apart from state).
struct MembraneRest {
  Eigen::Matrix<double, 3, 2> G;  // F = Σ_a x_a G.row(a): gradients of the linear shape functions
  double area = 0;                 // A₀ (µm²)
};

MembraneRest membraneRest(const Vec3& X0, const Vec3& X1, const Vec3& X2);

/// Energy of one triangle; optionally its gradient (9) and Hessian (9×9) in the order x0, x1, x2.
/// mu and lambda are plane-stress Lamé constants (MPa), h the thickness (µm).
double membraneEnergy(const MembraneRest& rest, const Vec3& x0, const Vec3& x1, const Vec3& x2,
                      double mu, double lambda, double h, Vec9* grad, Mat9* hess);

/// In-plane stress of one triangle at the current positions.
struct MembraneStress {
  Mat3 cauchy = Mat3::Zero();  // Cauchy stress σ = P Fᵀ / J (MPa), a 3×3 tensor in the wall's plane
  double principalMax = 0;     // σ₁ ≥ σ₂ (MPa)
  double principalMin = 0;
  double vonMises = 0;         // √(σ₁² − σ₁σ₂ + σ₂²) (MPa)
  double energyDensity = 0;    // Ψ, strain energy per rest volume (MPa = pJ/µm³)
};

/// Principal values σ₁ ≥ σ₂ and von Mises √(σ₁² − σ₁σ₂ + σ₂²) of a 3×3 in-plane stress tensor,
/// read in the plane with unit normal n (MPa).
struct InPlanePrincipal {
  double max = 0, min = 0, vonMises = 0;
};
InPlanePrincipal inPlanePrincipal(const Mat3& sigma, const Vec3& n);

MembraneStress membraneStress(const MembraneRest& rest, const Vec3& x0, const Vec3& x1,
                              const Vec3& x2, double mu, double lambda);

}  // namespace tp
