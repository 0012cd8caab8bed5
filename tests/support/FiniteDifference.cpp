#include "support/FiniteDifference.h"

namespace tp::test {

Eigen::VectorXd fdGradient(const std::function<double(const Eigen::VectorXd&)>& f,
                           const Eigen::VectorXd& x, double h) {
  Eigen::VectorXd g(x.size());
  Eigen::VectorXd xp = x;
  for (int i = 0; i < x.size(); ++i) {
    xp[i] = x[i] + h;
    const double fp = f(xp);
    xp[i] = x[i] - h;
    const double fm = f(xp);
    xp[i] = x[i];
    g[i] = (fp - fm) / (2 * h);
  }
  return g;
}

Eigen::MatrixXd fdJacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& g,
                           const Eigen::VectorXd& x, double h) {
  const Eigen::VectorXd g0 = g(x);
  Eigen::MatrixXd J(g0.size(), x.size());
  Eigen::VectorXd xp = x;
  for (int j = 0; j < x.size(); ++j) {
    xp[j] = x[j] + h;
    const Eigen::VectorXd gp = g(xp);
    xp[j] = x[j] - h;
    const Eigen::VectorXd gm = g(xp);
    xp[j] = x[j];
    J.col(j) = (gp - gm) / (2 * h);
  }
  return J;
}

double relError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double floor) {
  return (a - b).cwiseAbs().maxCoeff() / (b.cwiseAbs().maxCoeff() + floor + 1e-300);
}

}  // namespace tp::test
