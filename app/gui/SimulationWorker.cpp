#include "SimulationWorker.h"

#include <QMetaObject>
#include <QTimer>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <thread>
#include <exception>
#include <stdexcept>
#include <sstream>

#include "experiment/Drag.h"
#include "experiment/Stress.h"
#include "io/Paths.h"
#include "io/Ply.h"
#include "io/TissueFiles.h"
#include "io/Vtu.h"
#include "mesh/Quality.h"
#include "solver/CholmodSolver.h"

namespace tp::gui {

struct SimulationWorker::State {
  std::shared_ptr<const CellComplex> base;  // the tissue as loaded (unrefined)
  std::string path;
  double cellSize = 0;                      // µm, of the loaded tissue
  std::unique_ptr<Experiment> experiment;   // its rest state under turgor, the site
  std::unique_ptr<PreparedSite> site;       // the mesh at the site, its model and indentation
  std::shared_ptr<const TissueGeometry> geometry;
  SimulationParams params;
  Schedule schedule;
  int autoLevel = MeshSettings{}.level;  // the level the automatic mesh uses now
  int generation = 0;
  int preparation = 0;
  int depthSerial = 0;     // drag equilibria solved so far (an estimate waits for a pause)
  double liveDepth = 0;    // deepest equilibrium of the current drag (µm)
  double liveEstimated = -1;  // the depth its error was last estimated at
  DragFollower drag;          // the drag's step toward the depth asked (core/experiment/Drag.h)
  std::string meshStatus;
  mutable StressField turgidStress;  // at the turgid state of preparation turgidStressFor
  mutable int turgidStressFor = -1;

