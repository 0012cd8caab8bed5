#pragma once
// The force–depth plot (QCustomPlot): one graph per curve with a legend, a list to remove or
// clear curves, real (µm, µN) or nondimensional axes ([I] = I/L, [F] = F/(E L²)), and export to
// PNG, SVG or PDF (atomic writes).

#include <QColor>
#include <QString>
#include <QWidget>

#include <utility>
#include <vector>

#include "Curves.h"

class QCheckBox;
class QCustomPlot;
class QCPAbstractPlottable;
class QCPAxisRect;
class QIODevice;
class QImage;
class QListWidget;

namespace tp::gui {

/// Writes `image` as PNG with its resolution recorded (dots per metre from `dpi`), so that slide
/// and page tools size it as drawn. False when writing fails.
bool savePng(QImage& image, QIODevice* device, double dpi);

class PlotPanel : public QWidget {
  Q_OBJECT

 public:
  explicit PlotPanel(QWidget* parent = nullptr);

  QCustomPlot* plot() const { return plot_; }
  bool nondimensional() const;
  void setNondimensional(bool on);
  /// Index of the curve selected in the list, −1 if none.
  int selectedCurve() const;
  /// Selects curve `index` in the list (−1: none), as a click on it or on its graph does.
  void setSelectedCurve(int index);
  /// The colour curve `index` of the list is drawn in (it keeps it when others are removed).
  static QColor colourOf(const NamedCurve& curve, int index);
  /// Curves shown (a curve with an unloading branch draws two graphs).
  int curveCount() const { return static_cast<int>(curves_.size()); }

  /// How an exported plot is laid out.
  struct ExportOptions {
    int width = 0, height = 0;  // pixels (PNG) or points (SVG, PDF); 0: the widget's size
    // PNG only: the image is width × height pixels drawn for this resolution (text and lines
    // scaled by dpi/96, so 300 dpi is a print figure whose text reads as on screen), and the
    // file says so (its pHYs).
    double dpi = 96;
    enum class Legend { Inside, Outside, None };
    Legend legend = Legend::Outside;  // Outside: in a column right of the axes, clear of data
  };

  /// Writes the plot as PNG, SVG or PDF (by the suffix). False with a message on failure.
  bool exportImage(const QString& path, const ExportOptions& options, QString* error);
  bool exportImage(const QString& path, int width, int height, QString* error) {
    return exportImage(path, ExportOptions{width, height}, error);
  }
  /// Draws the plot into `painter` (a QCPPainter) at `size` in its units, with the legend placed
  /// as asked: the figure export draws it beside the 3D view.
  void drawInto(QPainter* painter, const QSize& size, ExportOptions::Legend legend);
  /// Where the last export drew the axes' data area and the legend (its units): for tests.
  std::pair<QRect, QRect> lastExportLayout() const { return {lastAxes_, lastLegend_}; }

  /// Presentation (teaching) mode: axis, tick and legend fonts 1.6 times larger and thicker
  /// lines, for a projector; off restores the normal look.
  void setPresentation(bool on);
  bool presentation() const { return presentation_; }

 public slots:
  /// Redraws every curve; L is the mean cell size (µm) for nondimensional axes.
  void setCurves(const std::vector<tp::gui::NamedCurve>& curves, double meanCellSize);

 signals:
  void removeRequested(int index);
  /// The curve selected in the list changed (−1: none).
  void selectionChanged(int index);
  void clearRequested();

 private:
  void redraw();
  /// The strip under the curves with a fit's residuals (measured − simulated), shown while a
  /// curve has them; its depth axis follows the plot's.
  void showResiduals(bool nondimensional);
  bool placeLegend();

  QCustomPlot* plot_;
  QCPAxisRect* residualRect_ = nullptr;
  QListWidget* list_;
  QCheckBox* nondim_;
  std::vector<NamedCurve> curves_;
  double cellSize_ = 0;
  bool presentation_ = false;
  QFont labelFont_, tickFont_, legendFont_;  // the normal look, restored after presenting
  QRect lastAxes_, lastLegend_;              // lastExportLayout()
  std::vector<std::pair<const QCPAbstractPlottable*, int>> graphCurve_;  // graph → its curve
  void rememberExportLayout();
};

}  // namespace tp::gui
