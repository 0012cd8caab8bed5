#include "Camera.h"

#include <algorithm>
#include <cmath>

namespace tp::gui {

namespace {

constexpr double kPi = 3.14159265358979323846;
double radians(double degrees) {
  return degrees * kPi / 180.0;
}

Eigen::Quaterniond fromAxes(const Eigen::Vector3d& x, const Eigen::Vector3d& y,
                            const Eigen::Vector3d& z) {
  Eigen::Matrix3d m;
  m.col(0) = x;
  m.col(1) = y;
  m.col(2) = z;
  return Eigen::Quaterniond(m).normalized();
}

}  // namespace

Camera::Camera() {
  scene_ = Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1));
  reset();
}

void Camera::setViewport(int width, int height) {
  width_ = std::max(1, width);
  height_ = std::max(1, height);
}

Eigen::Vector3d Camera::eye() const {
  return target_ - distance_ * viewDirection();
}
Eigen::Vector3d Camera::viewDirection() const {
  return orientation_ * -Eigen::Vector3d::UnitZ();
}
Eigen::Vector3d Camera::up() const {
  return orientation_ * Eigen::Vector3d::UnitY();
}
Eigen::Vector3d Camera::right() const {
  return orientation_ * Eigen::Vector3d::UnitX();
}

Eigen::Matrix4d Camera::viewMatrix() const {
  // World to camera: the inverse of the camera's rigid placement (orientation, eye).
  const Eigen::Matrix3d rt = orientation_.toRotationMatrix().transpose();
  Eigen::Matrix4d v = Eigen::Matrix4d::Identity();
  v.topLeftCorner<3, 3>() = rt;
  v.topRightCorner<3, 1>() = -rt * eye();
  return v;
}

double Camera::sceneRadius() const {
  return scene_.isEmpty() ? 1.0 : std::max(0.5 * scene_.diagonal().norm(), 1e-6);
}

Eigen::Matrix4d Camera::projectionMatrix() const {
  // Near and far planes hug the scene's bounding sphere, so depth precision is spent on it.
  const double r = sceneRadius();
  const Eigen::Vector3d c = scene_.isEmpty() ? target_ : scene_.center();
  const double dc = (c - eye()).dot(viewDirection());
  const double farPlane = std::max(dc + 1.1 * r, 1e-3 * r);
  const double nearPlane = std::max(dc - 1.1 * r, 2e-3 * farPlane);
  const double f = 1.0 / std::tan(0.5 * radians(fovY_));
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = f / aspect();
  p(1, 1) = f;
  p(2, 2) = (farPlane + nearPlane) / (nearPlane - farPlane);
  p(2, 3) = 2.0 * farPlane * nearPlane / (nearPlane - farPlane);
  p(3, 2) = -1.0;
  return p;
}

Eigen::Vector3d Camera::arcballPoint(const Eigen::Vector2d& pixel) const {
  // Shoemake's arcball: the unit sphere inscribed in the viewport, a hyperbolic sheet outside.
  const double s = std::min(width_, height_);
  const double x = (2.0 * pixel.x() - width_) / s;
  const double y = (height_ - 2.0 * pixel.y()) / s;
  const double r2 = x * x + y * y;
  if (r2 <= 0.5) return Eigen::Vector3d(x, y, std::sqrt(1.0 - r2));
  return Eigen::Vector3d(x, y, 0.5 / std::sqrt(r2)).normalized();
}

void Camera::rotate(const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  if (mode_ == RotationMode::Turntable) {
    // Half a turn across the smaller side of the viewport.
    const double degreesPerPixel = 180.0 / std::min(width_, height_);
    rotateBy((to.x() - from.x()) * degreesPerPixel, (to.y() - from.y()) * degreesPerPixel);
    return;
  }
  const Eigen::Vector3d a = arcballPoint(from), b = arcballPoint(to);
  if ((a - b).norm() < 1e-12) return;
  // The scene turns by q in the camera frame: the camera turns by q⁻¹ about the target.
  const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(a, b);
  orientation_ = (orientation_ * q.inverse()).normalized();
}

