#include "MainWindow.h"

#include <qcustomplot.h>

#include "Throttle.h"

#include <QAbstractSpinBox>
#include <QAction>
#include <QActionGroup>
#include <QApplication>
#include <QCheckBox>
#include <QCloseEvent>
#include <QDialog>
#include <QDialogButtonBox>
#include <QDockWidget>
#include <QFile>
#include <QFileInfo>
#include <QFormLayout>
#include <QKeyEvent>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QMimeData>
#include <QPushButton>
#include <QScreen>
#include <QScrollArea>
#include <QSettings>
#include <QStatusBar>
#include <QTextBrowser>
#include <QToolBar>
#include <QVBoxLayout>

#include "Autosave.h"
#include "BusyIndicator.h"
#include "Curves.h"
#include "DisplayPanel.h"
#include "FileActions.h"
#include "MapPanel.h"
#include "MapRunner.h"
#include "ParameterPanel.h"
#include "PlotPanel.h"
#include "RecentFiles.h"
#include "Resources.h"
#include "SimulationController.h"
#include "TissueView.h"

namespace tp::gui {

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent) {
  initResources();
  setObjectName("mainWindow");
  setWindowTitle(tr("TissueProbe"));
  setWindowIcon(QIcon(":/icons/tissueprobe.svg"));
  setAcceptDrops(true);
  controller_ = new SimulationController(this);
  view_ = new TissueView;
  setCentralWidget(view_);
  params_ = new ParameterPanel;
  display_ = new DisplayPanel;
  plot_ = new PlotPanel;
  mapRunner_ = new MapRunner(this);
  mapPanel_ = new MapPanel(mapRunner_, controller_);
  files_ = new FileActions(this, controller_, view_, plot_, display_, mapRunner_);
  createDocks();
  createMenus();
  createStatusBar();
  wire();
  controller_->setParams(params_->params());
  controller_->setSchedule(params_->schedule());
  // The first window fits the screen it opens on, with room for a title bar: the layout's
  // 1280×800 is taller than a 1280×800 or 1366×768 laptop screen, and the status bar at the
  // bottom carries the curve's estimated error. A saved geometry (below) takes precedence.
  QSize size(1280, 800);
  if (const QScreen* s = screen())
    size = size.boundedTo(s->availableGeometry().size() - QSize(0, 48));
  resize(size);
  // Space is "Run curve" everywhere but in a number box, where it used to go into the text and
  // blank the box: there it does nothing.
  for (QAbstractSpinBox* box : findChildren<QAbstractSpinBox*>()) box->installEventFilter(this);
  QSettings settings;
  restoreGeometry(settings.value("window/geometry").toByteArray());
  restoreState(settings.value("window/state").toByteArray());
  // Curves not yet saved are written aside every minute, to be recovered after a crash.
  files_->startAutosave();
}

MainWindow::~MainWindow() = default;

void MainWindow::createDocks() {
  // The parameters take the full height on the left; the plot spans the rest of the width.
  setCorner(Qt::BottomLeftCorner, Qt::LeftDockWidgetArea);
  auto dock = [this](const QString& title, const char* name, QWidget* w, Qt::DockWidgetArea area) {
    auto* d = new QDockWidget(title, this);
    d->setObjectName(name);  // restoreState finds docks by name
    d->setWidget(w);
    addDockWidget(area, d);
    return d;
  };
  auto* scroll = new QScrollArea;  // the parameter panel is tall: scroll on small screens
  scroll->setWidget(params_);
  scroll->setWidgetResizable(true);
  scroll->setFrameShape(QFrame::NoFrame);
  scroll->setMinimumWidth(params_->sizeHint().width() + 20);
  auto* p = dock(tr("Parameters"), "parametersDock", scroll, Qt::LeftDockWidgetArea);
  auto* d = dock(tr("Colour and section"), "displayDock", display_, Qt::RightDockWidgetArea);
  auto* c = dock(tr("Force–depth curves"), "plotDock", plot_, Qt::BottomDockWidgetArea);
  mapDock_ = dock(tr("Stiffness map"), "mapDock", mapPanel_, Qt::RightDockWidgetArea);
  tabifyDockWidget(d, mapDock_);
  d->raise();
  resizeDocks({c}, {260}, Qt::Vertical);
  viewMenu_ = new QMenu(tr("&View"), this);
  for (auto* w : {p, d, mapDock_, c}) viewMenu_->addAction(w->toggleViewAction());
}

