#pragma once
// The main window: lays out the 3D view and the docks (parameters, colour and section, plot),
// builds the menus and shortcuts, and wires the panels to the SimulationController. Nothing
// else: the work is in the classes it connects.

#include <QMainWindow>

#include <Eigen/Core>

#include <memory>

class QAction;
class QDialog;
class QDockWidget;
class QLabel;
class QMenu;

namespace tp::gui {

class BusyIndicator;
class DisplayPanel;
class FileActions;
class MapPanel;
class MapRunner;
class ParameterPanel;
class PlotPanel;
class SimulationController;
class TissueView;
struct FitOutcome;

class MainWindow : public QMainWindow {
  Q_OBJECT

 public:
  explicit MainWindow(QWidget* parent = nullptr);
  ~MainWindow() override;

  SimulationController* controller() const { return controller_; }
  TissueView* view() const { return view_; }
  PlotPanel* plotPanel() const { return plot_; }
  ParameterPanel* parameterPanel() const { return params_; }
  DisplayPanel* displayPanel() const { return display_; }
  FileActions* fileActions() const { return files_; }
  MapRunner* mapRunner() const { return mapRunner_; }
  MapPanel* mapPanel() const { return mapPanel_; }
  /// Selects the newest curve of site `number` (as the legend names it), which highlights its
  /// graph and its disc; a click on a site's disc does this. False when it has no curve.
  bool selectSite(int number);

 protected:
  bool eventFilter(QObject* watched, QEvent* e) override;
  void closeEvent(QCloseEvent* e) override;
  void dragEnterEvent(QDragEnterEvent* e) override;
  void dropEvent(QDropEvent* e) override;

 private:
  void createDocks();
  void createMenus();
  void createStatusBar();
  void wire();
  void updateRecentMenu();
  void updateSiteMarkers();
  void askFit();
  void showFit(const tp::gui::FitOutcome& outcome);
  void showControls();
  /// Help ▸ What you see: one page on the colours, the curve and the model's assumptions.
  void showExplanation();
  /// View ▸ Presentation: larger fonts everywhere, a high-contrast overlay, and only the 3D
  /// view and the curves; off restores the fonts and the docks as they were.
  void setPresentation(bool on);
  void showMapSite(const Eigen::Vector3d& restPoint);

  SimulationController* controller_;
  TissueView* view_;
  ParameterPanel* params_;
  DisplayPanel* display_;
  PlotPanel* plot_;
  FileActions* files_;
  MapRunner* mapRunner_;
  MapPanel* mapPanel_;
  QDockWidget* mapDock_ = nullptr;
  QAction* frameSite_ = nullptr;  // View ▸ Frame a picked site
  QAction* presentation_ = nullptr;  // View ▸ Presentation
  QByteArray normalState_;           // the docks before presenting
  QDialog* explanation_ = nullptr;   // Help ▸ What you see (created on first use)
  bool framePending_ = false;     // a site was picked: frame it once it is prepared
  QMenu* recentMenu_ = nullptr;
  QMenu* viewMenu_ = nullptr;
  BusyIndicator* busy_;
  QLabel *hoverLabel_, *probeLabel_, *meshLabel_;
};

}  // namespace tp::gui
