#include "MapRunner.h"

#include <QDir>
#include <QMetaObject>

#include <cinttypes>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <stdexcept>

#include "io/AtomicFile.h"
#include "io/Paths.h"
#include "io/TissueFiles.h"

namespace tp::gui {

namespace {

QString q(const std::string& s) { return QString::fromStdString(s); }

// FNV-1a (64 bit) of the plan's JSON: the name of its results folder.
QString planHash(const MapPlan& plan) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : plan.toJson().dump()) h = (h ^ c) * 1099511628211ull;
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return QString::fromLatin1(buf);
}

}  // namespace

MapRunner::MapRunner(QObject* parent) : QObject(parent) {}

MapRunner::~MapRunner() {
  cancel_ = true;
  if (thread_.joinable()) thread_.join();
}

bool MapRunner::start(const MapRequest& request, QString* why) {
  auto refuse = [why](const QString& text) {
    if (why) *why = text;
    return false;
  };
  if (running_) return refuse(tr("A stiffness map is running: cancel it first."));
  if (request.kinds.empty()) return refuse(tr("Choose the sites to map."));
  if (request.jobs < 1) return refuse(tr("At least one worker is needed."));
  if (request.cacheRoot.isEmpty()) return refuse(tr("No folder for the map's results."));
  ExperimentSettings settings = mapSettings(request.params.experimentSettings());
  settings.indentation.control = Control::Depth;
  settings.indentation.maxDepth = request.depth;
  settings.indentation.steps = request.steps;
  try {
    settings.validate();
  } catch (const std::exception& e) {
    return refuse(q(e.what()));
  }
  if (thread_.joinable()) thread_.join();  // the last map's thread, finished
  cancel_ = false;
  running_ = true;
  thread_ = std::thread([this, request, settings] {
    bool complete = false;
    QString message;
    try {
      const std::string path = request.tissuePath.isEmpty() ? defaultTissuePath()
                                                            : request.tissuePath.toStdString();
      auto cc = std::make_shared<const CellComplex>(readSimulationTissue(path));
      SessionMap map;
      map.params = request.params;
      MapPlan& plan = map.plan;
      plan.tissue = std::filesystem::absolute(path).lexically_normal().string();
      plan.tissueDigest = tissueDigest(*cc);
      plan.settings = settings;
      std::vector<MapSite> leftOut;  // on the clamped base
      plan.sites = mapSites(*cc, request.kinds, request.gridSpacing, "",
                            settings.indentation.probeRadius, &leftOut);
      if (plan.sites.empty()) throw std::runtime_error("the tissue has no such site");
      plan.checkSize();
      const QString folder = request.cacheRoot + "/" + planHash(plan);
      // What an earlier run of the same map left (it goes on from there).
      map.results = std::filesystem::exists((folder + "/plan.json").toStdString())
                        ? readResults(folder.toStdString(), plan)
                        : std::vector<TaskResult>(plan.taskCount());
      int before = 0;
      for (const TaskResult& r : map.results) before += r.task >= 0;
      QMetaObject::invokeMethod(
          this,
          [this, map, before, folder, n = static_cast<int>(leftOut.size())] {
            onPlanned(map, before, folder, n);
          },
          Qt::QueuedConnection);
      MapRunOptions options;
      options.outDir = folder.toStdString();
      options.jobs = request.jobs;
      options.cancel = &cancel_;
      options.host = "application";
      options.progress = [this](const MapProgress& p) {
        if (!p.last) return;
        const TaskResult r = *p.last;
        const int done = p.done, todo = p.todo, failed = p.failed;
        const double seconds = p.seconds;
        QMetaObject::invokeMethod(
            this,
            [this, r, done, todo, failed, seconds] {
              onTask(r);
              emit progress(done, todo, failed, seconds);
            },
            Qt::QueuedConnection);
      };
      const MapRunSummary s = runMap(cc, plan, options);
      complete = s.complete;
      if (s.cancelled)
        message = tr("Map cancelled: %1 site(s) done are kept and a new start goes on from them.")
                      .arg(s.done + s.skipped);
      else if (s.failed)
        message = tr("%1 site(s) did not converge (left out of the colours).").arg(s.failed);
      if (!leftOut.empty())
        message += (message.isEmpty() ? QString() : QString(" ")) +
                   tr("%1 site(s) left out: the probe would reach the clamped base there.")
                       .arg(leftOut.size());
      QMetaObject::invokeMethod(
          this, [this, complete, c = s.cancelled, message] { onFinished(complete, c, message); },
          Qt::QueuedConnection);
    } catch (const std::exception& e) {
      message = q(e.what());
      QMetaObject::invokeMethod(
          this, [this, message] { onFinished(false, false, message); }, Qt::QueuedConnection);
    }
  });
  return true;
}

