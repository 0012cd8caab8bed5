#pragma once
// Asks for the size of an image: a screenshot of the 3D view (pixels; the view's own size by
// default) or an exported plot (pixels, or points for SVG and PDF); presets 1×, 2× and 4× of the
// default, the aspect ratio kept unless unticked.

#include <QDialog>
#include <QSize>

class QCheckBox;
class QSpinBox;

namespace tp::gui {

class ScreenshotDialog : public QDialog {
  Q_OBJECT

 public:
  ScreenshotDialog(const QSize& viewSize, QWidget* parent = nullptr);
  /// The same for another image: `title` of the dialog, `unit` after the numbers (" px", " pt").
  ScreenshotDialog(const QSize& base, const QString& title, const QString& unit,
                   QWidget* parent = nullptr);
  QSize imageSize() const;

 private:
  void scaleTo(double factor);

  QSize view_;
  QSpinBox *width_, *height_;
  QCheckBox* keepAspect_;
};

}  // namespace tp::gui
