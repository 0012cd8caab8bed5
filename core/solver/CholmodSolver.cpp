#include "solver/CholmodSolver.h"

#include <cholmod.h>

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace tp {

struct CholmodSolver::Impl {
  cholmod_common common;
  cholmod_sparse* A = nullptr;
  cholmod_factor* L = nullptr;
  cholmod_dense* B = nullptr;
  cholmod_dense* X = nullptr;
  cholmod_dense* Y = nullptr;  // solve2 workspaces
  cholmod_dense* E = nullptr;
  bool factored = false;

  Impl() {
    cholmod_start(&common);
    common.supernodal = CHOLMOD_SUPERNODAL;
    common.print = 0;  // failures are reported through Status, not printed
  }
  ~Impl() {
    cholmod_free_dense(&B, &common);
    cholmod_free_dense(&X, &common);
    cholmod_free_dense(&Y, &common);
    cholmod_free_dense(&E, &common);
    cholmod_free_factor(&L, &common);
    cholmod_free_sparse(&A, &common);
    cholmod_finish(&common);
  }
};

CholmodSolver::CholmodSolver() : impl_(std::make_unique<Impl>()) {}
CholmodSolver::~CholmodSolver() = default;

bool CholmodSolver::analyzed() const { return impl_->L != nullptr; }

void CholmodSolver::analyze(const SparsePattern& pattern) {
  Impl& m = *impl_;
  cholmod_free_factor(&m.L, &m.common);
  cholmod_free_sparse(&m.A, &m.common);
  cholmod_free_dense(&m.B, &m.common);
  m.factored = false;
  const size_t n = pattern.n;
  m.A = cholmod_allocate_sparse(n, n, pattern.nnz(), 1, 1, 1, CHOLMOD_REAL, &m.common);
  if (!m.A) throw std::runtime_error("CHOLMOD: cannot allocate the matrix");
  std::memcpy(m.A->p, pattern.colPtr.data(), sizeof(int) * (n + 1));
  std::memcpy(m.A->i, pattern.rowIdx.data(), sizeof(int) * pattern.nnz());
  std::memset(m.A->x, 0, sizeof(double) * pattern.nnz());
  m.L = cholmod_analyze(m.A, &m.common);
  if (!m.L || m.common.status < CHOLMOD_OK)
    throw std::runtime_error("CHOLMOD: symbolic analysis failed (status " +
                             std::to_string(m.common.status) + ")");
  m.B = cholmod_zeros(n, 1, CHOLMOD_REAL, &m.common);
}

CholmodSolver::Status CholmodSolver::factorize(std::span<const double> values, double shift) {
  Impl& m = *impl_;
  if (!m.L) throw std::logic_error("CholmodSolver::factorize before analyze");
  if (values.size() != m.A->nzmax) throw std::invalid_argument("CholmodSolver: value count mismatch");
  m.factored = false;
  for (double v : values)
    if (!std::isfinite(v)) {
      message_ = "tangent matrix has non-finite entries";
      return Status::NonFinite;
    }
  std::memcpy(m.A->x, values.data(), sizeof(double) * values.size());
  double beta[2] = {shift, 0.0};
  const int ok = cholmod_factorize_p(m.A, beta, nullptr, 0, m.L, &m.common);
  if (m.common.status == CHOLMOD_NOT_POSDEF || (ok && m.L->minor < m.L->n)) {
    message_ = "tangent matrix not positive definite (column " + std::to_string(m.L->minor) + ")";
    return Status::NotPositiveDefinite;
  }
  if (!ok || m.common.status < CHOLMOD_OK) {
    message_ = "CHOLMOD factorisation failed (status " + std::to_string(m.common.status) + ")";
    return Status::Failed;
  }
  m.factored = true;
  message_.clear();
  return Status::Ok;
}

void CholmodSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  Impl& m = *impl_;
  if (!m.factored) throw std::logic_error("CholmodSolver::solve without a factorisation");
  const size_t n = m.L->n;
  if (static_cast<size_t>(b.size()) != n) throw std::invalid_argument("CholmodSolver: rhs size");
  std::memcpy(m.B->x, b.data(), sizeof(double) * n);
  if (!cholmod_solve2(CHOLMOD_A, m.L, m.B, nullptr, &m.X, nullptr, &m.Y, &m.E, &m.common))
    throw std::runtime_error("CHOLMOD: solve failed");
  x.resize(n);
  std::memcpy(x.data(), m.X->x, sizeof(double) * n);
}

bool CholmodSolver::factored() const { return impl_->factored; }

double CholmodSolver::factorNonzeros() const {
  const Impl& m = *impl_;
  return m.L ? m.common.lnz : 0.0;
}

}  // namespace tp
