#include "SimulationWorker.h"

#include <QMetaObject>

#include <cmath>
#include <exception>
#include <sstream>

#include "Preparation.h"
#include "experiment/Stress.h"
#include "io/Paths.h"
#include "io/Ply.h"
#include "io/Vtu.h"

namespace tp::gui {

struct SimulationWorker::State {
  std::shared_ptr<const CellComplex> base;  // the tissue as loaded (unrefined)
  std::string path;
  double cellSize = 0;                         // µm, of the loaded tissue
  std::shared_ptr<const CellComplex> complex;  // what is simulated (base or refined)
  std::shared_ptr<const TissueGeometry> geometry;
  // Declared in this order so that the Indentation (which holds a Model&) goes first.
  std::unique_ptr<Model> model;
  std::unique_ptr<Indentation> indentation;
  SimulationParams params;
  int generation = 0;
  int preparation = 0;

  bool prepared() const { return indentation && indentation->prepared(); }
};

namespace {

QString q(const std::string& s) {
  return QString::fromStdString(s);
}

std::vector<float> toFloats(const Points& x) {
  std::vector<float> out(static_cast<size_t>(x.size()));
  for (Eigen::Index i = 0; i < x.size(); ++i) out[i] = static_cast<float>(x.data()[i]);
  return out;
}

constexpr double kDragTolerance = 1e-7;  // relative residual of equilibria during a drag

// Per-triangle fields of a state: stress read-out and displacement from the turgid state.
void fillFields(const Model* model, const CellComplex& cc, const Points& x, const Points* turgid,
                Snapshot& s) {
  const int T = cc.triangleCount();
  for (auto& f : s.fields) f.assign(T, 0.0f);
  if (model) {
    const StressField st = computeStress(*model, x);
    for (int t = 0; t < T; ++t) {
      s.fields[int(Field::VonMises)][t] = float(st.triangles[t].vonMises);
      s.fields[int(Field::PrincipalMax)][t] = float(st.triangles[t].principalMax);
      s.fields[int(Field::EnergyDensity)][t] = float(st.triangles[t].energyDensity);
      s.fields[int(Field::BendingEnergyDensity)][t] = float(st.bendingEnergyDensity[t]);
    }
  }
  if (turgid && turgid->cols() == x.cols()) {
    // Mean of the corners' displacement magnitudes (µm).
    Eigen::VectorXd d = (x - *turgid).colwise().norm().transpose();
    for (int t = 0; t < T; ++t) {
      const auto& tri = cc.triangles[t];
      s.fields[int(Field::Displacement)][t] = float((d[tri[0]] + d[tri[1]] + d[tri[2]]) / 3.0);
    }
  }
}

std::string describePoint(const CurvePoint& p) {
  std::ostringstream st;
  st.precision(4);
  st << "depth " << p.depth << " µm, force " << p.force << " µN (" << p.iterations
     << " Newton iterations)";
  return st.str();
}

std::vector<VtuField> vtuTriangleFields(const StressField& st) {
  VtuField sigma{"cauchy_stress_MPa", 9, {}}, s1{"principal_max_MPa", 1, {}},
      s2{"principal_min_MPa", 1, {}}, vm{"von_mises_MPa", 1, {}},
      sed{"strain_energy_density_MPa", 1, {}}, bend{"bending_energy_density_MPa", 1, {}};
  for (size_t t = 0; t < st.triangles.size(); ++t) {
    const auto& ts = st.triangles[t];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) sigma.values.push_back(ts.cauchy(i, j));
    s1.values.push_back(ts.principalMax);
    s2.values.push_back(ts.principalMin);
    vm.values.push_back(ts.vonMises);
    sed.values.push_back(ts.energyDensity);
    bend.values.push_back(st.bendingEnergyDensity[t]);
  }
  return {sigma, s1, s2, vm, sed, bend};
}

}  // namespace

SimulationWorker::SimulationWorker() : s_(std::make_unique<State>()) {}
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

void SimulationWorker::requestRun(const Schedule& schedule) {
  cancel_ = false;  // here, not when the run starts: a cancel right after the request counts
  enqueue(Run{schedule});
}

void SimulationWorker::requestExportVtu(const QString& path) {
  enqueue(ExportVtu{path});
}

void SimulationWorker::stop() {
  stopping_ = true;
  cancel_ = true;
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
    post = !scheduled_;
    scheduled_ = true;
  }
  if (post) QMetaObject::invokeMethod(this, &SimulationWorker::processNext, Qt::QueuedConnection);
}