void MainWindow::createMenus() {
  auto add = [this](QMenu* m, const QString& text, const QKeySequence& key, const QString& tip,
                    auto slot) {
    QAction* a = m->addAction(text);
    if (!key.isEmpty()) a->setShortcut(key);
    a->setStatusTip(tip);
    a->setToolTip(tip);
    connect(a, &QAction::triggered, this, slot);
    addAction(a);  // shortcuts work while the menu bar is hidden, too
    return a;
  };
  QMenu* file = menuBar()->addMenu(tr("&File"));
  QAction* open = add(file, tr("&Open tissue…"), QKeySequence::Open, tr("Open a tissue (PLY)"),
                      [this] { files_->openTissueDialog(); });
  add(file, tr("Open &session…"), QKeySequence(tr("Ctrl+Shift+O")),
      tr("Open a saved session (JSON)"), [this] { files_->openSessionDialog(); });
  recentMenu_ = file->addMenu(tr("Open &recent"));
  QAction* save = add(file, tr("&Save session…"), QKeySequence::Save,
                      tr("Save the tissue, parameters, sites and curves (JSON)"),
                      [this] { files_->saveSessionDialog(); });
  file->addSeparator();
  add(file, tr("Export &plot…"), QKeySequence(tr("Ctrl+E")), tr("The plot as PNG, SVG or PDF"),
      [this] { files_->exportPlotDialog(); });
  add(file, tr("Export all &curves (CSV)…"), QKeySequence(tr("Ctrl+Shift+E")),
      tr("Every curve in one CSV with a 'curve' column"), [this] { files_->exportCurvesDialog(); });
  add(file, tr("&Import measured curve…"), QKeySequence(tr("Ctrl+I")),
      tr("A measured force–indentation curve (CSV/TSV with units in the header, or a JPK text "
         "export), drawn as points beside the simulated curves"),
      [this] { files_->importMeasuredCurveDialog(); });
  add(file, tr("Export selected curve (CSV)…"), QKeySequence(),
      tr("The selected (else the newest) curve"), [this] { files_->exportCurrentCurveDialog(); });
  QAction* shot = add(file, tr("Screens&hot of the 3D view…"), QKeySequence(tr("Ctrl+Shift+S")),
                      tr("A PNG of the 3D view at a chosen size"),
                      [this] { files_->exportScreenshotDialog(); });
  add(file, tr("Export &figure (view and curves)…"), QKeySequence(tr("Ctrl+Shift+F")),
      tr("The 3D view with its colour bar and the curves side by side, in one PNG or PDF, for "
         "slides and papers"),
      [this] { files_->exportFigureDialog(); });
  add(file, tr("Export deformed state (&VTU)…"), QKeySequence(tr("Ctrl+Shift+U")),
      tr("The current state with stress fields, for ParaView"),
      [this] { files_->exportVtuDialog(); });
  add(file, tr("Export stiffness &map (CSV)…"), QKeySequence(),
      tr("The map's table: one row per site (force, stiffness, Hertz modulus, mesh error)"),
      [this] { files_->exportMapTableDialog(); });
  add(file, tr("Export stiffness map surface (VTU)…"), QKeySequence(),
      tr("The outer surface coloured by the map (per site and interpolated), for ParaView"),
      [this] { files_->exportMapSurfaceDialog(); });
  file->addSeparator();
  add(file, tr("&Quit"), QKeySequence::Quit, tr("Quit TissueProbe"), [this] { close(); });

  menuBar()->addMenu(viewMenu_);
  viewMenu_->addSeparator();
  QAction* fit = add(viewMenu_, tr("&Fit to view"), QKeySequence(Qt::Key_F),
                     tr("Show the whole tissue (F)"), [this] { view_->fitToView(); });
  add(viewMenu_, tr("Front view"), QKeySequence(Qt::Key_1), tr("Look along +y (1)"),
      [this] { view_->setStandardView(Camera::StandardView::Front); });
  add(viewMenu_, tr("Right view"), QKeySequence(Qt::Key_3), tr("Look along −x (3)"),
      [this] { view_->setStandardView(Camera::StandardView::Right); });
  add(viewMenu_, tr("Top view"), QKeySequence(Qt::Key_7), tr("Look down −z (7)"),
      [this] { view_->setStandardView(Camera::StandardView::Top); });
  add(viewMenu_, tr("&Reset view"), QKeySequence(Qt::Key_R), tr("The initial view (R)"),
      [this] { view_->resetView(); });
  add(viewMenu_, tr("&Zoom to the probe"), QKeySequence(Qt::Key_Z),
      tr("Frame the probe and the cells around it (Z)"), [this] { view_->zoomToProbe(); });
  frameSite_ = viewMenu_->addAction(tr("Frame a &picked site"));
  frameSite_->setObjectName("frameSiteAction");
  frameSite_->setCheckable(true);
  frameSite_->setChecked(QSettings().value("view/frameSite", true).toBool());
  frameSite_->setToolTip(tr("After a click picks a site, look at it from close by (as Z does), "
                            "so that a 1 µm dimple can be seen"));
  connect(frameSite_, &QAction::toggled, this,
          [](bool on) { QSettings().setValue("view/frameSite", on); });
  QAction* arcball = viewMenu_->addAction(tr("&Arcball rotation"));
  arcball->setCheckable(true);
  arcball->setToolTip(tr("Turn freely (arcball) instead of about the vertical axis (turntable)"));
  connect(arcball, &QAction::toggled, this, [this](bool on) {
    view_->setRotationMode(on ? Camera::RotationMode::Arcball : Camera::RotationMode::Turntable);
  });

  presentation_ = add(viewMenu_, tr("&Presentation"), QKeySequence(Qt::Key_F5),
                      tr("For a lecture: large fonts, a high-contrast overlay, only the tissue and "
                         "the curves (F5 again to go back)"),
                      [] {});
  presentation_->setObjectName("presentationAction");
  presentation_->setCheckable(true);
  connect(presentation_, &QAction::toggled, this, &MainWindow::setPresentation);

  QMenu* sim = menuBar()->addMenu(tr("&Simulation"));
  QAction* run =
      add(sim, tr("&Run curve"), QKeySequence(Qt::Key_Space),
          tr("Run the loading schedule from depth 0 (Space)"), [this] { controller_->runCurve(); });
  QAction* cancel = add(sim, tr("&Cancel"), QKeySequence(Qt::Key_Escape),
                        tr("Stop the running curve after its current point (Esc)"),
                        [this] { controller_->cancelRun(); });
  add(sim, tr("&Fit measured curves…"), QKeySequence(tr("Ctrl+F")),
      tr("Fit the walls' E, the turgor p (and h, a contact offset) to the measured curves at "
         "the current site; Cancel stops it"),
      [this] { askFit(); });
  add(sim, tr("Stiffness &map…"), QKeySequence(tr("Ctrl+M")),
      tr("Indent many sites (cell middles, junctions, a grid) in the background and colour the "
         "surface by their stiffness"),
      [this] {
        mapDock_->show();
        mapDock_->raise();
      });
  sim->addSeparator();
  add(sim, tr("&Turgid preset"), QKeySequence(), tr("Turgor p = 0.8 MPa"),
      [this] { params_->applyTurgidPreset(); });
  add(sim, tr("&Plasmolysed preset"), QKeySequence(), tr("Turgor p = 0"),
      [this] { params_->applyPlasmolysedPreset(); });

  QMenu* help = menuBar()->addMenu(tr("&Help"));
  add(help, tr("&Mouse and keys"), QKeySequence::HelpContents, tr("How to drive the 3D view"),
      [this] { showControls(); });
  add(help, tr("&What you see"), QKeySequence(),
      tr("What the colours and the curve mean, and what the model assumes"),
      [this] { showExplanation(); })
      ->setObjectName("explanationAction");
  add(help, tr("&About TissueProbe"), QKeySequence(), tr("About"), [this] {
    QMessageBox::about(this, tr("About TissueProbe"),
                       tr("TissueProbe %1: an AFM-style spherical probe indenting a plant tissue "
                          "of polyhedral cells under turgor.\nUnits: µm, MPa, µN.")
                           .arg(QCoreApplication::applicationVersion()));
  });

  QToolBar* tools = addToolBar(tr("Tools"));
  tools->setObjectName("toolBar");
  open->setIcon(QIcon(":/icons/open.svg"));
  save->setIcon(QIcon(":/icons/save.svg"));
  run->setIcon(QIcon(":/icons/run.svg"));
  cancel->setIcon(QIcon(":/icons/cancel.svg"));
  fit->setIcon(QIcon(":/icons/fit.svg"));
  shot->setIcon(QIcon(":/icons/screenshot.svg"));
  for (QAction* a : {open, save, run, cancel, fit, shot}) tools->addAction(a);
  viewMenu_->insertAction(viewMenu_->actions().value(3), tools->toggleViewAction());
  updateRecentMenu();
}

