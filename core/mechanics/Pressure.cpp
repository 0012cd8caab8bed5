#include "mechanics/Pressure.h"

namespace tp {

double pressureEnergy(double dp, const Vec3& x0, const Vec3& x1, const Vec3& x2, Vec9* grad,
                      Mat9* hess) {
  const double c = -dp / 6.0;
  if (grad) {
    grad->segment<3>(0) = c * x1.cross(x2);
    grad->segment<3>(3) = c * x2.cross(x0);
    grad->segment<3>(6) = c * x0.cross(x1);
  }
  if (hess) {
    // ∂(x_j × x_k)/∂x_k = [x_j]×, ∂(x_j × x_k)/∂x_j = −[x_k]× (i, j, k cyclic).
    hess->setZero();
    const Vec3* xs[3] = {&x0, &x1, &x2};
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      hess->block<3, 3>(3 * i, 3 * j) = -c * crossMatrix(*xs[k]);
      hess->block<3, 3>(3 * i, 3 * k) = c * crossMatrix(*xs[j]);
    }
  }
  return c * x0.dot(x1.cross(x2));
}

}  // namespace tp
