#include "support/ModelDerivatives.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "support/FiniteDifference.h"

namespace tp::test {

namespace {

Eigen::MatrixXd denseHessian(const SparsePattern& p, const std::vector<double>& values) {
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(p.n, p.n);
  for (int c = 0; c < p.n; ++c)
    for (int k = p.colPtr[c]; k < p.colPtr[c + 1]; ++k) {
      H(p.rowIdx[k], c) = values[k];
      H(c, p.rowIdx[k]) = values[k];
    }
  return H;
}

Eigen::VectorXd freeVector(const Model& m, const Eigen::VectorXd& full) {
  Eigen::VectorXd u(m.dofs().freeCount());
  for (int i = 0; i < u.size(); ++i) u[i] = full[m.dofs().freeDofs()[i]];
  return u;
}

Points withFree(const Model& m, const Points& base, const Eigen::VectorXd& u) {
  Points x = base;
  for (int i = 0; i < u.size(); ++i) x.data()[m.dofs().freeDofs()[i]] = u[i];
  return x;
}

}  // namespace

Points perturbedRest(const CellComplex& cc, double amp, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amp, amp);
  Points y = cc.rest;
  for (int v = 0; v < y.cols(); ++v)
    if (!cc.fixed[v])
      for (int k = 0; k < 3; ++k) y(k, v) += u(rng);
  return y;
}

DerivativeErrors modelDerivativeErrors(const Model& m, const Points& x0, double h, int onlyTerm) {
  Evaluation ev;
  m.evaluate(x0, ev, EvalOptions{.hessian = true, .onlyTerm = onlyTerm});
  const Eigen::VectorXd u0 =
      freeVector(m, Eigen::Map<const Eigen::VectorXd>(x0.data(), x0.size()));
  const auto energy = [&](const Eigen::VectorXd& u) {
    return m.energy(withFree(m, x0, u), nullptr, onlyTerm);
  };
  const auto gradient = [&](const Eigen::VectorXd& u) {
    Evaluation e;
    m.evaluate(withFree(m, x0, u), e, EvalOptions{.onlyTerm = onlyTerm});
    return freeVector(m, e.gradient);
  };
  DerivativeErrors r;
  const double w = m.energy(x0, nullptr, onlyTerm);
  r.energy = std::abs(ev.energy.total() - w) / (1 + std::abs(w));
  const Eigen::MatrixXd Hall = denseHessian(m.pattern(), ev.hessian);
  const int nf = m.dofs().freeCount(), na = m.pattern().n - nf;
  Eigen::MatrixXd H = Hall.topLeftCorner(nf, nf);
  if (na > 0) {
    // Own unknowns the term does not touch have an empty block (another term's, or none in
    // this configuration): leave them out of the elimination.
    std::vector<int> used;
    for (int i = 0; i < na; ++i)
      if (Hall(nf + i, nf + i) != 0.0) used.push_back(nf + i);
    if (!used.empty()) {
      Eigen::MatrixXd B(nf, used.size()), C(used.size(), used.size());
      for (size_t j = 0; j < used.size(); ++j) {
        B.col(j) = Hall.block(0, used[j], nf, 1);
        for (size_t i = 0; i < used.size(); ++i) C(i, j) = Hall(used[i], used[j]);
      }
      H -= B * C.ldlt().solve(B.transpose());
    }
  }
  // What central differences can resolve: a value known to ε·magnitude (the size of what
  // cancels inside it, EnergyParts::magnitude) gives a gradient known to about ε·magnitude/h,
  // and a gradient of size magnitude/ℓ (ℓ the mean edge) a Hessian known to ε·magnitude/(h·ℓ).
  // Errors are relative to the larger of the finite-difference value and that noise divided by
  // the tolerance the tests use (1e-6 for gradients, 1e-5 for Hessians): a gradient that is
  // tiny inside a large cancelling energy cannot be checked more finely than that.
  const double eps = std::numeric_limits<double>::epsilon();
  const double noiseG = eps * ev.energy.magnitude / h, noiseH = noiseG / m.meanEdgeLength();
  const Eigen::VectorXd gFd = fdGradient(energy, u0, h);
  const Eigen::MatrixXd hFd = fdJacobian(gradient, u0, h);
  const Eigen::VectorXd gAn = freeVector(m, ev.gradient);
  r.gradient = (gAn - gFd).cwiseAbs().maxCoeff() /
               std::max({gFd.cwiseAbs().maxCoeff(), 1e6 * noiseG, 1e-300});
  r.hessian = (H - hFd).cwiseAbs().maxCoeff() /
              std::max({hFd.cwiseAbs().maxCoeff(), 1e5 * noiseH, 1e-300});
  return r;
}

}  // namespace tp::test