void MainWindow::createStatusBar() {
  busy_ = new BusyIndicator;
  hoverLabel_ = new QLabel;
  probeLabel_ = new QLabel;
  probeLabel_->setObjectName("probeLabel");
  meshLabel_ = new QLabel;
  meshLabel_->setObjectName("meshLabel");
  meshLabel_->setToolTip(tr("The mesh around the site and the estimated discretisation error of "
                            "the last curve's deepest point"));
  statusBar()->addWidget(busy_);
  statusBar()->addPermanentWidget(meshLabel_);
  statusBar()->addPermanentWidget(hoverLabel_);
  statusBar()->addPermanentWidget(probeLabel_);
}

void MainWindow::wire() {
  SimulationController* c = controller_;
  // Worker results → view, status, plot.
  connect(c, &SimulationController::snapshotReady, view_, &TissueView::setSnapshot);
  // The status bar and the plot follow the worker at most five times a second (Throttle.h).
  auto* probeText = new Throttle(200, [this] {
    const Snapshot& s = controller_->latest();
    probeLabel_->setText(
        s.probeVisible
            ? tr("depth %1 µm · force %2 µN")
                  .arg(s.depth, 0, 'f', 3)
                  .arg(QString::fromStdString(forceText(s.force)))
            : QString::fromStdString(s.status));
  }, this);
  connect(c, &SimulationController::snapshotReady, probeText, &Throttle::request);
  connect(c, &SimulationController::snapshotReady, this, [this](const Snapshot& s) {
    if (s.phase == Snapshot::Phase::Prepared) meshLabel_->setText(QString::fromStdString(s.meshStatus));
  });
  connect(c, &SimulationController::meshErrorChanged, meshLabel_, &QLabel::setText);
  auto* plotUpdate = new Throttle(200, [this] {
    plot_->setCurves(controller_->curves(), controller_->meanCellSize());
  }, this);
  // Points added during a drag or a run wait for the throttle; a curve added, removed or cleared,
  // or any change while the worker is idle, is shown at once, and whatever is pending is shown
  // when the worker goes idle.
  connect(c, &SimulationController::curvesChanged, plotUpdate, [this, plotUpdate] {
    if (!controller_->busy() ||
        plot_->curveCount() != static_cast<int>(controller_->curves().size()))
      plotUpdate->now();
    else
      plotUpdate->request();
  });
  connect(c, &SimulationController::busyChanged, busy_, &BusyIndicator::setBusy);
  connect(c, &SimulationController::busyChanged, this, [plotUpdate, probeText](bool busy) {
    if (busy) return;
    plotUpdate->flush();
    probeText->flush();
  });
  connect(c, &SimulationController::statusMessage, this,
          [this](const QString& m) { statusBar()->showMessage(m, 5000); });
  connect(c, &SimulationController::solveFailed, view_, &TissueView::clearTarget);
  connect(c, &SimulationController::solveFailed, this, [this](const QString& m) {
    statusBar()->showMessage(tr("Not converged: %1").arg(m));  // stays until the next message
  });
  connect(c, &SimulationController::settingsRefused, this, [this](const QString& m) {
    showError(this, tr("Settings refused"), m);
  });
  connect(c, &SimulationController::loadFailed, this, [this](const QString& m) {
    view_->setPlaceholder(
        tr("No tissue: open one with File ▸ Open tissue (Ctrl+O) or drop a "
           ".ply file here"));
    showError(this, tr("Cannot open the tissue"), m);
  });
  connect(c, &SimulationController::tissueLoaded, this,
          [this](const QString& path, const QString& summary) {
            setWindowTitle(tr("TissueProbe — %1").arg(QFileInfo(path).fileName()));
            statusBar()->showMessage(tr("Loaded %1: %2").arg(path, summary), 5000);
          });
  connect(c, &SimulationController::exportFinished, this,
          [this](const QString& path, bool ok, const QString& m) {
            if (ok)
              statusBar()->showMessage(tr("Wrote %1").arg(path), 5000);
            else
              showError(this, tr("Cannot write the state"), m);
          });
  // Parameters, depth and runs.
  connect(params_, &ParameterPanel::paramsChanged, c, &SimulationController::setParams);
  connect(params_, &ParameterPanel::scheduleChanged, c, &SimulationController::setSchedule);
  connect(c, &SimulationController::paramsChanged, params_, &ParameterPanel::setParams);
  connect(c, &SimulationController::scheduleChanged, params_, &ParameterPanel::setSchedule);
  connect(params_, &ParameterPanel::depthChanged, c, &SimulationController::requestDepth);
  connect(params_, &ParameterPanel::depthChanged, view_, &TissueView::setRequestedDepth);
  connect(view_, &TissueView::depthRequested, params_, &ParameterPanel::setDepth);
  connect(c, &SimulationController::requestedDepthChanged, params_, &ParameterPanel::showDepth);
  connect(c, &SimulationController::requestedDepthChanged, view_, &TissueView::setRequestedDepth);
  connect(params_, &ParameterPanel::runRequested, c, &SimulationController::runCurve);
  connect(params_, &ParameterPanel::cancelRequested, c, &SimulationController::cancelRun);
  connect(c, &SimulationController::runningChanged, params_, &ParameterPanel::setRunning);
  connect(c, &SimulationController::runProgress, params_, &ParameterPanel::setProgress);
  // The view.
  connect(view_, &TissueView::sitePicked, c, &SimulationController::pickSite);
  // A picked site is framed once it is prepared (View ▸ Frame a picked site); the view has the
  // snapshot by then (connected first).
  connect(view_, &TissueView::sitePicked, this,
          [this] { framePending_ = frameSite_->isChecked() && !controller_->running(); });
  connect(c, &SimulationController::snapshotReady, this, [this](const Snapshot& s) {
    if (!framePending_ || s.phase != Snapshot::Phase::Prepared || !s.newSite) return;
    framePending_ = false;
    view_->zoomToProbe();
  });
  connect(c, &SimulationController::solveFailed, this, [this] { framePending_ = false; });
  connect(c, &SimulationController::settingsRefused, this, [this] { framePending_ = false; });
  connect(view_, &TissueView::pickRejected, this,
          [this](const QString& why) { statusBar()->showMessage(why, 5000); });
  connect(view_, &TissueView::hoverChanged, hoverLabel_, &QLabel::setText);
  connect(display_, &DisplayPanel::fieldChanged, view_, &TissueView::setField);
  connect(display_, &DisplayPanel::colorMapChanged, view_, &TissueView::setColorMapKind);
  connect(display_, &DisplayPanel::autoRangeChanged, view_, &TissueView::setAutoRange);
  connect(display_, &DisplayPanel::deformationScaleChanged, view_,
          &TissueView::setDeformationScale);
  connect(display_, &DisplayPanel::rangeChanged, view_, &TissueView::setRange);
  connect(display_, &DisplayPanel::outlinesChanged, view_, &TissueView::setOutlinesVisible);
  connect(display_, &DisplayPanel::meshChanged, view_, &TissueView::setMeshVisible);
  connect(display_, &DisplayPanel::glyphsChanged, view_, &TissueView::setGlyphsVisible);
  connect(view_, &TissueView::siteMarkerClicked, this, &MainWindow::selectSite);
  connect(display_, &DisplayPanel::sectionChanged, view_, &TissueView::setSection);
  connect(view_, &TissueView::rangeChanged, display_, &DisplayPanel::showRange);
  connect(c, &SimulationController::fitFinished, this, &MainWindow::showFit);
  // The stiffness map: colours, site dots, clicks for a site's curve.
  connect(display_, &DisplayPanel::mapValueChanged, view_, &TissueView::setMapValue);
  connect(mapRunner_, &MapRunner::mapChanged, this, [this] {
    std::vector<Eigen::Vector3d> sites;
    if (mapRunner_->hasMap())
      for (const TaskResult& r : mapRunner_->map().results)
        if (r.task >= 0 && r.converged() && r.contact.allFinite()) sites.push_back(r.contact);
    view_->setMap(mapRunner_->field(), std::move(sites));
  });
  connect(c, &SimulationController::snapshotReady, mapRunner_, [this](const Snapshot& s) {
    if (!s.empty()) mapRunner_->setTissue(s.geometry->path, s.geometry->meanCellSize);
  });
  connect(mapPanel_, &MapPanel::showRequested, this, [this] { display_->showMapValue(0); });
  connect(mapPanel_, &MapPanel::statusMessage, this,
          [this](const QString& m) { statusBar()->showMessage(m, 8000); });
  connect(view_, &TissueView::mapPointPicked, this, &MainWindow::showMapSite);
  // Earlier sites on the tissue, the selected curve's highlighted.
  connect(c, &SimulationController::sitesChanged, this, &MainWindow::updateSiteMarkers);
  connect(c, &SimulationController::curvesChanged, this, &MainWindow::updateSiteMarkers);
  connect(plot_, &PlotPanel::selectionChanged, this, &MainWindow::updateSiteMarkers);
  // The plot and the files.
  connect(plot_, &PlotPanel::removeRequested, c, &SimulationController::removeCurve);
  connect(plot_, &PlotPanel::clearRequested, this, [this, c] {
    // Every curve goes: ask first (they may not be saved anywhere).
    const int n = static_cast<int>(c->curves().size());
    if (n == 0) return;
    const auto answer = QMessageBox::question(
        this, tr("Remove every curve"),
        c->hasUnsavedCurves()
            ? tr("Remove all %n curve(s)? They have not been saved.", "", n)
            : tr("Remove all %n curve(s)?", "", n),
        QMessageBox::Yes | QMessageBox::No, QMessageBox::No);
    if (answer == QMessageBox::Yes) c->clearCurves();
  });
  connect(files_, &FileActions::recentFilesChanged, this, &MainWindow::updateRecentMenu);
  connect(files_, &FileActions::statusMessage, this,
          [this](const QString& m) { statusBar()->showMessage(m, 5000); });
}