  bool prepared() const { return site && site->indentation && site->indentation->prepared(); }
  const CellComplex& complex() const { return site ? *site->complex : *base; }
  int level() const { return params.autoMesh ? autoLevel : params.meshLevel; }
};

namespace {

// Bits of request kinds (their index in the Request variant) for interruptibleBy_.
constexpr int kLoadBit = 1 << 0, kPrepareBit = 1 << 1, kDepthBit = 1 << 2, kRunBit = 1 << 3,
              kExportBit = 1 << 4, kEstimateBit = 1 << 5, kFitBit = 1 << 6;
constexpr int kAnything =
    kLoadBit | kPrepareBit | kDepthBit | kRunBit | kExportBit | kEstimateBit | kFitBit;

QString q(const std::string& s) {
  return QString::fromStdString(s);
}

std::vector<float> toFloats(const Points& x) {
  std::vector<float> out(static_cast<size_t>(x.size()));
  for (Eigen::Index i = 0; i < x.size(); ++i) out[i] = static_cast<float>(x.data()[i]);
  return out;
}

constexpr int kEstimateDelayMs = 800;     // a drag at rest this long gets its error estimated

// Per-triangle colour quantities of a state (experiment/Quantities.h).
void fillFields(const Model* model, const CellComplex& cc, const Points& x, const Points* turgid,
                const StressField* turgidStress, Snapshot& s) {
  std::optional<StressField> st;
  if (model) st = computeStress(*model, x);
  const QuantityInputs in{st ? &*st : nullptr, turgidStress, &cc, &x, turgid};
  const auto values = triangleQuantities(in);
  for (int q = 0; q < kFieldCount; ++q) s.fields[q].assign(values[q].begin(), values[q].end());
  s.principalAxes.clear();
  if (!st) return;
  // The largest principal stress of each triangle's Cauchy tensor read in its plane (basis e₁
  // along an edge, e₂ = n × e₁): σ₁ = (s₁₁+s₂₂)/2 + √(((s₁₁−s₂₂)/2)² + s₁₂²), along the angle
  // θ = ½ atan2(2 s₁₂, s₁₁ − s₂₂) from e₁ (Mohr's circle).
  const int T = cc.triangleCount();
  s.principalAxes.resize(3 * static_cast<size_t>(T));
  for (int t = 0; t < T; ++t) {
    const auto& tri = cc.triangles[t];
    const Vec3 a = x.col(tri[0]), b = x.col(tri[1]), c = x.col(tri[2]);
    Vec3 e1 = b - a, n = (b - a).cross(c - a);
    Vec3 axis = Vec3::Zero();
    if (e1.norm() > 0 && n.norm() > 0 && t < static_cast<int>(st->triangles.size())) {
      e1.normalize();
      n.normalize();
      const Vec3 e2 = n.cross(e1);
      const Mat3& sigma = st->triangles[t].cauchy;
      const double s11 = e1.dot(sigma * e1), s22 = e2.dot(sigma * e2),
                   s12 = 0.5 * (e1.dot(sigma * e2) + e2.dot(sigma * e1));
      const double s1 = 0.5 * (s11 + s22) + std::hypot(0.5 * (s11 - s22), s12);
      const double theta = 0.5 * std::atan2(2 * s12, s11 - s22);
      axis = s1 * (std::cos(theta) * e1 + std::sin(theta) * e2);
    }
    for (int k = 0; k < 3; ++k) s.principalAxes[3 * t + k] = static_cast<float>(axis[k]);
  }
}

std::string describePoint(const CurvePoint& p) {
  std::ostringstream st;
  st.precision(4);
  st << "depth " << p.depth << " µm, force " << p.force << " µN (" << p.iterations
     << " Newton iterations)";
  return st.str();
}

std::string percent(double relative) {
  std::ostringstream s;
  s.precision(relative < 0.1 ? 2 : 3);
  s << 100 * relative << " %";
  return s.str();
}

// "mesh level 3", with "(automatic)" and the junction band when asked for.
std::string meshLevelText(int level, bool automatic, bool band) {
  std::string s = "mesh level " + std::to_string(level);
  if (automatic || band)
    s += std::string(" (") + (automatic ? "automatic" : "") + (automatic && band ? ", " : "") +
         (band ? "junction band" : "") + ")";
  return s;
}

}  // namespace

SimulationWorker::SimulationWorker() : s_(std::make_unique<State>()) {
  qRegisterMetaType<tp::gui::MeshErrorReport>();
  qRegisterMetaType<tp::gui::FitOutcome>();
}
SimulationWorker::~SimulationWorker() = default;

void SimulationWorker::requestLoad(const QString& path, const SimulationParams& params,
                                   const SiteRequest& site) {
  enqueue(Load{path, params, site});
}

void SimulationWorker::requestPrepare(const SimulationParams& params, const SiteRequest& site) {
  enqueue(Prepare{params, site});
}

void SimulationWorker::requestDepth(double depth) {
  enqueue(Depth{depth});
}

std::uint64_t SimulationWorker::cancelsSoFar() {
  std::lock_guard lock(mutex_);
  return cancels_;
}

void SimulationWorker::requestRun(const Schedule& schedule) {
  enqueue(Run{schedule, cancelsSoFar()});  // a Cancel after this request stops the run
}

void SimulationWorker::requestExportVtu(const QString& path) {
  enqueue(ExportVtu{path});
}

void SimulationWorker::requestFit(const tp::FitSettings& settings,
                                  const std::vector<tp::FitCurve>& curves) {
  enqueue(Fit{settings, curves, cancelsSoFar()});  // as for a run
}

void SimulationWorker::stop() {
  stopping_ = true;
  stop_ = true;
  std::lock_guard lock(mutex_);
  queue_.clear();
}

void SimulationWorker::enqueue(Request r) {
  bool post = false;
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    // Coalesce: a newer depth or preparation replaces the same kind waiting at the tail. New
    // parameters "at the current site" keep the site of the preparation they replace (a pick
    // not yet handled).
    const bool coalesce = !queue_.empty() && queue_.back().index() == r.index() &&
                          (std::holds_alternative<Depth>(r) || std::holds_alternative<Prepare>(r));
    if (coalesce) {
      if (auto* p = std::get_if<Prepare>(&r); p && p->site.kind == SiteRequest::Kind::Current)
        p->site = std::get<Prepare>(queue_.back()).site;
      queue_.back() = std::move(r);
    } else {
      queue_.push_back(std::move(r));
    }
    // The task in hand gives way if this request may stop it (an interruption, not a Cancel:
    // the next task must not inherit it).
    if (interruptibleBy_ & (1 << queue_.back().index())) stop_ = true;
    post = !scheduled_;
    scheduled_ = true;
  }
  if (post) QMetaObject::invokeMethod(this, &SimulationWorker::processNext, Qt::QueuedConnection);
}

