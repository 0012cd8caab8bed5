#pragma once
// A perspective camera orbiting a target point: view and projection matrices (OpenGL
// conventions, column vectors, NDC z in [-1, 1]), orbit (turntable about the world z axis or
// arcball), pan, zoom, fit to a bounding box, standard views and the ray through a pixel.
// Pixels are the widget's logical pixels: x to the right, y downwards, (0, 0) the top-left
// corner. World units: µm. No GL and no window needed.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tp::gui {

struct Ray {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = -Eigen::Vector3d::UnitZ();  // unit
};

class Camera {
 public:
  enum class StandardView {
    Front,  // looking along +y, z up (Blender's numpad 1)
    Right,  // looking along −x, z up (numpad 3)
    Top,    // looking along −z, y up (numpad 7)
  };
  enum class RotationMode { Turntable, Arcball };

  Camera();

  void setViewport(int width, int height);
  int width() const { return width_; }
  int height() const { return height_; }
  double aspect() const { return double(width_) / double(height_); }

  void setRotationMode(RotationMode mode) { mode_ = mode; }
  RotationMode rotationMode() const { return mode_; }

  const Eigen::Vector3d& target() const { return target_; }
  double distance() const { return distance_; }
  /// Camera-to-world rotation: the camera looks along −z of its frame, y up.
  const Eigen::Quaterniond& orientation() const { return orientation_; }
  double fieldOfView() const { return fovY_; }  // vertical, degrees
  Eigen::Vector3d eye() const;
  Eigen::Vector3d viewDirection() const;  // unit, from the eye into the scene
  Eigen::Vector3d up() const;
  Eigen::Vector3d right() const;

  Eigen::Matrix4d viewMatrix() const;
  Eigen::Matrix4d projectionMatrix() const;
  Eigen::Matrix4d viewProjection() const { return projectionMatrix() * viewMatrix(); }

  /// Orbit for a mouse drag from one pixel to another (turntable or arcball).
  void rotate(const Eigen::Vector2d& from, const Eigen::Vector2d& to);
  /// Turntable orbit by angles (degrees): yaw about the world z axis, pitch about the camera's
  /// horizontal axis. Positive yaw turns the scene to the right, positive pitch tilts its top
  /// towards the viewer.
  void rotateBy(double yawDegrees, double pitchDegrees);
  /// Moves the target so that the point under `from` follows the mouse to `to`.
  void pan(const Eigen::Vector2d& from, const Eigen::Vector2d& to);
  /// Moves the eye towards the target: distance /= factor (factor > 1 zooms in).
  void zoom(double factor);
  /// Zooms towards a pixel: the point under it at the target's depth stays under it.
  void zoomAt(const Eigen::Vector2d& pixel, double factor);

  /// The scene's extent, for the near and far planes and for the standard views and reset.
  void setSceneBounds(const Eigen::AlignedBox3d& box);
  const Eigen::AlignedBox3d& sceneBounds() const { return scene_; }
  /// Keeps the orientation, centres the box and backs off until it fits the view.
  void fit(const Eigen::AlignedBox3d& box);
  /// Turns the camera to look along `direction` (from the eye into the scene), its up as close
  /// to world +z as the direction allows; the target and distance stay.
  void lookAlong(const Eigen::Vector3d& direction);
  void fitToScene() { fit(scene_); }
  /// Sets the whole pose (a saved one): the target, the camera-to-world rotation (normalised)
  /// and the distance (positive).
  void setPose(const Eigen::Vector3d& target, const Eigen::Quaterniond& orientation,
               double distance) {
    target_ = target;
    orientation_ = orientation.normalized();
    distance_ = distance;
  }
  void setStandardView(StandardView view);
  /// A three-quarter view from the front, slightly from above, fitted to the scene.
  void reset();

  /// World point to (pixel x, pixel y, NDC depth in [−1, 1]).
  Eigen::Vector3d project(const Eigen::Vector3d& world) const;
  /// Inverse of project.
  Eigen::Vector3d unproject(const Eigen::Vector3d& pixel) const;
  /// The ray from the eye through a pixel.
  Ray rayAt(double x, double y) const;
  /// World size of one pixel at the target's depth (µm per pixel).
  double pixelSize() const;

 private:
  Eigen::Vector3d arcballPoint(const Eigen::Vector2d& pixel) const;
  double sceneRadius() const;

  int width_ = 800, height_ = 600;
  RotationMode mode_ = RotationMode::Turntable;
  Eigen::Vector3d target_ = Eigen::Vector3d::Zero();
  double distance_ = 10;
  Eigen::Quaterniond orientation_ = Eigen::Quaterniond::Identity();
  double fovY_ = 30;
  Eigen::AlignedBox3d scene_;
};

}  // namespace tp::gui
