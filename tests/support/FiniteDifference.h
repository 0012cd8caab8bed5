#pragma once
// Central finite differences for checking gradients and Hessians of any energy term.

#include <Eigen/Core>
#include <functional>

namespace tp::test {

/// Gradient of f at x by central differences with step h.
Eigen::VectorXd fdGradient(const std::function<double(const Eigen::VectorXd&)>& f,
                           const Eigen::VectorXd& x, double h);
/// Jacobian of g (e.g. an analytic gradient) at x by central differences: column j = ∂g/∂x_j.
Eigen::MatrixXd fdJacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& g,
                           const Eigen::VectorXd& x, double h);
/// max |a − b| / (max |b| + floor): a relative error that is meaningful for vectors and matrices.
double relError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double floor = 1e-12);

}  // namespace tp::test