namespace {

// The worker's threads: every core but the one left to the drawing.
int solverThreads() {
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()) - 1);
}

}  // namespace

void SimulationWorker::processNext() {
  // The solver shares the machine with the drawing. Under a software renderer (Mesa llvmpipe)
  // both want every core, and a parallel region whose second thread is descheduled waits at its
  // barrier: dragging on the default meristem at level 3 under Xvfb gave 0.05 equilibria/s with
  // two solver threads and 0.4 with one. The worker leaves one core to the drawing (and the
  // drawing keeps to one: leaveTheSolverItsCores).
  static thread_local const bool threadsSet = [] {
    omp_set_num_threads(solverThreads());
    return true;
  }();
  (void)threadsSet;
  std::optional<Request> r;
  {
    std::lock_guard lock(mutex_);
    if (!queue_.empty()) {
      r = std::move(queue_.front());
      queue_.pop_front();
      // What may stop this task: a curve only by Cancel; a preparation by a newer site or
      // parameters; an estimate by anything.
      interruptibleBy_ = std::holds_alternative<Prepare>(*r) || std::holds_alternative<Load>(*r)
                             ? kLoadBit | kPrepareBit
                         : std::holds_alternative<EstimateLive>(*r) ? kAnything
                                                                    : 0;
      // A run or fit starts stopped if Cancel was pressed since its request (even while other
      // tasks ran in between: clearing the flag for them lost such a Cancel, a flaky
      // ControllerTest); anything else starts afresh, interruptions included.
      std::uint64_t asked = cancels_;
      if (const auto* run = std::get_if<Run>(&*r)) asked = run->cancelsAtRequest;
      if (const auto* fit = std::get_if<Fit>(&*r)) asked = fit->cancelsAtRequest;
      stop_ = asked != cancels_;
    }
  }
  if (r && !stopping_) {
    try {
      std::visit([this](const auto& req) { handle(req); }, *r);
    } catch (const Cancelled&) {
      // Stopped for a newer request: it follows in the queue.
    } catch (const std::exception& e) {
      if (dynamic_cast<const std::invalid_argument*>(&e)) emit refused(QString::fromUtf8(e.what()));
      emit failed(QString::fromUtf8(e.what()));
    }
  }
  bool more = false;
  {
    std::lock_guard lock(mutex_);
    interruptibleBy_ = 0;
    more = !queue_.empty() && !stopping_;
    scheduled_ = more;
  }
  // One request per event, so the thread can still be told to quit between requests.
  if (more)
    QMetaObject::invokeMethod(this, &SimulationWorker::processNext, Qt::QueuedConnection);
  else
    emit idle();
}

void SimulationWorker::handle(const Load& r) {
  std::string path;
  try {
    path = r.path.isEmpty() ? defaultTissuePath() : r.path.toStdString();
  } catch (const std::exception& e) {
    emit loadFailed(r.path, QString::fromUtf8(e.what()));
    return;
  }
  emit busy(tr("Reading %1…").arg(q(path)));
  CellComplex cc;
  try {  // the same reading and checks as the command line: a valid tissue that can be simulated
    cc = readSimulationTissue(path);
  } catch (const std::exception& e) {  // names the file, and the line or the problem
    emit loadFailed(q(path), QString::fromUtf8(e.what()));
    return;
  }
  // The new tissue replaces the old one only now that it is known to be good.
  auto base = std::make_shared<const CellComplex>(std::move(cc));
  s_->site.reset();
  s_->experiment.reset();
  s_->base = base;
  s_->path = path;
  s_->cellSize = meanCellSize(*base);
  s_->geometry = makeTissueGeometry(*base, ++s_->generation, path, s_->cellSize);
  s_->params = r.params;
  s_->autoLevel = MeshSettings{}.level;
  emit loaded(q(path), tr("%1 cells, %2 vertices, %3 triangles")
                           .arg(base->cellCount())
                           .arg(base->vertexCount())
                           .arg(base->triangleCount()));
  emit snapshotReady(snapshot(Snapshot::Phase::Rest));
  SiteRequest site = r.site;
  if (site.kind != SiteRequest::Kind::Point) site.kind = SiteRequest::Kind::Top;
  prepare(r.params, site, site.kind == SiteRequest::Kind::Top);
}

