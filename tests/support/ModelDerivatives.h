#pragma once
// The assembled model's gradient and sparse Hessian against finite differences, for the whole
// model or one of its terms (EvalOptions::onlyTerm): the slot tables and the scatter are
// checked, not only the element formulas.

#include <string>

#include "mechanics/Model.h"

namespace tp::test {

struct DerivativeErrors {
  double energy = 0;    // |W(evaluate) − W(energy)| / (1 + |W|)
  double gradient = 0;  // relError against central differences of the energy
  double hessian = 0;   // relError against central differences of the gradient
};

/// Errors at x with finite-difference step h (µm); onlyTerm < 0: every term. Koiter bending's
/// own unknowns are eliminated (the energy is minimised over them), so the position Hessian is
/// the Schur complement of the assembled matrix.
/// The complex's rest positions with every free vertex moved by uniform random offsets in
/// [−amp, amp] per component (µm), reproducibly from `seed`.
Points perturbedRest(const CellComplex& cc, double amp, unsigned seed);

DerivativeErrors modelDerivativeErrors(const Model& m, const Points& x, double h, int onlyTerm = -1);

}  // namespace tp::test
