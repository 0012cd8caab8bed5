#pragma once
// Sparse symmetric positive-definite solver: CHOLMOD supernodal Cholesky behind a small interface
// that keeps the symbolic analysis (fill-reducing ordering, supernodes) across numeric
// factorisations, and checks the values are finite before factorising.
// (geometry-central's stateful solver and libigl's precompute/solve split are the model.)

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mechanics/Assembly.h"

namespace tp {

class CholmodSolver {
 public:
  CholmodSolver();
  ~CholmodSolver();
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;

  /// Caps the BLAS threads of every factorisation in the process while it lives (OpenBLAS has
  /// one count for all): 1 when several solvers run at once on their own threads (a map), the
  /// solver's cores during a drag in the application. Caps held at once on several threads
  /// combine to the smallest; each one's end leaves the others in force.
  class BlasThreadCap {
   public:
    explicit BlasThreadCap(int threads);
    ~BlasThreadCap();
    BlasThreadCap(const BlasThreadCap&) = delete;
    BlasThreadCap& operator=(const BlasThreadCap&) = delete;

   private:
    int threads_;
  };
  /// The cap in force (the smallest held), or 0 when there is none.
  static int blasThreadCap();

  /// Symbolic analysis of the pattern (upper triangle, CSC). Must precede factorize().
  /// `node` (optional): for each unknown, its node (a vertex; ids from 0, a node's unknowns
  /// anywhere). The fill-reducing ordering is then METIS's on the graph of the nodes, weighted
  /// by their unknowns, each node's unknowns eliminated together (Model::orderingNodes()).
  /// Without it, CHOLMOD orders the graph of the unknowns itself.
  void analyze(const SparsePattern& pattern, std::span<const int> node = {});
  bool analyzed() const;

  enum class Status { Ok, NotPositiveDefinite, NonFinite, Failed };
  /// The numeric factorisation's precision. Single (the default): this class's own supernodal
  /// factorisation in single precision on CHOLMOD's analysis, half the time of CHOLMOD's in
  /// double (BM_Factorization, bench/README.md), and CHOLMOD in double whenever a pivot fails in
  /// single precision, so that "not positive definite" is double precision's verdict. Double:
  /// CHOLMOD's alone.
  enum class Precision { Single, Double };
  void setFactorPrecision(Precision p) { precision_ = p; }
  /// Numeric factorisation of A + shift·I with A's values over the analysed pattern.
  Status factorize(std::span<const double> values, double shift = 0.0);
  /// Solves A x = b with the last successful factorisation (to double precision: after a
  /// single-precision factorisation by iterative refinement against A itself).
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x);
  /// Whether the factor held is the single-precision one.
  bool singlePrecisionFactor() const;
  /// The same with a single-precision copy of the factor: about half the memory traffic of
  /// solve(), accurate to ~1e-6 relative. For preconditioning. With two or more OpenMP threads
  /// the two largest independent subtrees of the supernodal elimination tree are solved at once
  /// (see SolveSchedule); `threads` = 1 forces the serial order, 0 takes omp_get_max_threads().
  void solveSinglePrecision(const Eigen::VectorXd& b, Eigen::VectorXd& x, int threads = 0);

  /// How solveSinglePrecision splits the supernodes: owner 0 or 1 for those in one of the two
  /// threads' subtrees, 2 for the rest (the separators above them, solved by one thread), and the
  /// estimated time of the split relative to the serial solve (1 when not split).
  struct SolveSchedule {
    std::vector<std::uint8_t> owner;          // per supernode
    std::vector<int> supers[3];               // each owner's supernodes, in increasing order
    std::vector<int> rows1, rowsTop;          // the columns of owner 1's and of the top supernodes
    double parallelFraction = 1;              // (top work + larger thread's work) / total work
  };
  const SolveSchedule& solveSchedule();

  /// True when a factorisation is held (solve() may be called).
  bool factored() const;
  /// Floating-point operations of one numeric factorisation (CHOLMOD's count from the analysis).
  double factorFlops() const;
  /// Nonzeros of the factor L (after a factorisation), for reports.
  double factorNonzeros() const;
  std::string lastMessage() const { return message_; }

 private:
  struct Impl;
  bool factorizeSingle(double shift);
  std::unique_ptr<Impl> impl_;
  Precision precision_ = Precision::Single;
  std::vector<float> factorF_;  // the supernodal values of L in single precision
  bool factorFValid_ = false;
  SolveSchedule schedule_;      // of the analysed structure
  bool scheduleValid_ = false;
  std::string message_;
};

}  // namespace tp
