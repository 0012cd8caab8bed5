#pragma once
// The contact patch's own solves inside the Newton iteration: nonlinear elimination of the
// pressed vertices (ContactRelaxation) and the exact tangent over them as a correction of the
// lagged preconditioner (LocalTangent). Units: µm, µN, pJ.
//
// Why: on a refined patch the residual a load step leaves after its predictor, and after its
// first Newton iteration, sits almost all on the pressed triangles' vertices (90 % of its square
// on 4–9 of 15,000 unknowns on the default meristem at level 3: bench/README.md, 2026-12-05):
// each pressed triangle's penalty force grows as the square of its penetration
// (mechanics/Contact.h), so a step that is exact for the rest of the tissue leaves an error
// there, and a second global iteration (an assembly and a CG solve) followed. And the tangent
// changes most there between load steps (triangles enter the contact with the penalty's
// stiffness), which is what the lagged Cholesky factor that preconditions CG misses.

#include <Eigen/Cholesky>
#include <vector>

#include "mechanics/Model.h"

namespace tp {

/// Row-wise index of a symmetric pattern's upper triangle: for row i, the columns j > i holding
/// an entry and that entry's position in the value array.
struct PatternRows {
  const SparsePattern* pattern = nullptr;
  int nnz = -1;
  std::vector<int> start, col, pos;
  /// Rebuilds for P unless already built for it.
  void build(const SparsePattern& P);
  bool builtFor(const SparsePattern& P) const { return pattern == &P && nnz == P.nnz(); }
};

/// The tangent's unknowns (indices into model.pattern()) of the free position components of the
/// triangles the probe presses at x, then the terms' own unknowns coupled to them (Koiter's edge
/// unknowns: without them a local problem is far too stiff). Empty without a pressed triangle.
std::vector<int> pressedUnknowns(const Model& model, const Points& x, const PatternRows& rows);

/// A symmetric matrix A (values over rows.pattern) seen from a few of its unknowns L: the dense
/// block A_LL and the entries of A's rows L.
class LocalTangent {
 public:
  // Unknowns solved densely. The default probe pressed 0.5 µm into level 4 has ~1,000 (212
  // triangles in contact with their mid-edge unknowns); at 450, as before 2026-12-05, those
  // solves had neither the relaxation nor the preconditioner's block: the level-4 50-step curve
  // took 86 Newton iterations and 13.6-14.0 s, the error estimate's level-4 end point 7 and 4
  // factorisations; at 1,500, 65 iterations and 9.9-10.4 s, 4 and 2 (bench/README.md). A dense
  // factorisation of 1,500 costs ~1 GFlop, a tenth of the level-4 sparse one (9.9 GFlop).
  static constexpr int kMaxSize = 1500;

  /// False (and inactive) when `unknowns` is empty or larger than kMaxSize, or, with `factor`,
  /// when A_LL is not positive definite.
  bool build(const PatternRows& rows, const std::vector<double>& values,
             std::vector<int> unknowns, bool factor);
  void clear() { active_ = false; }
  bool active() const { return active_; }
  int size() const { return static_cast<int>(unknowns_.size()); }
  const std::vector<int>& unknowns() const { return unknowns_; }
  const Eigen::MatrixXd& block() const { return block_; }
  /// y −= A (E w): E extends a local vector w by zeros.
  void subtractProduct(const Eigen::VectorXd& w, Eigen::VectorXd& y) const;
  /// z += E A_LL⁻¹ (r − A z)_L: after it, r − A z vanishes on L (a block Gauss–Seidel step).
  void correct(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;

 private:
  struct Entry {
    int a, j;  // A(unknowns[a], j)
    double v;
  };
  std::vector<int> unknowns_;
  std::vector<Entry> entries_;
  Eigen::MatrixXd block_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  bool active_ = false;
};

/// Nonlinear elimination of the contact vertices: the pressed triangles' vertices (with the edge
/// unknowns coupled to them) moved to the minimum of the energy over them alone, the rest of the
/// tissue held ("nonlinear elimination": Lanzkron, Rose & Wilkes, SIAM J. Sci. Comput. 17, 1996;
/// Cai & Keyes, SIAM J. Sci. Comput. 24, 2002, as nonlinear preconditioning).
///
/// The local energy is the contact's, exact, plus the rest of the energy to second order about
/// the current state: its gradient there (the model's gradient less the contact's) and its
/// Hessian from the last tangent assembled (less that tangent's contact part, recomputed at the
/// state and probe it was assembled at). That Hessian may lag a step behind; the move is only a
/// proposal, which the solver keeps when the model's own energy and residual say it helped.
class ContactRelaxation {
 public:
  /// Remembers the tangent `hessian` (over model.pattern()) assembled at x with the model's
  /// probe; `projected` when its contact part was each element's positive part.
  void hold(const Model& model, const Points& x, const std::vector<double>& hessian,
            bool projected);
  /// The held tangent's values, when held for this model's pattern and probe radius (else null).
  const std::vector<double>* heldTangent(const Model& model) const;
  /// Where the held tangent was assembled: the positions, the probe, and whether its contact
  /// part was each element's positive part.
  const Points& heldPositions() const { return x_; }
  const Probe& heldProbe() const { return probe_; }
  bool heldProjected() const { return projected_; }

  /// The move of the local unknowns' positions (into dx, 3 × V, zero elsewhere) that minimises
  /// the local energy at x, whose gradient over all components is `gradient`; stops when the
  /// local residual is below `tolerance` (µN) or has fallen a thousandfold. False when nothing is
  /// held for this model, no triangle is pressed, the local problem is too large for a dense
  /// solve, or no step decreased the local energy (then dx is unspecified).
  bool relax(const Model& model, const PatternRows& rows, const Points& x,
             const Eigen::VectorXd& gradient, double tolerance, Points& dx);

 private:
  bool held_ = false;
  const SparsePattern* pattern_ = nullptr;
  int nnz_ = -1;
  std::vector<double> hessian_;
  Points x_;
  Probe probe_;
  ContactLaw law_;
  bool projected_ = false;
  std::vector<int> touched_;
  std::vector<int> local_;  // per position component: its local index, or −1
  LocalTangent block_;
};

}  // namespace tp
