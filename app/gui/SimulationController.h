#pragma once
// The window's side of the simulation, on the GUI thread: starts the worker's thread, turns
// user intentions (open, pick a site, drag the probe, change a parameter, run a curve) into
// worker requests, and keeps what the window shows besides the 3D view: the parameters, the
// sites picked and the curves, growing as equilibria arrive. No widgets: MainWindow wires it to
// the panels, and tests drive it directly. Units: µm, MPa, µN.

#include <QObject>
#include <QString>
#include <QThread>

#include <Eigen/Core>
#include <vector>

#include "Curves.h"
#include "Parameters.h"
#include "SessionFile.h"
#include "SimulationWorker.h"  // FitOutcome
#include "Snapshot.h"

namespace tp::gui {

class SimulationWorker;

class SimulationController : public QObject {
  Q_OBJECT

 public:
  explicit SimulationController(QObject* parent = nullptr);
  /// Stops a running curve, drops waiting requests and waits for the worker's thread.
  ~SimulationController() override;

  /// Loads a tissue (empty: the shipped default) and prepares it at its top.
  void loadTissue(const QString& path);
  /// New parameters: prepares again at the current site (only if they changed).
  void setParams(const SimulationParams& params);
  void setSchedule(const Schedule& schedule);
  /// A click on the displayed triangle `triangle` of geometry `generation`.
  void pickSite(int generation, int triangle, const Eigen::Vector3d& barycentric);
  /// The probe's depth (µm, ≥ 0) the user asks for; solved as soon as the worker is free.
  void requestDepth(double depth);
  void runCurve();
  void cancelRun();
  void exportVtu(const QString& path);
  void removeCurve(int index);
  /// A measured curve (imported from a file), drawn beside the simulated ones.
  void addMeasuredCurve(NamedCurve curve);
  /// A finished simulated curve computed elsewhere (a stiffness map's site), added as it is.
  void addSimulatedCurve(NamedCurve curve);
  /// Fits the chosen values to every measured curve at the current site (experiment/Fit.h),
  /// from the current parameters; the fitted curves are added when it ends. False (nothing
  /// started) without a measured curve, a prepared site or anything to fit.
  bool fitMeasuredCurves(bool E, bool p, bool h, bool offset, QString* why = nullptr);
  bool fitting() const { return fitting_; }
  void clearCurves();

  SessionState session() const;
  /// Restores parameters, schedule, sites and curves, then loads the tissue and prepares the
  /// session's current site.
  void applySession(const SessionState& session);

  const SimulationParams& params() const { return params_; }
  const Schedule& schedule() const { return schedule_; }
  const std::vector<NamedCurve>& curves() const { return curves_; }
  /// The sites picked on the current tissue (µm), in order: "site N" is sites()[N − 1].
  const std::vector<Eigen::Vector3d>& sites() const { return sites_; }
  int currentSite() const { return currentSite_; }
  /// The index in sites() of the site curve k was made at (the nearest within 2 µm of its own
  /// point: a site's point moves a little when prepared again with other parameters), or −1 (a
  /// measured curve, or a site no longer in the list).
  int siteOfCurve(int k) const;
  /// Curves made since the session was last saved (or its curves exported), which closing the
  /// window or clearing would lose.
  bool hasUnsavedCurves() const { return unsaved_ && !curves_.empty(); }
  void markCurvesSaved() { unsaved_ = false; }
  /// Curves that are in no file of the user's (a session recovered from an autosave).
  void markCurvesUnsaved() { unsaved_ = true; }
  const Snapshot& latest() const { return latest_; }
  const QString& tissuePath() const { return tissuePath_; }
  bool busy() const { return busy_; }
  /// Nothing asked of the worker is waiting or being done: not busy, not running, and no
  /// request sent that it has not finished (busy() turns on only when the worker starts one).
  bool idle() const;
  bool running() const { return running_; }
  bool prepared() const { return latest_.probeVisible; }
  double requestedDepth() const { return requestedDepth_; }
  double meanCellSize() const;
  /// Snapshots received since start (for measuring equilibria per second).
  int snapshotCount() const { return snapshotCount_; }
  /// The worker's thread: tests post work to it that holds the worker while they make requests
  /// (what the worker does between two calls on this thread otherwise depends on the load).
  QThread* workerThread() { return &thread_; }

 signals:
  void snapshotReady(const tp::gui::Snapshot& snapshot);
  void curvesChanged();
  void sitesChanged();
  void busyChanged(bool busy, const QString& what);
  void statusMessage(const QString& text);
  void solveFailed(const QString& message);
  /// Settings or a site refused before any solve (shown in a dialog).
  void settingsRefused(const QString& message);
  void loadFailed(const QString& message);
  void tissueLoaded(const QString& path, const QString& summary);
  void paramsChanged(const tp::gui::SimulationParams& params);
  void scheduleChanged(const tp::gui::Schedule& schedule);
  /// The depth control should show this (a preparation resets it, a run moves it).
  void requestedDepthChanged(double depth);
  void runningChanged(bool running);
  void runProgress(int done, int total);
  void exportFinished(const QString& path, bool ok, const QString& message);
  /// The mesh and its estimated discretisation error, for the status bar.
  void meshErrorChanged(const QString& text);
  void fitFinished(const tp::gui::FitOutcome& outcome);

 private:
  void onFitFinished(const tp::gui::FitOutcome& outcome);
  void onSnapshot(const Snapshot& s);
  void onRunStarted(int total, bool rerun);
  void onMeshError(const MeshErrorReport& report);
  void onRunFinished(bool completed);
  void recordSite(const Eigen::Vector3d& site, bool isNew);
  void setRequestedDepth(double depth);
  std::string uniqueName(const std::string& base) const;

  QThread thread_;
  SimulationWorker* worker_ = nullptr;  // lives in thread_

  SimulationParams params_;
  Schedule schedule_;
  QString tissuePath_;
  std::vector<Eigen::Vector3d> sites_, pendingSites_;  // pending: for the tissue being loaded
  int currentSite_ = -1, pendingCurrentSite_ = -1;
  std::vector<NamedCurve> curves_;
  int nextColour_ = 0;   // palette index of the next new curve: removing one recolours none
  bool unsaved_ = false;
  int liveCurve_ = -1, runCurve_ = -1, lastRunCurve_ = -1;
  int lastPreparation_ = -1;
  Snapshot latest_;
  bool busy_ = false, running_ = false, fitting_ = false;
  double requestedDepth_ = 0;
  int snapshotCount_ = 0;
};

}  // namespace tp::gui
