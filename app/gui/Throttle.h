#pragma once
// Runs an action at most once per interval, with the state current when it runs: many requests
// in a burst (a probe drag delivers an equilibrium every few tens of milliseconds) become one
// call. Used for the widgets outside the 3D view, because with a QOpenGLWidget in the window every
// widget repaint makes Qt compose the whole window with OpenGL, which a software renderer pays in
// CPU time taken from the solver.

#include <QObject>
#include <QTimer>
#include <functional>

namespace tp::gui {

class Throttle : public QObject {
  Q_OBJECT

 public:
  Throttle(int intervalMs, std::function<void()> action, QObject* parent = nullptr);
  /// Asks for the action: now if it has not run for an interval, else at the end of it.
  void request();
  /// Runs a pending action at once (e.g. when a drag ends).
  void flush();
  /// Runs the action at once whether or not one is pending (a change the user must see now).
  void now();

 private:
  void fire();

  std::function<void()> action_;
  QTimer timer_;
  bool pending_ = false;
};

}  // namespace tp::gui
