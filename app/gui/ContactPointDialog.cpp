#include "ContactPointDialog.h"

#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QLabel>
#include <QPushButton>
#include <QVBoxLayout>

#include <qcustomplot.h>

#include <algorithm>

namespace tp::gui {

ContactPointDialog::ContactPointDialog(const RawCurveReading& reading, const QString& file,
                                       QWidget* parent)
    : QDialog(parent), reading_(reading), estimate_(reading.contactHeight) {
  setObjectName("contactPointDialog");
  setWindowTitle(tr("Contact point of %1").arg(file));
  auto* layout = new QVBoxLayout(this);
  auto* intro = new QLabel(
      tr("The approach, its force less the baseline fitted far from the sample. The curve is "
         "converted to indentation from the contact point (the line): estimated where the force "
         "last leaves the baseline's noise. Move it with the box or a click on the plot."));
  intro->setWordWrap(true);
  layout->addWidget(intro);
  plot_ = new QCustomPlot;
  plot_->setObjectName("contactPlot");
  plot_->setMinimumSize(520, 300);
  QVector<double> h, f;
  for (size_t k = 0; k < reading.height.size(); ++k) {
    h.push_back(reading.height[k]);
    f.push_back(reading.force[k] - reading.baselineOffset - reading.baselineSlope * reading.height[k]);
  }
  QCPGraph* g = plot_->addGraph();
  g->setData(h, f);
  g->setLineStyle(QCPGraph::lsNone);
  g->setScatterStyle(QCPScatterStyle(QCPScatterStyle::ssDisc, 3));
  plot_->xAxis->setLabel(tr("piezo height (µm), towards the sample ←"));
  plot_->yAxis->setLabel(tr("force − baseline (µN)"));
  plot_->rescaleAxes();
  line_ = new QCPItemStraightLine(plot_);
  line_->setPen(QPen(QColor(200, 60, 40), 1.5));
  layout->addWidget(plot_, 1);
  auto* form = new QFormLayout;
  height_ = new QDoubleSpinBox;
  height_->setObjectName("contactHeight");
  const auto [lo, hi] = std::minmax_element(reading.height.begin(), reading.height.end());
  height_->setRange(reading.height.empty() ? 0 : *lo, reading.height.empty() ? 0 : *hi);
  height_->setDecimals(4);
  height_->setSingleStep(0.01);
  height_->setSuffix(tr(" µm"));
  auto* reset = new QPushButton(tr("Estimate (%1 µm)").arg(estimate_, 0, 'f', 4));
  auto* row = new QHBoxLayout;
  row->addWidget(height_, 1);
  row->addWidget(reset);
  form->addRow(tr("Contact at piezo height"), row);
  result_ = new QLabel;
  result_->setObjectName("contactResult");
  form->addRow(result_);
  layout->addLayout(form);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
  buttons->button(QDialogButtonBox::Ok)->setText(tr("Import"));
  layout->addWidget(buttons);
  connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
  connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
  connect(reset, &QPushButton::clicked, this, [this] { setContactHeight(estimate_); });
  connect(height_, &QDoubleSpinBox::valueChanged, this, &ContactPointDialog::showContact);
  connect(plot_, &QCustomPlot::mousePress, this, [this](QMouseEvent* e) {
    setContactHeight(plot_->xAxis->pixelToCoord(e->position().x()));
  });
  setContactHeight(estimate_);
  shown_ = height_->value();
  showContact(height_->value());
}

bool ContactPointDialog::moved() const { return height_->value() != shown_; }

double ContactPointDialog::contactHeight() const { return moved() ? height_->value() : estimate_; }

void ContactPointDialog::setContactHeight(double height) {
  height_->setValue(height);  // clamped to the data by the box
}

void ContactPointDialog::showContact(double box) {
  const double height = box == shown_ ? estimate_ : box;
  line_->point1->setCoords(height, 0);
  line_->point2->setCoords(height, 1);
  // What the conversion gives there (the same conversion the import makes).
  int points = 0;
  double deepest = 0;
  try {
    RawCurveOptions options;
    options.contactHeight = height;
    const RawCurveReading r = indentationFromApproach(reading_.height, reading_.force,
                                                      reading_.springConstant, "curve", options);
    points = static_cast<int>(r.curve.depth.size());
    for (double d : r.curve.depth) deepest = std::max(deepest, d);
  } catch (const std::exception& e) {
    result_->setText(QString::fromUtf8(e.what()));
    plot_->replot(QCustomPlot::rpQueuedReplot);
    return;
  }
  result_->setText(tr("%1 points past contact, deepest indentation %2 µm%3")
                       .arg(points)
                       .arg(deepest, 0, 'f', 3)
                       .arg(box == shown_ ? tr(" (the estimate)")
                                          : tr(" (moved %1 µm)").arg(height - estimate_, 0, 'f', 4)));
  plot_->replot(QCustomPlot::rpQueuedReplot);
}

}  // namespace tp::gui
