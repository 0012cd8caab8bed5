#pragma once
// Exact derivatives of the probe force at an equilibrium under displacement control with
// respect to the wall's Young modulus E, the turgor pressure p, the wall thickness h and the
// probe's depth, by implicit differentiation of the equilibrium (no finite differences of
// curves). Units: µN per MPa (E, p), µN per µm (h, depth).
//
// At equilibrium the gradient g(x; θ) = ∂W/∂x vanishes on the free unknowns; differentiating,
// K dx/dθ = −∂g/∂θ with K the tangent (the force needs one solve only: its adjoint). The force
// F = a·∂W/∂c (c the sphere's centre, a the axis) changes by dF/dθ = (∂²W/∂x∂c a)·dx/dθ (+ its
// explicit part: none for E, p, h; a·∂²W/∂c² a for the depth, which moves c by a).
// What each parameter enters: the membrane energy is E·h times a function of the strains
// (St Venant–Kirchhoff, plane-stress Lamé constants ∝ E at fixed ν), every bending energy
// E·h³ times a function of the curvatures, the turgor term −p·V: so ∂g/∂E = (g_membrane +
// g_bending)/E, ∂g/∂h = g_membrane/h + 3 g_bending/h, ∂g/∂p = −∂V/∂x. The contact law's
// stiffness κ = 1e3 E h (a numerical penalty scaled with the walls) adds g_contact/E and
// g_contact/h, and the explicit parts F/E and F/h, as it must for the model's own F(θ). Own
// unknowns of a term (Koiter's edge slopes) sit at their optimum, where their gradient is zero for
// every E, h: they take a zero right-hand side. The depth counts from first contact with the turgid
// state, which θ moves as well: that shift (the turgid state's response at the touching point,
// along the axis) times the tangent stiffness is part of dF/dθ at a given depth, as a fit needs it.

#include "experiment/Indentation.h"

namespace tp {

struct ForceSensitivity {
  bool ok = false;
  double force = 0;   // µN, at the state
  double dE = 0;      // ∂F/∂E, µN/MPa
  double dp = 0;      // ∂F/∂p (the uniform turgor), µN/MPa
  double dh = 0;      // ∂F/∂h, µN/µm
  double dDepth = 0;  // ∂F/∂depth: the tangent stiffness, µN/µm
};

/// How the turgid state moves with E, p and h (3V × 3: µm per MPa of E, per MPa of p, per µm of
/// h): the same for every depth of one curve, so a fit computes it once per curve (one
/// factorisation).
struct TurgidResponse {
  bool ok = false;
  Eigen::MatrixXd u;
};
TurgidResponse turgidResponse(Indentation& indentation);

/// The sensitivities of the force at the indentation's current depth (axis held; the contact
/// point follows θ: the site is the material point `restSite` when the settings give one, else
/// the surface point nearest to `site`, as Indentation places it). The model's pressures must be
/// uniform (the turgor p of every cell). One linear solve with the tangent at the state (the
/// adjoint of the force; see EquilibriumSolver::tangentSolve for how), and three with the tangent
/// at the turgid state unless `turgid`, from turgidResponse() on the same indentation, is given.
ForceSensitivity forceSensitivity(Indentation& indentation,
                                  const TurgidResponse* turgid = nullptr);

}  // namespace tp
