#include "MapPanel.h"

#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QSpinBox>
#include <QStandardPaths>
#include <QThread>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>
#include <map>

#include "FileActions.h"
#include "MapRunner.h"
#include "SimulationController.h"

namespace tp::gui {

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  if (v.size() % 2) return v[m];
  return 0.5 * (v[m] + *std::max_element(v.begin(), v.begin() + m));
}

QString duration(double seconds) {
  if (seconds < 90) return QObject::tr("%1 s").arg(std::lround(seconds));
  if (seconds < 5400) return QObject::tr("%1 min").arg(std::lround(seconds / 60));
  return QObject::tr("%1 h").arg(seconds / 3600, 0, 'f', 1);
}

}  // namespace

MapPanel::MapPanel(MapRunner* runner, SimulationController* controller, QWidget* parent)
    : QWidget(parent), runner_(runner), controller_(controller) {
  setObjectName("mapPanel");
  cacheRoot_ = QStandardPaths::writableLocation(QStandardPaths::CacheLocation) + "/maps";
  auto* layout = new QVBoxLayout(this);
  auto* form = new QFormLayout;
  sites_ = new QComboBox;
  sites_->setObjectName("mapSites");
  sites_->addItem(tr("Cell middles"), "cells");
  sites_->addItem(tr("Anticlinal junctions"), "junctions");
  sites_->addItem(tr("Cell middles and junctions"), "cells,junctions");
  sites_->addItem(tr("Grid seen from above"), "grid");
  sites_->setToolTip(tr("Cell middles: the middle of each cell's outer wall. Junctions: where "
                        "the outer walls of two cells meet. Grid: a square raster seen from "
                        "above, as an AFM scans."));
  spacing_ = new QDoubleSpinBox;
  spacing_->setObjectName("mapSpacing");
  spacing_->setRange(0, 1000);
  spacing_->setDecimals(1);
  spacing_->setSuffix(tr(" µm"));
  spacing_->setSpecialValueText(tr("mean cell size"));
  spacing_->setToolTip(tr("The grid's spacing (at its lowest: the mean cell size)"));
  depth_ = new QDoubleSpinBox;
  depth_->setObjectName("mapDepth");
  depth_->setRange(0.01, 20);
  depth_->setDecimals(2);
  depth_->setSingleStep(0.1);
  depth_->setValue(0.5);
  depth_->setSuffix(tr(" µm"));
  depth_->setToolTip(tr("Each site is indented to this depth; its stiffness is force / depth"));
  steps_ = new QSpinBox;
  steps_->setObjectName("mapSteps");
  steps_->setRange(2, 200);
  steps_->setValue(5);
  steps_->setToolTip(tr("Points of each site's curve (the tangent stiffness is the last step's)"));
  jobs_ = new QSpinBox;
  jobs_->setObjectName("mapJobs");
  jobs_->setRange(1, std::max(1, QThread::idealThreadCount()));
  jobs_->setValue(std::max(1, QThread::idealThreadCount()));
  jobs_->setToolTip(tr("Sites solved at once, one per core; the interactive probe shares them"));
  form->addRow(tr("Sites"), sites_);
  form->addRow(tr("Grid spacing"), spacing_);
  form->addRow(tr("Depth"), depth_);
  form->addRow(tr("Points"), steps_);
  form->addRow(tr("Workers"), jobs_);
  layout->addLayout(form);
  note_ = new QLabel(tr("Every site is indented with the current parameters."));
  note_->setObjectName("mapParameters");
  note_->setWordWrap(true);
  layout->addWidget(note_);
  connect(controller_, &SimulationController::snapshotReady, this, [this](const Snapshot& s) {
    if (s.phase == Snapshot::Phase::Prepared)
      note_->setText(tr("Every site is indented with the current parameters: %1%2.")
                         .arg(QString::fromStdString(describe(s.params)))
                         .arg(s.params.autoMesh ? tr(", the mesh refined until converged")
                                                : QString()));
  });
  auto* buttons = new QHBoxLayout;
  start_ = new QPushButton(tr("Start map"));
  start_->setObjectName("mapStart");
  cancel_ = new QPushButton(tr("Cancel"));
  cancel_->setObjectName("mapCancel");
  show_ = new QPushButton(tr("Show on the tissue"));
  show_->setObjectName("mapShow");
  show_->setToolTip(tr("Colour the outer surface by the map's stiffness; then click a site "
                       "for its curve"));
  buttons->addWidget(start_);
  buttons->addWidget(cancel_);
  buttons->addWidget(show_);
  layout->addLayout(buttons);
  progress_ = new QProgressBar;
  progress_->setObjectName("mapProgressBar");
  progress_->setRange(0, 1);
  progress_->setValue(0);
  layout->addWidget(progress_);
  status_ = new QLabel;
  status_->setObjectName("mapStatus");
  status_->setWordWrap(true);
  summary_ = new QLabel;
  summary_->setObjectName("mapSummary");
  summary_->setWordWrap(true);
  summary_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  layout->addWidget(status_);
  layout->addWidget(summary_);
  layout->addStretch(1);

  connect(sites_, &QComboBox::currentIndexChanged, this, &MapPanel::updateState);
  connect(start_, &QPushButton::clicked, this, &MapPanel::startMap);
  connect(cancel_, &QPushButton::clicked, runner_, &MapRunner::cancel);
  connect(show_, &QPushButton::clicked, this, &MapPanel::showRequested);
  connect(runner_, &MapRunner::started, this, [this](int tasks, int before) {
    progress_->setRange(0, tasks);
    progress_->setValue(before);
    const int out = runner_->sitesLeftOut();
    const QString leftOut =
        out ? " " + tr("(%1 left out: the probe would reach the clamped base there)").arg(out)
            : QString();
    status_->setText(
        before
            ? tr("%1 of %2 sites%3 were done before; going on…").arg(before).arg(tasks).arg(leftOut)
            : tr("%1 sites to map%2…").arg(tasks).arg(leftOut));
    updateState();
  });
  connect(runner_, &MapRunner::progress, this,
          [this](int done, int todo, int failed, double seconds) {
            const double rate = seconds > 0 ? done / seconds : 0;
            progress_->setValue(runner_->sitesDone());
            status_->setText(tr("%1 of %2 sites done this run%3 · %4 sites/min · about %5 left")
                                 .arg(done)
                                 .arg(todo)
                                 .arg(failed ? tr(" (%1 not converged)").arg(failed) : QString())
                                 .arg(60 * rate, 0, 'f', 1)
                                 .arg(rate > 0 ? duration((todo - done) / rate) : tr("?")));
          });
  connect(runner_, &MapRunner::mapChanged, this, &MapPanel::updateSummary);
  connect(runner_, &MapRunner::mapChanged, this, &MapPanel::updateState);
  connect(runner_, &MapRunner::finished, this,
          [this](bool complete, bool cancelled, const QString& message) {
            if (progress_->maximum() == 0) progress_->setRange(0, 1);  // ended before its sites
            if (complete) progress_->setValue(progress_->maximum());
            QString text = complete ? tr("Map complete.")
                           : cancelled ? QString()
                                       : tr("Map stopped.");
            if (!message.isEmpty()) text += (text.isEmpty() ? "" : " ") + message;
            status_->setText(text);
            emit statusMessage(text);
            if (!complete && !cancelled && runner_->sitesDone() == 0 && !message.isEmpty())
              showError(this, tr("Cannot make the stiffness map"), message);
            updateState();
          });
  updateState();
}