void SimulationWorker::handle(const Prepare& r) {
  if (!s_->base) return;
  const SiteRequest& site = r.site;
  const bool newSite = site.kind == SiteRequest::Kind::Rest || site.kind == SiteRequest::Kind::Top;
  prepare(r.params, site, newSite);
}

bool SimulationWorker::prepare(const SimulationParams& params, const SiteRequest& request,
                               bool newSite, bool keepLevel) {
  State& s = *s_;
  // Refining to run a curve again is the same experiment one level finer: its settings (site,
  // schedule) stay as they are, so the end values it knows at other levels stay valid for the
  // error of the finer run (Experiment::curveError).
  const bool finer = keepLevel && s.experiment;
  ExperimentSettings settings = finer ? s.experiment->settings() : params.experimentSettings();
  if (!finer) {
    switch (request.kind) {
      case SiteRequest::Kind::Top:
        break;
      case SiteRequest::Kind::Point:
        settings.indentation.site = request.point;
        break;
      case SiteRequest::Kind::Current:
        if (s.experiment && s.experiment->basePrepared())
          settings.indentation.restSite = s.experiment->restSite();
        break;
      case SiteRequest::Kind::Rest:
        settings.indentation.restSite = request.point;
        break;
    }
  }
  // The automatic mesh starts again from its first level for a new site or new parameters; it
  // keeps the level it has reached when it refines to run a curve again.
  if (!keepLevel) s.autoLevel = MeshSettings{}.level;
  settings.mesh.level = params.autoMesh ? s.autoLevel : params.meshLevel;
  const int level = settings.mesh.level;
  Monitor monitor;
  monitor.cancel = &stop_;
  monitor.stage = [this](const std::string& what) { emit busy(q(what)); };
  std::unique_ptr<PreparedSite> site;
  try {
    settings.validate();
    if (!s.experiment) {
      s.experiment = std::make_unique<Experiment>(s.base, settings);
      // A pick has the view still: the core left to the drawing helps prepare the site.
      s.experiment->setSpareCore(std::thread::hardware_concurrency() > 1);
    } else
      s.experiment->setSettings(settings);
    site = s.experiment->prepareSite(level, monitor);
  } catch (const Cancelled&) {
    throw;
  } catch (const std::exception& e) {
    if (dynamic_cast<const std::invalid_argument*>(&e)) emit refused(QString::fromUtf8(e.what()));
    emit failed(
        tr("Preparation failed, the previous state is kept: %1").arg(QString::fromUtf8(e.what())));
    return false;
  }
  // Success: the new state replaces the old one.
  s.site = std::move(site);
  s.params = params;
  s.geometry = makeTissueGeometry(*s.site->complex, ++s.generation, s.path, s.cellSize, level);
  ++s.preparation;
  s.liveDepth = 0;
  s.liveEstimated = -1;
  s.drag.reset();
  std::ostringstream mesh;
  mesh << meshLevelText(level, params.autoMesh, junctionBandApplies(params.experimentSettings()))
       << ": " << s.site->complex->vertexCount() << " vertices; error not yet estimated";
  s.meshStatus = mesh.str();
  Snapshot snap = snapshot(Snapshot::Phase::Prepared);
  snap.point = CurvePoint{0.0, 0.0, 0, 0.0, true, false};
  snap.newSite = newSite;
  std::ostringstream st;
  st.precision(3);
  st << "turgid, probe touching (ready in " << s.site->seconds << " s)";
  snap.status = st.str();
  emit snapshotReady(snap);
  return true;
}

