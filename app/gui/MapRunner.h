#pragma once
// A stiffness map in the application: runs tp::runMap (experiment/Map.h) on its own thread,
// beside the interactive simulation, into a cache folder named by the plan (a cancelled or
// interrupted map goes on where it stopped when the same map is asked again), and keeps the map
// the window shows: plan, parameters and the sites done, growing as they finish. Units: µm,
// MPa, µN.

#include <QObject>
#include <QString>

#include <atomic>
#include <memory>
#include <thread>
#include <vector>

#include "Parameters.h"
#include "SessionFile.h"
#include "experiment/Map.h"

namespace tp::gui {

/// What the user asks for: the sites of the current tissue and the indentation at each.
struct MapRequest {
  QString tissuePath;                 // empty: the shipped default tissue
  SimulationParams params;            // material, pressure, probe, mesh (as the window's)
  std::vector<SiteKind> kinds{SiteKind::CellMiddle};
  double gridSpacing = std::numeric_limits<double>::quiet_NaN();  // µm; NaN: the mean cell size
  double depth = 0.5;                 // µm, the end of each site's curve
  int steps = 5;
  int jobs = 1;                       // worker threads
  QString cacheRoot;                  // where the maps' folders go
};

class MapRunner : public QObject {
  Q_OBJECT

 public:
  explicit MapRunner(QObject* parent = nullptr);
  /// Cancels a running map and waits for its workers (each stops at its next Newton iteration).
  ~MapRunner() override;

  /// Starts a map in the background; false (with why) when one is running or the request is
  /// refused (no sites, a value out of range). The tissue is read and the sites placed on the
  /// map's thread: a bad tissue ends the map with finished(false, …, message).
  bool start(const MapRequest& request, QString* why = nullptr);
  void cancel();
  bool running() const { return running_; }

  /// The map shown (from a run or a session); none before either.
  bool hasMap() const { return map_.has_value(); }
  const SessionMap& map() const { return *map_; }
  /// The map's values over the surface, within 1.5 mean cell sizes of a done site at most.
  std::shared_ptr<const MapField> field() const { return field_; }
  /// The folder of the running (or last) map's results.
  const QString& folder() const { return folder_; }
  int sitesDone() const;
  /// Of the sites asked for, those the running (or last) map left out: the probe would reach
  /// the clamped base there (mapSites).
  int sitesLeftOut() const { return leftOut_; }
  /// A map from a session (replaces the one shown; refused while a map runs).
  bool setMap(SessionMap map);
  /// The tissue the window shows (its file and mean cell size, µm): the map is drawn (field())
  /// only on the tissue it was made on, its colours reaching 1.5 cell sizes from a site.
  void setTissue(const std::string& path, double cellSize);
  /// The map shown is of another tissue than the window's.
  bool otherTissue() const { return otherTissue_; }
  void clear();
  /// The map's table and surface (experiment/Map.h), written atomically; the surface needs the
  /// tissue (read from the plan's path). Throws std::runtime_error.
  void exportTable(const QString& path) const;
  void exportSurface(const QString& path) const;
  /// The curve of the map's site nearest to `restPoint` (µm, rest geometry) within `within` µm,
  /// as the plot shows it; its task, or −1 when no done site with a curve is that near.
  int siteCurve(const Eigen::Vector3d& restPoint, double within, NamedCurve* curve) const;

 signals:
  /// The plan is made: the sites are known (the map is shown, empty).
  void started(int tasks, int alreadyDone);
  void progress(int done, int todo, int failed, double seconds);
  /// A site was added to the map shown, or the map was replaced or cleared.
  void mapChanged();
  void finished(bool complete, bool cancelled, const QString& message);

 private:
  void onPlanned(const SessionMap& map, int alreadyDone, const QString& folder, int leftOut);
  void onTask(const TaskResult& r);
  void onFinished(bool complete, bool cancelled, const QString& message);
  void rebuildField();

  std::thread thread_;
  std::atomic<bool> cancel_{false};
  bool running_ = false;
  std::optional<SessionMap> map_;
  std::shared_ptr<const MapField> field_;
  QString folder_;
  int leftOut_ = 0;
  double cellSize_ = std::numeric_limits<double>::infinity();  // of the tissue shown, µm
  std::string tissue_;        // the tissue shown, absolute ("" before one is)
  bool otherTissue_ = false;
};

}  // namespace tp::gui
