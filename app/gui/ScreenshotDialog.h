#pragma once
// Asks for the size of an image: a screenshot of the 3D view (pixels; the view's own size by
// default) or an exported plot (pixels, or points for SVG and PDF); presets 1×, 2× and 4× of the
// default, the aspect ratio kept unless unticked; for a plot or a figure also its resolution and
// where the legend goes.

#include <QDialog>
#include <QSize>

class QCheckBox;
class QComboBox;
class QFormLayout;
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

  /// Adds a resolution box (PNG: the image is drawn for this many dots per inch).
  void addResolution(double dpi);
  double resolution() const;
  /// Adds a choice of where the legend goes: inside the axes (top left), outside on the right
  /// (the default), or none. Index as PlotPanel::ExportOptions::Legend.
  void addLegendChoice();
  int legendChoice() const;

 private:
  void scaleTo(double factor);

  QSize view_;
  QSpinBox *width_, *height_;
  QCheckBox* keepAspect_;
  QFormLayout* form_ = nullptr;
  QSpinBox* dpi_ = nullptr;
  QComboBox* legend_ = nullptr;
};

}  // namespace tp::gui
