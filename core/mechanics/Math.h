#pragma once
// Small fixed-size helpers shared by the energy terms.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tp {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// [a]×, the matrix with [a]× b = a × b.
inline Mat3 crossMatrix(const Vec3& a) {
  Mat3 m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

}  // namespace tp
