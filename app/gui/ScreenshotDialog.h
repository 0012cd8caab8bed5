#pragma once
// Asks for the size (pixels) of a screenshot of the 3D view: the view's own size by default,
// presets 2× and 4×, the aspect ratio kept unless unticked.

#include <QDialog>
#include <QSize>

class QCheckBox;
class QSpinBox;

namespace tp::gui {

class ScreenshotDialog : public QDialog {
  Q_OBJECT

 public:
  ScreenshotDialog(const QSize& viewSize, QWidget* parent = nullptr);
  QSize imageSize() const;

 private:
  void scaleTo(double factor);

  QSize view_;
  QSpinBox *width_, *height_;
  QCheckBox* keepAspect_;
};

}  // namespace tp::gui
