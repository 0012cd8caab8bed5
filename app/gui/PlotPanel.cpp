#include "PlotPanel.h"

#include <QCheckBox>
#include <QFileInfo>
#include <QHBoxLayout>
#include <QListWidget>
#include <QPdfWriter>
#include <QPushButton>
#include <QRegularExpression>
#include <QSaveFile>
#include <QSvgGenerator>
#include <QVBoxLayout>

#include <qcustomplot.h>
#include <algorithm>
#include <cmath>
#include <memory>

namespace tp::gui {

bool savePng(QImage& image, QIODevice* device, double dpi) {
  const int dpm = int(std::lround(dpi / 0.0254));  // 1 inch = 0.0254 m
  image.setDotsPerMeterX(dpm);
  image.setDotsPerMeterY(dpm);
  return image.save(device, "PNG");
}

namespace {

// Distinguishable colours (Tableau 10), in the order curves are added.
const QColor kPalette[] = {QColor(31, 119, 180),  QColor(255, 127, 14),  QColor(44, 160, 44),
                           QColor(214, 39, 40),   QColor(148, 103, 189), QColor(140, 86, 75),
                           QColor(227, 119, 194), QColor(127, 127, 127), QColor(188, 189, 34),
                           QColor(23, 190, 207)};

}  // namespace

QColor PlotPanel::colourOf(const NamedCurve& c, int index) {
  const int k = c.colour >= 0 ? c.colour : index;
  return kPalette[k % std::size(kPalette)];
}

PlotPanel::PlotPanel(QWidget* parent) : QWidget(parent) {
  setObjectName("plotPanel");
  plot_ = new QCustomPlot;
  plot_->setObjectName("forceDepthPlot");
  plot_->setMinimumSize(320, 200);
  plot_->legend->setVisible(true);
  plot_->legend->setFont(QFont(font().family(), 8));
  plot_->legend->setBrush(QColor(255, 255, 255, 220));
  plot_->axisRect()->insetLayout()->setInsetAlignment(0, Qt::AlignTop | Qt::AlignLeft);
  plot_->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  plot_->setToolTip(tr("Force–depth curves: drag to pan, wheel to zoom"));
  labelFont_ = plot_->xAxis->labelFont();
  tickFont_ = plot_->xAxis->tickLabelFont();
  legendFont_ = plot_->legend->font();
  connect(plot_, &QCustomPlot::afterLayout, this, [this] {
    if (placeLegend()) plot_->replot(QCustomPlot::rpQueuedReplot);
  });

  list_ = new QListWidget;
  list_->setObjectName("curveList");
  list_->setToolTip(tr("Curves on the plot; select one to remove it"));
  list_->setMaximumWidth(220);
  list_->setTextElideMode(Qt::ElideRight);  // the site first, then as much as fits
  list_->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  auto* remove = new QPushButton(tr("Remove"));
  remove->setToolTip(tr("Remove the selected curve"));
  auto* clear = new QPushButton(tr("Clear"));
  clear->setObjectName("clearCurves");
  clear->setToolTip(tr("Remove every curve"));
  nondim_ = new QCheckBox(tr("Nondimensional"));
  nondim_->setToolTip(
      tr("Axes [I] = I/L and [F] = F/(E L²), with L the mean cell size "
         "cbrt(tissue volume / cells) and E each curve's Young's modulus"));

  auto* side = new QVBoxLayout;
  side->addWidget(list_, 1);
  auto* buttons = new QHBoxLayout;
  buttons->addWidget(remove);
  buttons->addWidget(clear);
  side->addLayout(buttons);
  side->addWidget(nondim_);
  auto* layout = new QHBoxLayout(this);
  layout->setContentsMargins(2, 2, 2, 2);
  layout->addWidget(plot_, 1);
  layout->addLayout(side);

  connect(remove, &QPushButton::clicked, this, [this] {
    if (selectedCurve() >= 0) emit removeRequested(selectedCurve());
  });
  connect(clear, &QPushButton::clicked, this, &PlotPanel::clearRequested);
  connect(nondim_, &QCheckBox::toggled, this, &PlotPanel::redraw);
  // A click on a curve's graph (its loading or unloading branch) selects it, as in the list.
  connect(plot_, &QCustomPlot::plottableClick, this,
          [this](QCPAbstractPlottable* p, int, QMouseEvent*) {
            for (const auto& [graph, curve] : graphCurve_)
              if (graph == p) setSelectedCurve(curve);
          });
  connect(list_, &QListWidget::currentRowChanged, this, [this](int row) {
    redraw();
    emit selectionChanged(row);
  });
  redraw();
}

bool PlotPanel::nondimensional() const {
  return nondim_->isChecked();
}
void PlotPanel::setNondimensional(bool on) {
  nondim_->setChecked(on);
}
int PlotPanel::selectedCurve() const {
  return list_->currentRow();
}
void PlotPanel::setSelectedCurve(int index) {
  list_->setCurrentRow(index >= 0 && index < list_->count() ? index : -1);
  if (list_->currentRow() < 0) list_->clearSelection();
}

namespace {

// The curve's name with its mesh and estimated discretisation error.
QString label(const NamedCurve& c) {
  if (c.measured) return QString::fromStdString(c.name);  // "measured · file"
  QString text = QString::fromStdString(c.name) + " · " + QString::fromStdString(meshErrorText(c));
  if (c.meshLevel >= 0) text += QObject::tr(" (mesh level %1)").arg(c.meshLevel);
  return text;
}

// The legend's shorter entry: the name without the site's coordinates (they are in the list
// and its tooltips) and the error, so that the legend stays clear of the curves (placeLegend).
QString legendLabel(const NamedCurve& c) {
  QString name = QString::fromStdString(c.name);
  if (c.measured) return name;
  name.remove(QRegularExpression(QStringLiteral(" \\([^()]*\\) µm")));
  return name + " · " + QString::fromStdString(meshErrorText(c));
}

QString tooltip(const NamedCurve& c) {
  QString tip = label(c);
  if (c.meshError >= 0)
    tip += QObject::tr("\nEstimated at %1 %2: %3")
               .arg(c.meshErrorAt)
               .arg(c.meshErrorForce ? QObject::tr("µN") : QObject::tr("µm"))
               .arg(QString::fromStdString(c.meshErrorMethod));
  return tip;
}

}  // namespace

void PlotPanel::setCurves(const std::vector<NamedCurve>& curves, double meanCellSize) {
  curves_ = curves;
  cellSize_ = meanCellSize;
  // Keep the list (and its selection) when only points were added.
  bool sameNames = list_->count() == static_cast<int>(curves_.size());
  for (int i = 0; sameNames && i < list_->count(); ++i)
    sameNames = list_->item(i)->text() == label(curves_[i]);
  if (!sameNames) {
    const int row = list_->currentRow();
    list_->clear();
    for (const auto& c : curves_) {
      list_->addItem(label(c));
      list_->item(list_->count() - 1)->setToolTip(tooltip(c));
    }
    if (row < list_->count()) list_->setCurrentRow(row);
  }
  redraw();
}

void PlotPanel::setPresentation(bool on) {
  presentation_ = on;
  auto scaled = [on](QFont f) {
    if (on) f.setPointSizeF(f.pointSizeF() * 1.6);
    return f;
  };
  for (QCPAxis* a : {plot_->xAxis, plot_->yAxis}) {
    a->setLabelFont(scaled(labelFont_));
    a->setTickLabelFont(scaled(tickFont_));
  }
  plot_->legend->setFont(scaled(legendFont_));
  redraw();
}

void PlotPanel::redraw() {
  const bool nd = nondimensional() && cellSize_ > 0;
  plot_->clearGraphs();
  graphCurve_.clear();
  for (size_t i = 0; i < curves_.size(); ++i) {
    const NamedCurve& c = curves_[i];
    const AxisScale s = axisScale(nd, cellSize_, c.params.youngModulus);
    QCPGraph* g = plot_->addGraph();
    graphCurve_.emplace_back(g, static_cast<int>(i));
    g->setName(legendLabel(c));
    QColor colour = colourOf(c, static_cast<int>(i));
    // The curve selected in the list stands out: thicker, the others faded.
    const int selected = list_->currentRow();
    const bool highlighted = static_cast<int>(i) == selected;
    if (selected >= 0 && !highlighted) colour.setAlpha(90);
    const double k = presentation_ ? 1.6 : 1.0;  // line widths and marker sizes
    g->setPen(QPen(colour, (highlighted ? 3.6 : 1.8) * k, c.live ? Qt::DashLine : Qt::SolidLine));
    g->setScatterStyle(QCPScatterStyle(
        c.live ? QCPScatterStyle::ssCross : QCPScatterStyle::ssDisc, colour, 5 * k));
    if (c.measured) {  // an experiment's points: markers only, no line through them
      g->setLineStyle(QCPGraph::lsNone);
      g->setScatterStyle(QCPScatterStyle(QCPScatterStyle::ssCircle,
                                         QPen(colour, (highlighted ? 2.0 : 1.2) * k), Qt::NoBrush,
                                         (highlighted ? 7 : 5) * k));
    }
    // Loading and unloading apart: the unloading branch (a run's way back) is its own graph,
    // dotted, without a legend entry, so it is not merged into the loading one by depth.
    QVector<double> x, y, ux, uy;
    for (const CurvePoint& p : c.points)
      if (p.converged && std::isfinite(p.force)) {
        (p.unloading ? ux : x).push_back(p.depth * s.depth);
        (p.unloading ? uy : y).push_back(p.force * s.force);
      }
    g->setData(x, y);  // sorted by depth: a drag back and forth draws one curve
    if (!ux.isEmpty()) {
      // It starts where loading ended.
      if (!x.isEmpty()) {
        ux.prepend(x.back());
        uy.prepend(y.back());
      }
      QCPGraph* u = plot_->addGraph();
      graphCurve_.emplace_back(u, static_cast<int>(i));
      u->setName(label(c) + tr(" (unloading)"));
      u->setPen(QPen(colour, (highlighted ? 3.6 : 1.8) * k, Qt::DotLine));
      u->setScatterStyle(QCPScatterStyle(QCPScatterStyle::ssCircle, colour, 5 * k));
      u->setData(ux, uy);
      u->removeFromLegend();
    }
  }
  if (nd) {
    plot_->xAxis->setLabel(tr("[I] = I / L   (L = %1 µm)").arg(cellSize_, 0, 'f', 2));
    plot_->yAxis->setLabel(tr("[F] = F / (E L²)"));
  } else {
    plot_->xAxis->setLabel(tr("indentation depth I (µm)"));
    plot_->yAxis->setLabel(tr("force F (µN)"));
  }
  plot_->rescaleAxes();
  // Start both axes at zero and leave a margin above the data.
  for (QCPAxis* a : {plot_->xAxis, plot_->yAxis}) {
    QCPRange r = a->range();
    const double hi = r.upper > 0 ? r.upper * 1.08 : 1.0;
    a->setRange(std::min(0.0, r.lower), hi);
  }
  showResiduals(nd);
  plot_->legend->setVisible(!curves_.empty());
  placeLegend();
  plot_->replot(QCustomPlot::rpQueuedReplot);
}

// The legend goes in the corner of the axes where it hides the fewest points of the curves: the
// top left, where rising force–depth curves leave room, unless the curves pass there (a tall
// legend over axes squeezed by the residual strip, a curve that rises steeply and levels off);
// then the bottom right, the top right or the bottom left, whichever hides fewest (and when none
// is free, the legend lets the points show through). Judged on the axes' size at the last
// layout, and again after each layout (a resized plot): true when it moved.
bool PlotPanel::placeLegend() {
  QCPLayoutInset* inset = plot_->axisRect()->insetLayout();
  const int index = inset->elements(false).indexOf(plot_->legend);
  if (index < 0 || !plot_->legend->visible()) return false;
  const QRect axes = plot_->axisRect()->rect();
  const QSize legend = plot_->legend->minimumOuterSizeHint();
  if (axes.width() <= 0 || axes.height() <= 0) return false;
  const double fw = std::min(1.0, (legend.width() + 12.0) / axes.width());
  const double fh = std::min(1.0, (legend.height() + 12.0) / axes.height());
  const QCPRange xr = plot_->xAxis->range(), yr = plot_->yAxis->range();
  if (xr.size() <= 0 || yr.size() <= 0) return false;
  const Qt::Alignment corners[] = {Qt::AlignTop | Qt::AlignLeft, Qt::AlignBottom | Qt::AlignRight,
                                   Qt::AlignTop | Qt::AlignRight, Qt::AlignBottom | Qt::AlignLeft};
  int hidden[4] = {0, 0, 0, 0};
  for (int g = 0; g < plot_->graphCount(); ++g) {
    if (plot_->graph(g)->keyAxis() != plot_->xAxis) continue;  // the residual strip's
    for (const QCPGraphData& d : *plot_->graph(g)->data()) {
      const double fx = (d.key - xr.lower) / xr.size(), fy = (d.value - yr.lower) / yr.size();
      const bool left = fx <= fw, right = fx >= 1 - fw, top = fy >= 1 - fh, bottom = fy <= fh;
      hidden[0] += top && left;
      hidden[1] += bottom && right;
      hidden[2] += top && right;
      hidden[3] += bottom && left;
    }
  }
  int best = 0;
  for (int k = 1; k < 4; ++k)
    if (hidden[k] < hidden[best]) best = k;
  // Axes too small for a free corner: the points under the legend show through it.
  const QColor background(255, 255, 255, hidden[best] > 0 ? 140 : 220);
  if (plot_->legend->brush().color() != background) plot_->legend->setBrush(background);
  if (inset->insetAlignment(index) == corners[best]) return false;
  inset->setInsetAlignment(index, corners[best]);
  return true;
}

void PlotPanel::showResiduals(bool nd) {
  bool any = false;
  for (const NamedCurve& c : curves_) any = any || !c.residuals.empty();
  QCPLayoutGrid* layout = plot_->plotLayout();
  if (!any) {
    if (residualRect_) {
      layout->remove(residualRect_);  // deletes it, with its axes
      layout->simplify();
      residualRect_ = nullptr;
    }
    return;
  }
  if (!residualRect_) {
    residualRect_ = new QCPAxisRect(plot_);
    residualRect_->setObjectName("residualStrip");
    layout->addElement(1, 0, residualRect_);
    layout->setRowStretchFactor(0, 3);
    layout->setRowStretchFactor(1, 1);
    // The two plots' axes line up: one margin for both on the left and right.
    auto* margins = new QCPMarginGroup(plot_);
    plot_->axisRect()->setMarginGroup(QCP::msLeft | QCP::msRight, margins);
    residualRect_->setMarginGroup(QCP::msLeft | QCP::msRight, margins);
    // Depth: the same range as the curves above, whatever pans or zooms it.
    QCPAxis* depth = residualRect_->axis(QCPAxis::atBottom);
    connect(plot_->xAxis, qOverload<const QCPRange&>(&QCPAxis::rangeChanged), depth,
            qOverload<const QCPRange&>(&QCPAxis::setRange));
    // A strip a quarter of the plot high: three ticks are as many as its labels have room for.
    residualRect_->axis(QCPAxis::atLeft)->ticker()->setTickStepStrategy(
        QCPAxisTicker::tssMeetTickCount);
    residualRect_->axis(QCPAxis::atLeft)->ticker()->setTickCount(3);
    residualRect_->setRangeDrag(Qt::Vertical);
    residualRect_->setRangeZoom(Qt::Vertical);
  }
  QCPAxis* x = residualRect_->axis(QCPAxis::atBottom);
  QCPAxis* y = residualRect_->axis(QCPAxis::atLeft);
  // Zero, the perfect fit: a thin grey line across.
  QCPGraph* zero = plot_->addGraph(x, y);
  zero->setPen(QPen(QColor(120, 120, 120), 1.0));
  zero->setData(QVector<double>{-1e6, 1e6}, QVector<double>{0.0, 0.0});
  zero->removeFromLegend();
  double extent = 0;
  const int selected = list_->currentRow();
  for (size_t i = 0; i < curves_.size(); ++i) {
    const NamedCurve& c = curves_[i];
    if (c.residuals.size() != c.points.size()) continue;
    const AxisScale s = axisScale(nd, cellSize_, c.params.youngModulus);
    QColor colour = colourOf(c, static_cast<int>(i));
    if (selected >= 0 && static_cast<int>(i) != selected) colour.setAlpha(90);
    QCPGraph* g = plot_->addGraph(x, y);
    g->setName(tr("residuals of %1").arg(QString::fromStdString(c.name)));
    g->setPen(QPen(colour, 1.2));
    g->setScatterStyle(QCPScatterStyle(QCPScatterStyle::ssDisc, colour, 5));
    g->removeFromLegend();
    QVector<double> px, py;
    for (size_t k = 0; k < c.points.size(); ++k)
      if (std::isfinite(c.residuals[k])) {
        px.push_back(c.points[k].depth * s.depth);
        py.push_back(c.residuals[k] * s.force);
        extent = std::max(extent, std::abs(py.back()));
      }
    g->setData(px, py);
  }
  x->setLabel(QString());
  x->setRange(plot_->xAxis->range());
  y->setLabel(nd ? tr("residual [F]") : tr("residual (µN)"));
  // Symmetric about zero, so that a bias shows as an offset.
  y->setRange(-1.15 * extent - 1e-12, 1.15 * extent + 1e-12);
}

namespace {

// Puts the legend where an export of `size` (its units) wants it, and back where it was when it
// goes out of scope. Outside is a column right of the axes when the legend takes at most 40 % of
// the width, else a row under them (a narrow figure keeps its axes); a legend wider than the
// figure gets a smaller font (not below 5 pt) rather than being cut.
class LegendPlacement {
 public:
  using Legend = PlotPanel::ExportOptions::Legend;
  LegendPlacement(QCustomPlot* plot, Legend where, const QSize& size)
      : plot_(plot), font_(plot->legend->font()), brush_(plot->legend->brush()) {
    visible_ = plot_->legend->visible();
    if (where == Legend::None) plot_->legend->setVisible(false);
    if (where != Legend::Outside || !visible_) return;
    const int wide = plot_->legend->minimumOuterSizeHint().width();
    const bool right = wide <= 0.4 * size.width();
    if (!right && wide > 0.95 * size.width()) {
      QFont f = font_;
      f.setPointSizeF(std::max(5.0, f.pointSizeF() * 0.95 * size.width() / wide));
      plot_->legend->setFont(f);
    }
    QCPLayoutInset* inset = plot_->axisRect()->insetLayout();
    const int index = inset->elements(false).indexOf(plot_->legend);
    if (index >= 0) alignment_ = inset->insetAlignment(index);
    inset->take(plot_->legend);
    holder_ = new QCPLayoutGrid;
    QCPLayoutGrid* grid = plot_->plotLayout();
    if (right) {  // legend on top, a spacer under it taking the height
      grid->addElement(0, grid->columnCount(), holder_);
      grid->setColumnStretchFactor(grid->columnCount() - 1, 0.001);
      holder_->addElement(0, 0, plot_->legend);
      holder_->addElement(1, 0, new QCPLayoutElement(plot_));
      holder_->setRowStretchFactor(0, 0.001);
    } else {  // legend on the left, a spacer right of it taking the width
      grid->addElement(grid->rowCount(), 0, holder_);
      grid->setRowStretchFactor(grid->rowCount() - 1, 0.001);
      holder_->addElement(0, 0, plot_->legend);
      holder_->addElement(0, 1, new QCPLayoutElement(plot_));
      holder_->setColumnStretchFactor(0, 0.001);
    }
    plot_->legend->setBrush(Qt::NoBrush);
  }
  ~LegendPlacement() {
    plot_->legend->setVisible(visible_);
    plot_->legend->setFont(font_);
    plot_->legend->setBrush(brush_);
    if (!holder_) return;
    holder_->take(plot_->legend);
    plot_->plotLayout()->remove(holder_);  // deletes it and the spacer
    plot_->plotLayout()->simplify();
    plot_->axisRect()->insetLayout()->addElement(plot_->legend, alignment_);
    plot_->replot(QCustomPlot::rpQueuedReplot);
  }
  LegendPlacement(const LegendPlacement&) = delete;
  LegendPlacement& operator=(const LegendPlacement&) = delete;