void MainWindow::updateRecentMenu() {
  recentMenu_->clear();
  const QStringList files = RecentFiles::list();
  for (const QString& f : files)
    connect(recentMenu_->addAction(QFileInfo(f).fileName()), &QAction::triggered, this,
            [this, f] { files_->open(f); });
  if (!files.isEmpty()) recentMenu_->addSeparator();
  QAction* clear = recentMenu_->addAction(tr("Clear the list"));
  clear->setEnabled(!files.isEmpty());
  connect(clear, &QAction::triggered, this, [this] {
    RecentFiles::clear();
    updateRecentMenu();
  });
}

void MainWindow::showExplanation() {
  if (!explanation_) {
    explanation_ = new QDialog(this);
    explanation_->setObjectName("explanationDialog");
    explanation_->setWindowTitle(tr("What you see"));
    auto* text = new QTextBrowser;
    text->setObjectName("explanationText");
    QFile page(":/help/what-you-see.html");
    text->setHtml(page.open(QIODevice::ReadOnly) ? QString::fromUtf8(page.readAll())
                                                 : tr("The help page is missing from this build."));
    text->setOpenExternalLinks(true);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Close);
    connect(buttons, &QDialogButtonBox::rejected, explanation_, &QDialog::hide);
    auto* layout = new QVBoxLayout(explanation_);
    layout->addWidget(text);
    layout->addWidget(buttons);
    explanation_->resize(620, 640);
  }
  explanation_->show();  // not modal: it can stay open beside the window
  explanation_->raise();
}

