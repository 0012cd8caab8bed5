#pragma once
// The simulation, off the GUI thread. A SimulationWorker lives in its own QThread and owns the
// core's Experiment (the tissue at rest under turgor, the site refined and prepared on it);
// nothing else touches them. It is a thin adapter: the workflow is core/experiment/Experiment.h,
// the same the command line runs. Requests may be made from any thread: they are queued under a
// mutex and handled one at a time, in order, by the worker's event loop (Qt's mandelbrot
// pattern). A request of the same kind as the last one still waiting replaces it, so a probe
// dragged faster than the solver is only solved at the newest depth. Results leave as immutable
// Snapshots, by value, through queued signals. Long work (a preparation, a curve, a mesh-error
// estimate) is stopped within one Newton iteration by an atomic flag (Avogadro's calcworker
// pattern): Cancel stops a curve, a newer site or parameters stop a preparation, anything new
// stops an estimate. Units: µm, MPa, µN.

#include <QObject>
#include <QString>

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <variant>

#include "Parameters.h"
#include "Snapshot.h"
#include "experiment/Fit.h"

namespace tp::gui {

/// Where to put the probe when preparing: the default site (the top of the tissue), the site of
/// the current preparation (new parameters), a point near the turgid surface (the nearest
/// outer-surface point is used), or a material point of the surface given by its rest position
/// (a pick: any refinement keeps the tissue's rest surface, so it names the same point on every
/// mesh).
struct SiteRequest {
  enum class Kind { Top, Current, Point, Rest };
  Kind kind = Kind::Top;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // Kind::Point and Kind::Rest, µm
};

/// What a fit in the worker ended with: the result, or why there is none.
struct FitOutcome {
  bool ok = false;
  QString message;
  std::shared_ptr<const tp::FitResult> result;
};

class SimulationWorker : public QObject {
  Q_OBJECT

 public:
  SimulationWorker();
  ~SimulationWorker() override;

  // Thread-safe requests.
  /// Reads and checks a tissue (empty path: the shipped default), then prepares it.
  void requestLoad(const QString& path, const SimulationParams& params, const SiteRequest& site);
  /// Refines the mesh around the site, solves its rest state and places the probe.
  void requestPrepare(const SimulationParams& params, const SiteRequest& site);
  /// Moves the probe to a depth (µm) from first contact and solves.
  void requestDepth(double depth);
  /// Runs a loading (and unloading) schedule from depth 0, then estimates its mesh error (and,
  /// with the automatic mesh, refines and runs again until it is within tolerance).
  void requestRun(const Schedule& schedule);
  /// Writes the current state with its stress fields as VTU.
  void requestExportVtu(const QString& path);
  /// Fits the settings' E, p, h to measured curves on the loaded tissue (experiment/Fit.h);
  /// stopped by cancel() within one Newton iteration.
  void requestFit(const tp::FitSettings& settings, const std::vector<tp::FitCurve>& curves);
  /// Stops a running curve (within one Newton iteration).
  void cancel() {
    std::lock_guard lock(mutex_);
    ++cancels_;  // a run or fit requested before this and not started yet sees it when it starts
    stop_ = true;
  }
  /// Drops every waiting request and stops what runs; used before the thread quits.
  void stop();
  /// A request waits or is being handled (from the moment it is asked for: the busy() signal
  /// comes only when the worker starts on it).
  bool hasWork() const {
    std::lock_guard lock(mutex_);
    return scheduled_ || !queue_.empty();
  }

 signals:
  void snapshotReady(const tp::gui::Snapshot& snapshot);
  void busy(const QString& what);
  void idle();
  void loaded(const QString& path, const QString& summary);
  void loadFailed(const QString& path, const QString& message);
  /// A solve that failed; the last good state is kept.
  void failed(const QString& message);
  /// Settings or a site refused before solving (out of range, off the tissue, on its clamped
  /// base), with the value and what is allowed; `failed` follows with the same message.
  void refused(const QString& message);
  /// A run begins; `rerun` when it replaces the last one on a finer mesh.
  void runStarted(int total, bool rerun);
  void runProgress(int done, int total);
  void runFinished(bool completed);
  void meshErrorEstimated(const tp::gui::MeshErrorReport& report);
  void exported(const QString& path);
  void exportFailed(const QString& path, const QString& message);
  void fitFinished(const tp::gui::FitOutcome& outcome);

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
  // Runs and fits carry the count of Cancels at their request: one pressed after it stops them
  // even if it came before they started, whatever ran in between.
  struct Run {
    Schedule schedule;
    std::uint64_t cancelsAtRequest = 0;
  };
  struct ExportVtu {
    QString path;
  };
  struct EstimateLive {  // the error of the curve grown by dragging, once the drag rests
    int preparation;
  };
  struct Fit {
    tp::FitSettings settings;
    std::vector<tp::FitCurve> curves;
    std::uint64_t cancelsAtRequest = 0;
  };
  using Request = std::variant<Load, Prepare, Depth, Run, ExportVtu, EstimateLive, Fit>;

  void enqueue(Request r);
  std::uint64_t cancelsSoFar();
  void processNext();
  void handle(const Load& r);
  void handle(const Prepare& r);
  void handle(const Depth& r);
  void handle(const Run& r);
  void handle(const ExportVtu& r);
  void handle(const EstimateLive& r);
  void handle(const Fit& r);
  bool prepare(const SimulationParams& params, const SiteRequest& site, bool newSite,
               bool keepLevel = false);
  bool runSchedule(const Schedule& schedule, bool rerun);
  Snapshot snapshot(Snapshot::Phase phase) const;

  mutable std::mutex mutex_;
  std::deque<Request> queue_;
  bool scheduled_ = false;
  int interruptibleBy_ = 0;        // what may stop the task in hand (bits of request kinds)
  std::atomic<bool> stop_{false};  // the task in hand stops at its next Newton iteration
  std::atomic<bool> stopping_{false};
  std::uint64_t cancels_ = 0;  // Cancels so far (guarded by mutex_)

  // Owned by the worker's thread only.
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace tp::gui

Q_DECLARE_METATYPE(tp::gui::FitOutcome)
