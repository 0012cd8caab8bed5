#include "ScreenshotDialog.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDialogButtonBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSpinBox>

#include <cmath>

namespace tp::gui {

namespace {
constexpr int kMaxSide = 8192;  // within every OpenGL implementation's renderbuffer limit
}

ScreenshotDialog::ScreenshotDialog(const QSize& viewSize, QWidget* parent)
    : ScreenshotDialog(viewSize, tr("Screenshot of the 3D view"), tr(" px"), parent) {}

ScreenshotDialog::ScreenshotDialog(const QSize& base, const QString& title, const QString& unit,
                                   QWidget* parent)
    : QDialog(parent), view_(base.expandedTo(QSize(1, 1))) {
  setWindowTitle(title);
  width_ = new QSpinBox;
  height_ = new QSpinBox;
  for (auto* s : {width_, height_}) {
    s->setRange(16, kMaxSide);
    s->setSuffix(unit);
  }
  width_->setValue(view_.width());
  height_->setValue(view_.height());
  keepAspect_ = new QCheckBox(tr("Keep the aspect ratio"));
  keepAspect_->setChecked(true);
  auto* presets = new QHBoxLayout;
  for (double f : {1.0, 2.0, 4.0}) {
    auto* b = new QPushButton(tr("%1×").arg(f));
    b->setToolTip(tr("%1 times the default size").arg(f));
    presets->addWidget(b);
    connect(b, &QPushButton::clicked, this, [this, f] { scaleTo(f); });
  }
  connect(width_, &QSpinBox::valueChanged, this, [this](int w) {
    if (!keepAspect_->isChecked()) return;
    const QSignalBlocker block(height_);
    height_->setValue(int(std::lround(w * double(view_.height()) / view_.width())));
  });
  connect(height_, &QSpinBox::valueChanged, this, [this](int h) {
    if (!keepAspect_->isChecked()) return;
    const QSignalBlocker block(width_);
    width_->setValue(int(std::lround(h * double(view_.width()) / view_.height())));
  });
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
  connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
  connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
  form_ = new QFormLayout(this);
  form_->addRow(tr("Width"), width_);
  form_->addRow(tr("Height"), height_);
  form_->addRow(keepAspect_);
  form_->addRow(tr("Presets"), presets);
  form_->addRow(buttons);
}

void ScreenshotDialog::addResolution(double dpi) {
  dpi_ = new QSpinBox;
  dpi_->setObjectName("exportDpi");
  dpi_->setRange(24, 2400);
  dpi_->setSuffix(tr(" dpi"));
  dpi_->setValue(int(std::lround(dpi)));
  dpi_->setToolTip(tr("PNG: text and lines are drawn for this resolution (96: as on screen; "
                      "300: a print figure of width / 300 inches)"));
  form_->insertRow(form_->rowCount() - 1, tr("Resolution"), dpi_);
}

double ScreenshotDialog::resolution() const {
  return dpi_ ? dpi_->value() : 96.0;
}

void ScreenshotDialog::addLegendChoice() {
  legend_ = new QComboBox;
  legend_->setObjectName("exportLegend");
  legend_->addItem(tr("inside, top left"));
  legend_->addItem(tr("outside, on the right"));
  legend_->addItem(tr("none"));
  legend_->setCurrentIndex(1);
  form_->insertRow(form_->rowCount() - 1, tr("Legend"), legend_);
}

int ScreenshotDialog::legendChoice() const {
  return legend_ ? legend_->currentIndex() : 1;
}

void ScreenshotDialog::scaleTo(double factor) {
  const QSignalBlocker a(width_), b(height_);
  width_->setValue(int(std::lround(view_.width() * factor)));
  height_->setValue(int(std::lround(view_.height() * factor)));
}

QSize ScreenshotDialog::imageSize() const {
  return {width_->value(), height_->value()};
}

}  // namespace tp::gui