void MainWindow::setPresentation(bool on) {
  static const char* const kSideDocks[] = {"parametersDock", "displayDock", "mapDock"};
  if (on == !normalState_.isEmpty()) return;
  // Larger fonts on what stays in view (menus, tool and status bars, the curves' dock), not on
  // the application: the hidden docks keep theirs, so nothing grows the window's minimum size.
  QWidget* const large[] = {menuBar(), statusBar(), findChild<QDockWidget*>("plotDock")};
  if (on) {
    normalState_ = saveState();
    for (const char* name : kSideDocks)
      if (auto* d = findChild<QDockWidget*>(name)) d->hide();
    if (auto* c = findChild<QDockWidget*>("plotDock")) c->show();
    for (QWidget* w : large) {
      if (!w) continue;
      QFont f = QApplication::font(w);
      f.setPointSizeF(f.pointSizeF() * 1.5);
      w->setFont(f);
    }
    view_->setOverlayScale(1.6);
    plot_->setPresentation(true);
    statusBar()->showMessage(tr("Presentation: F5 to go back"), 4000);
  } else {
    for (QWidget* w : large)
      if (w) w->setFont(QFont());  // inherit again
    restoreState(normalState_);
    normalState_.clear();
    view_->setOverlayScale(1.0);
    plot_->setPresentation(false);
  }
  if (presentation_->isChecked() != on) presentation_->setChecked(on);
}

