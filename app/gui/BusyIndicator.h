#pragma once
// The status bar's sign that the worker is busy: what it does and for how long, refreshed twice
// a second. Deliberately not an animated progress bar: with a QOpenGLWidget in the window, every
// repaint of any widget makes Qt compose the whole window with OpenGL, which on a software
// renderer costs CPU time the solver needs (an animated bar made preparations ten times slower).

#include <QElapsedTimer>
#include <QLabel>
#include <QTimer>

namespace tp::gui {

class BusyIndicator : public QLabel {
  Q_OBJECT

 public:
  explicit BusyIndicator(QWidget* parent = nullptr);
  bool busy() const { return busy_; }

 public slots:
  void setBusy(bool busy, const QString& what);

 private:
  void refresh();

  bool busy_ = false;
  QString what_;
  QElapsedTimer since_;
  QTimer timer_;
};

}  // namespace tp::gui