void Camera::rotateBy(double yawDegrees, double pitchDegrees) {
  const Eigen::AngleAxisd yaw(-radians(yawDegrees), Eigen::Vector3d::UnitZ());
  const Eigen::AngleAxisd pitch(-radians(pitchDegrees), Eigen::Vector3d::UnitX());
  orientation_ = (Eigen::Quaterniond(yaw) * orientation_ * Eigen::Quaterniond(pitch)).normalized();
}

double Camera::pixelSize() const {
  return 2.0 * distance_ * std::tan(0.5 * radians(fovY_)) / height_;
}

void Camera::pan(const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  const Eigen::Vector2d d = (to - from) * pixelSize();
  target_ -= d.x() * right() - d.y() * up();
}

void Camera::zoom(double factor) {
  if (!(factor > 0) || !std::isfinite(factor)) return;
  const double r = sceneRadius();
  distance_ = std::clamp(distance_ / factor, 1e-3 * r, 100.0 * r);
}

void Camera::zoomAt(const Eigen::Vector2d& pixel, double factor) {
  const double before = distance_;
  // The point under the pixel in the plane through the target facing the camera.
  const double depth = project(target_).z();
  const Eigen::Vector3d p = unproject({pixel.x(), pixel.y(), depth});
  zoom(factor);
  // With the distance scaled by s, moving the target a fraction 1 − s towards p keeps p's pixel.
  target_ += (1.0 - distance_ / before) * (p - target_);
}

void Camera::setSceneBounds(const Eigen::AlignedBox3d& box) {
  if (!box.isEmpty()) scene_ = box;
}

void Camera::fit(const Eigen::AlignedBox3d& box) {
  if (box.isEmpty()) return;
  const double r = std::max(0.5 * box.diagonal().norm(), 1e-6);
  const double halfY = 0.5 * radians(fovY_);
  const double halfX = std::atan(std::tan(halfY) * aspect());
  // The bounding sphere touches the narrower side of the view frustum, with a 5 % margin.
  target_ = box.center();
  distance_ = 1.05 * r / std::sin(std::min(halfX, halfY));
}

void Camera::setStandardView(StandardView view) {
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY(),
                        Z = Eigen::Vector3d::UnitZ();
  switch (view) {
    case StandardView::Front:
      orientation_ = fromAxes(X, Z, -Y);
      break;
    case StandardView::Right:
      orientation_ = fromAxes(Y, Z, X);
      break;
    case StandardView::Top:
      orientation_ = fromAxes(X, Y, Z);
      break;
  }
  fitToScene();
}

void Camera::lookAlong(const Eigen::Vector3d& direction) {
  if (!(direction.norm() > 0)) return;
  const Eigen::Vector3d back = -direction.normalized();  // the camera's z: towards the eye
  Eigen::Vector3d right = Eigen::Vector3d::UnitZ().cross(back);
  if (right.norm() < 1e-6) right = Eigen::Vector3d::UnitX();  // looking straight down or up
  right.normalize();
  orientation_ = fromAxes(right, back.cross(right), back);
}

void Camera::reset() {
  setStandardView(StandardView::Front);
  rotateBy(-25.0, 25.0);  // a little from the left and from above
  fitToScene();
}

Eigen::Vector3d Camera::project(const Eigen::Vector3d& world) const {
  const Eigen::Vector4d clip = viewProjection() * world.homogeneous();
  const Eigen::Vector3d ndc = clip.head<3>() / clip.w();
  return {0.5 * (ndc.x() + 1.0) * width_, 0.5 * (1.0 - ndc.y()) * height_, ndc.z()};
}

Eigen::Vector3d Camera::unproject(const Eigen::Vector3d& pixel) const {
  const Eigen::Vector4d ndc(2.0 * pixel.x() / width_ - 1.0, 1.0 - 2.0 * pixel.y() / height_,
                            pixel.z(), 1.0);
  const Eigen::Vector4d w = viewProjection().inverse() * ndc;
  return w.head<3>() / w.w();
}

Ray Camera::rayAt(double x, double y) const {
  Ray r;
  r.origin = eye();
  r.direction = (unproject({x, y, 1.0}) - r.origin).normalized();
  return r;
}

}  // namespace tp::gui