void MainWindow::showControls() {
  QMessageBox::information(
      this, tr("Mouse and keys"),
      tr("Left drag: turn the tissue (turntable, or arcball from the View menu)\n"
         "Shift+left or middle drag: pan · Wheel: zoom\n"
         "Hover: the cell under the cursor is highlighted and named in the status bar\n"
         "Left click on the outer surface: choose the indentation site\n"
         "Right drag or Ctrl+left drag (vertically): push the probe in or pull it out\n"
         "Arrows: turn · +/-: zoom · F: fit · 1/3/7: front/right/top · R: reset · "
         "Z: zoom to the probe\n"
         "Space: run the curve · Esc: cancel"));
}

void MainWindow::askFit() {
  QDialog dialog(this);
  dialog.setWindowTitle(tr("Fit measured curves"));
  auto* form = new QFormLayout(&dialog);
  form->addRow(new QLabel(tr("Fit to every measured curve, at the current site, from the current "
                             "parameters (the others held):")));
  auto* e = new QCheckBox(tr("E, the walls' Young modulus"));
  auto* p = new QCheckBox(tr("p, the turgor pressure"));
  auto* h = new QCheckBox(tr("h, the wall thickness"));
  auto* o = new QCheckBox(tr("a contact-point offset per curve"));
  e->setChecked(true);
  p->setChecked(true);
  for (QCheckBox* b : {e, p, h, o}) form->addRow(b);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
  buttons->button(QDialogButtonBox::Ok)->setText(tr("Fit"));
  connect(buttons, &QDialogButtonBox::accepted, &dialog, &QDialog::accept);
  connect(buttons, &QDialogButtonBox::rejected, &dialog, &QDialog::reject);
  form->addRow(buttons);
  if (dialog.exec() != QDialog::Accepted) return;
  QString why;
  if (!controller_->fitMeasuredCurves(e->isChecked(), p->isChecked(), h->isChecked(),
                                      o->isChecked(), &why))
    QMessageBox::warning(this, tr("Cannot fit"), why);
}