void SimulationWorker::handle(const Depth& r) {
  if (!s_->prepared()) return;
  // A drag's factorisations keep to the solver's cores in BLAS too: OpenBLAS's other threads
  // spin after each factorisation, on the core the drawing uses while the probe moves. A drag
  // under Xvfb (TP_GUI_MEASURE=1 … dragRatesOnTheDefaultMeristem, 2-core VM, builds
  // alternated) went 7.19–10.84 → 9.45–11.89 equilibria/s, faster in 5 of 5 pairs (medians 9.85
  // → 10.80). Other tasks (a pick, a curve) run while the view is still and keep every BLAS
  // thread.
  const CholmodSolver::BlasThreadCap blasCap(solverThreads());
  emit busy(tr("Solving at depth %1 µm…").arg(r.depth, 0, 'f', 3));
  // One equilibrium a bounded step toward the depth asked (core/experiment/Drag.h); the rest of
  // the way is the next request, unless a newer depth (the cursor's) has arrived.
  Indentation& ind = *s_->site->indentation;
  const DragStep step = s_->drag.toward(ind, r.depth);
  const CurvePoint& pt = step.point;
  if (step.more) {
    bool newer;
    {
      std::lock_guard lock(mutex_);
      newer = !queue_.empty();  // a newer request comes first
    }
    if (!newer) enqueue(Depth{r.depth});
  }
  if (step.failed()) {
    emit failed(q(ind.lastMessage()));
    return;
  }
  if (!pt.converged) return;  // tried again with a smaller step
  s_->liveDepth = std::max(s_->liveDepth, pt.depth);
  Snapshot snap = snapshot(Snapshot::Phase::Equilibrium);
  snap.point = pt;
  snap.force = pt.force;
  snap.status = describePoint(pt);
  emit snapshotReady(snap);
  // When the drag rests (no other depth solved for kEstimateDelayMs), estimate the error of
  // its deepest point. An empty queue is not enough: the view sends the next depth only when
  // this equilibrium is back, so during a drag the queue is empty most of the time, and an
  // estimate started then (a finer mesh, seconds) would hold up every drag step.
  const int preparation = s_->preparation;
  const int serial = ++s_->depthSerial;
  QTimer::singleShot(kEstimateDelayMs, this, [this, preparation, serial] {
    if (serial != s_->depthSerial) return;  // still dragging: the last depth schedules it again
    {
      std::lock_guard lock(mutex_);
      if (!queue_.empty()) return;
    }
    enqueue(EstimateLive{preparation});
  });
}

void SimulationWorker::handle(const EstimateLive& r) {
  State& s = *s_;
  if (!s.prepared() || r.preparation != s.preparation || !(s.liveDepth > 0) ||
      s.liveDepth == s.liveEstimated)
    return;
  ExperimentSettings settings = s.experiment->settings();
  settings.indentation.control = Control::Depth;
  settings.indentation.maxDepth = s.liveDepth;
  s.experiment->setSettings(settings);
  Monitor monitor;
  monitor.cancel = &stop_;
  monitor.stage = [this](const std::string& what) { emit busy(q(what)); };
  // The drag's deepest point at this level: solved again here only if the probe has moved on.
  Indentation& ind = *s.site->indentation;
  const double depthNow = ind.depth();
  ind.solver().setCancelFlag(&stop_);
  const CurvePoint deepest = ind.goToDepth(s.liveDepth);
  ind.solver().setCancelFlag(nullptr);
  if (!deepest.converged) return;
  const MeshError e = s.experiment->estimateError(s.site->level, deepest.force, monitor);
  if (depthNow != s.liveDepth) ind.goToDepth(depthNow);
  s.liveEstimated = s.liveDepth;
  MeshErrorReport report;
  report.preparation = s.preparation;
  report.run = false;
  report.level = s.site->level;
  report.at = s.liveDepth;
  report.relative = e.relative;
  report.method = e.method;
  std::ostringstream st;
  st << meshLevelText(s.site->level, false, junctionBandApplies(s.params.experimentSettings()))
     << ": error " << (e.estimated() ? "±" + percent(e.relative) : "not estimated") << " at "
     << s.liveDepth << " µm";
  if (e.estimated() && s.params.autoMesh && e.relative > s.params.meshTolerance)
    st << " (above the " << percent(s.params.meshTolerance)
       << " asked: run a curve to refine automatically)";
  s.meshStatus = st.str();
  emit meshErrorEstimated(report);
}

void SimulationWorker::handle(const Run& r) {
  // Whatever happens, the controller hears that the run is over (it disables controls meanwhile).
  bool completed = false;
  try {
    s_->schedule = r.schedule;
    completed = runSchedule(r.schedule, false);
  } catch (const Cancelled&) {
  } catch (const std::exception& e) {
    if (dynamic_cast<const std::invalid_argument*>(&e)) emit refused(QString::fromUtf8(e.what()));
    emit failed(QString::fromUtf8(e.what()));
  }
  emit runFinished(completed);
}