 private:
  QCustomPlot* plot_;
  QFont font_;
  QBrush brush_;
  bool visible_ = true;
  Qt::Alignment alignment_ = Qt::AlignTop | Qt::AlignLeft;  // in the axes, on screen
  QCPLayoutGrid* holder_ = nullptr;
};

}  // namespace

void PlotPanel::drawInto(QPainter* painter, const QSize& size, ExportOptions::Legend legend) {
  const LegendPlacement placed(plot_, legend, size);
  auto* qcp = static_cast<QCPPainter*>(painter);
  plot_->toPainter(qcp, size.width(), size.height());
  rememberExportLayout();
}

void PlotPanel::rememberExportLayout() {
  lastAxes_ = plot_->axisRect()->rect();
  lastLegend_ = plot_->legend->visible() ? plot_->legend->outerRect() : QRect();
}

bool PlotPanel::exportImage(const QString& path, const ExportOptions& options, QString* error) {
  const int w = options.width > 0 ? options.width : plot_->width();
  const int h = options.height > 0 ? options.height : plot_->height();
  const QString suffix = QFileInfo(path).suffix().toLower();
  if (suffix != "png" && suffix != "svg" && suffix != "pdf") {
    if (error) *error = tr("%1: unknown format '%2' (use .png, .svg or .pdf)").arg(path, suffix);
    return false;
  }
  if (!(options.dpi >= 24 && options.dpi <= 2400)) {
    if (error) *error = tr("%1: a resolution of %2 dpi is not one to draw at (24–2400)").arg(path).arg(options.dpi);
    return false;
  }
  QSaveFile file(path);  // written aside and renamed on commit: atomic
  if (!file.open(QIODevice::WriteOnly)) {
    if (error) *error = tr("%1: %2").arg(path, file.errorString());
    return false;
  }
  bool ok = true;
  {
    const double scale = suffix == "png" ? options.dpi / 96.0 : 1.0;
    const LegendPlacement placed(plot_, options.legend,
                                 QSize(int(std::lround(w / scale)), int(std::lround(h / scale))));
    if (suffix == "svg" || suffix == "pdf") {
      QCPPainter painter;
      std::unique_ptr<QPaintDevice> device;
      if (suffix == "svg") {
        auto* svg = new QSvgGenerator;
        svg->setOutputDevice(&file);
        svg->setSize(QSize(w, h));
        svg->setViewBox(QRect(0, 0, w, h));
        svg->setTitle(tr("TissueProbe force–depth curves"));
        device.reset(svg);
      } else {
        auto* pdf = new QPdfWriter(&file);
        pdf->setResolution(72);  // one device unit = one point
        pdf->setPageSize(QPageSize(QSizeF(w, h), QPageSize::Point, QString(), QPageSize::ExactMatch));
        pdf->setPageMargins(QMarginsF(0, 0, 0, 0));
        pdf->setCreator(QStringLiteral("TissueProbe"));
        device.reset(pdf);
      }
      ok = painter.begin(device.get());
      if (ok) {
        painter.setMode(QCPPainter::pmVectorized);
        painter.setMode(QCPPainter::pmNoCaching);
        plot_->toPainter(&painter, w, h);
        rememberExportLayout();
        painter.end();
      }
      device.reset();  // finishes the document before the commit
    } else {
      // The layout at w/scale × h/scale, drawn scale times larger: w × h pixels.
      QImage image = plot_->toPixmap(int(std::lround(w / scale)), int(std::lround(h / scale)), scale)
                         .toImage();
      rememberExportLayout();
      if (image.size() != QSize(w, h))
        image = image.scaled(w, h, Qt::IgnoreAspectRatio, Qt::SmoothTransformation);
      ok = savePng(image, &file, options.dpi);
    }
  }
  if (!ok || !file.commit()) {
    if (error) *error = tr("%1: could not write the plot (%2)").arg(path, file.errorString());
    return false;
  }
  return true;
}

}  // namespace tp::gui
