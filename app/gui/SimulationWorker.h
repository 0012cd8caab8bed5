#pragma once
// The simulation, off the GUI thread. A SimulationWorker lives in its own QThread and owns the
// tissue, the Model and the Indentation; nothing else touches them. Requests may be made from any
// thread: they are queued under a mutex and handled one at a time, in order, by the worker's
// event loop (Qt's mandelbrot pattern). A request of the same kind as the last one still waiting
// replaces it, so a probe dragged faster than the solver is only solved at the newest depth.
// Results leave as immutable Snapshots, by value, through queued signals. A running curve is
// stopped by an atomic flag checked between points (Avogadro's calcworker pattern).
// Units: µm, MPa, µN.

#include <QObject>
#include <QString>

#include <Eigen/Core>
#include <atomic>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <variant>

#include "Parameters.h"
#include "Snapshot.h"

namespace tp::gui {

/// Where to put the probe when preparing: the default site (the top of the tissue), the site of
/// the current preparation (new parameters), a point (the nearest outer-surface point is used),
/// or a pick on the displayed triangles (barycentric weights), mapped to the turgid state by the
/// worker.
struct SiteRequest {
  enum class Kind { Top, Current, Point, Pick };
  Kind kind = Kind::Top;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // Kind::Point, µm
  int generation = -1;                              // Kind::Pick: the geometry picked on
  int triangle = -1;
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> restPoint;  // the material point (rest state, µm) to stay on
};

class SimulationWorker : public QObject {
  Q_OBJECT

 public:
  SimulationWorker();
  ~SimulationWorker() override;

  // Thread-safe requests.
  /// Reads and checks a tissue (empty path: the shipped default), then prepares it.
  void requestLoad(const QString& path, const SimulationParams& params, const SiteRequest& site);
  /// Solves the turgid state and places the probe (refining around the site if asked).
  void requestPrepare(const SimulationParams& params, const SiteRequest& site);
  /// Moves the probe to a depth (µm) from first contact and solves.
  void requestDepth(double depth);
  /// Runs a loading (and unloading) schedule from depth 0.
  void requestRun(const Schedule& schedule);
  /// Writes the current state with its stress fields as VTU.
  void requestExportVtu(const QString& path);
  /// Stops a running schedule after its current point.
  void cancel() { cancel_ = true; }
  /// Drops every waiting request and stops a run; used before the thread quits.
  void stop();

 signals:
  void snapshotReady(const tp::gui::Snapshot& snapshot);
  void busy(const QString& what);
  void idle();
  void loaded(const QString& path, const QString& summary);
  void loadFailed(const QString& path, const QString& message);
  /// A solve that failed; the last good state is kept.
  void failed(const QString& message);
  void runStarted(int total);
  void runProgress(int done, int total);
  void runFinished(bool completed);
  void exported(const QString& path);
  void exportFailed(const QString& path, const QString& message);

 private:
  struct Load {
    QString path;
    SimulationParams params;
    SiteRequest site;
  };
  struct Prepare {
    SimulationParams params;
    SiteRequest site;
  };
  struct Depth {
    double depth;
  };
  struct Run {
    Schedule schedule;
  };
  struct ExportVtu {
    QString path;
  };
  using Request = std::variant<Load, Prepare, Depth, Run, ExportVtu>;

  void enqueue(Request r);
  void processNext();
  void handle(const Load& r);
  void handle(const Prepare& r);
  void handle(const Depth& r);
  void handle(const Run& r);
  void handle(const ExportVtu& r);
  bool prepare(const SimulationParams& params, const SiteRequest& site, bool newSite);
  bool runSchedule(const Schedule& schedule);
  Snapshot snapshot(Snapshot::Phase phase) const;

  std::mutex mutex_;
  std::deque<Request> queue_;
  bool scheduled_ = false;
  std::atomic<bool> cancel_{false};
  std::atomic<bool> stopping_{false};

  // Owned by the worker's thread only.
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace tp::gui