bool SimulationWorker::runSchedule(const Schedule& sc, bool rerun) {
  State& s = *s_;
  if (!s.prepared()) {
    emit failed(tr("Nothing to run: the indentation is not prepared"));
    return false;
  }
  // The schedule is part of the experiment's settings (the end value the error is judged at).
  ExperimentSettings settings = s.experiment->settings();
  IndentationSettings& is = settings.indentation;
  is.control = sc.control;
  is.maxDepth = sc.maxDepth;
  is.maxForce = sc.maxForce;
  is.steps = sc.steps;
  is.unload = sc.unload;
  s.experiment->setSettings(settings);
  s.site->indentation->setSchedule(is);
  const int total = static_cast<int>(scheduleTargets(is).size());
  emit runStarted(total, rerun);
  emit busy(tr("Running the curve (mesh level %1)…").arg(s.site->level));
  Indentation& ind = *s.site->indentation;
  bool first = true;
  const auto curve = ind.run(
      [&](const CurvePoint& pt, int done, int all) {
        if (first) {  // depth 0 (the run starts from first contact)
          Snapshot start = snapshot(Snapshot::Phase::Equilibrium);
          start.point = CurvePoint{0.0, 0.0, 0, 0.0, true, false};
          start.fromRun = true;
          emit snapshotReady(start);
          first = false;
        }
        Snapshot snap = snapshot(Snapshot::Phase::Equilibrium);
        snap.point = pt;
        snap.force = pt.force;
        snap.status = describePoint(pt);
        snap.fromRun = true;
        if (pt.converged) emit snapshotReady(snap);
        emit runProgress(done, all);
        emit busy(tr("Running the curve (mesh level %1): point %2 of %3…")
                      .arg(s.site->level)
                      .arg(done)
                      .arg(all));
      },
      &stop_);
  if (stop_) return false;
  if (curve.size() != static_cast<size_t>(total) + 1 || !curve.back().converged) {
    emit failed(q(ind.lastMessage()));
    return false;
  }
  // Its discretisation error at the deepest point: from the next finer level, or (the automatic
  // mesh refining again) from the level run before when that is within tolerance.
  const bool force = sc.control == Control::Force;
  const CurvePoint& end = curve[sc.steps];
  Monitor monitor;
  monitor.cancel = &stop_;
  monitor.stage = [this](const std::string& what) { emit busy(q(what)); };
  const double value = force ? end.depth : end.force;
  const MeshError e = s.experiment->curveError(s.site->level, value, monitor);
  MeshErrorReport report;
  report.preparation = s.preparation;
  report.run = true;
  report.level = s.site->level;
  report.at = force ? sc.maxForce : sc.maxDepth;
  report.force = force;
  report.relative = e.relative;
  report.method = e.method;
  emit meshErrorEstimated(report);
  std::ostringstream st;
  st << meshLevelText(s.site->level, false, junctionBandApplies(s.params.experimentSettings()))
     << ": error " << (e.estimated() ? "±" + percent(e.relative) : "not estimated") << " at "
     << report.at << (force ? " µN" : " µm");
  s.meshStatus = st.str();
  const MeshSettings mesh = s.experiment->settings().mesh;
  if (s.params.autoMesh && e.estimated() && e.relative > s.params.meshTolerance &&
      s.site->level < mesh.maxLevel) {
    // Not converged to the tolerance: one level finer, same site, and the curve again.
    s.autoLevel = s.site->level + 1;
    emit busy(tr("Estimated error %1 is above the %2 asked: refining to level %3…")
                  .arg(q(percent(e.relative)), q(percent(s.params.meshTolerance)))
                  .arg(s.autoLevel));
    SiteRequest here;
    here.kind = SiteRequest::Kind::Current;
    if (!prepare(s.params, here, false, true)) return false;
    return runSchedule(sc, true);
  }
  return true;
}