void MainWindow::showFit(const FitOutcome& outcome) {
  if (!outcome.ok || !outcome.result) {
    QMessageBox::warning(this, tr("Fit failed"), outcome.message);
    return;
  }
  const FitResult& r = *outcome.result;
  QString text;
  for (const FitValue& v : r.values) {
    if (v.fitted)
      text += tr("%1 = %2 ± %3 %4   (95 %: %5 to %6)\n")
                  .arg(QString::fromStdString(v.key))
                  .arg(v.value, 0, 'g', 5)
                  .arg(v.error, 0, 'g', 2)
                  .arg(QString::fromStdString(v.unit))
                  .arg(v.value - 1.96 * v.error, 0, 'g', 5)
                  .arg(v.value + 1.96 * v.error, 0, 'g', 5);
    else
      text += tr("%1 = %2 %3 (held)\n")
                  .arg(QString::fromStdString(v.key))
                  .arg(v.value, 0, 'g', 5)
                  .arg(QString::fromStdString(v.unit));
  }
  for (int i = 0; i < r.correlation.rows(); ++i)
    for (int j = i + 1; j < r.correlation.cols(); ++j)
      text += tr("correlation %1–%2: %3\n")
                  .arg(QString::fromStdString(r.fittedKeys[i]))
                  .arg(QString::fromStdString(r.fittedKeys[j]))
                  .arg(r.correlation(i, j), 0, 'f', 3);
  text += tr("rms residual %1 µN (%2 µN at the start)\n").arg(r.rms, 0, 'g', 3).arg(r.rmsStart, 0, 'g', 3);
  for (size_t i = 0; i < r.curves.size(); ++i) {
    text += tr("curve %1: Hertz apparent modulus %2 MPa, mesh level %3")
                .arg(i + 1)
                .arg(r.curves[i].hertzModulus, 0, 'g', 4)
                .arg(r.curves[i].meshLevel);
    // The automatic mesh's error at the fitted values, which E (∝ the forces) carries too.
    if (r.curves[i].meshError.estimated())
      text += tr(" (discretisation error ±%1 % at the fitted values)")
                  .arg(100 * r.curves[i].meshError.relative, 0, 'g', 2);
    text += "\n";
  }
  if (!r.converged) text += tr("\nThe fit did not converge: %1\n").arg(outcome.message);
  if (!r.advice.empty()) text += "\n" + QString::fromStdString(r.advice);
  QMessageBox box(r.identifiable && r.converged ? QMessageBox::Information : QMessageBox::Warning,
                  tr("Fit of the measured curves"), text, QMessageBox::Ok, this);
  box.setObjectName("fitResult");
  box.exec();
}

void MainWindow::showMapSite(const Eigen::Vector3d& restPoint) {
  // The site nearest the click, within half a cell: its curve joins the plot.
  NamedCurve curve;
  const double within = 0.5 * std::max(controller_->meanCellSize(), 1.0);
  const int task = mapRunner_->siteCurve(restPoint, within, &curve);
  if (task < 0) {
    statusBar()->showMessage(
        mapRunner_->hasMap()
            ? tr("No map site here: click on a dot (or choose a quantity to pick indentation sites)")
            : tr("No stiffness map yet: Simulation ▸ Stiffness map"),
        5000);
    return;
  }
  const TaskResult* r = &mapRunner_->map().results[task];
  const auto& curves = controller_->curves();
  if (std::none_of(curves.begin(), curves.end(),
                   [&](const NamedCurve& c) { return c.name == curve.name; }))
    controller_->addSimulatedCurve(std::move(curve));
  statusBar()->showMessage(tr("%1: force %2 µN at %3 µm, secant %4 µN/µm, tangent %5 µN/µm, "
                                "Hertz %6 MPa, mesh level %7%8")
                                 .arg(QString::fromStdString(mapRunner_->map().plan.site(r->task).label))
                                 .arg(r->force, 0, 'g', 4)
                                 .arg(r->depth, 0, 'g', 3)
                                 .arg(r->secant, 0, 'g', 4)
                                 .arg(r->tangent, 0, 'g', 4)
                                 .arg(r->hertz, 0, 'g', 4)
                                 .arg(r->level)
                                 .arg(r->meshError >= 0
                                          ? tr(", mesh error ±%1 %").arg(100 * r->meshError, 0, 'g', 2)
                                          : QString()));
}