bool MapPanel::startMap() {
  MapRequest r;
  r.tissuePath = controller_->tissuePath();
  r.params = controller_->params();
  r.kinds.clear();
  for (const QString& word : sites_->currentData().toString().split(','))
    r.kinds.push_back(parseSiteKind(word.toStdString()));
  if (spacing_->value() > 0) r.gridSpacing = spacing_->value();
  r.depth = depth_->value();
  r.steps = steps_->value();
  r.jobs = jobs_->value();
  r.cacheRoot = cacheRoot_;
  QString why;
  if (!runner_->start(r, &why)) {
    showError(this, tr("Cannot start the stiffness map"), why);
    return false;
  }
  progress_->setRange(0, 0);  // busy until the sites are placed
  status_->setText(tr("Reading the tissue and placing the sites…"));
  updateState();
  return true;
}

void MapPanel::updateState() {
  const bool running = runner_->running();
  start_->setEnabled(!running);
  cancel_->setEnabled(running);
  show_->setEnabled(runner_->hasMap() && runner_->field() && !runner_->field()->empty());
  spacing_->setEnabled(sites_->currentData().toString() == "grid");
  for (QWidget* w : std::initializer_list<QWidget*>{sites_, depth_, steps_, jobs_})
    w->setEnabled(!running);
}

void MapPanel::updateSummary() {
  if (!runner_->hasMap()) {
    summary_->clear();
    return;
  }
  if (runner_->otherTissue()) {
    summary_->setText(tr("The map is of %1, not of the tissue shown.")
                          .arg(QString::fromStdString(runner_->map().plan.tissue)));
    return;
  }
  const SessionMap& m = runner_->map();
  // Per kind of site: how many are done, and the median and range of their secant stiffness.
  std::map<std::string, std::vector<double>> byKind;
  std::map<std::string, double> worstError;  // the largest estimated mesh error; < 0 unknown
  int done = 0, failed = 0;
  double depth = 0;
  for (const TaskResult& r : m.results) {
    if (r.task < 0) continue;
    ++done;
    if (!r.converged()) {
      ++failed;
      continue;
    }
    const std::string kind = toString(m.plan.site(r.task).kind);
    byKind[kind].push_back(r.secant);
    const bool known = !worstError.count(kind) || worstError[kind] >= 0;
    worstError[kind] = known && r.meshError >= 0 ? std::max(worstError[kind], r.meshError) : -1.0;
    depth = r.depth;
  }
  QString text = tr("%1 of %2 sites done").arg(done).arg(m.plan.taskCount());
  if (failed) text += tr(", %1 not converged (left out)").arg(failed);
  if (!byKind.empty()) text += tr(". Secant stiffness at %1 µm:").arg(depth, 0, 'g', 3);
  for (const auto& [kind, values] : byKind) {
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    const double e = worstError[kind];
    text += tr("\n%1: median %2 µN/µm, %3–%4 (%5 sites; %6)")
                .arg(kind == "cells" ? tr("cell middles")
                     : kind == "junctions" ? tr("junctions")
                     : QString::fromStdString(kind))
                .arg(median(values), 0, 'g', 3)
                .arg(*lo, 0, 'g', 3)
                .arg(*hi, 0, 'g', 3)
                .arg(values.size())
                .arg(e >= 0 ? tr("mesh error up to ±%1 %").arg(100 * e, 0, 'g', 2)
                            : tr("mesh error not estimated at every site"));
  }
  summary_->setText(text);
}

}  // namespace tp::gui