void SimulationWorker::handle(const ExportVtu& r) {
  if (!s_->base) {
    emit exportFailed(r.path, tr("no tissue is loaded"));
    return;
  }
  emit busy(tr("Writing %1…").arg(r.path));
  try {
    const State& s = *s_;
    const CellComplex& cc = s.complex();
    if (s.prepared()) {
      const Indentation& ind = *s.site->indentation;
      const StateFields f = stateFields(*s.site->model, ind.state(), ind.turgidState());
      writeVtu(r.path.toStdString(), cc, ind.state(), f.points, f.triangles);
    } else {
      writeVtu(r.path.toStdString(), cc, cc.rest);
    }
    emit exported(r.path);
  } catch (const std::exception& e) {
    emit exportFailed(r.path, QString::fromUtf8(e.what()));
  }
}

void SimulationWorker::handle(const Fit& r) {
  FitOutcome out;
  if (!s_->base) {
    out.message = tr("no tissue is loaded");
    emit fitFinished(out);
    return;
  }
  emit busy(tr("Fitting…"));
  // A fit's length is not known in advance (Levenberg-Marquardt stops when it converges): the
  // progress bar runs as busy (range 0-0) and is full when the fit is done, empty if not.
  emit runProgress(0, 0);
  Monitor monitor;
  monitor.cancel = &stop_;
  monitor.stage = [this](const std::string& what) { emit busy(q(what)); };
  // The prepared site as the material point it is (its rest position), as the rest of the
  // application keeps it across parameters, not the point in space it occupies at the starting
  // values: a site held in space slides over the surface as E and p change the turgid shape.
  // From E 130, p 0.6 on a level-3 curve made at the top at 100, 0.8 the fit gave E 122.7,
  // p 0.744 with the site held in space (as `tissueprobe-cli fit --site` with that point does),
  // 98.9, 0.807 with the material point.
  tp::FitSettings settings = r.settings;
  if (s_->experiment && s_->experiment->basePrepared()) {
    settings.start.indentation.site.reset();
    settings.start.indentation.restSite = s_->experiment->restSite();
  }
  try {
    out.result = std::make_shared<const FitResult>(fitCurves(s_->base, settings, r.curves, monitor));
    out.ok = true;
    out.message = q(out.result->message);
  } catch (const Cancelled&) {
    out.message = tr("the fit was cancelled");
  } catch (const std::exception& e) {
    out.message = QString::fromUtf8(e.what());
  }
  emit runProgress(out.ok ? 1 : 0, 1);
  emit fitFinished(out);
}

Snapshot SimulationWorker::snapshot(Snapshot::Phase phase) const {
  const State& s = *s_;
  Snapshot snap;
  snap.geometry = s.geometry;
  snap.phase = phase;
  snap.params = s.params;
  snap.preparation = s.preparation;
  const bool prepared = s.prepared();
  const CellComplex& cc = s.complex();
  const Points& x = prepared ? s.site->indentation->state() : cc.rest;
  snap.positions = toFloats(x);
  if (prepared) snap.turgidPositions = toFloats(s.site->indentation->turgidState());
  const StressField* turgidStress = nullptr;
  if (prepared) {
    // The turgid state's stress, once per preparation (the "change from turgid" quantities).
    if (s.turgidStressFor != s.preparation) {
      s.turgidStress = computeStress(*s.site->model, s.site->indentation->turgidState());
      s.turgidStressFor = s.preparation;
    }
    turgidStress = &s.turgidStress;
  }
  fillFields(prepared ? s.site->model.get() : nullptr, cc, x,
             prepared ? &s.site->indentation->turgidState() : nullptr, turgidStress, snap);
  snap.cellVolumes = cellVolumes(cc, x);
  if (prepared) {
    const Indentation& ind = *s.site->indentation;
    const ProbePlacement& pl = ind.placement();
    snap.probeVisible = true;
    snap.site = pl.site;
    snap.axis = pl.axis;
    snap.contactCenter = pl.contactCenter;
    snap.probeRadius = ind.settings().probeRadius;
    snap.depth = ind.depth();
    snap.contactTriangles = s.site->model->touchedTriangles(x);
  }
  snap.status = !prepared ? "at rest (not under pressure)" : "turgid, probe touching";
  snap.meshStatus = s.meshStatus;
  return snap;
}

}  // namespace tp::gui