bool MainWindow::selectSite(int number) {
  const auto& curves = controller_->curves();
  for (int k = static_cast<int>(curves.size()) - 1; k >= 0; --k)
    if (controller_->siteOfCurve(k) == number - 1) {
      plot_->setSelectedCurve(k);  // the list, the graph and the disc follow
      statusBar()->showMessage(tr("Site %1: its newest curve is selected").arg(number), 4000);
      return true;
    }
  statusBar()->showMessage(tr("Site %1 has no curve yet").arg(number), 4000);
  return false;
}

void MainWindow::updateSiteMarkers() {
  // A site takes the colour of its newest curve.
  const auto& sites = controller_->sites();
  const auto& curves = controller_->curves();
  std::vector<TissueView::SiteMarker> markers(sites.size());
  for (size_t i = 0; i < sites.size(); ++i) {
    markers[i].position = sites[i];
    markers[i].number = static_cast<int>(i) + 1;
  }
  for (size_t k = 0; k < curves.size(); ++k)
    if (const int i = controller_->siteOfCurve(static_cast<int>(k)); i >= 0)
      markers[i].colour = PlotPanel::colourOf(curves[k], static_cast<int>(k));
  const int selected = plot_->selectedCurve();
  if (selected >= 0 && selected < static_cast<int>(curves.size()))
    if (const int i = controller_->siteOfCurve(selected); i >= 0) markers[i].highlighted = true;
  // The current site has the probe on it: no disc over the contact, unless it is selected.
  const int current = controller_->currentSite();
  if (current >= 0 && current < static_cast<int>(markers.size()) && !markers[current].highlighted)
    markers.erase(markers.begin() + current);
  view_->setSiteMarkers(std::move(markers));
}

bool MainWindow::eventFilter(QObject* watched, QEvent* e) {
  if ((e->type() == QEvent::KeyPress || e->type() == QEvent::ShortcutOverride) &&
      qobject_cast<QAbstractSpinBox*>(watched)) {
    const auto* key = static_cast<QKeyEvent*>(e);
    if (key->key() == Qt::Key_Space && key->modifiers() == Qt::NoModifier) {
      e->accept();  // (an accepted ShortcutOverride keeps the Run shortcut from firing)
      return true;
    }
  }
  return QMainWindow::eventFilter(watched, e);
}

void MainWindow::closeEvent(QCloseEvent* e) {
  // Curves made since the last save would be lost: save, discard or stay.
  if (controller_->hasUnsavedCurves()) {
    const int n = static_cast<int>(controller_->curves().size());
    const auto answer = QMessageBox::question(
        this, tr("Unsaved curves"),
        tr("%n curve(s) have not been saved. Save the session before quitting?", "", n),
        QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel, QMessageBox::Save);
    if (answer == QMessageBox::Cancel || (answer == QMessageBox::Save && !files_->saveSessionDialog())) {
      e->ignore();
      return;
    }
  }
  setPresentation(false);  // the layout remembered is the working one, not the lecture's
  files_->autosave()->finish();  // a clean exit: nothing to recover
  QSettings settings;
  settings.setValue("window/geometry", saveGeometry());
  settings.setValue("window/state", saveState());
  controller_->cancelRun();
  QMainWindow::closeEvent(e);
}

void MainWindow::dragEnterEvent(QDragEnterEvent* e) {
  for (const QUrl& url : e->mimeData()->urls())
    if (url.isLocalFile()) {
      e->acceptProposedAction();
      return;
    }
}

void MainWindow::dropEvent(QDropEvent* e) {
  for (const QUrl& url : e->mimeData()->urls())
    if (url.isLocalFile()) {
      files_->open(url.toLocalFile());
      e->acceptProposedAction();
      return;
    }
}

}  // namespace tp::gui
