#pragma once
// The contact point of a raw AFM curve, shown and moved by the user before the curve is
// converted (issue 13): the approach as the force less its baseline against the piezo height,
// a vertical line at the contact point (the estimate first), a box for its height and a click on
// the plot to move it, with what the conversion would give (points, deepest indentation).
// Units: µm, µN.

#include <QDialog>

#include "io/JpkCurve.h"

class QCustomPlot;
class QCPItemStraightLine;
class QDoubleSpinBox;
class QLabel;

namespace tp::gui {

class ContactPointDialog : public QDialog {
  Q_OBJECT

 public:
  /// `reading`: the curve converted at its estimated contact point (parseJpkForceCurve).
  ContactPointDialog(const RawCurveReading& reading, const QString& file, QWidget* parent = nullptr);

  /// The contact point chosen (µm, piezo height): the estimate until the user moves it.
  double contactHeight() const;
  bool moved() const;
  void setContactHeight(double height);
  QCustomPlot* plot() const { return plot_; }

 private:
  void showContact(double box);

  RawCurveReading reading_;
  double estimate_;
  double shown_ = 0;  // the estimate as the box holds it (rounded to its decimals)
  QCustomPlot* plot_;
  QCPItemStraightLine* line_;
  QDoubleSpinBox* height_;
  QLabel* result_;
};

}  // namespace tp::gui