void MapRunner::cancel() { cancel_ = true; }

int MapRunner::sitesDone() const {
  int n = 0;
  if (map_)
    for (const TaskResult& r : map_->results) n += r.task >= 0;
  return n;
}

void MapRunner::onPlanned(const SessionMap& map, int alreadyDone, const QString& folder,
                          int leftOut) {
  map_ = map;
  folder_ = folder;
  leftOut_ = leftOut;
  rebuildField();
  emit started(map.plan.taskCount(), alreadyDone);
  emit mapChanged();
}

void MapRunner::onTask(const TaskResult& r) {
  if (!map_ || r.task < 0 || r.task >= static_cast<int>(map_->results.size())) return;
  map_->results[r.task] = r;
  rebuildField();
  emit mapChanged();
}

void MapRunner::onFinished(bool complete, bool cancelled, const QString& message) {
  running_ = false;
  emit finished(complete, cancelled, message);
}

void MapRunner::setTissue(const std::string& path, double cellSize) {
  const std::string tissue = std::filesystem::absolute(path).lexically_normal().string();
  if (tissue == tissue_ && cellSize == cellSize_) return;
  tissue_ = tissue;
  cellSize_ = cellSize > 0 ? cellSize : std::numeric_limits<double>::infinity();
  if (!map_) return;
  rebuildField();
  emit mapChanged();
}

bool MapRunner::setMap(SessionMap map) {
  if (running_) return false;
  map_ = std::move(map);
  folder_.clear();
  rebuildField();
  emit mapChanged();
  return true;
}

void MapRunner::clear() {
  if (running_) return;
  map_.reset();
  field_.reset();
  emit mapChanged();
}

void MapRunner::rebuildField() {
  otherTissue_ = map_ && !tissue_.empty() && map_->plan.tissue != tissue_;
  field_ = map_ && !otherTissue_
               ? std::make_shared<const MapField>(map_->plan, map_->results, 1.5 * cellSize_)
               : nullptr;
}

void MapRunner::exportTable(const QString& path) const {
  if (!map_) throw std::runtime_error("there is no stiffness map to export");
  writeFileAtomically(path.toStdString(),
                      [&](std::ostream& o) { o << mapTable(map_->plan, map_->results); });
}

void MapRunner::exportSurface(const QString& path) const {
  if (!map_) throw std::runtime_error("there is no stiffness map to export");
  const CellComplex cc = readSimulationTissue(map_->plan.tissue);
  if (tissueDigest(cc) != map_->plan.tissueDigest)
    throw std::runtime_error(map_->plan.tissue + " is not the tissue the map was made on any more");
  writeFileAtomically(path.toStdString(),
                      [&](std::ostream& o) { o << mapSurfaceVtu(cc, map_->plan, map_->results); });
}

int MapRunner::siteCurve(const Eigen::Vector3d& restPoint, double within, NamedCurve* curve) const {
  if (!field_ || field_->empty()) return -1;
  double distance = 0;
  const int task = field_->nearestTask(restPoint, &distance);
  if (task < 0 || distance > within) return -1;
  const TaskResult& r = map_->results[task];
  if (r.curve.empty()) return -1;  // a result of an earlier version
  const MapSite& site = map_->plan.site(task);
  NamedCurve c;
  c.name = "map " + site.label + " · " + describe(map_->params);
  c.site = r.contact.allFinite() ? Eigen::Vector3d(r.contact) : Eigen::Vector3d(site.point);
  c.params = map_->params;
  for (const auto& [depth, force] : r.curve) {
    CurvePoint p;
    p.depth = depth;
    p.force = force;
    p.converged = true;
    c.points.push_back(p);
  }
  c.meshLevel = r.level;
  c.meshError = r.meshError;
  c.meshErrorAt = r.depth;
  c.meshErrorMethod = "stiffness map site";
  if (curve) *curve = std::move(c);
  return task;
}

}  // namespace tp::gui