void SimulationWorker::processNext() {
  std::optional<Request> r;
  {
    std::lock_guard lock(mutex_);
    if (!queue_.empty()) {
      r = std::move(queue_.front());
      queue_.pop_front();
    }
  }
  if (r && !stopping_) {
    try {
      std::visit([this](const auto& req) { handle(req); }, *r);
    } catch (const std::exception& e) {
      emit failed(QString::fromUtf8(e.what()));
    }
  }
  bool more = false;
  {
    std::lock_guard lock(mutex_);
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
  try {
    cc = readPly(path);
  } catch (const std::exception& e) {  // PlyError names the file and the line
    emit loadFailed(q(path), QString::fromUtf8(e.what()));
    return;
  }
  const ValidityReport report = checkValidity(cc);
  if (!report.ok()) {
    emit loadFailed(q(path), tr("%1: not a valid tissue: %2").arg(q(path), q(report.summary())));
    return;
  }
  if (cc.triangleCount() == 0) {
    emit loadFailed(q(path), tr("%1: the file holds no faces").arg(q(path)));
    return;
  }
  // The new tissue replaces the old one only now that it is known to be good.
  auto base = std::make_shared<const CellComplex>(std::move(cc));
  s_->indentation.reset();
  s_->model.reset();
  s_->base = base;
  s_->complex = base;
  s_->path = path;
  s_->cellSize = meanCellSize(*base);
  s_->geometry = makeTissueGeometry(*base, ++s_->generation, path, s_->cellSize);
  s_->params = r.params;
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
  SiteRequest site = r.site;
  const bool newSite = site.kind == SiteRequest::Kind::Pick || site.kind == SiteRequest::Kind::Top;
  if (site.kind == SiteRequest::Kind::Current) {
    // The same material point: remember where it is in the rest state, since the new turgid
    // state (another pressure, modulus, …) moves it.
    site.kind = s_->prepared() ? SiteRequest::Kind::Point : SiteRequest::Kind::Top;
    if (s_->prepared()) {
      const ProbePlacement& pl = s_->indentation->placement();
      site.point = pl.site;
      site.restPoint =
          restPositionOf(*s_->model, s_->indentation->turgidState(), pl.site, pl.triangle);
    }
  }
  if (site.kind == SiteRequest::Kind::Pick) {
    // A pick on a geometry that has been replaced since is stale: drop it.
    if (!s_->geometry || site.generation != s_->geometry->generation) return;
    const Points& x = s_->prepared() ? s_->indentation->turgidState() : s_->complex->rest;
    const int t = site.triangle;
    if (t < 0 || t >= s_->complex->triangleCount()) return;
    const auto& tri = s_->complex->triangles[t];
    site.point = site.barycentric[0] * x.col(tri[0]) + site.barycentric[1] * x.col(tri[1]) +
                 site.barycentric[2] * x.col(tri[2]);
    site.kind = SiteRequest::Kind::Point;
  }
  prepare(r.params, site, newSite);
}

bool SimulationWorker::prepare(const SimulationParams& params, const SiteRequest& site,
                               bool newSite) {
  State& s = *s_;
  PreparationRequest request;
  request.params = params;
  if (site.kind == SiteRequest::Kind::Point) request.site = site.point;
  request.restPoint = site.restPoint;
  try {
    PreparedIndentation p = prepareIndentation(
        s.base, s.cellSize, request, [this](const std::string& what) { emit busy(q(what)); });
    // Success: the new state replaces the old one (the old indentation goes before its model).
    s.indentation.reset();
    s.model = std::move(p.model);
    s.indentation = std::move(p.indentation);
    s.params = params;
    if (p.complex != s.complex) {
      s.complex = p.complex;
      s.geometry = makeTissueGeometry(*s.complex, ++s.generation, s.path, s.cellSize);
    }
    ++s.preparation;
  } catch (const std::exception& e) {
    emit failed(
        tr("Preparation failed, the previous state is kept: %1").arg(QString::fromUtf8(e.what())));
    return false;
  }
  Snapshot snap = snapshot(Snapshot::Phase::Prepared);
  snap.point = CurvePoint{0.0, 0.0, 0, 0.0, true, false};
  snap.newSite = newSite;
  emit snapshotReady(snap);
  return true;
}

void SimulationWorker::handle(const Depth& r) {
  if (!s_->prepared()) return;
  emit busy(tr("Solving at depth %1 µm…").arg(r.depth, 0, 'f', 3));
  // A drag shows equilibria rather than measuring them: a residual of 1e-7 of the load scale
  // (forces good to ~1e-5 µN of tens of µN) lets most drag steps finish in one Newton iteration
  // instead of two. Curve runs keep the solver's own tolerance (1e-8).
  SolverOptions& options = s_->indentation->solver().options();
  const double tolerance = options.tolerance;
  options.tolerance = std::max(tolerance, kDragTolerance);
  const CurvePoint pt = s_->indentation->goToDepth(r.depth);
  options.tolerance = tolerance;
  if (!pt.converged) {
    emit failed(q(s_->indentation->lastMessage()));
    return;
  }
  Snapshot snap = snapshot(Snapshot::Phase::Equilibrium);
  snap.point = pt;
  snap.force = pt.force;
  snap.status = describePoint(pt);
  emit snapshotReady(snap);
}

void SimulationWorker::handle(const Run& r) {
  // Whatever happens, the controller hears that the run is over (it disables controls meanwhile).
  bool completed = false;
  try {
    completed = runSchedule(r.schedule);
  } catch (const std::exception& e) {
    emit failed(QString::fromUtf8(e.what()));
  }
  emit runFinished(completed);
}

bool SimulationWorker::runSchedule(const Schedule& sc) {
  if (!s_->prepared()) {
    emit failed(tr("Nothing to run: the indentation is not prepared"));
    return false;
  }
  Indentation& ind = *s_->indentation;
  // The schedule of Indentation::run, driven here so that every point is shown as it comes and
  // the schedule can change without preparing again. Depth 0 first (a drag may have left the
  // probe pressed in).
  const bool force = sc.control == Control::Force;
  const double top = force ? sc.maxForce : sc.maxDepth;
  std::vector<double> targets;
  for (int k = 1; k <= sc.steps; ++k) targets.push_back(top * k / sc.steps);
  if (sc.unload)
    for (int k = sc.steps - 1; k >= 0; --k) targets.push_back(top * k / sc.steps);
  const int total = static_cast<int>(targets.size());
  emit runStarted(total);
  emit busy(tr("Running the curve…"));
  if (ind.depth() != 0.0 && !ind.goToDepth(0.0).converged) {
    emit failed(q(ind.lastMessage()));
    return false;
  }
  Snapshot first = snapshot(Snapshot::Phase::Equilibrium);
  first.point = CurvePoint{0.0, 0.0, 0, 0.0, true, false};
  first.fromRun = true;
  emit snapshotReady(first);
  for (int i = 0; i < total; ++i) {
    if (cancel_) return false;  // checked between points, as Indentation::run does
    emit busy(tr("Running the curve: point %1 of %2…").arg(i + 1).arg(total));
    CurvePoint pt = force ? ind.applyForce(targets[i]) : ind.goToDepth(targets[i]);
    pt.unloading = sc.unload && i >= sc.steps;
    if (!pt.converged) {
      emit failed(q(ind.lastMessage()));
      return false;
    }
    Snapshot snap = snapshot(Snapshot::Phase::Equilibrium);
    snap.point = pt;
    snap.force = pt.force;
    snap.status = describePoint(pt);
    snap.fromRun = true;
    emit snapshotReady(snap);
    emit runProgress(i + 1, total);
  }
  return true;
}

void SimulationWorker::handle(const ExportVtu& r) {
  if (!s_->complex) {
    emit exportFailed(r.path, tr("no tissue is loaded"));
    return;
  }
  emit busy(tr("Writing %1…").arg(r.path));
  try {
    const CellComplex& cc = *s_->complex;
    const Points& x = s_->prepared() ? s_->indentation->state() : cc.rest;
    std::vector<VtuField> triangleFields;
    if (s_->model) triangleFields = vtuTriangleFields(computeStress(*s_->model, x));
    VtuField disp{"displacement_um", 3, {}}, dispRest{"displacement_from_rest_um", 3, {}};
    const Points& turgid = s_->prepared() ? s_->indentation->turgidState() : cc.rest;
    for (int v = 0; v < cc.vertexCount(); ++v)
      for (int k = 0; k < 3; ++k) {
        disp.values.push_back(x(k, v) - turgid(k, v));
        dispRest.values.push_back(x(k, v) - cc.rest(k, v));
      }
    writeVtu(r.path.toStdString(), cc, x, {disp, dispRest}, triangleFields);
    emit exported(r.path);
  } catch (const std::exception& e) {
    emit exportFailed(r.path, QString::fromUtf8(e.what()));
  }
}

Snapshot SimulationWorker::snapshot(Snapshot::Phase phase) const {
  const State& s = *s_;
  Snapshot snap;
  snap.geometry = s.geometry;
  snap.phase = phase;
  snap.params = s.params;
  snap.preparation = s.preparation;
  const bool prepared = s.prepared();
  const Points& x = prepared ? s.indentation->state() : s.complex->rest;
  snap.positions = toFloats(x);
  fillFields(prepared ? s.model.get() : nullptr, *s.complex, x,
             prepared ? &s.indentation->turgidState() : nullptr, snap);
  snap.cellVolumes = cellVolumes(*s.complex, x);
  if (prepared) {
    const Indentation& ind = *s.indentation;
    const ProbePlacement& pl = ind.placement();
    snap.probeVisible = true;
    snap.site = pl.site;
    snap.axis = pl.axis;
    snap.contactCenter = pl.contactCenter;
    snap.probeRadius = ind.settings().probeRadius;
    snap.depth = ind.depth();
  }
  snap.status = !prepared ? "at rest (not under pressure)" : "turgid, probe touching";
  return snap;
}

}  // namespace tp::gui
