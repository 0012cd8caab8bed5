#include "SimulationController.h"

#include <algorithm>

#include "SimulationWorker.h"

namespace tp::gui {

SimulationController::SimulationController(QObject* parent) : QObject(parent) {
  qRegisterMetaType<tp::gui::Snapshot>();
  thread_.setObjectName("simulation");
  worker_ = new SimulationWorker;
  worker_->moveToThread(&thread_);
  // The worker emits from its thread: Qt queues each call into this (the GUI) thread, and the
  // arguments (snapshots included) are copied.
  connect(worker_, &SimulationWorker::snapshotReady, this, &SimulationController::onSnapshot);
  connect(worker_, &SimulationWorker::busy, this, [this](const QString& what) {
    busy_ = true;
    emit busyChanged(true, what);
  });
  connect(worker_, &SimulationWorker::idle, this, [this] {
    busy_ = false;
    emit busyChanged(false, QString());
  });
  connect(worker_, &SimulationWorker::loaded, this,
          [this](const QString& path, const QString& summary) {
            // The sites belong to the tissue: they change only once the new one has loaded.
            tissuePath_ = path;
            sites_ = pendingSites_;
            currentSite_ = pendingCurrentSite_;
            emit sitesChanged();
            emit tissueLoaded(path, summary);
          });
  connect(worker_, &SimulationWorker::loadFailed, this,
          [this](const QString&, const QString& message) { emit loadFailed(message); });
  connect(worker_, &SimulationWorker::failed, this, &SimulationController::solveFailed);
  connect(worker_, &SimulationWorker::refused, this, &SimulationController::settingsRefused);
  connect(worker_, &SimulationWorker::runStarted, this, &SimulationController::onRunStarted);
  connect(worker_, &SimulationWorker::meshErrorEstimated, this,
          &SimulationController::onMeshError);
  connect(worker_, &SimulationWorker::runProgress, this, &SimulationController::runProgress);
  connect(worker_, &SimulationWorker::fitFinished, this, &SimulationController::onFitFinished);
  connect(worker_, &SimulationWorker::runFinished, this, &SimulationController::onRunFinished);
  connect(worker_, &SimulationWorker::exported, this,
          [this](const QString& path) { emit exportFinished(path, true, QString()); });
  connect(worker_, &SimulationWorker::exportFailed, this,
          [this](const QString& path, const QString& message) {
            emit exportFinished(path, false, message);
          });
  thread_.start();
}

SimulationController::~SimulationController() {
  worker_->stop();
  thread_.quit();
  thread_.wait();
  delete worker_;  // its thread has finished: nothing runs in it any more
}

double SimulationController::meanCellSize() const {
  return latest_.empty() ? 0.0 : latest_.geometry->meanCellSize;
}

bool SimulationController::idle() const { return !busy_ && !running_ && !worker_->hasWork(); }

void SimulationController::loadTissue(const QString& path) {
  cancelRun();  // a running curve would hold the new tissue back
  // A new tissue starts without sites; its curves stay on the plot for comparison.
  pendingSites_.clear();
  pendingCurrentSite_ = -1;
  worker_->requestLoad(path, params_, SiteRequest{});
}

void SimulationController::setParams(const SimulationParams& params) {
  if (params == params_) return;
  params_ = params;
  SiteRequest site;
  site.kind = SiteRequest::Kind::Current;  // whatever site the worker has when it gets there
  if (!latest_.empty()) worker_->requestPrepare(params_, site);
}

void SimulationController::setSchedule(const Schedule& schedule) {
  schedule_ = schedule;
}

void SimulationController::pickSite(int generation, int triangle,
                                    const Eigen::Vector3d& barycentric) {
  if (running_ || latest_.empty()) return;
  // The material point under the click, by the rest positions of the geometry clicked on; a
  // click on a geometry replaced since (a slow click while the mesh was refined) is dropped.
  const TissueGeometry& g = *latest_.geometry;
  if (generation != g.generation || triangle < 0 || triangle >= g.triangleCount()) return;
  SiteRequest site;
  site.kind = SiteRequest::Kind::Rest;
  for (int k = 0; k < 3; ++k) {
    const std::uint32_t v = g.triangles[3 * triangle + k];
    site.point += barycentric[k] * Eigen::Vector3d(g.rest[3 * v], g.rest[3 * v + 1], g.rest[3 * v + 2]);
  }
  worker_->requestPrepare(params_, site);
}

void SimulationController::requestDepth(double depth) {
  depth = std::max(0.0, depth);
  if (running_ || !prepared()) return;
  requestedDepth_ = depth;
  worker_->requestDepth(depth);
}

void SimulationController::setRequestedDepth(double depth) {
  if (depth == requestedDepth_) return;
  requestedDepth_ = depth;
  emit requestedDepthChanged(depth);
}

void SimulationController::runCurve() {
  if (running_ || !prepared()) return;
  running_ = true;
  emit runningChanged(true);
  worker_->requestRun(schedule_);
}

void SimulationController::cancelRun() {
  if (running_ || fitting_) worker_->cancel();
}

bool SimulationController::fitMeasuredCurves(bool E, bool p, bool h, bool offset, QString* why) {
  auto refuse = [&](const QString& m) {
    if (why) *why = m;
    return false;
  };
  if (fitting_ || running_) return refuse(tr("a curve or a fit is running"));
  if (!prepared()) return refuse(tr("no site is prepared yet"));
  if (!E && !p && !h && !offset) return refuse(tr("choose at least one value to fit"));
  FitSettings fs;
  fs.start = params_.experimentSettings();
  // The site: the current one as a material point (the worker sets it: it knows that point);
  // the axis: the inward normal there in the starting values' turgid state (experiment/Fit.h).
  fs.fitE = E;
  fs.fitP = p;
  fs.fitH = h;
  fs.fitOffset = offset;
  std::vector<FitCurve> data;
  for (const NamedCurve& c : curves_) {
    if (!c.measured) continue;
    FitCurve f;
    f.data.name = c.name;
    for (const CurvePoint& pt : c.points) {
      f.data.depth.push_back(pt.depth);
      f.data.force.push_back(pt.force);
    }
    data.push_back(std::move(f));
  }
  if (data.empty()) return refuse(tr("no measured curve: import one first (File ▸ Import measured curve)"));
  fitting_ = true;
  emit runningChanged(true);  // the curve panel's Cancel stops the fit too
  worker_->requestFit(fs, data);
  return true;
}

void SimulationController::onFitFinished(const FitOutcome& outcome) {
  fitting_ = false;
  emit runningChanged(false);
  if (outcome.ok && outcome.result) {
    const FitResult& r = *outcome.result;
    // The simulated curves at the fitted values, at the measured depths used.
    auto text = [](const FitValue* v) {
      return v->fitted ? QString("%1 %2 ± %3 %4")
                             .arg(QString::fromStdString(v->key))
                             .arg(v->value, 0, 'g', 4)
                             .arg(v->error, 0, 'g', 2)
                             .arg(QString::fromStdString(v->unit))
                       : QString("%1 %2 %3 (held)")
                             .arg(QString::fromStdString(v->key))
                             .arg(v->value, 0, 'g', 4)
                             .arg(QString::fromStdString(v->unit));
    };
    const QString values = text(r.find("E")) + ", " + text(r.find("p"));
    for (size_t i = 0; i < r.curves.size(); ++i) {
      NamedCurve c;
      c.name = tr("fit · %1").arg(values).toStdString();
      c.site = latest_.site;
      c.params = params_;
      c.params.youngModulus = r.find("E")->value;
      c.params.pressure = r.find("p")->value;
      c.params.thickness = r.find("h")->value;
      for (size_t k = 0; k < r.curves[i].depth.size(); ++k) {
        c.points.push_back(
            CurvePoint{r.curves[i].depth[k], r.curves[i].simulated[k], 0, 0.0, true, false});
        c.residuals.push_back(r.curves[i].measured[k] - r.curves[i].simulated[k]);
      }
      c.meshLevel = r.curves[i].meshLevel;
      if (r.curves[i].meshError.estimated() && !r.curves[i].depth.empty()) {
        // Of the force at the deepest point, at the fitted values, on the mesh the fit ended on.
        c.meshError = r.curves[i].meshError.relative;
        c.meshErrorAt = r.curves[i].depth.back();
        c.meshErrorForce = false;
        c.meshErrorMethod = r.curves[i].meshError.method + " (at the fitted values)";
      }
      c.colour = nextColour_++;
      curves_.push_back(std::move(c));
    }
    unsaved_ = true;
    emit curvesChanged();
  }
  emit fitFinished(outcome);
}

void SimulationController::exportVtu(const QString& path) {
  worker_->requestExportVtu(path);
}

void SimulationController::addMeasuredCurve(NamedCurve curve) {
  curve.measured = true;
  curve.live = false;
  curve.params = params_;  // its nondimensional axes take the current E
  curve.colour = nextColour_++;
  curve.preparation = -1;
  curves_.push_back(std::move(curve));
  unsaved_ = true;
  emit curvesChanged();
}

void SimulationController::addSimulatedCurve(NamedCurve curve) {
  curve.measured = false;
  curve.live = false;
  curve.colour = nextColour_++;
  curve.preparation = -1;
  curves_.push_back(std::move(curve));
  unsaved_ = true;
  emit curvesChanged();
}

void SimulationController::removeCurve(int index) {
  if (index < 0 || index >= static_cast<int>(curves_.size())) return;
  curves_.erase(curves_.begin() + index);
  auto shift = [index](int& i) { i = i == index ? -1 : i > index ? i - 1 : i; };
  shift(liveCurve_);
  shift(runCurve_);
  shift(lastRunCurve_);
  emit curvesChanged();
}

int SimulationController::siteOfCurve(int k) const {
  if (k < 0 || k >= static_cast<int>(curves_.size()) || curves_[k].measured) return -1;
  int best = -1;
  double bestDistance = 2.0;  // µm: farther, the curve is of a site not in the list
  for (size_t i = 0; i < sites_.size(); ++i) {
    const double d = (sites_[i] - curves_[k].site).norm();
    if (d < bestDistance) bestDistance = d, best = static_cast<int>(i);
  }
  return best;
}

void SimulationController::clearCurves() {
  curves_.clear();
  nextColour_ = 0;
  unsaved_ = false;
  liveCurve_ = runCurve_ = lastRunCurve_ = -1;
  emit curvesChanged();
}

void SimulationController::recordSite(const Eigen::Vector3d& site, bool isNew) {
  // A new site (a pick, a load) is added; a preparation at the current one (new parameters, a
  // session) only updates its point, which moves a little with the turgid state.
  if (isNew || currentSite_ < 0) {
    sites_.push_back(site);
    currentSite_ = static_cast<int>(sites_.size()) - 1;
  } else {
    sites_[currentSite_] = site;
  }
  emit sitesChanged();
}

void SimulationController::onSnapshot(const Snapshot& s) {
  // The equilibrium shown before this one, of the same preparation: where a drag that begins
  // now starts from (a run's last point, say).
  CurvePoint before{0.0, 0.0, 0, 0.0, true, false};  // else first contact
  if (latest_.phase == Snapshot::Phase::Equilibrium && latest_.preparation == s.preparation &&
      latest_.point)
    before = *latest_.point;
  latest_ = s;
  ++snapshotCount_;
  if (s.phase == Snapshot::Phase::Prepared && s.preparation != lastPreparation_) {
    lastPreparation_ = s.preparation;
    recordSite(s.site, s.newSite);
    liveCurve_ = -1;  // the next drag starts a new curve
    setRequestedDepth(0.0);
  }
  if (s.point && s.phase == Snapshot::Phase::Equilibrium) {
    int& index = s.fromRun ? runCurve_ : liveCurve_;
    if (!s.fromRun && index < 0) {
      NamedCurve c;
      c.site = s.site;
      c.params = s.params;
      c.live = true;
      c.preparation = s.preparation;
      c.meshLevel = s.geometry ? s.geometry->meshLevel : -1;
      c.name = uniqueName(curveName(currentSite_ + 1, s.site, s.params, true));
      // Its first point is the state it starts from: first contact after a site is prepared,
      // or where a run ended (not the origin, which such a drag never passed through: its
      // curve was drawn with a straight line from there).
      c.points.push_back(before);
      c.colour = nextColour_++;
      curves_.push_back(std::move(c));
      index = static_cast<int>(curves_.size()) - 1;
    }
    if (index >= 0) {
      curves_[index].points.push_back(*s.point);
      unsaved_ = true;
      emit curvesChanged();
    }
  }
  emit snapshotReady(s);
}

std::string SimulationController::uniqueName(const std::string& base) const {
  // Curves are told apart by name (legend, CSV): a repeat gets " (2)", " (3)", …
  auto taken = [this](const std::string& n) {
    return std::any_of(curves_.begin(), curves_.end(), [&](const auto& c) { return c.name == n; });
  };
  std::string name = base;
  for (int k = 2; taken(name); ++k) name = base + " (" + std::to_string(k) + ")";
  return name;
}

void SimulationController::onRunStarted(int, bool rerun) {
  NamedCurve c;
  c.site = latest_.site;
  c.params = latest_.params;
  c.preparation = latest_.preparation;
  c.meshLevel = latest_.geometry ? latest_.geometry->meshLevel : -1;
  unsaved_ = true;
  // A run again on a finer mesh replaces the one whose error was above the tolerance, in its
  // place: it keeps its name, colour and position in the list (and so any selection of it).
  if (rerun && lastRunCurve_ >= 0 && lastRunCurve_ < static_cast<int>(curves_.size())) {
    NamedCurve& old = curves_[lastRunCurve_];
    c.name = std::move(old.name);
    c.colour = old.colour;
    old = std::move(c);
    runCurve_ = lastRunCurve_;
    emit curvesChanged();
    return;
  }
  c.name = uniqueName(curveName(currentSite_ + 1, latest_.site, latest_.params, false));
  c.colour = nextColour_++;
  curves_.push_back(std::move(c));
  runCurve_ = lastRunCurve_ = static_cast<int>(curves_.size()) - 1;
  emit curvesChanged();
}

void SimulationController::onMeshError(const MeshErrorReport& r) {
  // The curve it belongs to: the last run, or the drag curve, of that preparation.
  int index = -1;
  for (int i = static_cast<int>(curves_.size()) - 1; i >= 0 && index < 0; --i)
    if (curves_[i].preparation == r.preparation && curves_[i].live != r.run) index = i;
  if (index >= 0) {
    NamedCurve& c = curves_[index];
    c.meshLevel = r.level;
    c.meshError = r.relative;
    c.meshErrorAt = r.at;
    c.meshErrorForce = r.force;
    c.meshErrorMethod = r.method;
    emit curvesChanged();
  }
  QString text = r.relative >= 0
                     ? tr("Mesh level %1: estimated discretisation error ±%2 % at %3 %4")
                           .arg(r.level)
                           .arg(100 * r.relative, 0, 'g', 2)
                           .arg(r.at)
                           .arg(r.force ? tr("µN") : tr("µm"))
                     : tr("Mesh level %1: the discretisation error could not be estimated (%2)")
                           .arg(r.level)
                           .arg(QString::fromStdString(r.method));
  if (r.relative > params_.meshTolerance && params_.autoMesh)
    text += tr(" — above the %1 % asked").arg(100 * params_.meshTolerance, 0, 'g', 2);
  emit meshErrorChanged(text);
}

void SimulationController::onRunFinished(bool completed) {
  running_ = false;
  runCurve_ = -1;
  liveCurve_ = -1;       // a drag after a run starts its own curve
  requestedDepth_ = -1;  // force the notification
  setRequestedDepth(latest_.depth);
  emit runningChanged(false);
  emit statusMessage(completed ? tr("Curve finished") : tr("Curve stopped"));
}

SessionState SimulationController::session() const {
  SessionState s;
  s.tissuePath = tissuePath_.toStdString();
  s.params = params_;
  s.schedule = schedule_;
  s.sites = sites_;
  s.currentSite = currentSite_;
  s.curves = curves_;
  return s;
}

void SimulationController::applySession(const SessionState& session) {
  cancelRun();
  params_ = session.params;
  schedule_ = session.schedule;
  curves_ = session.curves;
  nextColour_ = 0;
  for (auto& c : curves_) c.colour = nextColour_++;
  unsaved_ = false;  // as saved
  liveCurve_ = runCurve_ = lastRunCurve_ = -1;
  pendingSites_ = session.sites;
  pendingCurrentSite_ = session.currentSite;
  emit paramsChanged(params_);
  emit scheduleChanged(schedule_);
  emit curvesChanged();
  SiteRequest site;
  if (pendingCurrentSite_ >= 0) {
    site.kind = SiteRequest::Kind::Point;
    site.point = pendingSites_[pendingCurrentSite_];
  }
  worker_->requestLoad(QString::fromStdString(session.tissuePath), params_, site);
}

}  // namespace tp::gui
